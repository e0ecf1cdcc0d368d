//! Post-processing of motions of valid systems.

use super::model::foreign_bar;
use super::{reference_system, MAX_HARMONICS};
use crate::checks::{moderate_motion, typed, CaseResult, Checks};
use crate::draw::Draw;
use nonsmooth_modes::modal::{branch_seed, diagnose, energy, grazing_energy, law_history};
use nonsmooth_modes::system::{HarmonicBalanceSettings, NonsmoothSystem};
use nonsmooth_modes::verify::{periodicity_check, PeriodicityOptions, SpringUpdate};
use nonsmooth_modes::Solution;
use std::f64::consts::PI;

/// Post-processing of a motion of a valid system at any frequency, with any sizes:
/// `Solution` and its histories, fields and diagnostics, `diagnose`, `law_history`, the
/// energy, the grazing energy and the periodicity check.
pub(crate) fn post_processing(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let system = reference_system(d, c)?;
    let s = HarmonicBalanceSettings {
        harmonics: d
            .size("harmonics", 1..=MAX_HARMONICS)
            .clamp(1, MAX_HARMONICS),
        samples_per_harmonic: d.size("samples", 3..=30).clamp(3, 64),
        ..Default::default()
    };
    let mut problem = typed(c, "NonsmoothSystem::new", NonsmoothSystem::new(&system, s))?;
    if let Ok((e_g, _)) = grazing_energy(&system) {
        c.finite("E_g", [&e_g]);
    }
    let omega = d.real("omega", 0.3..=50.0);
    let seed_omega = if omega.is_finite() && omega > 0.0 {
        omega
    } else {
        1.6
    };
    let mut x = branch_seed(&mut problem, 1, 1, seed_omega.clamp(1e-3, 1e3))
        .unwrap_or_else(|_| vec![0.0; problem.dimension()]);
    let scale = d.real("motion scale", 0.1..=10.0);
    x.iter_mut().for_each(|v| *v *= scale);
    if d.flag("wrong length", 0.05) {
        x.pop();
    }
    let moderate_inputs = x.len() == problem.dimension() && moderate_motion(&system, &x, omega);
    if moderate_inputs {
        c.finite("energy", [&energy(&system, problem.basis(), &x, omega)]);
    }
    let refinement = d.size("refinement", 1..=4);
    if let Ok(diag) = diagnose(&problem, &x, omega, refinement) {
        c.finite("diagnose", &diag.residual_norm);
        c.finite(
            "diagnose",
            [
                &diag.max_penetration,
                &diag.min_contact_force,
                &diag.energy_drift,
            ],
        );
    }
    let law = d.size("law", 0..=1);
    let samples = d.size("samples", 1..=64);
    if let Ok(h) = law_history(&problem, &x, omega, law, samples) {
        for v in [&h.time, &h.gap, &h.force, &h.residual] {
            c.finite("law history", v);
        }
    }
    let solution = typed(c, "Solution::new", Solution::new(&problem, &x, omega))?;
    c.finite("period", [&solution.period()]);
    let end = if d.flag("foreign end", 0.1) {
        foreign_bar().left()
    } else {
        system.bar_id(0).expect("a bar").right()
    };
    if let Ok(h) = solution.end_history(end, d.size("end samples", 1..=32)) {
        for v in [&h.time, &h.displacement, &h.strain, &h.contact_force] {
            c.finite("end history", v);
        }
    }
    let (bar, positions, instants) = (
        d.size("grid bar", 0..=1),
        d.size("positions", 1..=8),
        d.size("instants", 1..=8),
    );
    if let Ok(g) = solution.displacement_grid(bar, positions, instants) {
        for v in [&g.position, &g.time, &g.displacement] {
            c.finite("displacement grid", v);
        }
    }
    if let Ok(e) = solution.energy_normalized() {
        c.finite("E / E_g", [&e]);
    }
    let position = d.rng.unit() * system.bars()[0].length();
    if moderate_inputs {
        let field = solution.field().at(0, position, d.rng.unit() * 2.0 * PI);
        c.finite(
            "field",
            [&field.displacement, &field.velocity, &field.strain],
        );
    }
    // The march costs `periods 2 pi / (omega dt)` steps: only frequencies from 0.3 (or
    // invalid ones, rejected before marching) keep it short.
    if !(omega.is_finite() && omega < 0.3) {
        let options = PeriodicityOptions {
            dt: d.real("dt", 0.02..=0.2),
            adjust_grid: d.flag("adjust grid", 0.5),
            spring: d.pick(
                "spring update",
                &[SpringUpdate::Exact, SpringUpdate::Midpoint],
            ),
            periods: d.size("periods", 1..=2).min(3),
        };
        let report = if d.flag("via solution", 0.5) {
            solution.periodicity_check(&options)
        } else {
            periodicity_check(&system, problem.basis(), &x, omega, &options)
        };
        if let Ok(r) = report {
            c.finite(
                "periodicity",
                [
                    &r.period,
                    &r.dt,
                    &r.defect,
                    &r.initial_norm,
                    &r.displacement_defect,
                    &r.initial_energy,
                    &r.energy_drift,
                    &r.initial_penetration,
                    &r.max_penetration,
                    &r.min_contact_force,
                    &r.projected_energy,
                    &r.projection_error,
                ],
            );
        }
    }
    // Issue 26: the check at the largest frequency the problem accepts over up to 2^64
    // periods (a period near 1e-14: up to about 2e5 time units) once ran for hours as the
    // waves' pieces multiplied at every impact. It now ends within seconds with a report of
    // what the merges removed, or is refused at once with its cost (`TooCostly`, `TooLarge`).
    if d.flag("check at the largest frequency", 0.03) {
        let options = PeriodicityOptions {
            dt: d.real("dt at the largest frequency", 0.02..=0.2),
            periods: d.pick(
                "periods at the largest frequency",
                &[1, 3, 1 << 40, usize::MAX],
            ),
            ..Default::default()
        };
        let top = problem.description().max_frequency();
        if let Ok(r) = periodicity_check(&system, problem.basis(), &x, top, &options) {
            c.finite(
                "periodicity at the largest frequency",
                [
                    &r.defect,
                    &r.displacement_defect,
                    &r.energy_drift,
                    &r.projected_energy,
                    &r.projection_error,
                ],
            );
        }
    }
    Ok(())
}
