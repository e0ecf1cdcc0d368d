//! Post-processing of motions of valid systems.

use super::model::foreign_bar;
use super::{reference_system, MAX_HARMONICS};
use crate::checks::{moderate_motion, typed, CaseResult, Checks};
use crate::draw::Draw;
use nonsmooth_modes::fourier::{Basis, MEMORY_BUDGET_BYTES};
use nonsmooth_modes::modal::{branch_seed, diagnose, energy, grazing_energy, law_history};
use nonsmooth_modes::stability::{hill, HillOptions};
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};
use nonsmooth_modes::verify::{periodicity_check, PeriodicityOptions, SpringUpdate};
use nonsmooth_modes::{SettingsError, Solution};
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
    // Histories of `N refinement` samples, four doubles each.
    let grid = problem.basis().samples() as f64;
    let refinement = d.size_or_budget("refinement", 1..=4, 4.0 * grid);
    let diagnosed = diagnose(&problem, &x, omega, refinement);
    budget_consistent(c, "diagnose", 4.0 * grid * refinement as f64, &diagnosed);
    if let Ok(diag) = diagnosed {
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
    let samples = d.size_or_budget("samples", 1..=64, 4.0);
    let laws = system.contact_count();
    let history = law_history(&problem, &x, omega, law, samples);
    index_consistent(c, "law_history", (law, laws), &history);
    if law < laws {
        budget_consistent(c, "law_history", 4.0 * samples as f64, &history);
    }
    if let Ok(h) = history {
        for v in [&h.time, &h.gap, &h.force, &h.residual] {
            c.finite("law history", v);
            c.exact("law history", v);
        }
    }
    hill_case(d, c, (&system, s), &x, omega);
    let solution = typed(c, "Solution::new", Solution::new(&problem, &x, omega))?;
    c.finite("period", [&solution.period()]);
    let end = if d.flag("foreign end", 0.1) {
        foreign_bar().left()
    } else {
        system.bar_id(0).expect("a bar").right()
    };
    let bars = system.bars().len();
    let samples = d.size_or_budget("end samples", 1..=32, 4.0);
    let history = solution.end_history(end, samples);
    index_consistent(c, "end_history", (end.bar.index(), bars), &history);
    if end.bar.index() < bars {
        budget_consistent(c, "end_history", 4.0 * samples as f64, &history);
    }
    if let Ok(h) = history {
        for v in [&h.time, &h.displacement, &h.strain, &h.contact_force] {
            c.finite("end history", v);
            c.exact("end history", v);
        }
    }
    let bar = d.size("grid bar", 0..=1);
    let (positions, instants) = if d.flag("grid at the budget", d.edge / 4.0) {
        // `(p + 1)(i + 1) - 1` values: `2^29` doubles (4 GiB), then one position more.
        let extra = d.pick("extra positions", &[1usize, 2, 1 << 20]);
        ((1 << 14) - 1 + extra, (1 << 15) - 1)
    } else {
        (d.size("positions", 1..=8), d.size("instants", 1..=8))
    };
    let g = solution.displacement_grid(bar, positions, instants);
    index_consistent(c, "displacement_grid", (bar, bars), &g);
    if bar < bars {
        let (p, i) = (positions as f64, instants as f64);
        budget_consistent(c, "displacement_grid", p * i + p + i, &g);
    }
    if let Ok(g) = g {
        for v in [&g.position, &g.time, &g.displacement] {
            c.finite("displacement grid", v);
            c.exact("displacement grid", v);
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

/// A request of `index` among `count` items: `IndexOutOfRange` exactly when it is out of
/// range, naming that index and count (a wrapped `index + 1` named another).
fn index_consistent<T>(
    c: &mut Checks,
    what: &str,
    (index, count): (usize, usize),
    result: &Result<T, SettingsError>,
) {
    let out = index >= count;
    match result {
        Err(SettingsError::IndexOutOfRange {
            index: i, count: n, ..
        }) => c.expect(out && (*i, *n) == (index, count), || {
            format!("{what}: index {i} of {n} for index {index} of {count}")
        }),
        _ => c.expect(!out, || {
            format!("{what}: index {index} of {count} not refused")
        }),
    }
}

/// A request of `doubles` values checked against the memory budget: refused when they
/// exceed it (by `TooLarge` unless an earlier check refused it), and a `TooLarge` only then,
/// carrying the bytes of the request.
fn budget_consistent<T>(
    c: &mut Checks,
    what: &str,
    doubles: f64,
    result: &Result<T, SettingsError>,
) {
    let bytes = doubles * 8.0;
    let over = bytes > MEMORY_BUDGET_BYTES as f64;
    match result {
        Err(SettingsError::TooLarge(e)) => c.expect(over && e.requested_bytes == bytes, || {
            format!("{what}: {e} for {bytes:e} bytes")
        }),
        Ok(_) => c.expect(!over, || format!("{what}: {bytes:e} bytes not refused")),
        Err(_) => {}
    }
}

/// Hill's method at the motion `x` (any scale, any frequency, maybe the wrong length) with
/// drawn options: finite exponents, residuals and `max_multiplier >= 1`, or a typed error.
fn hill_case(
    d: &mut Draw,
    c: &mut Checks,
    (system, settings): (&BarSystem, HarmonicBalanceSettings),
    x: &[f64],
    omega: f64,
) {
    let options = HillOptions {
        tolerance: d.real("hill tolerance", 1e-6..=1e-1),
        max_modulus: d.real("hill max modulus", 1.5..=1e3),
        shifts_per_frequency: d.size("hill shifts", 1..=8),
    };
    match hill(system, settings, x, omega, &options) {
        Ok(h) => {
            c.finite(
                "hill",
                [&h.max_multiplier, &h.residual, &h.time_shift_residual],
            );
            c.finite("hill", h.trivial_distance.iter());
            c.finite("hill", h.exponents.iter().flat_map(|e| [&e.re, &e.im]));
            c.expect(h.max_multiplier >= 1.0, || {
                format!("hill: max_multiplier {} below 1", h.max_multiplier)
            });
        }
        Err(e) => {
            c.error("hill", &e);
        }
    }
}
