//! `--basis full`: the branch of the period grid continued in the constant + cosine + sine
//! basis (`branches::full_basis_branch`) from the cosine run's first converged point.

use crate::args::Args;
use nonsmooth_modes::branches::{
    compute, full_basis_branch, full_basis_system, to_full_basis, Method, Request, TimeDomainCheck,
};
use nonsmooth_modes::continuation::linspace;
use nonsmooth_modes::system::BarSystem;
use nonsmooth_modes::verify::periodicity_check;
use std::io::Write;

/// The columns of a full-basis run.
const HEADER: &str = "step,period,omega,energy,energy_normalized,converged,status,unfolding,\
                      sine_share,asymmetry,residual_norm,iterations";

/// Runs the grid `request` in the cosine basis for its start, then the full basis over the
/// same periods from there; writes one row per period and returns `(rows, converged)`.
pub fn run_full_basis(
    a: &Args,
    system: &BarSystem,
    request: &Request,
    (t0, t1): (f64, f64),
    out: &mut dyn Write,
) -> Result<(usize, usize), Box<dyn std::error::Error>> {
    let verify = a.verify.then(|| TimeDomainCheck::for_system(system));
    let extra = if verify.is_some() {
        ",periodicity_defect,displacement_defect"
    } else {
        ""
    };
    writeln!(out, "{HEADER}{extra}")?;
    let request = match request.method {
        Method::PeriodGrid(_) => request.clone(),
        _ => return Err("--basis full continues the period grid".into()),
    };
    let cosine = compute(system, &request)?;
    let periods = linspace(t0, t1, a.steps)?;
    let Some(first) = cosine.points.iter().find(|p| p.converged) else {
        return Err("--basis full: the cosine run found no start on the grid".into());
    };
    let start = to_full_basis(&first.x, a.settings.harmonics);
    let solver = request.solver_for(&request.method)?;
    let rest = periods[first.step..].to_vec();
    let full = full_basis_branch(system, &a.settings, &start, rest, solver)?;
    let basis = full_basis_system(system, &a.settings)?.basis().clone();
    let mut converged = 0;
    for (step, &period) in periods.iter().enumerate() {
        let point = full.points.iter().find(|p| p.step + first.step == step);
        let Some(p) = point else {
            let status = if step < first.step {
                "before-start"
            } else {
                "rejected"
            };
            let omega = 2.0 * std::f64::consts::PI / period;
            let empty = ",".repeat(5 + 2 * usize::from(verify.is_some()));
            writeln!(out, "{step},{period},{omega},,,false,{status}{empty}")?;
            continue;
        };
        converged += 1;
        write!(
            out,
            "{step},{},{},{:e},{},true,converged,{:e},{:e},{:e},{:e},{}",
            p.period,
            p.omega,
            p.energy,
            p.energy_normalized,
            p.unfolding,
            p.sine_share,
            p.asymmetry,
            p.residual_norm,
            p.iterations
        )?;
        if let Some(check) = &verify {
            match periodicity_check(system, &basis, &p.x, p.omega, &check.options) {
                Ok(r) => write!(out, ",{:e},{:e}", r.defect, r.displacement_defect)?,
                Err(e) => {
                    eprintln!("backbone: step {step} not checked: {e}");
                    write!(out, ",,")?;
                }
            }
        }
        writeln!(out)?;
    }
    eprintln!(
        "backbone: full basis from step {} ended: {:?}; {} rejected steps",
        first.step,
        full.end,
        full.rejected.len()
    );
    Ok((periods.len(), converged))
}
