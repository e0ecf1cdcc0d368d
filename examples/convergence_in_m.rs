//! Convergence in the number of harmonics `m` of the two first nonsmooth modes with an exact
//! family: the clamped bar facing a wall, `E/E_g = 8 / (pi^2 (T - 3)^2)`, and the free–free
//! bar between two walls, `E/E_g = 8 / (pi^2 (2T - 3)^2)` (unit bars, gaps `1e-3`).
//!
//! ```text
//! cargo run --release --example convergence_in_m -- [--harmonics 20,40,80,160] [--out FILE]
//!     [--ways grid,selection,...] [--selection-width C]
//! ```
//!
//! Each way of computing the branch runs over the system's own period grid
//! ([`BackboneOptions::for_mode`], 181 periods) at each `m`:
//! - `grid`: the period grid ([`Method::PeriodGrid`]);
//! - `auto`: [`Method::Auto`] (which lifts its run at `m / 2` where its own falls short,
//!   and keeps the paper's equations or harmonic selection, whichever covers more periods);
//! - `auto-checked`: the same with the time-domain check ([`TimeDomainCheck::for_system`]),
//!   by which `Auto` judges its runs;
//! - `lifted`: the grid at the first `m`, each later `m` lifted from the one before it
//!   ([`lift`]): continuation in `m`, point by point;
//! - `corrected`: the grid's points whose state the exact time-domain map's shooting (the
//!   correction before the Floquet multipliers, [`StabilityOptions::default`]) brings to a
//!   periodic orbit, at the energy of that orbit;
//! - `lifted-corrected`: the lifted run's points corrected so;
//! - `extrapolated`: `2 E_m - E_(m/2)` from the lifted runs at `m` and `m / 2`, at the
//!   periods where both converged (an error decaying like `1/m`);
//! - `exact-start` (the clamped bar only): Newton at each period from the exact family's own
//!   Fourier coefficients, what the truncated equations give near the exact motion;
//! - `selection`: the period grid with the harmonics near a linear resonance held at zero
//!   ([`HarmonicBalanceSettings::resonance_band`](nonsmooth_modes::system::HarmonicBalanceSettings::resonance_band)
//!   `= C`, `--selection-width`, default [`RESONANCE_BAND`]);
//! - `selection-exact-start` (the clamped bar only): `exact-start` with that selection.
//!
//! `--ways` computes only the listed rows (all by default; `grid` is always computed, and
//! the multipliers only for `corrected` and `lifted-corrected`, which take most of the time).
//!
//! For each it prints and writes (CSV, `--out`, default `convergence_in_m.csv`; columns
//! `system,way,harmonics,converged,within_2,within_5,median_error`) the converged points,
//! the share of the 181 periods whose nearest converged point (within half a grid step) lies
//! within 2 % and within 5 % of the exact `E/E_g`, and the median relative error of the
//! converged points (empty without one).

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{
    compute, lift, BackboneOptions, Method, ModeBranches, Request, TimeDomainCheck,
};
use nonsmooth_modes::continuation::{linspace, ContinuationProblem};
use nonsmooth_modes::modal::energy;
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, clamped_grazing_energy, ClampedFirstMode,
};
use nonsmooth_modes::solve::{NonlinearSolver, Solver};
use nonsmooth_modes::stability::{StabilityOptions, Verdict};
use nonsmooth_modes::system::{AssemblyBuilder, BarSystem, NonsmoothSystem, RESONANCE_BAND};
use std::collections::HashMap;
use std::error::Error;
use std::f64::consts::PI;
use std::io::Write;

const GAP: f64 = 1e-3;

/// One system with an exact family: its name, the system and the family's `E/E_g` at `T`.
struct Family {
    name: &'static str,
    system: BarSystem,
    exact: fn(f64) -> f64,
}

/// One row of the table.
struct Row {
    converged: usize,
    within_2: f64,
    within_5: f64,
    /// `None` without a converged point.
    median_error: Option<f64>,
}

impl Row {
    /// The row of the converged points `(T, E/E_g)` against `exact` over the grid's
    /// `periods`. A period counts as within a bound when the point nearest to it (within half
    /// a grid step) is: a run that is not a grid (arclength) has points at other periods, and
    /// some periods with several.
    fn of(points: &[(f64, f64)], exact: fn(f64) -> f64, periods: &[f64]) -> Self {
        let error = |&(t, e): &(f64, f64)| (e / exact(t) - 1.0).abs();
        let mut errors: Vec<f64> = points.iter().map(error).collect();
        errors.sort_by(f64::total_cmp);
        let half_step = 0.5 * (periods[1] - periods[0]).abs();
        let nearest: Vec<Option<f64>> = (periods.iter())
            .map(|&period| {
                let distance = |p: &&(f64, f64)| (p.0 - period).abs();
                (points.iter())
                    .filter(|p| distance(p) <= half_step)
                    .min_by(|a, b| distance(a).total_cmp(&distance(b)))
                    .map(error)
            })
            .collect();
        let share = |bound: f64| {
            let within = nearest.iter().filter(|e| e.is_some_and(|e| e < bound));
            within.count() as f64 / periods.len() as f64
        };
        Self {
            converged: errors.len(),
            within_2: share(0.02),
            within_5: share(0.05),
            median_error: errors.get(errors.len() / 2).copied(),
        }
    }
}

fn free_free_between_walls() -> Result<BarSystem, Box<dyn Error>> {
    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::new(1.0, 1.0, 1.0)?);
    b.signorini(bar.left(), GAP)?;
    b.signorini(bar.right(), GAP)?;
    Ok(b.build()?)
}

/// The converged points of a run, as `(T, E/E_g)`.
fn converged(run: &ModeBranches) -> Vec<(f64, f64)> {
    run.converged()
        .map(|p| (p.period, p.energy_normalized))
        .collect()
}

/// `(T, E/E_g (1 + c))` of the converged points whose state the exact time-domain map's
/// shooting corrected to a periodic orbit (a verdict other than unresolved), `c` the
/// correction's relative change of energy.
fn corrected(run: &ModeBranches) -> Vec<(f64, f64)> {
    (run.converged())
        .filter_map(|p| match &p.stability {
            Some(Ok(f)) if f.verdict != Verdict::Unresolved => {
                Some((p.period, p.energy_normalized * (1.0 + f.energy_correction)))
            }
            _ => None,
        })
        .collect()
}

/// `(T, 2 E_m - E_m')` at the periods where both `coarse` (at `m'`) and `fine` (at
/// `m = 2 m'`) converged: Richardson's extrapolation for an error that decays like `1/m`.
fn extrapolated(coarse: &ModeBranches, fine: &ModeBranches) -> Vec<(f64, f64)> {
    let before: HashMap<u64, f64> = (converged(coarse).into_iter())
        .map(|(t, e)| (t.to_bits(), e))
        .collect();
    (converged(fine).into_iter())
        .filter_map(|(t, e)| before.get(&t.to_bits()).map(|e0| (t, 2.0 * e - e0)))
        .collect()
}

/// `(T, E/E_g)` where Newton converges at `periods` from the clamped bar's exact
/// coefficients at the request's harmonics.
fn exact_start(
    system: &BarSystem,
    periods: &[f64],
    request: &Request,
) -> Result<Vec<(f64, f64)>, Box<dyn Error>> {
    let mut problem = NonsmoothSystem::new(system, request.settings)?;
    let solver = Solver::default();
    let e_g = clamped_grazing_energy(GAP);
    let mut points = Vec::new();
    for &t in periods {
        let mut x = ClampedFirstMode::new(GAP, t).unknowns(request.settings.harmonics);
        let omega = 2.0 * PI / t;
        problem.set_parameter(omega);
        if solver.solve(&mut problem, &mut x).is_ok() {
            let e = energy(system, problem.basis(), &x, omega);
            points.push((t, e / e_g));
        }
    }
    Ok(points)
}

/// `(T, E/E_g)` where Newton converges at `periods` from the clamped bar's exact
/// The ways of computing a branch that the table can show, in its order.
const WAYS: [&str; 10] = [
    "grid",
    "corrected",
    "auto",
    "auto-checked",
    "lifted",
    "lifted-corrected",
    "extrapolated",
    "exact-start",
    "selection",
    "selection-exact-start",
];

fn main() -> Result<(), Box<dyn Error>> {
    let mut harmonics = vec![20, 40, 80, 160];
    let mut ways: Vec<String> = WAYS.iter().map(|w| w.to_string()).collect();
    let mut out = String::from("convergence_in_m.csv");
    let mut width = RESONANCE_BAND;
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        let value = args.next().ok_or_else(|| format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--harmonics" => {
                harmonics = (value.split(','))
                    .map(str::parse)
                    .collect::<Result<_, _>>()?;
            }
            "--out" => out = value,
            "--selection-width" => width = value.parse()?,
            "--ways" => {
                ways = value.split(',').map(str::to_string).collect();
                if let Some(w) = ways.iter().find(|w| !WAYS.contains(&w.as_str())) {
                    return Err(format!("unknown way {w} (ways: {})", WAYS.join(",")).into());
                }
            }
            _ => return Err(format!("unknown flag {flag}").into()),
        }
    }
    if harmonics.is_empty() || harmonics.windows(2).any(|w| w[1] < w[0]) {
        return Err("--harmonics takes increasing numbers".into());
    }
    let families = [
        Family {
            name: "clamped",
            system: clamped_bar_with_obstacle(GAP)?,
            exact: |t| 8.0 / (PI * PI * (t - 3.0).powi(2)),
        },
        Family {
            name: "free-free-walls",
            system: free_free_between_walls()?,
            exact: |t| 8.0 / (PI * PI * (2.0 * t - 3.0).powi(2)),
        },
    ];
    let mut csv = std::fs::File::create(&out)?;
    writeln!(
        csv,
        "system,way,harmonics,converged,within_2,within_5,median_error"
    )?;
    println!("| system | way | m | converged | within 2 % | within 5 % | median error |");
    println!("|---|---|---|---|---|---|---|");
    for family in &families {
        let grid = BackboneOptions::for_mode(&family.system, 1, 1)?;
        let periods = linspace(grid.grid.start, grid.grid.end, grid.grid.steps)?;
        let row = |points: Vec<(f64, f64)>| Row::of(&points, family.exact, &periods);
        let mut lifted: Option<ModeBranches> = None;
        for &m in &harmonics {
            let request = Request::new(1).harmonics(m);
            let wanted = |way: &str| ways.iter().any(|w| w == way);
            // The exact map's corrections come with the Floquet multipliers: asked only for
            // the rows that show them.
            let corrections = wanted("corrected") || wanted("lifted-corrected");
            let annotated = if corrections {
                request.clone().with_stability(StabilityOptions::default())
            } else {
                request.clone()
            };
            let check = TimeDomainCheck::for_system(&family.system);
            let by_grid = compute(
                &family.system,
                &annotated.clone().method(Method::PeriodGrid(grid)),
            )?;
            let mut rows = vec![("grid", row(converged(&by_grid)))];
            if corrections {
                rows.push(("corrected", row(corrected(&by_grid))));
            }
            if wanted("auto") {
                rows.push(("auto", row(converged(&compute(&family.system, &request)?))));
            }
            if wanted("auto-checked") {
                let checked = compute(&family.system, &request.clone().checked(check))?;
                rows.push(("auto-checked", row(converged(&checked))));
            }
            let selected = request.clone().resonance_band(width);
            if wanted("selection") {
                let run = compute(
                    &family.system,
                    &selected.clone().method(Method::PeriodGrid(grid)),
                )?;
                rows.push(("selection", row(converged(&run))));
            }
            if family.name == "clamped" && wanted("selection-exact-start") {
                let points = exact_start(&family.system, &periods, &selected)?;
                rows.push(("selection-exact-start", row(points)));
            }
            if wanted("lifted") || wanted("lifted-corrected") || wanted("extrapolated") {
                let chained = match &lifted {
                    Some(run) => lift(run, &annotated)?,
                    None => by_grid.clone(),
                };
                rows.push(("lifted", row(converged(&chained))));
                if corrections {
                    rows.push(("lifted-corrected", row(corrected(&chained))));
                }
                if let Some(coarse) = &lifted {
                    rows.push(("extrapolated", row(extrapolated(coarse, &chained))));
                }
                lifted = Some(chained);
            }
            if family.name == "clamped" && wanted("exact-start") {
                rows.push((
                    "exact-start",
                    row(exact_start(&family.system, &periods, &request)?),
                ));
            }
            rows.retain(|(way, _)| wanted(way));
            for (way, r) in rows {
                let name = family.name;
                // No converged point has no median: a dash in the table, empty in the CSV.
                let (shown, written) = match r.median_error {
                    Some(e) => (format!("{e:.3}"), e.to_string()),
                    None => ("—".to_string(), String::new()),
                };
                println!(
                    "| {name} | {way} | {m} | {} | {:.0} % | {:.0} % | {shown} |",
                    r.converged,
                    100.0 * r.within_2,
                    100.0 * r.within_5,
                );
                writeln!(
                    csv,
                    "{name},{way},{m},{},{},{},{written}",
                    r.converged, r.within_2, r.within_5
                )?;
            }
        }
    }
    Ok(())
}
