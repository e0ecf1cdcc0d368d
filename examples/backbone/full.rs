//! `--basis full`: the branch of the period grid continued in the constant + cosine + sine
//! basis (`branches::full_basis_branch`) from the cosine run's first converged point.

use crate::args::Args;
use crate::output::{say_check, say_outcomes};
use nonsmooth_modes::branches::{
    compute, full_basis_branch, to_full_basis, Method, Request, TimeDomainCheck,
};
use nonsmooth_modes::continuation::linspace;
use nonsmooth_modes::io::columns::{self, Digits, Group, Row};
use nonsmooth_modes::stability::{HillOptions, StabilityOptions};
use nonsmooth_modes::system::BarSystem;
use std::io::Write;

/// The columns of a full-basis run.
const HEADER: &str = "step,period,omega,energy,energy_normalized,converged,status,unfolding,\
                      sine_share,asymmetry,residual_norm,iterations,label";

/// Runs the grid `request` in the cosine basis for its start, then the full basis over the
/// same periods from there (checked in the time domain with `--verify`); writes one row per
/// period and returns `(rows, converged)`.
pub fn run_full_basis(
    a: &Args,
    system: &BarSystem,
    request: &Request,
    (t0, t1): (f64, f64),
    out: &mut dyn Write,
) -> Result<(usize, usize), Box<dyn std::error::Error>> {
    // After its own columns, those of the library's table that the flags ask for.
    let asked = [
        (Group::Verify, a.verify),
        (Group::Stability, a.stability),
        (Group::Hill, a.hill),
    ];
    let groups: Vec<Group> = asked.iter().filter(|g| g.1).map(|g| g.0).collect();
    let comma = if groups.is_empty() { "" } else { "," };
    writeln!(out, "{HEADER}{comma}{}", columns::header(&groups))?;
    if !matches!(request.method, Method::PeriodGrid(_)) {
        return Err("--basis full continues the period grid".into());
    }
    let cosine = compute(system, request)?;
    let periods = linspace(t0, t1, a.steps)?;
    let Some(first) = cosine.points.iter().find(|p| p.converged()) else {
        return Err("--basis full: the cosine run found no start on the grid".into());
    };
    let full_request = Request {
        solver: Some(request.solver_for(&request.method)?),
        check: a.verify.then(|| TimeDomainCheck::for_system(system)),
        stability: a.stability.then(StabilityOptions::default),
        hill: a.hill.then(HillOptions::default),
        ..request.clone()
    };
    let start = to_full_basis(&first.x, a.settings.harmonics)?;
    let rest = periods[first.step..].to_vec();
    let full = full_basis_branch(system, &full_request, &start, rest)?;
    let mut converged = 0;
    for (step, &period) in periods.iter().enumerate() {
        let found = full
            .points
            .iter()
            .find(|p| p.point.step + first.step == step);
        let Some(p) = found else {
            let status = if step < first.step {
                "before-start"
            } else {
                "rejected"
            };
            let omega = 2.0 * std::f64::consts::PI / period;
            // One empty cell per column after the status: six of its own, then the table's.
            let empty = ",".repeat(6 + columns::columns(&groups).count());
            writeln!(out, "{step},{period},{omega},,,false,{status}{empty}")?;
            continue;
        };
        converged += 1;
        let q = &p.point;
        let label = q
            .label
            .as_ref()
            .map(ToString::to_string)
            .unwrap_or_default();
        write!(
            out,
            "{step},{},{},{:e},{},true,converged,{:e},{:e},{:e},{:e},{},{label}",
            q.period,
            q.omega,
            q.energy,
            q.energy_normalized,
            p.unfolding,
            p.sine_share,
            p.asymmetry,
            q.residual_norm,
            q.iterations
        )?;
        if a.verify {
            say_check(q);
        }
        say_outcomes(q, a.stability, a.hill);
        let mut cells = String::new();
        columns::write_row(&groups, &Row::new(q, Digits::SHORT), &mut cells);
        writeln!(out, "{comma}{cells}")?;
    }
    eprintln!(
        "backbone: full basis from step {} ended: {:?}; {} rejected steps",
        first.step,
        full.end,
        full.rejected.len()
    );
    Ok((periods.len(), converged))
}
