//! Genuine subharmonics: leaving the `K`-fold repeated branch.
//!
//! A motion on the harmonics that are multiples of `K` only is `T/K`-periodic: it is the
//! nonsmooth mode of period `T/K` traced `K` times. This subspace `V_K` is invariant under
//! harmonic balance: the linear rows act harmonic by harmonic, and the law samples of a
//! motion in `V_K` are `T/K`-periodic, so their Gram matrices (Toeplitz + Hankel for the
//! cosines) couple harmonic `n` only with `n +- jK`. The Jacobian at a point of `V_K` is
//! therefore block diagonal: the block of `V_K` and the block `J_C` of the complement (the
//! harmonics that are not multiples of `K`). Newton's method started in `V_K` never leaves it,
//! and a branch that is genuinely `T`-periodic emanates from the repeated one only where
//! `J_C` is singular (a symmetry-breaking bifurcation), or exists apart from it.
//!
//! [`symmetry_breaking_direction`] finds the direction of `J_C` closest to singular (inverse
//! iteration) with its singularity measure; [`leave_subspace`] perturbs a point of the
//! repeated branch along it and solves, keeping a solution only if its share of the energy
//! off the multiples of `K` ([`subharmonic_share`]) is at least [`GENUINE_SHARE`].

use crate::branches::backbone::{backbone_with, BackboneOptions};
use crate::branches::point::{BackbonePoint, PointStatus, Timescale};
use crate::continuation::{
    linspace, ContinuationProblem, EndReason, PeriodParametrised, Sequential, Step,
};
use crate::error::{ContinuationError, Error};
use crate::fourier::{frequency_of_period, Basis};
use crate::linalg::{DenseMatrix, Lu};
use crate::modal::energy::energy;
use crate::modal::signature::subharmonic_share;
use crate::solve::{NonlinearSolver, Problem};
use crate::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};
use std::ops::ControlFlow;

/// Least share of the time-averaged energy off the multiples of `K` for a motion to count as
/// genuinely subharmonic (the repeated branch's share is rounding, below `1e-12`).
pub const GENUINE_SHARE: f64 = 1e-3;

/// Inverse-iteration steps of [`symmetry_breaking_direction`].
const INVERSE_ITERATIONS: usize = 4;

/// Perturbation sizes of [`leave_subspace`], relative to the largest unknown of the point.
pub const NUDGES: [f64; 4] = [0.1, -0.1, 0.5, -0.5];

/// The rows and columns of the complement block: the indices of the unknowns and of the
/// equations of the coefficients whose harmonic is not a multiple of `k`.
fn complement<B: Basis>(problem: &NonsmoothSystem<B>, k: usize) -> (Vec<usize>, Vec<usize>) {
    let basis = problem.basis();
    let len = basis.len();
    let per = problem.system().unknowns_per_harmonic();
    let laws = problem.system().contact_count();
    let linear = per - laws;
    let off: Vec<usize> = (0..len).filter(|&i| basis.harmonic(i) % k != 0).collect();
    let columns = off.iter().flat_map(|&i| i * per..(i + 1) * per).collect();
    let rows = off
        .iter()
        .flat_map(|&i| i * linear..(i + 1) * linear)
        .chain((0..laws).flat_map(|l| off.iter().map(move |&i| len * linear + l * len + i)))
        .collect();
    (rows, columns)
}

/// The direction in which the complement block `J_C` of the Jacobian at `x` (frequency
/// `omega`, a point of the `k`-fold repeated branch) is closest to singular, as a vector of
/// the problem's unknowns (zero on the multiples of `k`, unit largest entry), with the
/// measure `|J_C d| / (|J_C|_max |d|)` of its singularity (0 where `J_C` is exactly
/// singular). `None` for `k < 2`, a basis without such harmonics, or a non-finite Jacobian.
pub fn symmetry_breaking_direction<B: Basis>(
    problem: &mut NonsmoothSystem<B>,
    x: &[f64],
    omega: f64,
    k: usize,
) -> Option<(Vec<f64>, f64)> {
    if k < 2 || x.len() != problem.dimension() {
        return None;
    }
    let (rows, columns) = complement(problem, k);
    let c = columns.len();
    if c == 0 {
        return None;
    }
    problem.set_parameter(omega);
    let n = problem.dimension();
    let mut f = vec![0.0; n];
    problem.residual(x, &mut f);
    let mut jac = DenseMatrix::zeros(n, n);
    problem.jacobian(x, &mut jac);
    let mut block = DenseMatrix::zeros(c, c);
    let mut size: f64 = 0.0;
    for (b, &j) in columns.iter().enumerate() {
        for (a, &i) in rows.iter().enumerate() {
            block[(a, b)] = jac[(i, j)];
            size = size.max(jac[(i, j)].abs());
        }
    }
    if !(block.is_finite() && size > 0.0) {
        return None;
    }
    // An exactly singular block has a null direction the LU cannot give: shift by a
    // rounding-sized multiple of the identity.
    let lu = Lu::factor(&block, 0.0).ok().or_else(|| {
        let mut shifted = block.clone();
        (0..c).for_each(|i| shifted[(i, i)] += 1e-12 * size);
        Lu::factor(&shifted, 0.0).ok()
    })?;
    let mut d: Vec<f64> = (0..c).map(|i| 1.0 + (i % 7) as f64 / 7.0).collect();
    for _ in 0..INVERSE_ITERATIONS {
        lu.solve_in_place(&mut d);
        let largest = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if !(largest.is_finite() && largest > 0.0) {
            return None;
        }
        d.iter_mut().for_each(|v| *v /= largest);
    }
    let mut image = vec![0.0; c];
    block.mul_vec(&d, &mut image);
    let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
    let measure = norm(&image) / (size * norm(&d));
    let mut direction = vec![0.0; n];
    for (&j, v) in columns.iter().zip(&d) {
        direction[j] = *v;
    }
    Some((direction, measure))
}

/// A genuinely subharmonic solution near `x`, a point of the `k`-fold repeated branch at
/// `omega`: `x` perturbed along [`symmetry_breaking_direction`] by the sizes of [`NUDGES`]
/// (relative to the largest unknown of `x`), each solved by `solver`, the first whose energy
/// is above `floor` and whose [`subharmonic_share`] is at least [`GENUINE_SHARE`]. `None` if
/// none is.
pub fn leave_subspace<B: Basis>(
    problem: &mut NonsmoothSystem<B>,
    solver: &dyn NonlinearSolver,
    (x, omega): (&[f64], f64),
    k: usize,
    floor: f64,
) -> Option<Vec<f64>> {
    let (direction, _) = symmetry_breaking_direction(problem, x, omega, k)?;
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for nudge in NUDGES {
        let mut y: Vec<f64> = (x.iter().zip(&direction))
            .map(|(v, d)| v + nudge * scale * d)
            .collect();
        problem.set_parameter(omega);
        if solver.solve(problem, &mut y).is_err() {
            continue;
        }
        let (system, basis) = (problem.system(), problem.basis());
        let genuine = energy(system, basis, &y, omega) > floor
            && subharmonic_share(system, basis, &y, omega, k).is_ok_and(|s| s >= GENUINE_SHARE);
        if genuine {
            return Some(y);
        }
    }
    None
}

/// A genuinely subharmonic backbone: the `K`-fold repeated branch of `options` (`K =
/// options.subharmonic >= 2`) by [`backbone_with`], each converged point of which is tried
/// with [`leave_subspace`] until one leaves the subspace of the multiples of `K`; from there,
/// the rest of the period grid is continued on the genuine branch, whose points must keep a
/// share of at least [`GENUINE_SHARE`] off the multiples of `K` (else they are
/// [`PointStatus::Rejected`]: back on the repeated branch; or
/// [`PointStatus::CollapsedToRest`]). Every point of both stages goes
/// to `observer`, in step order. Returns `E_g` and the end reason of the stage that ended the
/// run (the repeated stage's if no point left the subspace).
///
/// # Errors
/// As [`backbone_with`]; [`ContinuationError::InvalidOption`] for `K < 2`.
pub(crate) fn genuine_subharmonic_backbone_with<S: NonlinearSolver>(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    options: &BackboneOptions,
    solver: S,
    mut observer: impl FnMut(BackbonePoint) -> ControlFlow<()>,
) -> Result<(f64, EndReason), Error> {
    let k = options.subharmonic;
    if k < 2 {
        return Err(ContinuationError::InvalidOption {
            what: "subharmonic order of a genuine subharmonic (at least 2)",
            value: k as f64,
        }
        .into());
    }
    let mut problem = NonsmoothSystem::new(system, settings)?;
    let mut switched: Option<(Vec<f64>, usize)> = None;
    let mut floor = f64::NAN;
    let mut stopped = false;
    let (e_g, end) = backbone_with(system, settings, options, &solver, |p: BackbonePoint| {
        // A converged point is tried off the subspace before it is moved to the observer
        // (the observer keeps it; its unknowns are not copied). If the observer stops the
        // run, the switch found is not taken.
        let left = p.converged().then(|| {
            floor = options.trivial_energy * p.energy / p.energy_normalized;
            leave_subspace(&mut problem, &solver, (&p.x, p.omega), k, floor).map(|y| (y, p.step))
        });
        if observer(p).is_break() {
            stopped = true;
            return ControlFlow::Break(());
        }
        match left.flatten() {
            Some(found) => {
                switched = Some(found);
                ControlFlow::Break(())
            }
            None => ControlFlow::Continue(()),
        }
    })?;
    let (Some((start, at)), false) = (switched, stopped) else {
        return Ok((e_g, end));
    };
    let grid = options.grid;
    let values = linspace(grid.start, grid.end, grid.steps)?.split_off(at);
    let omega = frequency_of_period(values[0]);
    problem.set_parameter(omega);
    let basis = problem.basis().clone();
    let mut driver = Sequential::new(
        PeriodParametrised::new(problem),
        &solver,
        start,
        values,
        options.sequential(),
    )?
    // The energy floor below decides what counts as rest.
    .with_rest_accepted()
    .with_acceptance(|x, period| {
        let omega = frequency_of_period(period);
        energy(system, &basis, x, omega) > floor
            && subharmonic_share(system, &basis, x, omega, k).is_ok_and(|s| s >= GENUINE_SHARE)
    });
    let branch = driver.run(&mut |step: &Step| {
        let Some(p) = step.point() else {
            return ControlFlow::Continue(());
        };
        let time = Timescale::of_period(p.parameter);
        let e = energy(system, &basis, &p.x, time.omega);
        let refused = if e > floor {
            PointStatus::Rejected
        } else {
            PointStatus::CollapsedToRest
        };
        let status = PointStatus::refused_as(p, refused);
        let mut point = BackbonePoint::from_parts(p, (&p.x, time), e, e_g, status);
        point.step += at + 1;
        observer(point)
    });
    Ok((e_g, branch.end))
}
