//! What the paper's lettered points are, and the pick of the point that is one: each figure
//! states the character its letter must have (the label of the branch, contacts and grazings
//! per period, the harmonic content and the nodes of each bar), and the point nearest the
//! paper's location among those that have it is the letter. A figure with no such point has
//! its letter "not found" in `summary.csv`, rather than a point that only sits at the place.

use crate::common::Res;
use crate::runs::Run;
use nonsmooth_modes::branches::BackbonePoint;
use nonsmooth_modes::fourier::CosineBasis;
use nonsmooth_modes::modal::{displacement_grid, harmonic_energies_by_bar, Label};
use nonsmooth_modes::system::BarSystem;

/// Relative band `|n Omega / omega_j - 1|` within which harmonic `n` of a bar counts as
/// resonating with the bar's mode `j`.
pub const RESONANCE_BAND: f64 = 0.05;

/// Share of its largest magnitude below which a displacement counts as zero when nodes are
/// counted (ripples of the truncated series around a node are not nodes).
const NODE_FLOOR: f64 = 0.05;

/// The content of one point: per bar, the share of that bar's energy in each harmonic
/// `0..=m`, and the fundamental frequency.
pub struct Content {
    pub omega: f64,
    pub by_bar: Vec<Vec<f64>>,
}

impl Content {
    /// The content of `p`, a point of `system` in `basis`.
    pub fn of(system: &BarSystem, basis: &CosineBasis, p: &BackbonePoint) -> Res<Self> {
        let by_bar = harmonic_energies_by_bar(system, basis, &p.x, p.omega)?
            .into_iter()
            .map(|e| {
                let total: f64 = e.iter().sum();
                let total = if total > 0.0 { total } else { 1.0 };
                e.iter().map(|v| v / total).collect()
            })
            .collect();
        Ok(Self {
            omega: p.omega,
            by_bar,
        })
    }

    /// The oscillating harmonic `n >= 1` holding most of bar `bar`'s energy.
    pub fn dominant(&self, bar: usize) -> usize {
        let e = &self.by_bar[bar];
        (1..e.len())
            .max_by(|&a, &b| e[a].total_cmp(&e[b]))
            .unwrap_or(1)
    }

    /// The largest share of bar `bar`'s energy in one harmonic `n >= 2` whose frequency
    /// `n Omega` lies within [`RESONANCE_BAND`] of one of the `natural` frequencies: how much
    /// of the bar's motion an internal resonance carries.
    pub fn resonant_share(&self, bar: usize, natural: &[f64]) -> f64 {
        let e = &self.by_bar[bar];
        (2..e.len())
            .filter(|&n| {
                let f = n as f64 * self.omega;
                natural.iter().any(|w| (f / w - 1.0).abs() < RESONANCE_BAND)
            })
            .map(|n| e[n])
            .fold(0.0, f64::max)
    }

    /// Share of bar `bar`'s energy in the harmonics `n` whose frequency `n Omega` lies within
    /// [`RESONANCE_BAND`] of `mode` (one of the bar's natural frequencies).
    pub fn share_near(&self, bar: usize, mode: f64) -> f64 {
        (1..self.by_bar[bar].len())
            .filter(|&n| (n as f64 * self.omega / mode - 1.0).abs() < RESONANCE_BAND)
            .map(|n| self.by_bar[bar][n])
            .sum()
    }
}

/// Interior nodes of bar `bar` in the motion `p`: the sign changes along the bar of its
/// displacement at the instant it is largest, values below [`NODE_FLOOR`] of the largest
/// left out.
pub fn nodes(system: &BarSystem, basis: &CosineBasis, p: &BackbonePoint, bar: usize) -> usize {
    let (nx, nt) = (61, 64);
    let g = displacement_grid(system, basis, &p.x, p.omega, bar, nx, nt);
    let row = |k: usize| &g.displacement[k * nx..(k + 1) * nx];
    let norm = |k: usize| row(k).iter().map(|u| u * u).sum::<f64>();
    let Some(k) = (0..nt).max_by(|&a, &b| norm(a).total_cmp(&norm(b))) else {
        return 0;
    };
    let most = row(k).iter().fold(0.0f64, |a, u| a.max(u.abs()));
    let signs: Vec<bool> = row(k)
        .iter()
        .filter(|u| u.abs() > NODE_FLOOR * most)
        .map(|u| *u > 0.0)
        .collect();
    signs.windows(2).filter(|w| w[0] != w[1]).count()
}

/// Whether `p` carries label `wanted` (compared by kind and numbers).
pub fn labelled(p: &BackbonePoint, wanted: &Label) -> bool {
    p.label.as_ref() == Some(wanted)
}

/// The converged point of `run` nearest the period `target` among those for which `has`
/// holds.
pub fn nearest_with(
    run: &Run,
    target: f64,
    mut has: impl FnMut(&BackbonePoint) -> Res<bool>,
) -> Res<Option<&BackbonePoint>> {
    let mut best: Option<&BackbonePoint> = None;
    for p in run.converged() {
        let closer = best.is_none_or(|b| (p.period - target).abs() < (b.period - target).abs());
        if closer && has(p)? {
            best = Some(p);
        }
    }
    Ok(best)
}

/// Least share of a bar's energy near one of its modes for that bar to count as internally
/// resonant with the mode.
pub const MIN_RESONANT_SHARE: f64 = 0.05;

/// Natural frequency of mode `j` of bar `bar` of `system` held at one end and free at the
/// other (a bar of the paper's two-bar systems with its contact open): `(2j - 1) pi c / (2 l)`.
pub fn clamped_free(system: &BarSystem, bar: usize, j: usize) -> f64 {
    let b = &system.bars()[bar];
    (2 * j - 1) as f64 * std::f64::consts::PI * b.wave_speed() / (2.0 * b.length())
}

/// Whether bar `bar` of `p` is in its NSM `j`: its harmonic 1 holds the most of its energy and
/// its displacement has `j - 1` nodes.
fn in_mode(
    system: &BarSystem,
    basis: &CosineBasis,
    p: &BackbonePoint,
    c: &Content,
    bar: usize,
    j: usize,
) -> bool {
    c.dominant(bar) == 1 && nodes(system, basis, p, bar) == j - 1
}

/// The converged point of `points` of median energy among those for which `has` holds.
fn median_with<'a>(
    points: impl Iterator<Item = &'a BackbonePoint>,
    mut has: impl FnMut(&BackbonePoint) -> Res<bool>,
) -> Res<Option<&'a BackbonePoint>> {
    let mut kept = Vec::new();
    for p in points.filter(|p| p.converged()) {
        if has(p)? {
            kept.push(p);
        }
    }
    kept.sort_by(|a, b| a.energy_normalized.total_cmp(&b.energy_normalized));
    Ok(kept.get(kept.len() / 2).copied())
}

/// The lettered points of Fig. 14 (configuration 1), by the paper's description:
/// - b, c, d: both bars in their NSM1 (no node, harmonic 1 the largest in each), on the
///   skeleton, nearest `Omega/omega_1 = 1.07, 1.2, 1.27` among `nsm1` (the NSM1 run's points
///   off its spikes, in order);
/// - e: the same, with bar 1 internally resonant with its mode 6 and bar 2 with its mode 4
///   (each at least [`MIN_RESONANT_SHARE`] of the bar's energy near the mode): the point where
///   the smaller of the two shares is largest;
/// - f: on the first NSM2 sub-branch (`first`), both bars with one node and bar 1 in its NSM2,
///   the skeleton point of median energy;
/// - g: on the second (`second`), both bars in their NSM2 (one node, harmonic 1 the largest in
///   each), the skeleton point of median energy.
pub fn fig14<'a>(
    system: &BarSystem,
    basis: &CosineBasis,
    w1: f64,
    nsm1: &[&'a BackbonePoint],
    first: Option<&'a Run>,
    second: Option<&'a Run>,
) -> Res<Vec<(&'static str, Option<&'a BackbonePoint>)>> {
    let both_nsm1 = |p: &BackbonePoint| -> Res<Option<Content>> {
        let c = Content::of(system, basis, p)?;
        let ok = labelled(p, &Label::Skeleton)
            && (0..2).all(|bar| in_mode(system, basis, p, &c, bar, 1));
        Ok(ok.then_some(c))
    };
    let mut kept = Vec::new();
    for &p in nsm1 {
        if let Some(c) = both_nsm1(p)? {
            kept.push((p, c));
        }
    }
    let near = |target: f64| {
        kept.iter()
            .min_by(|a, b| {
                (a.0.omega / w1 - target)
                    .abs()
                    .total_cmp(&(b.0.omega / w1 - target).abs())
            })
            .map(|(p, _)| *p)
    };
    let (mode6, mode4) = (clamped_free(system, 0, 6), clamped_free(system, 1, 4));
    let resonant = |c: &Content| c.share_near(0, mode6).min(c.share_near(1, mode4));
    let e = kept
        .iter()
        .filter(|(_, c)| resonant(c) >= MIN_RESONANT_SHARE)
        .max_by(|a, b| resonant(&a.1).total_cmp(&resonant(&b.1)))
        .map(|(p, _)| *p);
    let f = match first {
        Some(r) => median_with(r.points.iter(), |p| {
            let c = Content::of(system, basis, p)?;
            Ok(labelled(p, &Label::Skeleton)
                && in_mode(system, basis, p, &c, 0, 2)
                && nodes(system, basis, p, 1) == 1)
        })?,
        None => None,
    };
    let g = match second {
        Some(r) => median_with(r.points.iter(), |p| {
            let c = Content::of(system, basis, p)?;
            Ok(labelled(p, &Label::Skeleton)
                && (0..2).all(|bar| in_mode(system, basis, p, &c, bar, 2)))
        })?,
        None => None,
    };
    Ok(vec![
        ("b", near(1.07)),
        ("c", near(1.2)),
        ("d", near(1.27)),
        ("e", e),
        ("f", f),
        ("g", g),
    ])
}

/// The family-1 points a and b of Fig. 18 (configuration 3), by the paper's description:
/// bar 1 in its NSM1 (harmonic 1 the largest of its energy, no node), and bar 2 in NSM1 sub2
/// (harmonic 2 the largest of its energy) for a, in NSM1 (harmonic 1) for b; each the point of
/// `run` nearest the middle of its interval of `Omega/omega_1`: `[1, half]` for a,
/// `[half, 1.13]` for b, `half = omega_1^(2) / (2 omega_1)`.
pub fn fig18_family1<'a>(
    system: &BarSystem,
    basis: &CosineBasis,
    w1: f64,
    run: &'a Run,
    half: f64,
) -> Res<Vec<(&'static str, Option<&'a BackbonePoint>)>> {
    let mut out = Vec::new();
    for (letter, lo, hi, bar2) in [("a", 1.0, half, 2), ("b", half, 1.13, 1)] {
        let target = 2.0 * std::f64::consts::PI / (0.5 * (lo + hi) * w1);
        let p = nearest_with(run, target, |p| {
            Ok((lo..hi).contains(&(p.omega / w1))
                && fig18_family1_character(system, basis, p, bar2)?)
        })?;
        out.push((letter, p));
    }
    Ok(out)
}

/// Whether `p` has the character of Fig. 18's family 1 with bar 2 carried by its harmonic
/// `bar2`: bar 1 in its NSM1 (harmonic 1 the largest of its energy, no node), and `bar2` the
/// oscillating harmonic holding most of bar 2's energy.
pub fn fig18_family1_character(
    system: &BarSystem,
    basis: &CosineBasis,
    p: &BackbonePoint,
    bar2: usize,
) -> Res<bool> {
    let c = Content::of(system, basis, p)?;
    Ok(in_mode(system, basis, p, &c, 0, 1) && c.dominant(1) == bar2)
}

/// Whether `p` is within `tolerance` of its run's exact energy (always, for a run without an
/// exact family).
pub fn on_exact(run: &Run, p: &BackbonePoint, tolerance: f64) -> bool {
    run.exact
        .is_none_or(|e| (p.energy_normalized / e.at(p.period) - 1.0).abs() < tolerance)
}

/// Whether `p` touches the obstacle of a one-obstacle system `contacts` times per period.
pub fn contacts(p: &BackbonePoint, contacts: usize) -> bool {
    p.character
        .as_ref()
        .is_some_and(|c| c.contacts == [contacts])
}
