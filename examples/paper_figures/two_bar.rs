//! Figs. 14-16: two bars in contact in configuration 1, `(l, c, alpha)` = (0.95, 1, 1), with
//! the paper's definition `α = E₁A₁/(E₂A₂)` (`reference::paper_second_bar`): backbones with
//! snapshots of both bars, the contact interface, and a time-domain check of one point; and
//! the two-bar system and snapshots that Figs. 17 and 18 (`designs`) share.

use crate::common::{
    arclength_series, field, frame_on_branches, frequency_energy, labelled_series, marked, omega_1,
    over_gap, reference_line, right_end, settings, Ctx, Res, Stats, Table, BLUE, GAP, GREEN, RED,
    YELLOW,
};
use crate::lettered;
use crate::runs::{arclength_run, energy_run, run, Branch, Run};
use nonsmooth_modes::branches::BackbonePoint;
use nonsmooth_modes::fourier::CosineBasis;
use nonsmooth_modes::modal::{
    harmonic_energies_by_bar, law_history, natural_frequencies, ContactState,
};
use nonsmooth_modes::plot::{
    backbone_panel, snapshots_panel, Figure, LegendPosition, LinePanel, Marker, Panel, PlacedBar,
    Placement, Rgb, Series, SpaceTimeField, PALETTE,
};
use nonsmooth_modes::reference::{paper_second_bar, two_bars_in_contact};
use nonsmooth_modes::system::{BarSystem, NonsmoothSystem};
use nonsmooth_modes::verify::{march, periodicity_check, MarchOptions, PeriodicityOptions, State};
use std::f64::consts::PI;

/// Harmonics of every two-bar run.
pub const M: usize = 20;

/// Samples of the interface histories of Figs. 15 and 16.
const SAMPLES: usize = 600;

/// First natural frequency `pi c / (2 l)` of bar 2 in configurations 1 and 2, where
/// `l / c = 0.95`.
pub const OMEGA_1_BAR_2: f64 = PI / (2.0 * 0.95);

/// A two-bar system, its backbones and the first natural frequency `w1` of bar 1.
pub struct TwoBar {
    pub system: BarSystem,
    pub runs: Vec<Run>,
    pub w1: f64,
}

impl TwoBar {
    /// Bar 2 `(l, c, alpha)` (the paper's triplet, `α = E₁A₁/(E₂A₂)`) facing the unit
    /// bar, and its backbones along `branches`.
    pub fn new((l, c, alpha): (f64, f64, f64), branches: &[Branch<'_>]) -> Res<Self> {
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
    pub fn with_nsm2_of_bar_2(self) -> Res<Self> {
        self.with_energy_run("NSM2 (bar 2)", 4)
    }

    /// The system with system mode `mode`'s branch added, continued in the energy
    /// ([`energy_run`]) under `label`.
    pub fn with_energy_run(mut self, label: &str, mode: usize) -> Res<Self> {
        let run = energy_run(&self.system, M, label, mode)?;
        self.runs.push(run);
        Ok(self)
    }

    pub fn runs(&self) -> Vec<&Run> {
        self.runs.iter().collect()
    }

    /// The median, over the converged points of run `i`, of the share of the system's energy
    /// that internal resonances carry: the harmonics `n >= 2` whose frequency `n Omega` lies
    /// within [`lettered::RESONANCE_BAND`] of an open-contact natural frequency (`None` for a
    /// run without converged points). The paper compares configurations by it in words ("much
    /// less dominant"); configurations 1 and 2 share their natural frequencies, so the band
    /// covers the same harmonics in both.
    pub fn resonant_energy_median(&self, i: usize) -> Res<Option<f64>> {
        let basis = settings(M).cosine_basis()?;
        let points: Vec<&BackbonePoint> = self.runs[i].converged().collect();
        let highest = (M + 1) as f64 * points.iter().fold(0.0f64, |a, p| a.max(p.omega));
        let natural: Vec<f64> = natural_frequencies(&self.system, ContactState::Open, highest)?
            .iter()
            .map(|mode| mode.omega)
            .collect();
        let near = |f: f64| {
            natural
                .iter()
                .any(|w| (f / w - 1.0).abs() < lettered::RESONANCE_BAND)
        };
        let mut shares = Vec::with_capacity(points.len());
        for p in points {
            let by_bar = harmonic_energies_by_bar(&self.system, &basis, &p.x, p.omega)?;
            let total: f64 = by_bar.iter().flatten().sum();
            let resonant: f64 = (by_bar.iter())
                .flat_map(|e| {
                    (2..e.len())
                        .filter(|&n| near(n as f64 * p.omega))
                        .map(|n| e[n])
                })
                .sum();
            if total > 0.0 {
                shares.push(resonant / total);
            }
        }
        shares.sort_by(f64::total_cmp);
        Ok(shares.get(shares.len() / 2).copied())
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
pub fn snapshots_of(
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
pub fn named_snapshots(tb: &TwoBar, points: &[(&str, &BackbonePoint)]) -> Res<Vec<Panel>> {
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
    stats.note = resonance_note(tb)?;
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

/// The progress note of a configuration's NSM1 (run 0): the median share of its energy in
/// internal resonances ([`TwoBar::resonant_energy_median`]).
pub fn resonance_note(tb: &TwoBar) -> Res<String> {
    Ok(match tb.resonant_energy_median(0)? {
        Some(share) => format!(
            "NSM1: internal resonances carry a median {:.0} % of the energy",
            100.0 * share
        ),
        None => "NSM1: no converged point".into(),
    })
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
