//! Lettered motions that the figures' continued branches miss, sought as isolated solutions
//! at fixed frequencies from seeds that combine two linear modes on chosen harmonics.
//!
//! A point found here is converged, above rest, passes the time-domain check of the library's
//! backbones ([`TimeDomainCheck::for_system`]) and has the character its caller asks; it is a
//! solution at its frequency, not a continued branch, and the figures draw it beside their
//! branches.

use crate::common::{settings, Res};
use crate::runs::solved_point;
use nonsmooth_modes::branches::{BackbonePoint, TimeDomainCheck};
use nonsmooth_modes::continuation::ContinuationProblem;
use nonsmooth_modes::fourier::CosineBasis;
use nonsmooth_modes::modal::branch_seed;
use nonsmooth_modes::solve::{NonlinearSolver, SemismoothNewton};
use nonsmooth_modes::system::{BarSystem, NonsmoothSystem};
use nonsmooth_modes::verify::periodicity_check;

/// Energies `E/E_g` below this are rest: a seed can slide to it.
const ABOVE_REST: f64 = 1e-3;

/// A seed `a * first + b * second`, each part a system mode (1-based) on a harmonic, at the
/// linear mode's grazing amplitude ([`branch_seed`]), for each `(a, b)` of `weights`.
pub struct Combination<'w> {
    pub first: (usize, usize),
    pub second: (usize, usize),
    pub weights: &'w [(f64, f64)],
}

/// The first solution with the character `has`, over the frequencies `omegas` in their
/// order and the weights of `seed` in theirs, with `m` harmonics; `None` when no seed
/// converges to one.
pub fn seek(
    system: &BarSystem,
    basis: &CosineBasis,
    m: usize,
    omegas: &[f64],
    seed: &Combination<'_>,
    mut has: impl FnMut(&BackbonePoint) -> Res<bool>,
) -> Res<Option<BackbonePoint>> {
    let mut problem = NonsmoothSystem::new(system, settings(m))?;
    let solver = SemismoothNewton::default();
    let check = TimeDomainCheck::for_system(system);
    for &omega in omegas {
        let first = branch_seed(&mut problem, seed.first.0, seed.first.1, omega)?;
        let second = branch_seed(&mut problem, seed.second.0, seed.second.1, omega)?;
        for &(a, b) in seed.weights {
            let mut x: Vec<f64> = (first.iter().zip(&second))
                .map(|(u, v)| a * u + b * v)
                .collect();
            problem.set_parameter(omega);
            let Ok(info) = solver.solve(&mut problem, &mut x) else {
                continue;
            };
            let mut point = solved_point(system, basis, (x, omega), &info)?;
            if point.energy_normalized <= ABOVE_REST || !has(&point)? {
                continue;
            }
            point.time_domain =
                periodicity_check(system, basis, &point.x, omega, &check.options).ok();
            if point
                .time_domain
                .is_some_and(|r| r.displacement_defect <= check.max_displacement_defect)
            {
                return Ok(Some(point));
            }
        }
    }
    Ok(None)
}

/// `n` frequencies spread over `[lo, hi]` (the ends left out), nearest `target` first.
pub fn nearest_first(lo: f64, hi: f64, n: usize, target: f64) -> Vec<f64> {
    let mut v: Vec<f64> = (1..=n)
        .map(|k| lo + (hi - lo) * k as f64 / (n + 1) as f64)
        .collect();
    v.sort_by(|a, b| (a - target).abs().total_cmp(&(b - target).abs()));
    v
}
