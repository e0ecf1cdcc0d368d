//! Figs. 2 and 4-6: the harmonic-balance residual of the clamped bar, the Signorini condition
//! at one point of its first nonsmooth mode, the convergence of `R^(m)` with `m`, and the
//! contact-end histories against the exact solution.

use crate::common::{
    over_gap, reference_line, right_end, settings, Ctx, Res, Stats, Table, BLUE, GAP, GREEN, RED,
};
use crate::runs::{run, solved_point, Branch, Run};
use nonsmooth_modes::branches::{
    convergence_study, BackboneOptions, BackbonePoint, Method, PeriodGrid, Request,
};
use nonsmooth_modes::continuation::ContinuationProblem;
use nonsmooth_modes::modal::{diagnose, law_history};
use nonsmooth_modes::plot::{
    histories_panel, Figure, LinePanel, MapPanel, Marker, Panel, Rgb, Series,
};
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, ClampedFirstMode};
use nonsmooth_modes::solve::{NonlinearSolver, Problem, SemismoothNewton, Solver};
use nonsmooth_modes::system::{HarmonicBalanceSettings, NonsmoothSystem, RESONANCE_BAND};
use std::f64::consts::PI;

/// Period of the clamped-bar point of Figs. 4 and 5. The paper uses `T = 3.5`, where our
/// truncated system is resonant (`T = 2n/j` with `n = 7`: the sequential and the exact-seeded
/// solutions both carry a 7th-harmonic internal resonance, `E/E_g = 5.6` instead of 3.24 for
/// m = 20); 3.55 is the nearest period whose solutions stay on the main branch for m = 5..120.
const CLAMPED_T: f64 = 3.55;

/// Period of Fig. 6, the paper's caption's. The figure says, panel by panel, how far the
/// truncated solution's energy is from the exact one there.
const FIG6_T: f64 = 3.5;

/// Largest relative distance of a point's energy from the exact one for Fig. 5 to count it on
/// the main branch.
const ON_BRANCH: f64 = 0.05;

/// Samples of the contact-end histories of Figs. 4 and 6.
const SAMPLES: usize = 800;

/// The zero of `(a, b) -> (g_0, g_1)` reached by Newton's method (finite-difference Jacobian,
/// full steps) from `start`, if it converges to `1e-12` within 50 iterations.
fn common_zero(
    residual: &mut impl FnMut(f64, f64) -> (f64, f64),
    start: (f64, f64),
) -> Option<(f64, f64)> {
    let (mut a, mut b) = start;
    let h = 1e-7;
    for _ in 0..50 {
        let (f0, f1) = residual(a, b);
        if f0.hypot(f1) < 1e-12 {
            return Some((a, b));
        }
        let (fa0, fa1) = residual(a + h, b);
        let (fb0, fb1) = residual(a, b + h);
        let (j00, j10, j01, j11) = (
            (fa0 - f0) / h,
            (fa1 - f1) / h,
            (fb0 - f0) / h,
            (fb1 - f1) / h,
        );
        let det = j00 * j11 - j01 * j10;
        if !(det.is_finite() && det != 0.0) {
            return None;
        }
        a -= (j11 * f0 - j01 * f1) / det;
        b -= (j00 * f1 - j10 * f0) / det;
    }
    None
}

/// Fig. 2: the two harmonic-balance residuals `g_0`, `g_1` of the clamped bar with `m = 1`
/// over the contact-end displacement coefficients `(a_0, a_1)`.
pub fn fig02(ctx: &Ctx) -> Res<Stats> {
    let mut stats = Stats::default();
    let system = clamped_bar_with_obstacle(GAP)?;
    let mut problem = NonsmoothSystem::new(&system, settings(1))?;
    let period = CLAMPED_T;
    let omega = 2.0 * PI / period;
    let n = if ctx.quick { 31 } else { 61 };
    let a0: Vec<f64> = (0..n)
        .map(|i| -2.0 + 4.0 * i as f64 / (n - 1) as f64)
        .collect();
    let a1: Vec<f64> = (0..n)
        .map(|i| -3.0 + 6.0 * i as f64 / (n - 1) as f64)
        .collect();
    let dim = problem.dimension();
    let k1 = system.bars()[0].wavenumber(omega);
    let mut residual = |a: f64, b: f64| {
        // u(1, t) = a_0 + a_1 cos(Omega t) with u(0, t) = 0: A_n = 0, B_0 = a_0,
        // B_1 = a_1 k / sin(k).
        let mut x = vec![0.0; dim];
        // The basis' constant function is 1/2: coefficient 2 a_0 gives the mean a_0.
        x[problem.index(0, 0, 1)] = 2.0 * a * GAP;
        x[problem.index(1, 0, 1)] = b * GAP * k1 / k1.sin();
        let mut f = vec![0.0; dim];
        problem.set_parameter(omega);
        problem.residual(&x, &mut f);
        (f[dim - 2] / GAP, f[dim - 1] / GAP)
    };
    let (mut g0, mut g1) = (Vec::new(), Vec::new());
    let (mut ca0, mut ca1) = (Vec::new(), Vec::new());
    for &b in &a1 {
        for &a in &a0 {
            let (r0, r1) = residual(a, b);
            g0.push(r0);
            g1.push(r1);
            ca0.push(a);
            ca1.push(b);
        }
    }
    let line: Vec<(f64, f64, f64)> = (0..201)
        .map(|i| {
            let b = -3.0 + 6.0 * i as f64 / 200.0;
            let (r0, r1) = residual(0.0, b);
            (b, r0, r1)
        })
        .collect();
    // The common nontrivial zeros of g_0 and g_1 (the m = 1 solutions in contact), by Newton
    // with a finite-difference Jacobian from the neighbourhood the maps show.
    let zeros: Vec<(f64, f64)> = [1.5, -1.5]
        .into_iter()
        .filter_map(|b| common_zero(&mut residual, (-0.3, b)))
        .collect();
    stats.note = zeros
        .iter()
        .map(|(a, b)| format!("g₀ = g₁ = 0 at (a₀, a₁) = ({a:.4}, {b:.4}) g₀"))
        .collect::<Vec<_>>()
        .join("; ");
    stats.points = n * n + line.len();
    stats.converged = stats.points;
    let zero_set = |values: &[f64], color: Rgb| {
        let mut pts = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let v = values[j * n + i];
                if i + 1 < n {
                    let w = values[j * n + i + 1];
                    if v * w < 0.0 {
                        pts.push((a0[i] + (a0[i + 1] - a0[i]) * v / (v - w), a1[j]));
                    }
                }
                if j + 1 < n {
                    let w = values[(j + 1) * n + i];
                    if v * w < 0.0 {
                        pts.push((a0[i], a1[j] + (a1[j + 1] - a1[j]) * v / (v - w)));
                    }
                }
            }
        }
        Series::markers("", pts)
            .with_color(color)
            .with_marker(Marker::Circle)
            .with_size(2)
    };
    let map = |title: &str, values: &[f64]| MapPanel {
        title: title.into(),
        x_label: "a₀/g₀".into(),
        y_label: "a₁/g₀".into(),
        value_label: "/g₀".into(),
        x: a0.clone(),
        y: a1.clone(),
        values: values.to_vec(),
        diverging: true,
        overlay: vec![
            zero_set(values, Rgb::BLACK),
            Series::markers("", zeros.clone())
                .with_color(GREEN)
                .with_marker(Marker::Cross)
                .with_size(7),
        ],
    };
    let mut cut = LinePanel::new("a₀ = 0: g₀ (red), g₁ (blue)", "a₁/g₀", "residual/g₀");
    cut.series = vec![
        Series::line("g₀", line.iter().map(|p| (p.0, p.1)).collect()).with_color(RED),
        Series::line("g_1", line.iter().map(|p| (p.0, p.2)).collect()).with_color(BLUE),
    ];
    cut.y_guides = vec![0.0];
    let figure = Figure::new(
        format!("Fig. 2: HBM residuals of the clamped bar, m = 1, T = {period} (black dots: zero level; green crosses: g₀ = g₁ = 0)"),
        3,
        vec![
            map("g₀ (constant projection)", &g0).into(),
            map("g_1 (cosine projection)", &g1).into(),
            cut.into(),
        ],
    );
    ctx.svg(&mut stats, "fig02_residual_surfaces.svg", &figure)?;
    ctx.columns(
        &mut stats,
        "fig02_residual_surfaces.csv",
        &["a0_over_g0", "a1_over_g0", "g0_over_g0", "g1_over_g0"],
        &[&ca0, &ca1, &g0, &g1],
    )?;
    Ok(stats)
}

/// HB point of the clamped first mode at `period` for `m` harmonics (sequential from 3.95).
fn clamped_point(ctx: &Ctx, m: usize, period: f64) -> Res<(Run, BackbonePoint)> {
    let system = clamped_bar_with_obstacle(GAP)?;
    let steps = ((3.95 - period) / if ctx.quick { 0.025 } else { 0.01 }).round() as usize + 1;
    let label = format!("NSM1 m = {m}");
    let r = run(
        &system,
        m,
        &Branch::new(&label, 1, (3.95, period), steps.max(2)),
    )?;
    let p = r
        .points
        .iter()
        .rev()
        .find(|p| p.converged() && (p.period - period).abs() < 1e-9)
        .cloned()
        .ok_or_else(|| format!("m = {m}: no converged point at T = {period}"))?;
    Ok((r, p))
}

/// The point at `period` for `m` harmonics reached by Newton's method from the exact
/// family's coefficients, on the equations with the harmonic selection of width `band` (0:
/// the paper's), with its problem; `None` if Newton does not converge.
fn exact_seeded_point(
    m: usize,
    period: f64,
    band: f64,
) -> Res<Option<(NonsmoothSystem, BackbonePoint)>> {
    let system = clamped_bar_with_obstacle(GAP)?;
    let settings = HarmonicBalanceSettings {
        resonance_band: band,
        ..settings(m)
    };
    let mut problem = NonsmoothSystem::new(&system, settings)?;
    let omega = 2.0 * PI / period;
    let exact = ClampedFirstMode::new(GAP, period);
    let mut x = exact.unknowns(m);
    let solver = SemismoothNewton::default();
    problem.set_parameter(omega);
    let tolerance = solver.tolerance(&mut problem);
    let info = match solver.solve(&mut problem, &mut x) {
        Ok(info) => info,
        Err(_) => return Ok(None),
    };
    if info.residual_norm > tolerance {
        return Ok(None);
    }
    let basis = problem.basis().clone();
    let point = solved_point(&system, &basis, (x, omega), &info)?;
    Ok(Some((problem, point)))
}

/// The main-branch point at `period` for `m` harmonics, with the problem it solves: seeded
/// from the exact solution on the paper's equations; where that lands off the exact family's
/// energy (an internal resonance of the truncation: at `T = 3.5`, `7 Omega` is a natural
/// frequency of the bar in contact), seeded again on the equations that hold the resonant
/// harmonics at zero (the harmonic selection of [`RESONANCE_BAND`], as the default request
/// does); the sequential point if neither converges.
fn main_branch_point(
    ctx: &Ctx,
    stats: &mut Stats,
    m: usize,
    period: f64,
) -> Res<(NonsmoothSystem, BackbonePoint)> {
    stats.points += 1;
    let exact = ClampedFirstMode::new(GAP, period).energy_normalized();
    let on_branch = |p: &BackbonePoint| (p.energy_normalized / exact - 1.0).abs() <= ON_BRANCH;
    let paper = exact_seeded_point(m, period, 0.0)?;
    let chosen = match paper {
        Some(found) if on_branch(&found.1) => Some(found),
        other => exact_seeded_point(m, period, RESONANCE_BAND)?
            .filter(|found| on_branch(&found.1))
            .or(other),
    };
    if let Some((problem, p)) = chosen {
        stats.converged += 1;
        println!(
            "    m = {m:<3} T = {period}: E/Eg = {:.4} (exact {exact:.4}), seeded from the exact \
             solution{}",
            p.energy_normalized,
            held_text(&problem)
        );
        return Ok((problem, p));
    }
    let (r, p) = clamped_point(ctx, m, period)?;
    stats.count([&r]);
    println!("    m = {m:<3} T = {period}: exact seed failed, sequential point used");
    let system = clamped_bar_with_obstacle(GAP)?;
    Ok((NonsmoothSystem::new(&system, settings(m))?, p))
}

/// `", harmonics 7 and 14 held at zero"` for a problem whose selection drops harmonics, empty
/// otherwise.
fn held_text(problem: &NonsmoothSystem) -> String {
    let held = problem.dropped_harmonics();
    if held.is_empty() {
        return String::new();
    }
    let list: Vec<String> = held.iter().map(usize::to_string).collect();
    let named = match list.split_last() {
        Some((last, [])) => format!("harmonic {last}"),
        Some((last, rest)) => format!("harmonics {} and {last}", rest.join(", ")),
        None => String::new(),
    };
    format!(", {named} held at zero")
}

/// Contact-end histories `(t, u/g0, u_x/g0, r/g0)` of the main-branch point of the clamped
/// bar at `period` for `m` harmonics, the point's energy over the exact family's, and the
/// harmonics its equations hold at zero.
fn clamped_histories(
    ctx: &Ctx,
    stats: &mut Stats,
    m: usize,
    period: f64,
) -> Res<([Vec<f64>; 4], f64, String)> {
    let (problem, p) = main_branch_point(ctx, stats, m, period)?;
    let system = clamped_bar_with_obstacle(GAP)?;
    let h = right_end(&system, problem.basis(), &p, 0, SAMPLES)?;
    let law = law_history(&problem, &p.x, p.omega, 0, SAMPLES)?;
    let ratio = p.energy_normalized / ClampedFirstMode::new(GAP, period).energy_normalized();
    Ok((
        [
            h.time,
            over_gap(&h.displacement),
            over_gap(&h.strain),
            over_gap(&law.residual),
        ],
        ratio,
        held_text(&problem),
    ))
}

/// Exact contact-end histories `(u/g0, u_x/g0, r/g0)` at `period` on the instants `time`.
fn exact_histories(period: f64, time: &[f64]) -> [Vec<f64>; 3] {
    let e = ClampedFirstMode::new(GAP, period);
    [
        time.iter().map(|&t| e.end_displacement(t) / GAP).collect(),
        time.iter().map(|&t| -e.contact_force(t) / GAP).collect(),
        vec![0.0; time.len()],
    ]
}

/// Fig. 4: contact-end displacement and Signorini residual, exact and m = 20, 80.
pub fn fig04(ctx: &Ctx) -> Res<Stats> {
    let mut stats = Stats::default();
    let period = CLAMPED_T;
    let ms: &[usize] = if ctx.quick { &[20, 40] } else { &[20, 80] };
    let mut disp = LinePanel::new("contact-end displacement", "t", "u(1, t)/g₀");
    let mut comp = LinePanel::new("Signorini residual r = −min(λ, a_c g)", "t", "r(t)/g₀");
    let mut table = Table::default();
    let mut time = Vec::new();
    let mut penetrations = Vec::new();
    for (&m, color) in ms.iter().zip([RED, BLUE]) {
        let ([t, u, _, res], _, _) = clamped_histories(ctx, &mut stats, m, period)?;
        // u is in units of g0: the obstacle is at 1.
        let most = u.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b)) - 1.0;
        penetrations.push(format!("m = {m}: {:.2} % of g₀", 100.0 * most.max(0.0)));
        disp.series
            .push(Series::from_columns(format!("m = {m}"), &t, &u).with_color(color));
        comp.series
            .push(Series::from_columns(format!("m = {m}"), &t, &res).with_color(color));
        table.push(format!("u_over_g0_m{m}"), u);
        table.push(format!("r_over_g0_m{m}"), res);
        time = t;
    }
    let [ue, _, re] = exact_histories(period, &time);
    for (panel, values) in [(&mut disp, &ue), (&mut comp, &re)] {
        panel.series.push(
            Series::from_columns("exact", &time, values)
                .with_color(Rgb::BLACK)
                .with_size(1),
        );
    }
    disp.y_guides = vec![1.0];
    // The contact plateau magnified: the truncated motions penetrate the obstacle slightly.
    let mut zoom = disp.clone();
    zoom.title = format!(
        "contact plateau, zoom (penetration {})",
        penetrations.join(", ")
    );
    zoom.x_range = Some((0.0, 0.4));
    zoom.y_range = Some((0.985, 1.015));
    stats.note = format!("largest penetration {}", penetrations.join(", "));
    table.push("u_over_g0_exact", ue);
    table.push_front("t", time);
    let figure = Figure::new(
        format!("Fig. 4: Signorini condition at T = {period}, exact vs FD-BEM"),
        3,
        vec![disp.into(), zoom.into(), comp.into()],
    );
    ctx.svg(&mut stats, "fig04_signorini.svg", &figure)?;
    ctx.table(&mut stats, "fig04_signorini.csv", &table)?;
    Ok(stats)
}

/// Slope of the least-squares line through `(ln m, ln R)`, NaN for fewer than two points.
fn log_log_slope(points: &[&(f64, f64)]) -> f64 {
    if points.len() < 2 {
        return f64::NAN;
    }
    let n = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (m, r)| (a + m.ln(), b + r.ln()));
    let (mx, my) = (sx / n, sy / n);
    let (num, den) = points.iter().fold((0.0, 0.0), |(a, b), (m, r)| {
        (a + (m.ln() - mx) * (r.ln() - my), b + (m.ln() - mx).powi(2))
    });
    num / den
}

/// Fig. 5: convergence of `R^(m)` with `m` at one point of the first NSM: the main-branch
/// point (seeded from the exact solution) and the point the sequential run reaches.
pub fn fig05(ctx: &Ctx) -> Res<Stats> {
    let mut stats = Stats::default();
    let system = clamped_bar_with_obstacle(GAP)?;
    let period = CLAMPED_T;
    let exact = ClampedFirstMode::new(GAP, period).energy_normalized();
    let ms: Vec<usize> = if ctx.quick {
        vec![5, 10, 20, 40]
    } else {
        vec![5, 10, 15, 20, 30, 40, 60, 80, 100, 120]
    };
    let mut cols: [Vec<f64>; 7] = Default::default();
    let (mut main, mut off, mut seq) = (Vec::new(), Vec::new(), Vec::new());
    for &m in &ms {
        stats.points += 1;
        let nan = f64::NAN;
        let (r, e, pen) = match exact_seeded_point(m, period, 0.0)? {
            Some((problem, p)) => {
                stats.converged += 1;
                let d = diagnose(&problem, &p.x, p.omega, 8)?;
                (d.residual_norm[0], p.energy_normalized, d.max_penetration)
            }
            None => (nan, nan, nan),
        };
        // A point whose energy is off the exact one by more than ON_BRANCH is not on the main
        // branch (too few harmonics, or an internal resonance of the truncated system): it
        // says nothing about the main branch's rate.
        if (e / exact - 1.0).abs() <= ON_BRANCH {
            main.push((m as f64, r));
        } else if r.is_finite() {
            off.push((m as f64, r));
        }
        let grid = PeriodGrid {
            start: 3.95,
            end: period,
            steps: ctx.steps(91),
        };
        let request = Request::for_method(Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)))
            .settings(settings(m))
            .solver(Solver::Newton(SemismoothNewton::default()));
        let study = convergence_study(&system, &request, &[m])?;
        stats.points += 1;
        let last = study
            .first()
            .and_then(|run| Some((run, run.converged().last()?)));
        let (rs, es) = match last {
            Some((run, p)) if (p.period - period).abs() < 1e-9 => {
                stats.converged += 1;
                let d = diagnose(run.problem(), &p.x, p.omega, 8)?;
                (d.residual_norm[0], p.energy_normalized)
            }
            _ => (nan, nan),
        };
        seq.push((m as f64, rs));
        println!(
            "    m = {m:<3}  main branch: R = {r:.3e}, E/Eg = {e:.4}, penetration = {pen:.2e}; sequential: R = {rs:.3e}, E/Eg = {es:.4}"
        );
        for (c, v) in cols.iter_mut().zip([m as f64, r, e, pen, rs, es, exact]) {
            c.push(v);
        }
    }
    let mut panel = LinePanel::new(
        format!("R⁽ᵐ⁾ at T = {period} (NSM1, clamped bar)"),
        "number of harmonics m",
        "R⁽ᵐ⁾",
    );
    panel.x_log = true;
    panel.y_log = true;
    panel.series.push(
        Series::line("main branch: E within 5 % of exact", main.clone())
            .with_color(GREEN)
            .with_marker(Marker::Circle)
            .with_size(2),
    );
    panel.series.push(
        Series::markers("E off exact by more than 5 %", off)
            .with_color(GREEN)
            .with_marker(Marker::Ring)
            .with_size(5),
    );
    panel.series.push(
        Series::markers("sequential continuation from T = 3.95", seq)
            .with_color(RED)
            .with_marker(Marker::Triangle)
            .with_size(4),
    );
    let fit: Vec<&(f64, f64)> = main
        .iter()
        .filter(|p| p.1.is_finite() && p.1 > 0.0)
        .collect();
    if let (Some(first), Some(last)) = (fit.first(), fit.last()) {
        // 1/m reference through the geometric mean of the main-branch points.
        let c = (fit.iter().map(|(m, r)| (m * r).ln()).sum::<f64>() / fit.len() as f64).exp();
        panel.series.push(reference_line(
            "C / m",
            vec![(first.0, c / first.0), (last.0, c / last.0)],
        ));
        stats.note = format!(
            "fitted slope of log R vs log m over the main-branch points, m = {} to {}: {:.2}",
            first.0,
            last.0,
            log_log_slope(&fit)
        );
    }
    ctx.svg(
        &mut stats,
        "fig05_convergence.svg",
        &Figure::new(
            "Fig. 5: convergence of the Signorini residual",
            1,
            vec![panel.into()],
        ),
    )?;
    ctx.columns(
        &mut stats,
        "fig05_convergence.csv",
        &[
            "harmonics",
            "residual_norm_main",
            "energy_normalized_main",
            "max_penetration_main",
            "residual_norm_sequential",
            "energy_normalized_sequential",
            "energy_normalized_exact",
        ],
        &cols.iter().map(|c| c.as_slice()).collect::<Vec<_>>(),
    )?;
    Ok(stats)
}

/// Panel of the three contact-end histories `u`, `u_x`, `r` (in units of `g0`).
fn histories(title: String, t: &[f64], [u, ux, r]: [&[f64]; 3]) -> Res<Panel> {
    let mut p = histories_panel(
        title,
        t,
        &[("u(1, t)/g₀", u), ("uₓ(1, t)/g₀", ux), ("r(t)/g₀", r)],
    )?;
    p.series[0].color = Some(GREEN);
    p.series[1].color = Some(BLUE);
    p.series[2].color = Some(RED);
    p.y_range = Some((-2.6, 1.6));
    p.y_label = "contact-end values/g₀".into();
    Ok(p.into())
}

/// Fig. 6: `u(1,t)`, `u_x(1,t)` and `r(t)` at the caption's `T = 3.5` for m = 20, 40 and
/// exact; a panel whose energy is off the exact family's says so in its title.
pub fn fig06(ctx: &Ctx) -> Res<Stats> {
    let mut stats = Stats::default();
    let period = FIG6_T;
    let mut panels = Vec::new();
    let mut table = Table::default();
    let mut time = Vec::new();
    let mut add = |title: String, tag: &str, t: &[f64], signals: [Vec<f64>; 3]| -> Res<()> {
        panels.push(histories(
            title,
            t,
            [&signals[0], &signals[1], &signals[2]],
        )?);
        for (n, c) in ["u", "ux", "r"].into_iter().zip(signals) {
            table.push(format!("{n}_over_g0_{tag}"), c);
        }
        Ok(())
    };
    for m in [20usize, 40] {
        let ([t, u, ux, res], ratio, held) = clamped_histories(ctx, &mut stats, m, period)?;
        let title = if (ratio - 1.0).abs() > ON_BRANCH {
            format!("m = {m}: E/E_exact = {ratio:.2}, internal resonance of the truncation")
        } else {
            format!("m = {m}: E/E_exact = {ratio:.3}{held}")
        };
        add(title, &format!("m{m}"), &t, [u, ux, res])?;
        time = t;
    }
    add(
        "exact".into(),
        "exact",
        &time,
        exact_histories(period, &time),
    )?;
    table.push_front("t", time);
    ctx.svg(
        &mut stats,
        "fig06_histories.svg",
        &Figure::new(
            format!("Fig. 6: contact-end histories at T = {period}"),
            3,
            panels,
        ),
    )?;
    ctx.table(&mut stats, "fig06_histories.csv", &table)?;
    Ok(stats)
}
