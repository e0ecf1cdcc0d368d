//! Figs. 14-18: two bars in contact, in the configurations `(l, c, alpha)` = (0.95, 1, 1),
//! (3.8, 4, 4) and (0.95, 2, 1), with the paper's definition `α = E₁A₁/(E₂A₂)`
//! (`reference::paper_second_bar`): backbones with snapshots of both bars, the contact
//! interface, and a time-domain check of one point.

use crate::common::{
    arclength_series, field, frame_on_branches, frequency_energy, labelled_series, marked, omega_1,
    over_gap, reference_line, right_end, settings, Ctx, Res, Stats, Table, BLUE, GAP, GREEN, RED,
    YELLOW,
};
use crate::lettered;
use crate::runs::{arclength_run, energy_run, run, solved_point, Branch, Run};
use nonsmooth_modes::branches::BackbonePoint;
use nonsmooth_modes::continuation::ContinuationProblem;
use nonsmooth_modes::fourier::CosineBasis;
use nonsmooth_modes::modal::{branch_seed, harmonic_energies_by_bar, law_history};
use nonsmooth_modes::plot::{
    backbone_panel, snapshots_panel, Figure, LegendPosition, LinePanel, Marker, Panel, PlacedBar,
    Placement, Rgb, Series, SpaceTimeField, PALETTE,
};
use nonsmooth_modes::reference::{paper_second_bar, two_bars_in_contact};
use nonsmooth_modes::solve::{NonlinearSolver, SemismoothNewton};
use nonsmooth_modes::system::{BarSystem, NonsmoothSystem};
use nonsmooth_modes::verify::{march, periodicity_check, MarchOptions, PeriodicityOptions, State};
use std::f64::consts::PI;

/// Harmonics of every two-bar run.
const M: usize = 20;

/// Samples of the interface histories of Figs. 15 and 16.
const SAMPLES: usize = 600;

/// First natural frequency `pi c / (2 l)` of bar 2 in configurations 1 and 2, where
/// `l / c = 0.95`.
const OMEGA_1_BAR_2: f64 = PI / (2.0 * 0.95);

/// A two-bar system, its backbones and the first natural frequency `w1` of bar 1.
pub struct TwoBar {
    system: BarSystem,
    runs: Vec<Run>,
    w1: f64,
}

impl TwoBar {
    /// Bar 2 `(l, c, alpha)` (the paper's triplet, `α = E₁A₁/(E₂A₂)`) facing the unit
    /// bar, and its backbones along `branches`.
    fn new((l, c, alpha): (f64, f64, f64), branches: &[Branch<'_>]) -> Res<Self> {
        let system = two_bars_in_contact(paper_second_bar(l, c, alpha)?, GAP)?;
        let w1 = omega_1(&system)?;
        let runs = branches
            .iter()
            .map(|b| run(&system, M, b))
            .collect::<Res<Vec<Run>>>()?;
        Ok(Self { system, runs, w1 })
    }

    /// Configuration 1, `(0.95, 1, 1)`: NSM1 from `T = 3.95` down, and the NSM2 sub-branches
    /// near the second modes of bar 1 (`3 pi / 2`) and of bar 2.
    pub fn config1(ctx: &Ctx) -> Res<Self> {
        // System modes (open contact): bar 1 first, bar 2 first, bar 1 second, bar 2 second.
        let branches = [
            nsm1(ctx),
            Branch::new("NSM2 (bar 1)", 3, (1.33, 1.05), ctx.steps(141)),
        ];
        Self::new((0.95, 1.0, 1.0), &branches)?.with_nsm2_of_bar_2()
    }

    /// The system with NSM2 of bar 2 (system mode 4) added, continued in the energy: a period
    /// grid started at its linear period slides to rest at every step.
    fn with_nsm2_of_bar_2(mut self) -> Res<Self> {
        let run = energy_run(&self.system, M, "NSM2 (bar 2)", 4)?;
        self.runs.push(run);
        Ok(self)
    }

    fn runs(&self) -> Vec<&Run> {
        self.runs.iter().collect()
    }
}

/// NSM1 of a two-bar system from `T = 3.95` down to 2.85.
fn nsm1(ctx: &Ctx) -> Branch<'static> {
    Branch::new("NSM1", 1, (3.95, 2.85), ctx.steps(221))
}

/// Snapshot panel of both bars, fields in units of `g0`: bar 1 from 0, bar 2 mirrored from
/// `1 + l_2`.
fn snapshots(
    title: &str,
    (one, two): (&SpaceTimeField, &SpaceTimeField),
    l2: f64,
    instants: usize,
) -> Res<Panel> {
    let placed = |name, field, origin, mirrored| PlacedBar {
        name,
        field,
        placement: Placement { origin, mirrored },
    };
    let bars = [
        placed("bar 1", one, 0.0, false),
        placed("bar 2", two, 1.0 + l2, true),
    ];
    let mut panel = snapshots_panel(title, &bars, instants, &[1.0])?;
    panel.y_label = "u/g₀ (bar 1 solid, bar 2 dashed as −w)".into();
    panel.x_label = "position (8 instants over T, blue → red)".into();
    panel.legend = LegendPosition::Hidden;
    Ok(panel.into())
}

/// Snapshots of the harmonic-balance point `p` at 8 instants.
fn snapshots_of(
    system: &BarSystem,
    basis: &CosineBasis,
    p: &BackbonePoint,
    title: String,
) -> Res<Panel> {
    let [one, two] = [0, 1].map(|bar| {
        let mut f = field(system, basis, p, bar, 8);
        f.values.iter_mut().for_each(|v| *v /= GAP);
        f
    });
    snapshots(&title, (&one, &two), system.bars()[1].length(), 8)
}

/// Snapshot panels of `points` (name, point), titled `point {name}: ...`.
fn named_snapshots(tb: &TwoBar, points: &[(&str, &BackbonePoint)]) -> Res<Vec<Panel>> {
    let basis = settings(M).cosine_basis()?;
    points
        .iter()
        .map(|(name, p)| {
            let title = format!("point {name}: {}", frequency_energy(p, tb.w1));
            snapshots_of(&tb.system, &basis, p, title)
        })
        .collect()
}

/// Fig. 14 (and the data of 15 and 16): configuration 1.
pub fn fig14(ctx: &Ctx, tb: &TwoBar) -> Res<(Stats, Vec<BackbonePoint>)> {
    let mut stats = Stats::default();
    // The period grid scatters over NSM2 of bar 1; pseudo-arclength shows its two hardening
    // sub-branches (from omega_2^(1) and from about 3.23), joined by the escape's jumps.
    let nsm2_arc = Branch::new("NSM2 (bar 1) arclength", 3, (1.33, 1.05), 0);
    let arc = arclength_run(ctx, &tb.system, M, &nsm2_arc, tb.w1)?;
    stats.count(tb.runs.iter().chain([&arc]));
    let coloured: Vec<(&Run, Rgb, Marker)> = tb
        .runs
        .iter()
        .zip([GREEN, RED, PALETTE[5]])
        .map(|(r, c)| (r, c, Marker::Circle))
        .collect();
    let mut branches = labelled_series(&coloured, tb.w1);
    branches.extend(arclength_series(&arc, tb.w1, PALETTE[4], false));
    let mut bb = backbone_panel("(0.95, 1, 1): backbones, m = 20", &branches, None);
    frame_on_branches(&mut bb);
    let w12 = OMEGA_1_BAR_2;
    bb.x_guides = vec![w12 / tb.w1, 4.0 / 3.0 * w12 / tb.w1, 3.0];
    let conv: Vec<&BackbonePoint> = tb.runs[0].converged().collect();
    let nsm1: Vec<&BackbonePoint> = (0..conv.len())
        .filter(|&i| off_spike(&conv, i))
        .map(|i| conv[i])
        .collect();
    let basis = settings(M).cosine_basis()?;
    let lettered = lettered::fig14(
        &tb.system,
        &basis,
        tb.w1,
        &nsm1,
        tb.runs.get(1),
        tb.runs.get(2),
    )?;
    let picks: Vec<(&str, &BackbonePoint)> = lettered
        .iter()
        .filter_map(|&(name, p)| p.map(|p| (name, p)))
        .collect();
    for letter in ["b", "c", "d", "e", "f", "g"] {
        stats.lettered(letter, picks.iter().any(|(name, _)| *name == letter));
    }
    let panels = named_snapshots(tb, &picks)?;
    ctx.backbone_figure(
        &mut stats,
        "fig14_two_bar_config1",
        &Figure::new(
            "Fig. 14: two bars (l, c, α) = (0.95, 1, 1) (dashed: ω₁⁽²⁾, 4/3 ω₁⁽²⁾, ω₂⁽¹⁾)",
            3,
            marked(bb, "", &picks, tb.w1, panels),
        ),
        &tb.runs().into_iter().chain([&arc]).collect::<Vec<_>>(),
        tb.w1,
    )?;
    Ok((stats, picks.iter().map(|(_, p)| (*p).clone()).collect()))
}

/// Interface positions from `x = 1` in units of `g0`: bar 1 at `u(1)`, bar 2 at `g0 - w(l)`.
fn interface_positions(u: &[f64], w: &[f64]) -> (Vec<f64>, Vec<f64>) {
    (over_gap(u), w.iter().map(|w| (GAP - w) / GAP).collect())
}

/// Fig. 15: interface position and strain of both bars for two points of Fig. 14.
pub fn fig15(ctx: &Ctx, tb: &TwoBar, points: &[BackbonePoint]) -> Res<Stats> {
    let mut stats = Stats::default();
    let basis = settings(M).cosine_basis()?;
    let mut panels = Vec::new();
    let mut table = Table::default();
    for (p, tag) in points.iter().zip(["a", "b"]) {
        stats.points += 1;
        stats.converged += 1;
        let h1 = right_end(&tb.system, &basis, p, 0, SAMPLES)?;
        let h2 = right_end(&tb.system, &basis, p, 1, SAMPLES)?;
        let (pos1, pos2) = interface_positions(&h1.displacement, &h2.displacement);
        let (e1, e2) = (over_gap(&h1.strain), over_gap(&h2.strain));
        let mut panel = LinePanel::new(
            format!("({tag}) {}", frequency_energy(p, tb.w1)),
            "t",
            "position − 1 and strain, /g₀",
        );
        panel.series = vec![
            Series::from_columns("bar 1 position", &h1.time, &pos1).with_color(GREEN),
            Series::from_columns("bar 2 position", &h1.time, &pos2).with_color(YELLOW),
            Series::from_columns("bar 1 strain", &h1.time, &e1)
                .with_color(GREEN)
                .dashed(),
            Series::from_columns("bar 2 strain", &h1.time, &e2)
                .with_color(YELLOW)
                .dashed(),
        ];
        panels.push(Panel::Lines(panel));
        table.push(format!("t_{tag}"), h1.time);
        for (n, c) in [
            ("pos1", pos1),
            ("pos2", pos2),
            ("strain1", e1),
            ("strain2", e2),
        ] {
            table.push(format!("{n}_over_g0_{tag}"), c);
        }
    }
    ctx.svg(
        &mut stats,
        "fig15_two_bar_interface.svg",
        &Figure::new(
            "Fig. 15: contact interface, strain (dashed) and position (solid)",
            2,
            panels,
        ),
    )?;
    ctx.table(&mut stats, "fig15_two_bar_interface.csv", &table)?;
    Ok(stats)
}

/// A thin dashed line of the harmonic-balance solution, `(t, y)` pairs.
fn hb_line(label: &str, t: &[f64], y: &[f64], color: Rgb) -> Series {
    reference_line(label, t.iter().copied().zip(y.iter().copied()).collect()).with_color(color)
}

/// Fig. 16: time-domain check of point b of Fig. 14: exact d'Alembert march over one period
/// from the HB state at t = 0, compared with the HB motion.
pub fn fig16(ctx: &Ctx, tb: &TwoBar, p: &BackbonePoint) -> Res<Stats> {
    let mut stats = Stats::default();
    let basis = settings(M).cosine_basis()?;
    let options = PeriodicityOptions {
        dt: 0.01,
        ..Default::default()
    };
    let report = periodicity_check(&tb.system, &basis, &p.x, p.omega, &options)?;
    let period = 2.0 * PI / p.omega;
    let initial = State::from_harmonic_balance(&tb.system, &basis, &p.x, p.omega, 0.0, 0.01)?;
    let steps = (period / 0.01).round() as usize;
    let traj = march(
        &initial,
        period,
        &MarchOptions {
            snapshot_every: (steps / 8).max(1),
            ..Default::default()
        },
    )?;
    stats.points = 1;
    stats.converged = 1;
    stats.note = format!(
        "defect {:.3} (energy norm), displacement defect {:.3}, energy drift {:.1e}",
        report.defect, report.displacement_defect, report.energy_drift
    );
    println!("    {}", stats.note);
    // Interface positions from the march: ends are [bar0 left, bar0 right, bar1 left, ...].
    let t = &traj.times;
    let (u1, u2) = interface_positions(&traj.ends[1].displacement, &traj.ends[3].displacement);
    let tm: Vec<f64> = t.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
    let force = over_gap(&traj.contacts[0].force);
    let h1 = right_end(&tb.system, &basis, p, 0, SAMPLES)?;
    let h2 = right_end(&tb.system, &basis, p, 1, SAMPLES)?;
    let (hb1, hb2) = interface_positions(&h1.displacement, &h2.displacement);
    let problem = NonsmoothSystem::new(&tb.system, settings(M))?;
    let law = law_history(&problem, &p.x, p.omega, 0, SAMPLES)?;
    let mut pos = LinePanel::new("interface positions − 1", "t", "/g₀");
    pos.series = vec![
        Series::from_columns("bar 1, time domain", t, &u1).with_color(GREEN),
        Series::from_columns("bar 2, time domain", t, &u2).with_color(YELLOW),
        hb_line("bar 1, FD-BEM", &h1.time, &hb1, Rgb::BLACK),
        hb_line("bar 2, FD-BEM", &h2.time, &hb2, PALETTE[7]),
    ];
    let mut frc = LinePanel::new("contact force", "t", "λ/g₀");
    frc.series = vec![
        Series::from_columns("time domain (step mean)", &tm, &force).with_color(BLUE),
        hb_line("FD-BEM", &law.time, &over_gap(&law.force), Rgb::BLACK),
    ];
    // Snapshots of the marched field.
    let l2 = tb.system.bars()[1].length();
    let marched = |bar: usize| -> SpaceTimeField {
        let snaps = &traj.snapshots;
        let nx = snaps.first().map_or(0, |s| s.bars[bar].displacement.len());
        let length = if bar == 0 { 1.0 } else { l2 };
        SpaceTimeField {
            position: (0..nx)
                .map(|i| length * i as f64 / (nx.max(2) - 1) as f64)
                .collect(),
            time: snaps.iter().map(|s| s.time).collect(),
            values: snaps
                .iter()
                .flat_map(|s| s.bars[bar].displacement.iter().map(|v| v / GAP))
                .collect(),
        }
    };
    let (f1, f2) = (marched(0), marched(1));
    let instants = f1.time.len().min(8);
    let snap = snapshots("time-domain field, 8 instants", (&f1, &f2), l2, instants)?;
    ctx.svg(
        &mut stats,
        "fig16_time_domain_check.svg",
        &Figure::new(
            format!(
                "Fig. 16: time-domain march of point b (T = {period:.3}): periodicity defect {:.1}% (displacement {:.1}%)",
                100.0 * report.defect,
                100.0 * report.displacement_defect
            ),
            3,
            vec![snap, pos.into(), frc.into()],
        ),
    )?;
    let n = tm.len();
    ctx.columns(
        &mut stats,
        "fig16_time_domain_check.csv",
        &[
            "t_mid",
            "contact_force_over_g0",
            "pos1_over_g0",
            "pos2_over_g0",
        ],
        &[&tm, &force, &u1[1..=n], &u2[1..=n]],
    )?;
    Ok(stats)
}

/// Fig. 17: configuration 2 (3.8, 4, 4), NSM1 and one field.
pub fn fig17(ctx: &Ctx) -> Res<Stats> {
    let mut stats = Stats::default();
    // From T = 3.95 the grazing seed of this system slides to rest (bar 2, four times softer,
    // takes the motion); from 3.9 it starts on the branch.
    let nsm1 = Branch::new("NSM1", 1, (3.9, 2.85), ctx.steps(221));
    let tb = TwoBar::new((3.8, 4.0, 4.0), &[nsm1])?.with_nsm2_of_bar_2()?;
    stats.count(&tb.runs);
    let mut bb = backbone_panel(
        "(3.8, 4, 4), α = E₁A₁/(E₂A₂): NSM1 and NSM2, m = 20",
        &labelled_series(
            &[
                (&tb.runs[0], GREEN, Marker::Circle),
                (&tb.runs[1], RED, Marker::Circle),
            ],
            tb.w1,
        ),
        None,
    );
    let w12 = OMEGA_1_BAR_2;
    bb.x_guides = vec![w12 / tb.w1, 4.0 / 3.0 * w12 / tb.w1];
    let basis = settings(M).cosine_basis()?;
    let lowest = tb.runs[0]
        .converged()
        .min_by(|x, y| x.energy_normalized.total_cmp(&y.energy_normalized));
    let mut panels = Vec::new();
    let mut marks = Vec::new();
    if let Some(p) = lowest {
        marks.push(("b", p));
        panels.push(snapshots_of(
            &tb.system,
            &basis,
            p,
            format!("point b: {}", frequency_energy(p, tb.w1)),
        )?);
    }
    // Without a converged point the legend entry "point" is left out altogether.
    let all = if marks.is_empty() {
        vec![Panel::Lines(bb)]
    } else {
        marked(bb, "", &marks, tb.w1, panels)
    };
    ctx.backbone_figure(
        &mut stats,
        "fig17_two_bar_config2",
        &Figure::new("Fig. 17: two bars (3.8, 4, 4)", 2, all),
        &tb.runs(),
        tb.w1,
    )?;
    Ok(stats)
}

/// Bar 1's subharmonic motion in a family-2 point of configuration 3, where bar 2 moves in its
/// NSM1: `(n, j)` for bar 1 in NSM`j` sub`n`, i.e. its harmonic `n > 1` carrying the most of
/// its energy (at least half of the most any of its harmonics carries) near its clamped-free
/// mode `j` (`n Omega` within 5 % of `(2j - 1) pi / 2`); `None` when bar 2 is not in NSM1 (its
/// harmonic 1 not its largest) or bar 1 has no such harmonic.
fn subharmonic_of_bar_1(
    system: &BarSystem,
    basis: &CosineBasis,
    p: &BackbonePoint,
) -> Res<Option<(usize, usize)>> {
    let by_bar = harmonic_energies_by_bar(system, basis, &p.x, p.omega)?;
    let largest = |e: &[f64], from: usize| {
        (from..e.len())
            .max_by(|&a, &b| e[a].total_cmp(&e[b]))
            .unwrap_or(from)
    };
    let (bar1, bar2) = (&by_bar[0], &by_bar[1]);
    if largest(bar2, 1) != 1 {
        return Ok(None);
    }
    let n = largest(bar1, 2);
    let most = bar1.iter().copied().fold(0.0, f64::max);
    let j = ((n as f64 * p.omega / (PI / 2.0) + 1.0) / 2.0)
        .round()
        .max(1.0) as usize;
    let mode = (2 * j - 1) as f64 * PI / 2.0;
    let near = (n as f64 * p.omega / mode - 1.0).abs() < 0.05;
    Ok((bar1[n] >= 0.5 * most && near).then_some((n, j)))
}

/// Frequencies `Omega / omega_1` above `omega_3^(1)/2 = 2.5` where the paper's point e of
/// Fig. 18 (bar 1 in NSM3 sub2, hardening) is sought from seeds.
const ABOVE_HALF_OMEGA_3: [f64; 4] = [2.51, 2.53, 2.56, 2.6];

/// Bar 1 in NSM3 sub2 with bar 2 in NSM1 (the paper's point e of Fig. 18) at the lowest of
/// [`ABOVE_HALF_OMEGA_3`] where a seed combining bar 2's first mode on harmonic 1 (system mode
/// 2) and bar 1's third mode on harmonic 2 (system mode 4), in the ratios 1:1, 2:1 and 1:0.5,
/// converges to a motion in contact with that content.
fn hardening_nsm3_sub2(
    system: &BarSystem,
    basis: &CosineBasis,
    w1: f64,
) -> Res<Option<BackbonePoint>> {
    let mut problem = NonsmoothSystem::new(system, settings(M))?;
    let solver = SemismoothNewton::default();
    for ratio in ABOVE_HALF_OMEGA_3 {
        let omega = ratio * w1;
        let bar_2 = branch_seed(&mut problem, 2, 1, omega)?;
        let bar_1 = branch_seed(&mut problem, 4, 2, omega)?;
        for (a, b) in [(1.0, 1.0), (2.0, 1.0), (1.0, 0.5)] {
            let mut x: Vec<f64> = (bar_2.iter().zip(&bar_1))
                .map(|(u, v)| a * u + b * v)
                .collect();
            problem.set_parameter(omega);
            let Ok(info) = solver.solve(&mut problem, &mut x) else {
                continue;
            };
            let point = solved_point(system, basis, (x, omega), &info)?;
            // Above rest (a seed can slide to it), with the content of e.
            if point.energy_normalized > 1e-3
                && subharmonic_of_bar_1(system, basis, &point)? == Some((2, 3))
            {
                return Ok(Some(point));
            }
        }
    }
    Ok(None)
}

/// Fig. 18: configuration 3 (0.95, 2, 1): the two families and a few fields.
pub fn fig18(ctx: &Ctx) -> Res<Stats> {
    let mut stats = Stats::default();
    let w12 = 2.0 * PI / (2.0 * 0.95);
    let tb = TwoBar::new(
        (0.95, 2.0, 1.0),
        &[
            Branch::new("NSM1 (family 1)", 1, (3.95, 3.45), ctx.steps(101)),
            Branch::new(
                "NSM2 (family 2)",
                2,
                (2.0 * PI / w12 - 0.01, 1.45),
                ctx.steps(91),
            ),
        ],
    )?;
    let (runs, w1) = (&tb.runs, tb.w1);
    stats.count(runs);
    let mut bb = backbone_panel(
        "(0.95, 2, 1): backbones, m = 20",
        &{
            let mut s = labelled_series(
                &[
                    (&runs[0], Rgb::BLACK, Marker::Circle),
                    (&runs[1], PALETTE[7], Marker::Square),
                ],
                w1,
            );
            s[1].size = 2;
            s
        },
        None,
    );
    bb.x_guides = vec![1.0, 1.13, 0.5 * w12 / w1, w12 / w1, 1.25 * w12 / w1];
    // The paper's a and b (family 1) by the bars' harmonic content; its c, d and e are
    // family-2 points with bar 2 in NSM1 and bar 1 in NSM6 sub5, NSM3 sub2 below (softening)
    // and above (hardening) omega_3^(1)/2 (`subharmonic_of_bar_1`).
    let half = 0.5 * w12 / w1;
    let basis = settings(M).cosine_basis()?;
    let family1 = lettered::fig18_family1(&tb.system, &basis, w1, &runs[0], half)?;
    for (letter, p) in &family1 {
        stats.lettered(letter, p.is_some());
    }
    let mut classified = Vec::new();
    for p in runs[1].converged() {
        if let Some(nj) = subharmonic_of_bar_1(&tb.system, &basis, p)? {
            classified.push((p, nj));
        }
    }
    // The point of NSM`j` sub`n` in bar 1 nearest `omega_j / n`, on the side `side` of it.
    let nearest = |(n, j): (usize, usize), side: f64| {
        let centre = (2 * j - 1) as f64 * PI / 2.0 / n as f64;
        classified
            .iter()
            .filter(|(p, nj)| *nj == (n, j) && (p.omega - centre) * side >= 0.0)
            .min_by(|a, b| {
                (a.0.omega - centre)
                    .abs()
                    .total_cmp(&(b.0.omega - centre).abs())
            })
            .map(|(p, _)| *p)
    };
    // Family 2's grid does not reach NSM3 sub2 above omega_3^(1)/2: e is sought from seeds of
    // the combined motion itself when the run has none.
    let seeded = match nearest((2, 3), 1.0) {
        Some(_) => None,
        None => hardening_nsm3_sub2(&tb.system, &basis, w1)?,
    };
    let family2 = [
        ("c", nearest((5, 6), 1.0).or(nearest((5, 6), -1.0))),
        ("d", nearest((2, 3), -1.0)),
        ("e", nearest((2, 3), 1.0).or(seeded.as_ref())),
    ];
    for (letter, p) in &family2 {
        stats.lettered(letter, p.is_some());
    }
    let named: Vec<(&str, &BackbonePoint)> = family1
        .into_iter()
        .chain(family2)
        .filter_map(|(name, p)| p.map(|p| (name, p)))
        .collect();
    let panels = named_snapshots(&tb, &named)?;
    ctx.backbone_figure(
        &mut stats,
        "fig18_two_bar_config3",
        &Figure::new(
            "Fig. 18: two bars (0.95, 2, 1) (dashed: ω₁⁽¹⁾, 1.13 ω₁⁽¹⁾, ω₁⁽²⁾/2, ω₁⁽²⁾, 1.25 ω₁⁽²⁾)",
            3,
            marked(bb, "", &named, w1, panels),
        ),
        &tb.runs(),
        w1,
    )?;
    Ok(stats)
}

/// Whether the `i`-th of a branch's converged points (in order along the branch) is off an
/// internal-resonance spike: its energy is at most 1.5 times the median of its neighbours'
/// (three on each side). Spikes carry extra energy in a resonant harmonic; the paper's
/// lettered motions lie on the backbone between them.
fn off_spike(points: &[&BackbonePoint], i: usize) -> bool {
    let (lo, hi) = (i.saturating_sub(3), (i + 4).min(points.len()));
    let mut around: Vec<f64> = (lo..hi)
        .filter(|&j| j != i)
        .map(|j| points[j].energy_normalized)
        .collect();
    if around.is_empty() {
        return true;
    }
    around.sort_by(f64::total_cmp);
    points[i].energy_normalized <= 1.5 * around[around.len() / 2]
}
