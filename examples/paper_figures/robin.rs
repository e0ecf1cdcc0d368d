//! Figs. 10-13: the Robin-Signorini bar (ground spring `k_s = 0.5`): first mode and its
//! fields, second mode, and the third subharmonic of the second mode.

use crate::common::{
    arclength_series, field, frame_on_branches, frequency_energy, labelled_series, map_panel,
    marked, omega_1, point_map, series, settings, through_series, Ctx, Res, Stats, BLUE, GAP,
    GREEN, RED, YELLOW,
};
use crate::lettered::{contacts, labelled, nearest_with, Content, MIN_RESONANT_SHARE};
use crate::runs::{arclength_run, continued_from, kept_around, run, Branch, Run};
use nonsmooth_modes::branches::{symmetry_breaking_direction, BackbonePoint, GENUINE_SHARE};
use nonsmooth_modes::continuation::ContinuationProblem;
use nonsmooth_modes::modal::{
    energy, grazing_energy, law_history, natural_frequencies, subharmonic_share, ContactState,
    Label,
};
use nonsmooth_modes::plot::{backbone_panel, Figure, Marker, PALETTE};
use nonsmooth_modes::reference::{robin_bar_with_obstacle, ROBIN_FREE_FREQUENCIES};
use nonsmooth_modes::solve::{NonlinearSolver, SemismoothNewton};
use nonsmooth_modes::system::{BarSystem, NonsmoothSystem};
use std::f64::consts::PI;

/// Ground spring stiffness `k_s` of the paper's Robin bar.
const ROBIN_K: f64 = 0.5;

/// Second natural frequency `omega_2` of the open-contact Robin bar.
const OMEGA_2: f64 = ROBIN_FREE_FREQUENCIES[1];

/// Figs. 10 and 11: Robin bar NSM1 backbones (m = 20, 40) and three fields (m = 40).
pub fn fig10_11(ctx: &Ctx) -> Res<(Stats, Stats)> {
    let (mut s10, mut s11) = (Stats::default(), Stats::default());
    let system = robin_bar_with_obstacle(ROBIN_K, GAP)?;
    let w1 = omega_1(&system)?;
    let nsm1 = |m: usize| {
        let label = format!("NSM1 m = {m}");
        run(
            &system,
            m,
            &Branch::new(&label, 1, (9.5, 6.0), ctx.steps(176)),
        )
    };
    let (r20, r40) = (nsm1(20)?, nsm1(40)?);
    // Arclength at m = 40 fills the interval before omega_2/4 (1.211 to 1.259) where the
    // sequential run converges one point: the paper's remark on its Fig. 10.
    let branch = Branch::new("NSM1 arclength m = 40", 1, (9.5, 6.0), 0);
    let arc = arclength_run(ctx, &system, 40, &branch, w1)?;
    s10.count([&r20, &r40, &arc]);
    let mut branches = labelled_series(
        &[
            (&r20, GREEN, Marker::Circle),
            (&r40, BLUE, Marker::Triangle),
        ],
        w1,
    );
    branches[1].size = 2;
    branches.extend(arclength_series(&arc, w1, PALETTE[4], false));
    let mut bb = backbone_panel("Robin bar (k = 0.5): NSM1", &branches, None);
    frame_on_branches(&mut bb);
    bb.x_guides = vec![OMEGA_2 / 4.0 / w1];
    // Points a, b, c on the m = 40 branch, all on the skeleton (harmonic 1 dominant): a at low
    // energy and c at high energy, each with one contact per period; b around omega_2/4, where
    // harmonic 4 meets omega_2 and carries at least `MIN_RESONANT_SHARE` of the energy.
    let basis_40 = settings(40).cosine_basis()?;
    let meets_omega_2 = |p: &BackbonePoint| -> Res<bool> {
        let c = Content::of(&system, &basis_40, p)?;
        Ok(c.share_near(0, OMEGA_2) >= MIN_RESONANT_SHARE)
    };
    let targets = [
        (8.8, "a"),
        (2.0 * PI / (OMEGA_2 / 4.0) * 0.985, "b"),
        (6.6, "c"),
    ];
    let mut picks: Vec<(&str, &BackbonePoint)> = Vec::new();
    for &(t, n) in &targets {
        let p = nearest_with(&r40, t, |p| {
            if !labelled(p, &Label::Skeleton) {
                return Ok(false);
            }
            if n == "b" {
                meets_omega_2(p)
            } else {
                Ok(contacts(p, 1))
            }
        })?;
        if let Some(p) = p {
            picks.push((n, p));
        }
    }
    for (_, letter) in targets {
        s10.lettered(letter, picks.iter().any(|(name, _)| *name == letter));
    }
    ctx.backbone_figure(
        &mut s10,
        "fig10_robin_nsm1",
        &Figure::new(
            "Fig. 10: NSM1 of the Robin-Signorini bar (dashed: ω₂/4)",
            1,
            marked(bb, "m = 40", &picks, w1, Vec::new()),
        ),
        &[&r20, &r40, &arc],
        w1,
    )?;

    let basis = settings(40).cosine_basis()?;
    let mut panels = Vec::new();
    let (mut ct, mut cx, mut cu, mut cp) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (i, (name, p)) in picks.iter().enumerate() {
        let f = field(&system, &basis, p, 0, 60);
        s11.points += 1;
        s11.converged += 1;
        for (k, t) in f.time.iter().enumerate() {
            for (j, x) in f.position.iter().enumerate() {
                ct.push(*t);
                cx.push(*x);
                cu.push(f.values[k * f.position.len() + j]);
                cp.push(i as f64);
            }
        }
        panels.push(map_panel(
            format!("point {name}: {}", frequency_energy(p, w1)),
            &f,
        )?);
    }
    ctx.svg(
        &mut s11,
        "fig11_robin_nsm1_fields.svg",
        &Figure::new(
            "Fig. 11: NSM1 of the Robin-Signorini bar, m = 40",
            3,
            panels,
        ),
    )?;
    ctx.columns(
        &mut s11,
        "fig11_robin_nsm1_fields.csv",
        &["point", "t", "x", "u"],
        &[&cp, &ct, &cx, &cu],
    )?;
    Ok((s10, s11))
}

/// Fig. 12: Robin bar NSM2 backbone (m = 20) and two fields.
pub fn fig12(ctx: &Ctx) -> Res<Stats> {
    let mut stats = Stats::default();
    let system = robin_bar_with_obstacle(ROBIN_K, GAP)?;
    let w1 = omega_1(&system)?;
    let m = 20;
    let r = run(
        &system,
        m,
        &Branch::new("NSM2", 2, (1.90, 1.45), ctx.steps(91)),
    )?;
    // The continuation loses the branch where its energy blows up (it slides to rest at the
    // next steps); the converged points after that are isolated solutions, drawn apart.
    let (branch, beyond) = r.split_at_end(END_GAP, "NSM2 past its end (isolated)");
    stats.count([&branch, &beyond]);
    let mut bb = backbone_panel(
        "Robin bar: NSM2, m = 20",
        &[
            labelled_series(&[(&branch, RED, Marker::Circle)], w1),
            vec![series(&beyond, w1, RED, Marker::Ring)],
        ]
        .concat(),
        None,
    );
    frame_on_branches(&mut bb);
    // e: low energy, on the skeleton; d: among the internal resonances (a harmonic n >= 2 at
    // an open-contact natural frequency holds at least `MIN_RESONANT_SHARE` of the energy),
    // the largest local excess over its neighbours along the first unbroken run of converged
    // steps, below the blow-up.
    let conv: Vec<&BackbonePoint> = branch.points.iter().take_while(|p| p.converged()).collect();
    let e = conv
        .iter()
        .find(|p| p.period < 1.86 && labelled(p, &Label::Skeleton))
        .copied();
    let basis = settings(m).cosine_basis()?;
    let omega_max = (m + 1) as f64 * conv.iter().fold(0.0f64, |a, p| a.max(p.omega));
    let natural: Vec<f64> = natural_frequencies(&system, ContactState::Open, omega_max)?
        .iter()
        .map(|mode| mode.omega)
        .collect();
    let mut resonant = Vec::new();
    for w in conv.windows(3) {
        let share = Content::of(&system, &basis, w[1])?.resonant_share(0, &natural);
        if share >= MIN_RESONANT_SHARE {
            resonant.push(w);
        }
    }
    let d = resonant
        .into_iter()
        .max_by(|a, b| {
            let ex = |w: &[&BackbonePoint]| {
                w[1].energy_normalized / (0.5 * (w[0].energy_normalized + w[2].energy_normalized))
            };
            ex(a).total_cmp(&ex(b))
        })
        .map(|w| w[1]);
    let mut panels = Vec::new();
    let mut marks = Vec::new();
    for (name, p) in [("e", e), ("d", d)] {
        stats.lettered(name, p.is_some());
        if let Some(p) = p {
            marks.push((name, p));
            let title = format!("point {name}: {}", frequency_energy(p, w1));
            panels.push(point_map(&system, &basis, p, 60, title)?);
        }
    }
    ctx.backbone_figure(
        &mut stats,
        "fig12_robin_nsm2",
        &Figure::new(
            "Fig. 12: NSM2 of the Robin-Signorini bar",
            3,
            marked(bb, "", &marks, w1, panels),
        ),
        &[&branch, &beyond],
        w1,
    )?;
    Ok(stats)
}

/// Consecutive steps without a converged point after which a backbone of these figures counts
/// as ended (sequential runs visit the whole grid; beyond its end they find only isolated
/// solutions).
const END_GAP: usize = 3;

/// Impulse shares below which a third of the period counts as a grazing, and above which as a
/// contact (of the largest third's impulse).
const GRAZING_SHARE: f64 = 0.05;
const CONTACT_SHARE: f64 = 0.2;

/// The contacts and grazings of a sub3 motion: its period in three thirds (from the sample of
/// least contact force), each a contact when its impulse is at least [`CONTACT_SHARE`] of the
/// largest third's, a grazing when it is below [`GRAZING_SHARE`] while the gap closes to within
/// 5 % of `g0`; `None` when a third is neither.
fn contacts_and_grazings(
    problem: &NonsmoothSystem,
    p: &BackbonePoint,
) -> Res<Option<(usize, usize)>> {
    let n = 1200;
    let h = law_history(problem, &p.x, p.omega, 0, n)?;
    let k0 = (0..n)
        .min_by(|&a, &b| h.force[a].total_cmp(&h.force[b]))
        .unwrap_or(0);
    let (mut impulse, mut closest) = ([0.0_f64; 3], [f64::INFINITY; 3]);
    for j in 0..n {
        let (k, third) = ((k0 + j) % n, 3 * j / n);
        impulse[third] += h.force[k].max(0.0);
        closest[third] = closest[third].min(h.gap[k]);
    }
    let largest = impulse.iter().copied().fold(0.0, f64::max);
    if largest <= 0.0 {
        return Ok(None);
    }
    let (mut contacts, mut grazings) = (0, 0);
    for (i, c) in impulse.iter().zip(closest) {
        if *i >= CONTACT_SHARE * largest {
            contacts += 1;
        } else if *i < GRAZING_SHARE * largest && c < 0.05 * GAP {
            grazings += 1;
        } else {
            return Ok(None);
        }
    }
    Ok(Some((contacts, grazings)))
}

/// Nudges along the symmetry-breaking direction, in units of the largest unknown:
/// `branches::NUDGES` and a full step either way, which point g needs.
const WIDE_NUDGES: [f64; 6] = [0.1, -0.1, 0.5, -0.5, 1.0, -1.0];

/// A motion with one contact and two grazings per period reached by leaving the repeated branch
/// of `run` at fixed frequency: each converged point still on it (share off the multiples of 3
/// below `GENUINE_SHARE`) nudged along its symmetry-breaking direction by [`WIDE_NUDGES`] and
/// solved; the first genuinely subharmonic solution with that pattern, as a point at the same
/// frequency.
fn one_contact_off_the_repeated_branch(
    system: &BarSystem,
    m: usize,
    run: &Run,
) -> Res<Option<BackbonePoint>> {
    let mut problem = NonsmoothSystem::new(system, settings(m))?;
    let basis = problem.basis().clone();
    let (e_g, _) = grazing_energy(system)?;
    let solver = SemismoothNewton::default();
    for p in run.converged() {
        if subharmonic_share(system, &basis, &p.x, p.omega, 3)? >= GENUINE_SHARE {
            continue;
        }
        let Some((direction, _)) = symmetry_breaking_direction(&mut problem, &p.x, p.omega, 3)
        else {
            continue;
        };
        let scale = p.x.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        for nudge in WIDE_NUDGES {
            let mut y: Vec<f64> = (p.x.iter().zip(&direction))
                .map(|(v, d)| v + nudge * scale * d)
                .collect();
            problem.set_parameter(p.omega);
            let Ok(info) = solver.solve(&mut problem, &mut y) else {
                continue;
            };
            if subharmonic_share(system, &basis, &y, p.omega, 3)? < GENUINE_SHARE {
                continue;
            }
            let e = energy(system, &basis, &y, p.omega);
            let mut point = p.clone();
            (point.x, point.energy, point.energy_normalized) = (y, e, e / e_g);
            (point.residual_norm, point.iterations) = (info.residual_norm, info.iterations);
            if contacts_and_grazings(&problem, &point)? == Some((1, 2)) {
                return Ok(Some(point));
            }
        }
    }
    Ok(None)
}

/// Fig. 13: Robin bar NSM2 sub3 with m = 60, and points with one or two contacts.
pub fn fig13(ctx: &Ctx) -> Res<Stats> {
    let mut stats = Stats::default();
    let system = robin_bar_with_obstacle(ROBIN_K, GAP)?;
    let w1 = omega_1(&system)?;
    let m = if ctx.quick { 40 } else { 60 };
    let t3 = 3.0 * 2.0 * PI / OMEGA_2;
    // The repeated branch (NSM2 traced three times) has three equal contacts; g and f lie on
    // the genuinely T-periodic branch that leaves it.
    let branch = Branch::new("NSM2 sub3", 2, (t3 - 0.02, 4.6), ctx.steps(113)).subharmonic(3);
    let r = run(&system, m, &branch.genuine())?;
    stats.count([&r]);
    let mut bb = backbone_panel(
        format!("Robin bar: NSM2 sub3, m = {m}"),
        &labelled_series(&[(&r, YELLOW, Marker::Circle)], w1),
        None,
    );
    // g: one contact and two grazings per period; f: two contacts and one grazing.
    let mut g = None;
    let mut f = None;
    let problem = NonsmoothSystem::new(&system, settings(m))?;
    for p in r.converged() {
        match contacts_and_grazings(&problem, p)? {
            Some((1, 2)) if g.is_none() => g = Some((p, 1, 2)),
            Some((2, 1)) if f.is_none() => f = Some((p, 2, 1)),
            _ => {}
        }
    }
    let off = match g {
        Some(_) => None,
        None => {
            let repeated = Branch::new("NSM2 sub3 (repeated)", 2, (t3 - 0.02, 4.6), ctx.steps(113));
            let repeated = run(&system, m, &repeated.subharmonic(3))?;
            one_contact_off_the_repeated_branch(&system, m, &repeated)?
        }
    };
    if let Some(p) = &off {
        g = Some((p, 1, 2));
    }
    // g's own branch: continued from g both ways in steps of 0.001 in the period, kept while
    // its points stay genuinely subharmonic (off the repeated branch, which the continuation
    // falls back onto where the branch ends).
    let basis = settings(m).cosine_basis()?;
    let through_g = match g {
        Some((p, _, _)) => {
            let all = continued_from(&system, m, p, (0.001, 60), "branch through g")?;
            Some(kept_around(all, p, |q| {
                Ok(subharmonic_share(&system, &basis, &q.x, q.omega, 3)? >= GENUINE_SHARE)
            })?)
        }
        None => None,
    };
    if let Some(b) = &through_g {
        stats.count([b]);
        bb.series.push(through_series(b, w1));
    }
    let mut panels = Vec::new();
    let mut marks = Vec::new();
    let mut notes = Vec::new();
    for (name, p) in [("g", g), ("f", f)] {
        stats.lettered(name, p.is_some());
        if let Some((p, c, gr)) = p {
            marks.push((name, p));
            notes.push(format!(
                "{name}: {c} contact(s), {gr} grazing(s), {}",
                frequency_energy(p, w1)
            ));
            let title = format!(
                "point {name}: {c} contact(s), {gr} grazing(s), Ω/ω₁ = {:.3}",
                p.omega / w1
            );
            panels.push(point_map(&system, &basis, p, 90, title)?);
        } else {
            notes.push(format!("{name}: not found"));
        }
    }
    stats.note = notes.join("; ");
    ctx.backbone_figure(
        &mut stats,
        "fig13_robin_nsm2_sub3",
        &Figure::new(
            "Fig. 13: NSM2 sub3 of the Robin-Signorini bar",
            3,
            marked(bb, "", &marks, w1, panels),
        ),
        &[Some(&r), through_g.as_ref()]
            .into_iter()
            .flatten()
            .collect::<Vec<_>>(),
        w1,
    )?;
    Ok(stats)
}
