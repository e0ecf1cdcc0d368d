//! Figures beyond the paper's, one SVG and one CSV each.
//!
//! ```text
//! cargo run --release --features plot --example gallery -- [--out DIR] [--quick]
//! ```
//!
//! `--out` (default `gallery/`) receives:
//! - `stability_clamped.svg` and `.csv`: the clamped bar's first nonsmooth mode at `m = 20`
//!   (the paper's equations, [`Method::PeriodGrid`] on the system's grid) with the Floquet verdict of
//!   every converged point ([`nonsmooth_modes::stability`]): stable runs solid, unstable runs
//!   dashed, points without a verdict hollow; its exact branch ([`Request::with_exact`]:
//!   periodic orbits of the time-domain map continued from those points, with their
//!   verdicts) drawn the same way; the exact family as a black line; and the largest
//!   multiplier modulus of every harmonic-balance point with a verdict. CSV
//!   columns `period,omega_normalized,energy_normalized,verdict,max_multiplier,
//!   energy_correction` (`verdict`: 1 stable, -1 unstable, 0 unresolved, whose
//!   `max_multiplier` is NaN); `stability_clamped_exact.csv` the exact branch's points,
//!   columns `period,omega_normalized,energy_normalized,verdict,max_multiplier,damping`
//!   (`damping`: the grid's, on periods of an odd number of steps; NaN elsewhere).
//!
//! - `not_even_clamped.svg` and `.csv`: a periodic motion of the clamped bar that is not
//!   even in time, which the paper's cosine basis cannot hold. At `T = 3.089` (a period of
//!   the grid `3.95 -> 3.05` in 24 steps), seeds that put modes 2 to 4 in quadrature with
//!   mode 1 are solved in the full basis (`branches::full_basis_branch`) at `m = 20`, lifted
//!   to `m = 40` and solved again, checked in the time domain; the most asymmetric one that
//!   passes the check is drawn: its field `u(x, t) / g0` and its contact end's displacement
//!   over one period beside its mirror image about the instant where it is closest to even
//!   (an even motion would lie on its mirror); its Floquet verdict is printed. CSV columns `time,displacement,mirror,
//!   contact_force` (`time` from that instant, displacements over `g0`).
//!
//! - `frf_clamped.svg` and `.csv`: forced responses of the clamped bar with its clamped end
//!   moved by `U cos(Omega t)` and viscous damping `eta` (`forced::forced_response`, a
//!   frequency sweep up in 901 steps at `m = 20` with the harmonic selection
//!   `system::RESONANCE_BAND`), at `eta = 1e-3` and `U = 2e-6`, `1e-6`, with the first
//!   nonsmooth mode's backbone
//!   of the same discretisation and the exact family: the energy averaged over the period
//!   `E/E_g` and the amplitude at the obstacle (largest closure of the gap over `g0`)
//!   against `Omega/omega_1`. CSV columns `eta,omega_normalized,energy_normalized,
//!   amplitude,converged`.
//!
//! `--quick` uses 100 cells per travel time for the multipliers instead of 200 (for CI).

use nonsmooth_modes::branches::{
    compute, full_basis_branch, full_basis_system, quadrature_start, shift_origin,
    symmetry_instant, with_harmonics, BackboneOptions, BackbonePoint, FullBasisPoint, Method,
    Request, TimeDomainCheck,
};
use nonsmooth_modes::exact::ExactOptions;
use nonsmooth_modes::forced::{
    forced_response, Damping, Excitation, Forcing, ResponseMethod, ResponseRequest,
};
use nonsmooth_modes::fourier::frequency_of_period;
use nonsmooth_modes::io::write_columns_csv;
use nonsmooth_modes::modal::end_history;
use nonsmooth_modes::plot::{
    backbone_panel, render_svg, space_time_panel, stability_series, Figure, LinePanel, Rgb, Series,
    SpaceTimeField, FREQUENCY_LABEL, PALETTE,
};
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, ClampedFamily};
use nonsmooth_modes::stability::{floquet, Floquet, StabilityOptions};
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings, RESONANCE_BAND};
use std::error::Error;
use std::path::PathBuf;
use std::process::ExitCode;

type Res<T> = Result<T, Box<dyn Error>>;

const USAGE: &str = "usage: gallery [--out DIR] [--quick]";

/// A point's multipliers, where they were computed.
fn floquet_of(p: &BackbonePoint) -> Option<&Floquet> {
    p.stability.as_ref()?.as_ref().ok()
}

/// Whether a point is stable, when its multipliers were computed and give a verdict.
fn stable(p: &BackbonePoint) -> Option<bool> {
    floquet_of(p)?.verdict.stable()
}

/// The clamped bar's first nonsmooth mode with the verdict of every point.
fn stability_clamped(out: &std::path::Path, cells: f64) -> Res<()> {
    let gap = 1e-3;
    let system = clamped_bar_with_obstacle(gap)?;
    let options = StabilityOptions {
        cells_per_travel: cells,
        ..StabilityOptions::default()
    };
    // The paper's equations: the points `docs/validation.md` ("Stability") discusses.
    let grid = BackboneOptions::for_mode(&system, 1, 1)?;
    let exact_options = ExactOptions {
        stability: options,
        ..ExactOptions::default()
    };
    let request = Request::new(1)
        .harmonics(20)
        .method(Method::PeriodGrid(grid))
        .with_stability(options)
        .with_exact(exact_options);
    let result = compute(&system, &request)?;
    let exact = match &result.exact {
        Some(Ok(branch)) => branch.clone(),
        Some(Err(e)) => return Err(e.clone().into()),
        None => return Err("the run returned no exact branch".into()),
    };
    // omega_1 = pi c / (2 l) for the clamped-free unit bar.
    let omega_1 = std::f64::consts::FRAC_PI_2;
    let points: Vec<&BackbonePoint> = result.converged().collect();
    let marked: Vec<(f64, f64, Option<bool>)> = points
        .iter()
        .map(|p| (p.omega / omega_1, p.energy_normalized, stable(p)))
        .collect();
    let exact_marked: Vec<(f64, f64, Option<bool>)> = exact
        .points
        .iter()
        .map(|p| {
            (
                p.point.omega / omega_1,
                p.point.energy_normalized,
                stable(&p.point),
            )
        })
        .collect();
    let family = ClampedFamily::new(gap, 1)?.backbone(3.99, 3.04, 201);
    let mut backbone = backbone_panel("E/E_g", &[], None);
    backbone.series = stability_series("NSM1, m = 20", PALETTE[0], &marked);
    backbone
        .series
        .extend(stability_series("exact branch", PALETTE[1], &exact_marked));
    backbone.series.push(
        Series::line("exact family", family)
            .with_color(Rgb::BLACK)
            .with_size(1),
    );
    let moduli: Vec<(f64, f64, Option<bool>)> = points
        .iter()
        .filter_map(|p| {
            let f = floquet_of(p)?;
            // An unresolved point's multipliers describe no motion: not drawn.
            let stable = f.verdict.stable()?;
            Some((p.omega / omega_1, f.max_modulus, Some(stable)))
        })
        .collect();
    let multipliers = LinePanel {
        series: stability_series("NSM1", PALETTE[0], &moduli),
        ..LinePanel::new(
            "largest multiplier modulus (points with a verdict)",
            FREQUENCY_LABEL,
            "max |mu|",
        )
    };
    let figure = Figure::new(
        "Stability of the clamped bar's first nonsmooth mode: harmonic balance (m = 20) and \
         the exact branch",
        2,
        vec![backbone.into(), multipliers.into()],
    );
    render_svg(out.join("stability_clamped.svg"), &figure)?;
    write_verdicts(
        &out.join("stability_clamped.csv"),
        "stability_clamped:",
        &points,
        omega_1,
        ("energy_correction", &|f| f.energy_correction),
    )?;
    let exact_points: Vec<&BackbonePoint> = exact.points.iter().map(|p| &p.point).collect();
    // The grid's damping, on periods of an odd number of steps (NaN elsewhere).
    write_verdicts(
        &out.join("stability_clamped_exact.csv"),
        "stability_clamped: exact branch of",
        &exact_points,
        omega_1,
        ("damping", &|f| f.damping.unwrap_or(f64::NAN)),
    )
}

/// A CSV of `points` with their verdicts: columns `period,omega_normalized,energy_normalized,
/// verdict,max_multiplier` and `last` (its name and value; NaN without multipliers), with
/// `verdict` 1 stable, -1 unstable, 0 unresolved and `max_multiplier` NaN without a verdict
/// (the largest modulus of an unresolved point describes no motion). Prints the counts after
/// `what`.
fn write_verdicts(
    path: &std::path::Path,
    what: &str,
    points: &[&BackbonePoint],
    omega_1: f64,
    (last, value): (&str, &dyn Fn(&Floquet) -> f64),
) -> Res<()> {
    let column = |f: &dyn Fn(&BackbonePoint) -> f64| points.iter().map(|p| f(p)).collect();
    let columns: [Vec<f64>; 6] = [
        column(&|p| p.period),
        column(&|p| p.omega / omega_1),
        column(&|p| p.energy_normalized),
        column(&|p| match stable(p) {
            Some(true) => 1.0,
            Some(false) => -1.0,
            None => 0.0,
        }),
        column(&|p| {
            let judged = floquet_of(p).filter(|f| f.verdict.stable().is_some());
            judged.map_or(f64::NAN, |f| f.max_modulus)
        }),
        column(&|p| floquet_of(p).map_or(f64::NAN, value)),
    ];
    let refs: Vec<&[f64]> = columns.iter().map(Vec::as_slice).collect();
    let names = [
        "period",
        "omega_normalized",
        "energy_normalized",
        "verdict",
        "max_multiplier",
        last,
    ];
    let file = std::fs::File::create(path)?;
    write_columns_csv(&names, &refs, std::io::BufWriter::new(file))?;
    let count = |v: f64| columns[3].iter().filter(|&&c| c == v).count();
    println!(
        "{what} {} points, {} stable, {} unstable, {} unresolved",
        points.len(),
        count(1.0),
        count(-1.0),
        count(0.0)
    );
    Ok(())
}

/// The most asymmetric motion of the clamped bar at `period` found from seeds with modes 2
/// to 4 in quadrature with mode 1 at `m = 20`, solved again at `m = 40` and passing the
/// time-domain check there.
fn not_even_motion(system: &BarSystem, period: f64) -> Res<Option<FullBasisPoint>> {
    let coarse = HarmonicBalanceSettings {
        harmonics: 20,
        ..HarmonicBalanceSettings::default()
    };
    let fine = HarmonicBalanceSettings {
        harmonics: 40,
        ..coarse
    };
    let m = coarse.harmonics;
    let omega = frequency_of_period(period);
    let mut problem = full_basis_system(system, &coarse)?;
    let check = TimeDomainCheck::for_system(system);
    let checked = Request::new(1).settings(fine).checked(check);
    let mut best: Option<FullBasisPoint> = None;
    for mode in 2..=4 {
        for ratio in [0.1, 0.3, 1.0, 3.0] {
            let (start, _) = quadrature_start(&mut problem, mode, ratio, omega)?;
            let request = Request::new(1).settings(coarse);
            let Some(p) = full_basis_branch(system, &request, &start, vec![period])?
                .points
                .pop()
            else {
                continue;
            };
            let lifted = with_harmonics(&p.point.x, m, fine.harmonics)?;
            let Some(q) = full_basis_branch(system, &checked, &lifted, vec![period])?
                .points
                .pop()
            else {
                continue;
            };
            let verified = (q.point.time_domain)
                .is_some_and(|r| r.displacement_defect <= check.max_displacement_defect);
            if verified && best.as_ref().is_none_or(|b| q.asymmetry > b.asymmetry) {
                best = Some(q);
            }
        }
    }
    Ok(best)
}

/// A motion of the clamped bar that is not even in time: its field and its contact end
/// beside the end's mirror image.
fn not_even_clamped(out: &std::path::Path, cells: f64) -> Res<()> {
    let gap = 1e-3;
    let system = clamped_bar_with_obstacle(gap)?;
    let period = 3.95 - 22.0 * (3.95 - 3.05) / 23.0;
    let Some(p) = not_even_motion(&system, period)? else {
        return Err(format!("no motion that is not even found at T = {period}").into());
    };
    let q = &p.point;
    let m = 40;
    let basis = full_basis_system(
        &system,
        &HarmonicBalanceSettings {
            harmonics: m,
            ..HarmonicBalanceSettings::default()
        },
    )?
    .basis()
    .clone();
    let (theta0, _) = symmetry_instant(&q.x, m)?;
    let about = shift_origin(&q.x, m, theta0)?;
    let samples = 400;
    let end = system.bar_id(0).ok_or("no bar 1")?.right();
    let h = end_history(&system, &basis, &about, q.omega, end, samples);
    let v: Vec<f64> = h.displacement.iter().map(|u| u / gap).collect();
    let mirror: Vec<f64> = (0..samples).map(|k| v[(samples - k) % samples]).collect();
    let grid =
        nonsmooth_modes::modal::displacement_grid(&system, &basis, &about, q.omega, 0, 41, 81);
    let field = SpaceTimeField {
        position: grid.position,
        time: grid.time,
        values: grid.displacement.iter().map(|u| u / gap).collect(),
    };
    let title = format!(
        "T = {:.3}, E/E_g = {:.1}, m = {m}: u(x, t)/g₀",
        q.period, q.energy_normalized
    );
    let map = space_time_panel(title, &field, "u/g₀")?;
    let points = |values: &[f64]| h.time.iter().copied().zip(values.iter().copied()).collect();
    let mut history = LinePanel::new(
        format!("contact end, asymmetry {:.1} %", 100.0 * p.asymmetry),
        "t (from the instant closest to even)",
        "u(1, t)/g₀",
    );
    history.series = vec![
        Series::line("u(1, t)", points(&v)).with_color(PALETTE[0]),
        Series::line("u(1, −t): its mirror image", points(&mirror))
            .with_color(PALETTE[1])
            .dashed(),
        Series::line("gap", vec![(0.0, 1.0), (q.period, 1.0)])
            .with_color(Rgb::BLACK)
            .with_size(1),
    ];
    let figure = Figure {
        title: "A motion of the clamped bar that is not even in time".into(),
        columns: 2,
        panel_size: (640, 480),
        panels: vec![map.into(), history.into()],
    };
    render_svg(out.join("not_even_clamped.svg"), &figure)?;
    let names = ["time", "displacement", "mirror", "contact_force"];
    let force: Vec<f64> = h.contact_force.clone();
    let columns: [&[f64]; 4] = [&h.time, &v, &mirror, &force];
    let file = std::fs::File::create(out.join("not_even_clamped.csv"))?;
    write_columns_csv(&names, &columns, std::io::BufWriter::new(file))?;
    let defect = q.time_domain.map_or(f64::NAN, |r| r.displacement_defect);
    let options = StabilityOptions {
        cells_per_travel: cells,
        ..StabilityOptions::default()
    };
    let verdict = match floquet(&system, &basis, &q.x, q.omega, &options) {
        Ok(f) => format!(
            "{:?} at {cells} cells per travel time, largest multiplier {:.4}",
            f.verdict, f.max_multiplier
        ),
        Err(e) => format!("no multipliers: {e}"),
    };
    println!(
        "not_even_clamped: T = {:.4}, E/E_g = {:.2}, asymmetry {:.3}, displacement defect \
         {:.3}; {verdict}",
        q.period, q.energy_normalized, p.asymmetry, defect
    );
    Ok(())
}

/// Forced responses of the clamped bar at two levels of damping and forcing, with the
/// backbone they hang from.
fn frf_clamped(out: &std::path::Path) -> Res<()> {
    let gap = 1e-3;
    let system = clamped_bar_with_obstacle(gap)?;
    let settings = HarmonicBalanceSettings {
        harmonics: 20,
        resonance_band: RESONANCE_BAND,
        ..Default::default()
    };
    let omega_1 = std::f64::consts::FRAC_PI_2;
    let backbone = compute(&system, &Request::new(1).settings(settings))?;
    let skeleton: Vec<(f64, f64)> = (backbone.converged())
        .map(|p| (p.omega / omega_1, p.energy_normalized))
        .collect();
    let exact = ClampedFamily::new(gap, 1)?.backbone(3.99, 3.04, 201);
    let mut energy = backbone_panel("E/E_g averaged over the period", &[], None);
    energy.series = vec![
        Series::line("exact family", exact)
            .with_color(Rgb::BLACK)
            .with_size(1),
        Series::line("backbone, m = 20", skeleton).with_color(PALETTE[0]),
    ];
    let mut amplitude = LinePanel::new(
        "amplitude at the obstacle",
        FREQUENCY_LABEL,
        "max closure / g0",
    );
    let mut rows: [Vec<f64>; 5] = Default::default();
    let base = system.bar_id(0).ok_or("the clamped bar")?.left();
    for (k, (eta, u)) in [(1e-3, 2e-6), (1e-3, 1e-6)].into_iter().enumerate() {
        let request = ResponseRequest {
            settings,
            forcing: Forcing {
                damping: Damping::Uniform(eta),
                excitations: vec![Excitation::base_motion(base, u)],
            },
            omega_range: (1.55, 2.0),
            steps: 901,
            method: ResponseMethod::Sequential,
            solver: Default::default(),
        };
        let response = forced_response(&system, &request)?;
        let converged: Vec<_> = response.converged().collect();
        let label = format!("forced, eta = {eta:e}, U = {u:e}");
        let color = PALETTE[k + 1];
        let marks = |f: &dyn Fn(&nonsmooth_modes::forced::ResponsePoint) -> f64| {
            Series::markers(
                label.clone(),
                converged
                    .iter()
                    .map(|p| (p.omega / omega_1, f(p)))
                    .collect(),
            )
            .with_color(color)
            .with_size(2)
        };
        energy.series.push(marks(&|p| p.energy_normalized));
        amplitude.series.push(marks(&|p| p.amplitude));
        for p in &response.points {
            let values = [
                eta,
                p.omega / omega_1,
                p.energy_normalized,
                p.amplitude,
                f64::from(u8::from(p.converged)),
            ];
            for (column, v) in rows.iter_mut().zip(values) {
                column.push(v);
            }
        }
        if let Some(peak) = response.peak() {
            println!(
                "frf_clamped: eta {eta:e}, U {u:e}: {} of {} points converged, peak E/E_g \
                 {:.3} at Omega/omega_1 = {:.4}",
                converged.len(),
                response.points.len(),
                peak.energy_normalized,
                peak.omega / omega_1
            );
        }
    }
    let figure = Figure::new(
        "Forced responses of the clamped bar (base motion, m = 20) on its backbone",
        2,
        vec![energy.into(), amplitude.into()],
    );
    render_svg(out.join("frf_clamped.svg"), &figure)?;
    let names = [
        "eta",
        "omega_normalized",
        "energy_normalized",
        "amplitude",
        "converged",
    ];
    let refs: Vec<&[f64]> = rows.iter().map(Vec::as_slice).collect();
    let file = std::fs::File::create(out.join("frf_clamped.csv"))?;
    write_columns_csv(&names, &refs, std::io::BufWriter::new(file))?;
    Ok(())
}

fn main() -> ExitCode {
    let mut out = PathBuf::from("gallery");
    let mut quick = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--out" => match args.next() {
                Some(d) => out = PathBuf::from(d),
                None => {
                    eprintln!("gallery: --out needs a directory\n{USAGE}");
                    return ExitCode::from(2);
                }
            },
            "--quick" => quick = true,
            _ => {
                eprintln!("gallery: unknown argument `{a}`\n{USAGE}");
                return ExitCode::from(2);
            }
        }
    }
    let run = || -> Res<()> {
        std::fs::create_dir_all(&out)?;
        let cells = if quick { 100.0 } else { 200.0 };
        not_even_clamped(&out, cells)?;
        frf_clamped(&out)?;
        stability_clamped(&out, cells)
    };
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gallery: {e}");
            ExitCode::FAILURE
        }
    }
}
