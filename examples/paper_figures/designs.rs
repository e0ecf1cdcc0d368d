//! Figs. 17 and 18: two bars in contact in configurations 2, `(3.8, 4, 4)`, and 3,
//! `(0.95, 2, 1)`: other designs than configuration 1 (Figs. 14-16), with the same linear
//! frequencies (configuration 2) or well-separated ones (configuration 3).

use crate::common::{
    frequency_energy, labelled_series, marked, settings, through_series, Ctx, Res, Stats, GREEN,
    RED,
};
use crate::lettered;
use crate::runs::{continued_from, kept_around, Branch};
use crate::seeded::{self, Combination};
use crate::two_bar::{named_snapshots, resonance_note, snapshots_of, TwoBar, M, OMEGA_1_BAR_2};
use nonsmooth_modes::branches::BackbonePoint;
use nonsmooth_modes::fourier::CosineBasis;
use nonsmooth_modes::modal::harmonic_energies_by_bar;
use nonsmooth_modes::plot::{backbone_panel, Figure, Marker, Panel, Rgb, PALETTE};
use nonsmooth_modes::system::BarSystem;
use std::f64::consts::PI;

/// Fig. 17: configuration 2 (3.8, 4, 4), NSM1 and one field.
pub fn fig17(ctx: &Ctx) -> Res<Stats> {
    let mut stats = Stats::default();
    // From T = 3.95 the grazing seed of this system slides to rest (bar 2, four times softer,
    // takes the motion); from 3.9 it starts on the branch.
    let nsm1 = Branch::new("NSM1", 1, (3.9, 2.85), ctx.steps(221));
    // NSM2 of bar 1 (system mode 3) rises almost vertically against the soft bar 2 (within
    // 0.3 % of its linear frequency up to 300 times its grazing energy): a period grid steps
    // over it, the energy follows it.
    let tb = TwoBar::new((3.8, 4.0, 4.0), &[nsm1])?
        .with_energy_run("NSM2 (bar 1)", 3)?
        .with_nsm2_of_bar_2()?;
    stats.count(&tb.runs);
    stats.note = resonance_note(&tb)?;
    let mut bb = backbone_panel(
        "(3.8, 4, 4), α = E₁A₁/(E₂A₂): NSM1 and NSM2, m = 20",
        &labelled_series(
            &[
                (&tb.runs[0], GREEN, Marker::Circle),
                (&tb.runs[1], RED, Marker::Circle),
                (&tb.runs[2], PALETTE[5], Marker::Circle),
            ],
            tb.w1,
        ),
        None,
    );
    let w12 = OMEGA_1_BAR_2;
    bb.x_guides = vec![w12 / tb.w1, 4.0 / 3.0 * w12 / tb.w1, 3.0];
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
        &Figure::new(
            "Fig. 17: two bars (3.8, 4, 4) (dashed: ω₁⁽²⁾, 4/3 ω₁⁽²⁾, ω₂⁽¹⁾)",
            2,
            all,
        ),
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
/// converges to a checked motion in contact with that content.
fn hardening_nsm3_sub2(
    system: &BarSystem,
    basis: &CosineBasis,
    w1: f64,
) -> Res<Option<BackbonePoint>> {
    let omegas = ABOVE_HALF_OMEGA_3.map(|r| r * w1);
    let seed = Combination {
        first: (2, 1),
        second: (4, 2),
        weights: &[(1.0, 1.0), (2.0, 1.0), (1.0, 0.5)],
    };
    seeded::seek(system, basis, M, &omegas, &seed, |p| {
        Ok(subharmonic_of_bar_1(system, basis, p)? == Some((2, 3)))
    })
}

/// Bar 1 in NSM1 with bar 2 carried by its harmonic 1 (the paper's point b of Fig. 18) in
/// `(half, 1.13)` (`Omega / omega_1`), sought at seven frequencies spread over the interval,
/// nearest its middle first, from seeds combining bar 1's first mode (system mode 1) and bar
/// 2's first mode (system mode 2), both on harmonic 1, in the ratios `a : b` with
/// `a = 1, 2, 4` and `b = +-0.5, +-1, +-2`.
fn family1_with_nsm1_of_bar_2(
    system: &BarSystem,
    basis: &CosineBasis,
    w1: f64,
    half: f64,
) -> Res<Option<BackbonePoint>> {
    let omegas: Vec<f64> = seeded::nearest_first(half, 1.13, 19, 0.5 * (half + 1.13))
        .into_iter()
        .map(|r| r * w1)
        .collect();
    let weights: Vec<(f64, f64)> = [1.0, 2.0, 4.0]
        .into_iter()
        .flat_map(|a| [-2.0, -1.0, -0.5, 0.5, 1.0, 2.0].map(|b| (a, b)))
        .collect();
    let seed = Combination {
        first: (1, 1),
        second: (2, 1),
        weights: &weights,
    };
    seeded::seek(system, basis, M, &omegas, &seed, |p| {
        lettered::fig18_family1_character(system, basis, p, 1)
    })
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
    let mut family1 = lettered::fig18_family1(&tb.system, &basis, w1, &runs[0], half)?;
    // Family 1's grid keeps bar 2 on its harmonic 2 over the whole of `(half, 1.13)`: b is
    // sought from seeds of the motion itself when the run has none.
    let seeded_b = match family1[1].1 {
        Some(_) => None,
        None => family1_with_nsm1_of_bar_2(&tb.system, &basis, w1, half)?,
    };
    family1[1].1 = family1[1].1.or(seeded_b.as_ref());
    // The seeded b's own branch: continued from b both ways in steps of 0.002 in the period,
    // kept while its points keep b's character.
    let through_b = match &seeded_b {
        Some(b) => {
            let label = "family 1, bar 2 on harmonic 1 (through b)";
            let all = continued_from(&tb.system, M, b, (0.002, 30), label)?;
            let keep =
                |q: &BackbonePoint| lettered::fig18_family1_character(&tb.system, &basis, q, 1);
            Some(kept_around(all, b, keep)?)
        }
        None => None,
    };
    if let Some(b) = &through_b {
        stats.count([b]);
        bb.series.push(through_series(b, w1));
    }
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
        &tb.runs().into_iter().chain(&through_b).collect::<Vec<_>>(),
        w1,
    )?;
    Ok(stats)
}
