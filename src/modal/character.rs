//! Which motion a computed periodic point is: its [`Character`] (contacts and grazings per
//! period, where its energy lies among bars and harmonics, the linear modes it is near) and a
//! [`Label`] in the terms of Lu & Legrand (2021, §4.1): the skeleton of a nonsmooth mode
//! ("main NSM `i`"), a subharmonic ("NSM `i` sub `k`"), or an internal resonance.
//!
//! Both are post-processing of one point, like [`mod@crate::modal::signature`] which they
//! build on: one law history per law and `O(m)` flops for the energies.

use crate::check::check_finite;
use crate::check::check_frequency;
use crate::error::SettingsError;
use crate::fourier::Basis;
use crate::modal::signature::{contact_and_gap_samples, harmonic_energies_by_bar, periodic_runs};
use crate::system::NonsmoothSystem;
use std::fmt;

/// Width of the band `g <= GRAZING_TOLERANCE * s_l` above the obstacle in which an approach
/// counts as a grazing, relative to the gap scale `s_l` of law `l` (see [`character`]).
///
/// Why 2%: a sampled grazing misses the true closest approach by at most
/// `g''/2 (pi/N)^2`, for an approach on harmonic `j` about `2.5 (j/N)^2` of the swing, below
/// 2% wherever `N >= 12 j` (every harmonic with the default 30 samples per harmonic); an
/// approach that stays 2% of the swing away from the obstacle is visibly apart from it.
pub const GRAZING_TOLERANCE: f64 = 0.02;

/// What a computed periodic motion is like: what a user needs to tell which motion it is.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Character {
    /// Per unilateral law (the order of [`crate::system::BarSystem::laws`]): contact
    /// intervals per period ([`crate::modal::contact_intervals`]).
    pub contacts: Vec<usize>,
    /// Per unilateral law: grazings per period, approaches within the band
    /// [`GRAZING_TOLERANCE`] of the obstacle that contain no contact sample (see
    /// [`character`]).
    pub grazings: Vec<usize>,
    /// Share of the bars' time-averaged energy in each bar (sums to 1).
    pub energy_by_bar: Vec<f64>,
    /// Share of the bars' time-averaged energy in each harmonic `0..=m` (sums to 1).
    pub energy_by_harmonic: Vec<f64>,
    /// The oscillating harmonic `j >= 1` (frequency `j Omega`) holding the largest share; the
    /// lowest such `j` on a tie.
    pub dominant_harmonic: usize,
    /// The share of [`Character::dominant_harmonic`]: near 1 for a clean motion, well below
    /// it where two harmonics compete (the label is then less telling).
    pub dominant_share: f64,
    /// Per bar: the open-contact linear mode of the assembly whose natural frequency is
    /// nearest `j_b Omega`, `j_b` the harmonic holding most of that bar's energy. Numbered as
    /// in [`nearest_mode`] (0 for a rigid-body mode); `None` for a bar at rest (its
    /// oscillating energy at most `f64::EPSILON` of the motion's) or an empty `natural`.
    pub dominant_mode_by_bar: Vec<Option<usize>>,
    /// Per bar: the harmonic `j_b >= 1` with the largest energy in that bar (`None` for a bar
    /// at rest), the harmonic whose frequency `j_b Omega` names its mode.
    pub dominant_harmonic_by_bar: Vec<Option<usize>>,
}

/// The [`Character`] of the motion `x` of `problem` at fundamental frequency `omega`, with
/// `natural` the open-contact natural frequencies of the assembly, ascending (computed once by
/// the caller, e.g. from [`crate::modal::natural_frequencies`] with
/// [`ContactState::Open`](crate::modal::ContactState::Open); rigid-body modes of
/// [`crate::modal::rigid_body_modes`] enter as zeros).
///
/// # Energies
/// The shares are those of the time-averaged energies `E_(b,n)` of
/// [`harmonic_energies_by_bar`] (ground springs left out), divided by their sum: they do not
/// depend on the amplitude of `x`, and scaling the gaps with `x` leaves them unchanged.
///
/// # Grazings
/// Let `g_l(theta_k)` be the gap of law `l` on the `N` instants of the full grid and
/// `s_l = max(|g0_l|, max_k g_l - min_k g_l)` its scale (the gap at rest, or the swing of the
/// motion if larger), so that the count does not depend on units or on the amplitude. A
/// sample is *near* the obstacle if it is in contact (the criterion of
/// [`crate::modal::contact_intervals`]) or `g_l <= GRAZING_TOLERANCE s_l`. A grazing is a
/// maximal periodic run of near samples with no contact sample in it: an approach that comes
/// within the band and leaves it without a contact interval. The ripples of a truncated
/// Fourier series next to a contact interval, while they stay within the band, join its run
/// and so count as no grazing; the contact intervals themselves are counted by `contacts`.
///
/// # Errors
/// Those of [`harmonic_energies_by_bar`] and [`crate::modal::contact_intervals`] (wrong
/// length of `x`, a frequency that is not positive and finite or outside the problem's range,
/// non-finite unknowns or results); for `natural`, [`SettingsError::NotFinite`],
/// [`SettingsError::OutOfRange`] for a negative entry or one below its predecessor; and
/// [`SettingsError::NotPositive`] for a motion without oscillating energy (at rest, or
/// constant in time), whose shares would be `0/0`; [`SettingsError::NonFiniteResult`] if the
/// total energy overflows.
pub fn character<B: Basis>(
    problem: &mut NonsmoothSystem<B>,
    x: &[f64],
    omega: f64,
    natural: &[f64],
) -> Result<Character, SettingsError> {
    check_natural(natural)?;
    // Checks the length of `x`, `omega` and the finiteness of the histories.
    let laws = contact_and_gap_samples(problem, x, omega)?;
    let by_bar = harmonic_energies_by_bar(problem.system(), problem.basis(), x, omega)?;

    let offsets: Vec<f64> = problem.system().laws().map(|l| l.gap().offset).collect();
    let grazings = (laws.iter().zip(&offsets))
        .map(|((contact, gap), g0)| {
            let (lo, hi) = (gap.iter()).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), g| {
                (lo.min(*g), hi.max(*g))
            });
            let tolerance = GRAZING_TOLERANCE * g0.abs().max(hi - lo);
            let near: Vec<bool> = (gap.iter().zip(contact))
                .map(|(g, c)| *c || *g <= tolerance)
                .collect();
            runs_without(&near, contact)
        })
        .collect();
    let contacts = laws.iter().map(|(c, _)| periodic_runs(c)).collect();

    let harmonics = by_bar.first().map_or(0, Vec::len);
    let by_harmonic: Vec<f64> = (0..harmonics)
        .map(|n| by_bar.iter().map(|bar| bar[n]).sum())
        .collect();
    let total: f64 = by_harmonic.iter().sum();
    let oscillating: f64 = by_harmonic.iter().skip(1).sum();
    // Each energy is finite and non-negative: `None` means no oscillating energy at all.
    let Some(dominant_harmonic) = strongest_oscillating(&by_harmonic) else {
        return Err(SettingsError::NotPositive {
            what: "energy of the motion's oscillating harmonics",
            value: oscillating,
        });
    };
    check_finite("the motion's energy", omega, [&total])?;
    let energy_by_harmonic: Vec<f64> = by_harmonic.iter().map(|e| e / total).collect();
    let energy_by_bar = (by_bar.iter())
        .map(|bar| bar.iter().sum::<f64>() / total)
        .collect();
    let dominant_harmonic_by_bar: Vec<Option<usize>> = (by_bar.iter())
        .map(|bar| {
            let own: f64 = bar.iter().skip(1).sum();
            if own <= f64::EPSILON * oscillating {
                return None;
            }
            strongest_oscillating(bar)
        })
        .collect();
    let mut character = Character {
        contacts,
        grazings,
        energy_by_bar,
        dominant_share: energy_by_harmonic[dominant_harmonic],
        energy_by_harmonic,
        dominant_harmonic,
        dominant_mode_by_bar: Vec::new(),
        dominant_harmonic_by_bar,
    };
    character.name_modes(omega, natural);
    Ok(character)
}

impl Character {
    /// The frequencies `j Omega` whose nearest natural frequencies the character names at
    /// `omega`: the dominant harmonic's, and each moving bar's.
    pub fn named_frequencies(&self, omega: f64) -> impl Iterator<Item = f64> + Clone + '_ {
        let bars = self.dominant_harmonic_by_bar.iter().flatten();
        std::iter::once(&self.dominant_harmonic)
            .chain(bars)
            .map(move |j| *j as f64 * omega)
    }

    /// Names the dominant mode of each bar from `natural` (as [`character`] does), for a
    /// character computed before the natural frequencies were known far enough.
    pub fn name_modes(&mut self, omega: f64, natural: &[f64]) {
        self.dominant_mode_by_bar = (self.dominant_harmonic_by_bar.iter())
            .map(|j| nearest_mode(j.map(|j| j as f64 * omega)?, natural).map(|(mode, _)| mode))
            .collect();
    }
}

/// What a computed periodic motion is, in the terms of Lu & Legrand (2021, §4.1). See
/// [`label`] for the rule.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub enum Label {
    /// The low-energy branch of a mode (the paper's "main NSM `i`"): the requested order is
    /// `k = 1` and harmonic 1 dominates.
    Skeleton,
    /// Harmonic `harmonic` dominates instead of the requested one, and `harmonic Omega` meets
    /// the linear frequency `omega` of mode `mode` (the nearest open-contact natural
    /// frequency, numbered as in [`nearest_mode`]).
    InternalResonance {
        /// The dominant harmonic `j` (frequency `j Omega`).
        harmonic: usize,
        /// The open-contact linear mode nearest `j Omega`.
        mode: usize,
        /// Its natural frequency.
        omega: f64,
    },
    /// "NSM `i` sub `k`" (requested order `k > 1`): harmonic `k` dominates.
    Subharmonic {
        /// The subharmonic order `k`.
        order: usize,
    },
    /// The time-domain check was asked for and the point failed it: it is not a motion of the
    /// bars to tolerance, whatever its harmonic content says.
    Unverified,
    /// The point's harmonic content reads as the branch's own (skeleton or subharmonic), but
    /// the point does not continue the branch its run followed: it lies `ratio` times the
    /// predicted step away from the branch's secant prediction, more than
    /// [`JUMP_RATIO`](crate::branches::JUMP_RATIO) (a neighbouring solution the corrector
    /// jumped to), or it is a one-point spike whose energy is off its neighbours' chord
    /// ([`SPIKE_ENERGY`](crate::branches::SPIKE_ENERGY); a truncation resonance just outside
    /// the selection's band). Given by the runs of
    /// [`compute`](crate::branches::compute), never by [`label`].
    OffBranch {
        /// Distance to the branch's prediction over the predicted step.
        ratio: f64,
    },
}

impl Label {
    /// The kind of label without its numbers: `skeleton`, `subharmonic`,
    /// `internal-resonance`, `unverified` or `off-branch` (for grouping points in reports).
    pub fn kind(&self) -> &'static str {
        match self {
            Label::Skeleton => "skeleton",
            Label::Subharmonic { .. } => "subharmonic",
            Label::InternalResonance { .. } => "internal-resonance",
            Label::Unverified => "unverified",
            Label::OffBranch { .. } => "off-branch",
        }
    }
}

/// CSV-safe (no comma, no space): `skeleton`, `subharmonic-3`,
/// `internal-resonance-h3-mode2`, `unverified`, `off-branch`.
impl fmt::Display for Label {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Label::Subharmonic { order } => write!(f, "subharmonic-{order}"),
            Label::InternalResonance { harmonic, mode, .. } => {
                write!(f, "internal-resonance-h{harmonic}-mode{mode}")
            }
            other => f.write_str(other.kind()),
        }
    }
}

/// The [`Label`] of a motion of [`Character`] `character` at fundamental frequency `omega`,
/// computed on the branch of requested subharmonic order `order` (`k >= 1`), with `natural`
/// as for [`character`] and `verified` the outcome of the time-domain check if it was run.
///
/// # The rule
/// 1. `verified == Some(false)`: [`Label::Unverified`].
/// 2. The dominant harmonic `j` is `k`: [`Label::Skeleton`] for `k = 1`,
///    [`Label::Subharmonic`] for `k > 1`.
/// 3. Otherwise [`Label::InternalResonance`] with the mode whose natural frequency is nearest
///    `j Omega` ([`nearest_mode`]).
///
/// This is the label of one point's content. The runs of
/// [`compute`](crate::branches::compute) also ask whether the point continues the branch
/// they followed, and label a skeleton or subharmonic point that does not
/// [`Label::OffBranch`].
///
/// Why the dominant harmonic: near its skeleton, NSM `i` sub `k` is the linear mode `i`
/// (frequency `omega_i`) slightly deformed by the contacts and repeated over `k` of its
/// periods, so its fundamental is `Omega ~ omega_i / k` and the mode sits on the harmonic
/// `k` (`k Omega ~ omega_i`), which carries most of the energy; the contacts spread the rest
/// over the other harmonics. An internal resonance is where a harmonic `j` of the motion
/// meets another natural frequency, `j Omega ~ omega_n`: that mode is excited without
/// bound in the linear limit, takes energy from the main one, and harmonic `j` ends up
/// holding the largest share. So the dominant harmonic names the mode that carries the
/// motion, and `j Omega` tells which.
///
/// # Errors
/// [`SettingsError::ZeroIndex`] for `order = 0`; [`SettingsError::NotPositive`] or
/// [`SettingsError::FrequencyTooSmall`] for an `omega` that is not positive and finite or
/// below [`MIN_FREQUENCY`](crate::modal::MIN_FREQUENCY); those of [`character`] for
/// `natural`, and [`SettingsError::Length`] for an empty `natural` when the motion is an
/// internal resonance (there is no mode to name).
pub fn label(
    character: &Character,
    order: usize,
    omega: f64,
    natural: &[f64],
    verified: Option<bool>,
) -> Result<Label, SettingsError> {
    if order == 0 {
        return Err(SettingsError::ZeroIndex {
            what: "subharmonic order",
            value: 0,
        });
    }
    check_frequency(omega)?;
    check_natural(natural)?;
    let j = character.dominant_harmonic;
    Ok(if verified == Some(false) {
        Label::Unverified
    } else if j == order && order == 1 {
        Label::Skeleton
    } else if j == order {
        Label::Subharmonic { order }
    } else {
        let Some((mode, omega)) = nearest_mode(j as f64 * omega, natural) else {
            return Err(SettingsError::Length {
                what: "natural frequencies (an internal resonance needs one)",
                got: 0,
                expected: 1,
            });
        };
        Label::InternalResonance {
            harmonic: j,
            mode,
            omega,
        }
    })
}

/// The mode of `natural` (ascending, non-negative) whose frequency is nearest `frequency`,
/// as `(number, natural frequency)`, the lower one on a tie; `None` if `natural` is empty.
///
/// Numbering: the modes of positive frequency are numbered `1, 2, ...` in ascending order,
/// as [`crate::modal::natural_frequencies`] lists them and nonsmooth modes are named (NSM
/// `i` comes from mode `i`), whether or not zeros for rigid-body modes lead the list; a
/// rigid-body mode (a zero entry) is number 0. Passing the list with or without its zeros
/// thus names the same elastic modes.
pub fn nearest_mode(frequency: f64, natural: &[f64]) -> Option<(usize, f64)> {
    let rigid = natural.iter().take_while(|w| **w == 0.0).count();
    let (i, w) = (natural.iter().enumerate()).min_by(|(_, a), (_, b)| {
        let (da, db) = ((*a - frequency).abs(), (*b - frequency).abs());
        da.total_cmp(&db)
    })?;
    Some((if *w == 0.0 { 0 } else { i + 1 - rigid }, *w))
}

/// Checks the natural frequencies: finite, non-negative, ascending.
fn check_natural(natural: &[f64]) -> Result<(), SettingsError> {
    let mut previous = 0.0;
    for &w in natural {
        if !w.is_finite() {
            return Err(SettingsError::NotFinite {
                what: "natural frequency",
                value: w,
            });
        }
        if w < previous {
            return Err(SettingsError::OutOfRange {
                what: "natural frequency (non-negative, ascending)",
                value: w,
                min: previous,
                max: f64::MAX,
            });
        }
        previous = w;
    }
    Ok(())
}

/// The harmonic `j >= 1` of largest energy in `energies` (entry `n` for harmonic `n`), the
/// lowest on a tie; `None` if none is positive.
fn strongest_oscillating(energies: &[f64]) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (j, &e) in energies.iter().enumerate().skip(1) {
        if e > best.map_or(0.0, |(_, b)| b) {
            best = Some((j, e));
        }
    }
    best.map(|(j, _)| j)
}

/// The number of maximal periodic runs of `true` in `near` (the last value precedes the
/// first) in which `contact` is never `true`; a sequence that is `near` throughout is one run.
fn runs_without(near: &[bool], contact: &[bool]) -> usize {
    let n = near.len();
    // Start just after a sample that is not near, so that no run wraps around.
    let Some(start) = near.iter().position(|v| !v) else {
        return usize::from(n > 0 && !contact.iter().any(|c| *c));
    };
    let (mut runs, mut open, mut touched) = (0, false, false);
    for k in (start..n).chain(0..start) {
        if near[k] {
            open = true;
            touched |= contact[k];
        } else if open {
            runs += usize::from(!touched);
            (open, touched) = (false, false);
        }
    }
    runs + usize::from(open && !touched)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bar::Bar;
    use crate::continuation::ContinuationProblem;
    use crate::modal::linear::{natural_frequencies, open_mode, seed_from_mode, ContactState};
    use crate::modal::signature::contact_intervals;
    use crate::reference::{clamped_bar_with_obstacle, two_bars_in_contact, ClampedFirstMode};
    use crate::solve::{NonlinearSolver, SemismoothNewton};
    use crate::system::{BarSystem, HarmonicBalanceSettings};
    use std::f64::consts::PI;

    const SETTINGS: HarmonicBalanceSettings = HarmonicBalanceSettings {
        harmonics: 20,
        samples_per_harmonic: 30,
        complementarity: 4.0,
        kink_blend: 0.0,
        resonance_band: 0.0,
    };

    fn open_frequencies(system: &BarSystem, omega_max: f64) -> Vec<f64> {
        (natural_frequencies(system, ContactState::Open, omega_max).unwrap())
            .iter()
            .map(|m| m.omega)
            .collect()
    }

    /// The clamped bar's first nonsmooth mode at `T = 3.5` (gap `gap`, `m = 20`), solved
    /// from the exact motion: the problem, the unknowns and the frequency.
    fn clamped_point(gap: f64) -> (NonsmoothSystem, Vec<f64>, f64) {
        let system = clamped_bar_with_obstacle(gap).unwrap();
        let mut problem = NonsmoothSystem::new(&system, SETTINGS).unwrap();
        let omega = 2.0 * PI / 3.5;
        let mut x = ClampedFirstMode::new(gap, 3.5).unknowns(SETTINGS.harmonics);
        problem.set_parameter(omega);
        SemismoothNewton::default()
            .solve(&mut problem, &mut x)
            .unwrap();
        (problem, x, omega)
    }

    fn sums_to_one(shares: &[f64]) -> bool {
        (shares.iter().sum::<f64>() - 1.0).abs() <= 1e-12
    }

    #[test]
    fn runs_without_contact_count_approaches_only() {
        let (t, f) = (true, false);
        assert_eq!(runs_without(&[], &[]), 0);
        assert_eq!(runs_without(&[f, f], &[f, f]), 0);
        assert_eq!(runs_without(&[t, t], &[f, f]), 1);
        assert_eq!(runs_without(&[t, t], &[f, t]), 0);
        // A run through the end of the period counts once.
        assert_eq!(runs_without(&[t, f, f, t], &[f, f, f, f]), 1);
        // Two approaches, one of which touches.
        assert_eq!(runs_without(&[t, f, t, t, f], &[f, f, f, t, f]), 1);
        assert_eq!(runs_without(&[t, f, t, f, t, f], &[f; 6]), 3);
    }

    #[test]
    fn nearest_mode_numbers_elastic_modes_from_one() {
        let elastic = [1.0, 3.0, 5.0];
        let with_rigid = [0.0, 1.0, 3.0, 5.0];
        assert_eq!(nearest_mode(2.9, &elastic), Some((2, 3.0)));
        assert_eq!(nearest_mode(2.9, &with_rigid), Some((2, 3.0)));
        assert_eq!(nearest_mode(0.2, &with_rigid), Some((0, 0.0)));
        assert_eq!(nearest_mode(2.0, &elastic), Some((1, 1.0)));
        assert_eq!(nearest_mode(1.0, &[]), None);
    }

    /// The paper's first nonsmooth mode of the clamped bar: one contact, no grazing, harmonic
    /// 1 dominant, the skeleton.
    #[test]
    fn the_clamped_first_mode_is_a_skeleton() {
        let (mut problem, x, omega) = clamped_point(1e-3);
        let natural = open_frequencies(problem.system(), 30.0);
        let c = character(&mut problem, &x, omega, &natural).unwrap();
        assert_eq!(c.contacts, vec![1]);
        assert_eq!(c.grazings, vec![0]);
        assert_eq!(c.dominant_harmonic, 1);
        assert_eq!(c.energy_by_harmonic.len(), SETTINGS.harmonics + 1);
        assert!(sums_to_one(&c.energy_by_harmonic) && sums_to_one(&c.energy_by_bar));
        assert_eq!(c.energy_by_bar.len(), 1);
        // At T = 3.5 the impacts put a fifth of the energy on harmonic 6 (`6 Omega` near
        // the fourth mode, `7 pi / 2`); harmonic 1 keeps twice as much.
        let runner_up = (c.energy_by_harmonic.iter().enumerate())
            .filter(|(n, _)| *n != 1)
            .fold(0.0, |a: f64, (_, e)| a.max(*e));
        assert!(c.dominant_share > 0.4 && c.dominant_share > 2.0 * runner_up);
        assert_eq!(c.dominant_mode_by_bar, vec![Some(1)]);
        let l = label(&c, 1, omega, &natural, None).unwrap();
        assert_eq!(l, Label::Skeleton);
        assert_eq!((l.to_string(), l.kind()), ("skeleton".into(), "skeleton"));
        assert_eq!(label(&c, 1, omega, &natural, Some(true)).unwrap(), l);
        let failed = label(&c, 1, omega, &natural, Some(false)).unwrap();
        assert_eq!(failed.to_string(), "unverified");
    }

    /// Doubling the gap and the motion doubles every gap and quadruples every energy: the
    /// character does not change.
    #[test]
    fn the_character_is_invariant_under_gap_scaling() {
        let (mut problem, x, omega) = clamped_point(1e-3);
        let natural = open_frequencies(problem.system(), 30.0);
        let a = character(&mut problem, &x, omega, &natural).unwrap();
        let system = clamped_bar_with_obstacle(2e-3).unwrap();
        let mut doubled = NonsmoothSystem::new(&system, SETTINGS).unwrap();
        let y: Vec<f64> = x.iter().map(|v| 2.0 * v).collect();
        let b = character(&mut doubled, &y, omega, &natural).unwrap();
        assert_eq!((&a.contacts, &a.grazings), (&b.contacts, &b.grazings));
        assert_eq!(a.dominant_harmonic, b.dominant_harmonic);
        let pairs = (a.energy_by_harmonic.iter().zip(&b.energy_by_harmonic))
            .chain(a.energy_by_bar.iter().zip(&b.energy_by_bar));
        for (p, q) in pairs {
            assert!((p - q).abs() <= 1e-12, "{p} vs {q}");
        }
    }

    /// Mode 2 of the clamped bar (`3 pi / 2`) placed on harmonic 3 at `Omega = pi / 2`: all
    /// the energy on harmonic 3, an internal resonance with mode 2 on the branch of order 1,
    /// subharmonic 3 on the branch of order 3. Its end meets the obstacle three times per
    /// period: grazings just below the grazing amplitude, contacts above, nothing well below.
    #[test]
    fn a_motion_on_one_harmonic_names_its_mode() {
        let system = clamped_bar_with_obstacle(1e-3).unwrap();
        let mut problem = NonsmoothSystem::new(&system, SETTINGS).unwrap();
        let natural = open_frequencies(&system, 30.0);
        let mode = open_mode(&system, 2).unwrap();
        let omega = mode.omega / 3.0;
        let seed = seed_from_mode(&mut problem, &mode, 3, omega).unwrap();
        let scaled = |s: f64| seed.iter().map(|v| s * v).collect::<Vec<f64>>();

        let c = character(&mut problem, &scaled(0.99), omega, &natural).unwrap();
        assert_eq!(c.dominant_harmonic, 3);
        assert!((c.dominant_share - 1.0).abs() <= 1e-12);
        assert_eq!((c.contacts.clone(), c.grazings.clone()), (vec![0], vec![3]));
        assert_eq!(c.dominant_mode_by_bar, vec![Some(2)]);
        let l = label(&c, 1, omega, &natural, None).unwrap();
        assert_eq!(
            l,
            Label::InternalResonance {
                harmonic: 3,
                mode: 2,
                omega: mode.omega
            }
        );
        assert_eq!(l.to_string(), "internal-resonance-h3-mode2");
        assert_eq!(l.kind(), "internal-resonance");
        let sub = label(&c, 3, omega, &natural, None).unwrap();
        assert_eq!(
            (sub.to_string(), sub.kind()),
            ("subharmonic-3".into(), "subharmonic")
        );

        let touching = character(&mut problem, &scaled(1.05), omega, &natural).unwrap();
        assert_eq!((touching.contacts, touching.grazings), (vec![3], vec![0]));
        let apart = character(&mut problem, &scaled(0.9), omega, &natural).unwrap();
        assert_eq!((apart.contacts, apart.grazings), (vec![0], vec![0]));
        assert_eq!(
            contact_intervals(&mut problem, &scaled(1.05), omega).unwrap(),
            vec![3]
        );
    }

    /// Two bars (bar 2 of length 1/2: open-contact modes `pi/2` of bar 1, `pi` of bar 2,
    /// ...): bar 1 in mode 1 on harmonic 1, bar 2 in mode 2 on harmonic 2 at
    /// `Omega = pi / 2`. Each bar names its own mode; the shares are split between the bars.
    #[test]
    fn two_bars_share_the_energy() {
        let second = Bar::new(0.5, 1.0, 1.0).unwrap();
        let system = two_bars_in_contact(second, 1e-3).unwrap();
        let mut problem = NonsmoothSystem::new(&system, SETTINGS).unwrap();
        let natural = open_frequencies(&system, 20.0);
        assert!((natural[0] - PI / 2.0).abs() < 1e-9 && (natural[1] - PI).abs() < 1e-9);
        let omega = natural[0];
        let one = open_mode(&system, 1).unwrap();
        let two = open_mode(&system, 2).unwrap();
        let mut x = seed_from_mode(&mut problem, &one, 1, omega).unwrap();
        let c = character(&mut problem, &x, omega, &natural).unwrap();
        assert_eq!(c.energy_by_bar.len(), 2);
        assert_eq!(c.dominant_mode_by_bar, vec![Some(1), None]);

        let y = seed_from_mode(&mut problem, &two, 2, omega).unwrap();
        x.iter_mut().zip(&y).for_each(|(a, b)| *a += 0.5 * b);
        let c = character(&mut problem, &x, omega, &natural).unwrap();
        assert!(sums_to_one(&c.energy_by_bar) && sums_to_one(&c.energy_by_harmonic));
        assert!(
            c.energy_by_bar.iter().all(|s| *s > 0.01),
            "{:?}",
            c.energy_by_bar
        );
        assert_eq!(c.dominant_mode_by_bar, vec![Some(1), Some(2)]);
        // Without the natural frequencies there is no mode to name.
        let c = character(&mut problem, &x, omega, &[]).unwrap();
        assert_eq!(c.dominant_mode_by_bar, vec![None, None]);
    }

    #[test]
    fn bad_input_gives_typed_errors() {
        let (mut problem, x, omega) = clamped_point(1e-3);
        let natural = open_frequencies(problem.system(), 30.0);
        let mut ask =
            |x: &[f64], omega, natural: &[f64]| character(&mut problem, x, omega, natural);
        assert!(matches!(
            ask(&x[1..], omega, &natural),
            Err(SettingsError::Length { .. })
        ));
        for bad in [f64::NAN, 0.0, -1.0, f64::INFINITY] {
            assert!(matches!(
                ask(&x, bad, &natural),
                Err(SettingsError::NotPositive { .. })
            ));
        }
        let mut nan = x.clone();
        nan[5] = f64::NAN;
        assert!(matches!(
            ask(&nan, omega, &natural),
            Err(SettingsError::NotPositive { .. })
        ));
        assert!(matches!(
            ask(&x, omega, &[1.0, f64::NAN]),
            Err(SettingsError::NotFinite { .. })
        ));
        for unsorted in [&[3.0, 1.0][..], &[-1.0, 1.0][..]] {
            assert!(matches!(
                ask(&x, omega, unsorted),
                Err(SettingsError::OutOfRange { .. })
            ));
        }
        // At rest there is no share to give.
        assert!(matches!(
            ask(&vec![0.0; x.len()], omega, &natural),
            Err(SettingsError::NotPositive { .. })
        ));

        let c = ask(&x, omega, &natural).unwrap();
        assert!(matches!(
            label(&c, 0, omega, &natural, None),
            Err(SettingsError::ZeroIndex { .. })
        ));
        assert!(matches!(
            label(&c, 1, f64::NAN, &natural, None),
            Err(SettingsError::NotPositive { .. })
        ));
        // An empty list is enough for a skeleton, not for an internal resonance.
        assert_eq!(label(&c, 1, omega, &[], None), Ok(Label::Skeleton));
        assert!(matches!(
            label(&c, 2, omega, &[], None),
            Err(SettingsError::Length { got: 0, .. })
        ));
    }
}
