//! Branches in the full Fourier basis (`branches::full_basis_branch`) from any start, over
//! any periods, with any settings and solver.

use super::solvers::request_solver;
use super::{reference_system, settings};
use crate::checks::{typed, CaseResult, Checks};
use crate::draw::Draw;
use nonsmooth_modes::branches::{
    full_basis_branch, full_basis_system, to_full_basis, Request, TimeDomainCheck,
};
use nonsmooth_modes::fourier::frequency_of_period;
use nonsmooth_modes::modal::branch_seed;
use nonsmooth_modes::system::NonsmoothSystem;

/// A full-basis branch from a scaled cosine seed, a seed with sines or any vector, over a
/// few periods (some bad); every number of a point it returns is finite and each point's
/// step is one of the asked periods.
pub(crate) fn full_basis_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let system = reference_system(d, c)?;
    let s = settings(d);
    let base = 3.9 * d.real("period factor", 0.5..=2.0);
    // The list is the caller's own memory: its edge sizes are capped (0 stays, a typed error).
    let steps = d.size("steps", 1..=6).min(6);
    let periods: Vec<f64> = (0..steps)
        .map(|k| d.real("period", base * (1.0 - 0.02 * k as f64)..=base))
        .collect();
    let full = typed(c, "full basis system", full_basis_system(&system, &s))?;
    let n = full.dimension();
    let start = match d.pick("start", &["seed", "seed with sines", "any"]) {
        "any" => (0..n)
            .map(|_| d.real("coefficient", -1e-3..=1e-3))
            .collect(),
        kind => {
            let mut cosine = typed(c, "cosine system", NonsmoothSystem::new(&system, s))?;
            let omega = frequency_of_period(periods.first().copied().unwrap_or(base));
            let seed = typed(c, "seed", branch_seed(&mut cosine, 1, 1, omega))?;
            let scale = d.real("seed scale", 0.5..=3.0);
            let mut start = typed(c, "to full basis", to_full_basis(&seed, s.harmonics))?;
            start.iter_mut().for_each(|v| *v *= scale);
            if kind == "seed with sines" {
                let sines = start.len() / (2 * s.harmonics + 1) * (s.harmonics + 1);
                for v in &mut start[sines..] {
                    *v = d.real("sine", -1e-4..=1e-4);
                }
            }
            start
        }
    };
    let mut request = Request::new(1).settings(s);
    request.solver = request_solver(d, c)?;
    if d.flag("time-domain check", 0.2) {
        request = request.checked(TimeDomainCheck::for_system(&system));
    }
    let run = typed(
        c,
        "full basis branch",
        full_basis_branch(&system, &request, &start, periods.clone()),
    )?;
    for p in &run.points {
        let numbers = [
            p.point.period,
            p.point.omega,
            p.point.energy,
            p.point.energy_normalized,
            p.unfolding,
            p.sine_share,
            p.asymmetry,
            p.point.residual_norm,
        ];
        c.finite("full basis point", &numbers);
        c.finite("full basis point x", &p.point.x);
        c.expect(periods.get(p.point.step) == Some(&p.point.period), || {
            format!(
                "full basis point of step {} at T = {}",
                p.point.step, p.point.period
            )
        });
    }
    c.expect(
        run.points.len() + run.rejected.len() <= periods.len(),
        || {
            format!(
                "{} points and {} rejections from {} periods",
                run.points.len(),
                run.rejected.len(),
                periods.len()
            )
        },
    );
    Ok(())
}
