//! Time-domain periodicity check of every point of a backbone, written as CSV.
//!
//! ```text
//! cargo run --release --example verify_mode -- [--system ds|two-bar|exact] [--gap 1e-3]
//!     [--harmonics 20] [--dt 0.0025] [--period-start 3.95 --period-end 3.05 --steps 181]
//!     [--length2 0.95 --speed2 1 --stiffness-ratio 1]
//! ```
//!
//! Columns: `period,energy_normalized,exact_energy_normalized,converged,residual_norm,defect,
//! displacement_defect,initial_penetration,max_penetration,min_contact_force,energy_drift` (the exact energy is
//! that of the clamped bar's first mode, formulation §9, and is empty for the two-bar system).
//! Last comment lines summarise the defects.
//!
//! `--system exact` instead marches the exact first mode of the clamped bar (formulation §9,
//! positive and negative gaps) over one and ten periods and prints its defect, energy drift
//! and penetration.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{
    compute_observed, BackboneOptions, BackbonePoint, Method, PeriodGrid, Request,
};
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, two_bars_in_contact, ClampedFirstMode,
};
use nonsmooth_modes::solve::Solver;
use nonsmooth_modes::system::HarmonicBalanceSettings;
use nonsmooth_modes::verify::{periodicity_check, PeriodicityOptions};
use std::ops::ControlFlow;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut system_kind = String::from("ds");
    let (mut gap, mut harmonics, mut dt) = (1e-3, 20usize, 0.0025);
    let (mut start, mut end, mut steps) = (3.95, 3.05, 181usize);
    let (mut length2, mut speed2, mut ratio) = (0.95, 1.0, 1.0);
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut i = 0;
    while i < args.len() {
        let value = args.get(i + 1).ok_or("missing value")?;
        match args[i].as_str() {
            "--system" => system_kind = value.clone(),
            "--gap" => gap = value.parse()?,
            "--harmonics" => harmonics = value.parse()?,
            "--dt" => dt = value.parse()?,
            "--period-start" => start = value.parse()?,
            "--period-end" => end = value.parse()?,
            "--steps" => steps = value.parse()?,
            "--length2" => length2 = value.parse()?,
            "--speed2" => speed2 = value.parse()?,
            "--stiffness-ratio" => ratio = value.parse()?,
            other => return Err(format!("unknown option {other}").into()),
        }
        i += 2;
    }
    if system_kind == "exact" {
        exact_family(dt)?;
        return Ok(());
    }
    let system = match system_kind.as_str() {
        "ds" => clamped_bar_with_obstacle(gap)?,
        "two-bar" => two_bars_in_contact(Bar::new(length2, speed2, ratio)?, gap)?,
        other => return Err(format!("unknown system {other}").into()),
    };
    let settings = HarmonicBalanceSettings {
        harmonics,
        ..Default::default()
    };
    let basis = settings.cosine_basis()?;
    let options = BackboneOptions::on_grid(PeriodGrid { start, end, steps }, 1, 1);
    let request = Request {
        settings,
        method: Method::PeriodGrid(options),
        solver: Some(Solver::default()),
        ..Request::new(1)
    };
    let check = PeriodicityOptions {
        dt,
        ..Default::default()
    };
    println!("period,energy_normalized,exact_energy_normalized,converged,residual_norm,defect,displacement_defect,initial_penetration,max_penetration,min_contact_force,energy_drift");
    let mut defects = Vec::new();
    let mut failure = None;
    compute_observed(&system, &request, |p: &BackbonePoint| {
        let exact = if system_kind == "ds" {
            format!(
                "{:.6}",
                ClampedFirstMode::new(gap, p.period).energy_normalized()
            )
        } else {
            String::new()
        };
        match periodicity_check(&system, &basis, &p.x, p.omega, &check) {
            Ok(r) => {
                if p.converged() {
                    defects.push((r.defect, r.displacement_defect));
                }
                println!(
                    "{:.4},{:.6},{},{},{:.3e},{:.4e},{:.4e},{:.3e},{:.3e},{:.4e},{:.3e}",
                    p.period,
                    p.energy_normalized,
                    exact,
                    p.converged(),
                    p.residual_norm,
                    r.defect,
                    r.displacement_defect,
                    r.initial_penetration / gap,
                    r.max_penetration / gap,
                    r.min_contact_force,
                    r.energy_drift
                );
                ControlFlow::Continue(())
            }
            Err(e) => {
                failure = Some(e);
                ControlFlow::Break(())
            }
        }
    })?;
    if let Some(e) = failure {
        return Err(e.into());
    }
    for (name, pick) in [("energy-norm defect", 0), ("displacement defect", 1)] {
        let mut d: Vec<f64> = defects
            .iter()
            .map(|x| if pick == 0 { x.0 } else { x.1 })
            .collect();
        if d.is_empty() {
            break;
        }
        d.sort_by(f64::total_cmp);
        let quantile = |q: f64| d[((d.len() - 1) as f64 * q).round() as usize];
        let below = |t: f64| d.iter().filter(|v| **v < t).count();
        println!(
            "# {name} over {} converged points: min {:.3e} median {:.3e} max {:.3e}; below 1%: {}, below 2%: {}, below 5%: {}",
            d.len(),
            quantile(0.0),
            quantile(0.5),
            quantile(1.0),
            below(0.01),
            below(0.02),
            below(0.05)
        );
    }
    Ok(())
}

/// The exact first mode of the clamped bar against the integrator.
fn exact_family(dt: f64) -> Result<(), Box<dyn std::error::Error>> {
    use nonsmooth_modes::verify::{clamped_first_mode, periodicity_of_state};
    println!("gap,period,periods,defect,displacement_defect,energy_drift,max_penetration_over_gap,min_contact_force");
    for (gap, period) in [
        (1e-3, 3.2),
        (1e-3, 3.5),
        (1e-3, 3.8),
        (1e-3, 3.95),
        (-1e-3, 2.2),
        (-1e-3, 2.5),
        (-1e-3, 2.8),
    ] {
        let state = clamped_first_mode(gap, period, dt)?;
        for periods in [1, 10] {
            let options = PeriodicityOptions {
                dt,
                periods,
                ..Default::default()
            };
            let r = periodicity_of_state(&state, period, &options)?;
            println!(
                "{gap:e},{period},{periods},{:.3e},{:.3e},{:.3e},{:.3e},{:.4e}",
                r.defect,
                r.displacement_defect,
                r.energy_drift,
                r.max_penetration / gap.abs(),
                r.min_contact_force
            );
        }
    }
    Ok(())
}
