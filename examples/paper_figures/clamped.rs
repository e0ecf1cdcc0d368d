//! Figs. 7-9: backbones of the clamped bar against the exact families, sequential against
//! arclength continuation, and the internally resonant solutions of the first mode.

use crate::common::{arclength_series, labelled_series, marked, settings, subscript};
use crate::common::{
    omega_1, point_map, reference_line, series, Ctx, Res, Stats, BLUE, GAP, GREEN, RED, YELLOW,
};
use crate::lettered::{labelled, nearest_with, on_exact};
use crate::runs::{arclength_run, run, Branch, Exact, Run};
use nonsmooth_modes::branches::BackbonePoint;
use nonsmooth_modes::fourier::CosineBasis;
use nonsmooth_modes::modal::{harmonic_energies, Label};
use nonsmooth_modes::plot::{backbone_panel, Figure, Marker, Panel, Rgb};
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, ClampedFamily};
use nonsmooth_modes::system::BarSystem;
use std::f64::consts::PI;

/// The exact first mode `(Omega/omega_1, E/E_g)` for `T` from 3.99 down to 3.04.
fn first_mode_curve() -> Res<Vec<(f64, f64)>> {
    Ok(ClampedFamily::new(GAP, 1)?.backbone(3.99, 3.04, 201))
}

/// The first nonsmooth mode from `T = 3.95` down to 3.05 with `m` harmonics, labelled `label`.
fn nsm1(ctx: &Ctx, system: &BarSystem, label: &str, m: usize) -> Res<Run> {
    let branch = Branch::new(label, 1, (3.95, 3.05), ctx.steps(181));
    Ok(run(system, m, &branch)?.with_exact(Exact::new(1, 1)?))
}

/// Fig. 7: clamped-bar backbones (NSM1, NSM2, NSM2 sub2) with m = 20 and three fields.
pub fn fig07(ctx: &Ctx) -> Res<Stats> {
    let mut stats = Stats::default();
    let system = clamped_bar_with_obstacle(GAP)?;
    let w1 = omega_1(&system)?;
    let m = 20;
    let nsm2 = Branch::new("NSM2", 2, (1.3317, 1.2525), ctx.steps(81));
    let sub2 = Branch::new("NSM2 sub2", 2, (2.6633, 2.505), ctx.steps(81)).subharmonic(2);
    let runs = [
        nsm1(ctx, &system, "NSM1", m)?,
        run(&system, m, &nsm2)?.with_exact(Exact::new(2, 1)?),
        run(&system, m, &sub2)?.with_exact(Exact::new(2, 2)?),
    ];
    stats.count(&runs);
    let coloured: Vec<(&Run, Rgb, Marker)> = runs
        .iter()
        .zip([GREEN, RED, YELLOW])
        .map(|(r, c)| (r, c, Marker::Circle))
        .collect();
    let branches = labelled_series(&coloured, w1);
    let mut bb = backbone_panel("backbones, m = 20", &branches, Some(&first_mode_curve()?));
    let exact_nsm2 = ClampedFamily::new(GAP, 2)?.backbone(1.2525, 1.3330, 101);
    let exact_sub2: Vec<(f64, f64)> = exact_nsm2.iter().map(|&(w, e)| (w / 2.0, e)).collect();
    bb.series
        .push(reference_line("exact NSM2, NSM2 sub2", exact_nsm2));
    bb.series.push(reference_line("", exact_sub2));
    let basis = settings(m).cosine_basis()?;
    // a: NSM1, c: NSM2, d: NSM2 sub2, each labelled so and within 5 % of its exact family,
    // nearest the paper's period.
    let sub2 = Label::Subharmonic { order: 2 };
    let picks = [
        ("a", 3.6, Label::Skeleton),
        ("c", 1.29, Label::Skeleton),
        ("d", 2.58, sub2),
    ]
    .into_iter()
    .zip(&runs)
    .map(|((name, period, label), r)| {
        let p = nearest_with(r, period, |p| {
            Ok(labelled(p, &label) && on_exact(r, p, 0.05))
        })?;
        Ok((name, p))
    })
    .collect::<Res<Vec<_>>>()?;
    for (name, p) in &picks {
        stats.lettered(name, p.is_some());
    }
    let mut panels = Vec::new();
    let mut marks = Vec::new();
    for ((name, p), r) in picks.into_iter().zip(&runs) {
        if let Some(p) = p {
            marks.push((name, p));
            let title = format!(
                "point {name}: {}, T = {:.3}, E/E_g = {:.2}",
                r.label, p.period, p.energy_normalized
            );
            panels.push(point_map(&system, &basis, p, 60, title)?);
        }
    }
    let all = marked(bb, "", &marks, w1, panels);
    let refs: Vec<&Run> = runs.iter().collect();
    ctx.backbone_figure(
        &mut stats,
        "fig07_clamped_backbones",
        &Figure::new("Fig. 7: Dirichlet-Signorini bar, m = 20", 2, all),
        &refs,
        w1,
    )?;
    Ok(stats)
}

/// Fig. 8: first NSM by sequential and arclength continuation, m = 20 and 40.
pub fn fig08(ctx: &Ctx) -> Res<Stats> {
    let mut stats = Stats::default();
    let system = clamped_bar_with_obstacle(GAP)?;
    let w1 = omega_1(&system)?;
    let mut panels = Vec::new();
    let mut runs = Vec::new();
    let exact = first_mode_curve()?;
    for m in [20usize, 40] {
        let seq = nsm1(ctx, &system, &format!("NSM1 sequential m = {m}"), m)?;
        let label = format!("NSM1 arclength m = {m}");
        let branch = Branch::new(&label, 1, (3.95, 3.05), 0);
        let arc = arclength_run(ctx, &system, m, &branch, w1)?.with_exact(Exact::new(1, 1)?);
        stats.count([&seq, &arc]);
        let mut branches = vec![series(&seq, w1, GREEN, Marker::Circle)];
        branches.extend(arclength_series(&arc, w1, BLUE, true));
        let mut p = backbone_panel(format!("NSM1, m = {m}"), &branches, Some(&exact));
        p.y_range = Some((0.5, 400.0));
        panels.push(Panel::Lines(p));
        runs.push(seq);
        runs.push(arc);
    }
    let refs: Vec<&Run> = runs.iter().collect();
    ctx.backbone_figure(
        &mut stats,
        "fig08_sequential_arclength",
        &Figure::new("Fig. 8: first NSM, sequential vs arclength", 2, panels),
        &refs,
        w1,
    )?;
    Ok(stats)
}

/// Spikes of `run`: converged points above the exact curve by more than 15%, local maxima of
/// the ratio, at least 0.04 apart in T; the three largest, by decreasing period.
fn spikes(run: &Run, exact: Exact) -> Vec<&BackbonePoint> {
    let ratio = |p: &BackbonePoint| p.energy_normalized / exact.at(p.period);
    let mut spikes: Vec<&BackbonePoint> = Vec::new();
    let mut candidates: Vec<&BackbonePoint> = run.converged().filter(|p| ratio(p) > 1.15).collect();
    candidates.sort_by(|a, b| ratio(b).total_cmp(&ratio(a)));
    for c in candidates {
        if spikes.iter().all(|s| (s.period - c.period).abs() > 0.04) {
            spikes.push(c);
        }
        if spikes.len() == 3 {
            break;
        }
    }
    spikes.sort_by(|a, b| b.period.total_cmp(&a.period));
    spikes
}

/// The internal resonance of a spike point `p` of NSM1: the harmonic `n > 1` carrying the most
/// energy, and the clamped-free mode `j` whose frequency `(2j - 1) pi / 2` is nearest to
/// `n Omega`.
fn resonance(system: &BarSystem, basis: &CosineBasis, p: &BackbonePoint) -> Res<(usize, usize)> {
    let energies = harmonic_energies(system, basis, &p.x, p.omega)?;
    let n = (2..energies.len())
        .max_by(|&a, &b| energies[a].total_cmp(&energies[b]))
        .unwrap_or(1);
    let j = ((n as f64 * p.omega / (PI / 2.0) + 1.0) / 2.0)
        .round()
        .max(1.0) as usize;
    Ok((n, j))
}

/// Fig. 9: internally resonant solutions of the first NSM with m = 40 (points on spikes).
pub fn fig09(ctx: &Ctx) -> Res<Stats> {
    let mut stats = Stats::default();
    let system = clamped_bar_with_obstacle(GAP)?;
    let w1 = omega_1(&system)?;
    let m = 40;
    let r = nsm1(ctx, &system, "NSM1", m)?;
    stats.count([&r]);
    let exact = Exact::new(1, 1)?;
    let ratio = |p: &BackbonePoint| p.energy_normalized / exact.at(p.period);
    let spikes = spikes(&r, exact);
    let basis = settings(m).cosine_basis()?;
    let bb = backbone_panel(
        "NSM1, m = 40",
        &[series(&r, w1, GREEN, Marker::Circle)],
        Some(&first_mode_curve()?),
    );
    let mut panels = Vec::new();
    let mut notes = Vec::new();
    let lettered: Vec<(&str, &BackbonePoint)> = ["a", "b", "c"]
        .into_iter()
        .zip(spikes.iter().copied())
        .collect();
    for &(name, p) in &lettered {
        let (n, j) = resonance(&system, &basis, p)?;
        notes.push(format!(
            "{name}: T={:.3} x{:.2}, NSM1 with NSM{j} (harmonic {n})",
            p.period,
            ratio(p)
        ));
        let title = format!(
            "({name}) NSM1 with NSM{j} ({n}Ω ≈ ω{}), E/E_exact {:.2}",
            subscript(j),
            ratio(p)
        );
        panels.push(point_map(&system, &basis, p, 80, title)?);
    }
    stats.note = notes.join("; ");
    ctx.backbone_figure(
        &mut stats,
        "fig09_internal_resonances",
        &Figure::new(
            "Fig. 9: internally resonant NSM1 solutions, m = 40",
            2,
            marked(bb, "internal resonances", &lettered, w1, panels),
        ),
        &[&r],
        w1,
    )?;
    Ok(stats)
}
