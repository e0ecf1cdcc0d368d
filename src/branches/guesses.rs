//! The guesses of a branch's start: the grazing seed of a linear mode at a few frequencies
//! and amplitudes, with the motions of floating bars added where the system has any, and the
//! closing guesses of chains with floating bars (every gap next to a floating bar closed at
//! once by the seed's amplitude and the floating bars' offsets).

use crate::fourier::Basis;
use crate::linalg::{DenseMatrix, Lu};
use crate::modal::linear::{add_on_harmonic, rigid_body_modes, ContactState};
use crate::system::rows::{dot, HarmonicRows};
use crate::system::{BarSystem, NonsmoothSystem};

/// Frequencies of the start, relative to the linear mode's: `80/79`, `40/39` and `20/19`
/// (periods `79/80`, `39/40` and `19/20` of the mode's, the first of them the period
/// grid's first, [`crate::branches::PeriodGrid::for_mode`]).
pub const START_RATIOS: [f64; 3] = [80.0 / 79.0, 40.0 / 39.0, 20.0 / 19.0];

/// Frequencies of the energy backbone's start nearer the linear mode's than
/// [`START_RATIOS`], tried after them: `1 + 1 / (79 * 2^k)`, `k = 1..=12` (the first offset
/// halved twelve times, down to `3.1e-6`). A branch whose hardening is weak (a soft partner
/// in contact) rises so steeply that at `80/79` its motion is far above the grazing seed: its
/// frequency shift shrinks with the partner's stiffness.
pub const CLOSE_START_RATIOS: [f64; 12] = close_start_ratios();

/// `1 + 1 / (79 * 2^k)` for `k = 1..=12`.
const fn close_start_ratios() -> [f64; 12] {
    let mut ratios = [0.0; 12];
    let mut k = 0;
    while k < 12 {
        ratios[k] = 1.0 + 1.0 / (79.0 * (1u32 << (k + 1)) as f64);
        k += 1;
    }
    ratios
}

/// Amplitudes of the start, relative to the grazing seed's: a seed that only grazes can
/// slide to a rigid-body motion resting against an obstacle (a floating bar), one that
/// slightly penetrates cannot.
pub const START_AMPLITUDES: [f64; 3] = [1.0, 1.01, 1.1];

/// Further frequencies of the start, relative to the linear mode's, for a system with
/// rigid-body modes: the periodic motions of a bar held only by contacts (it shuttles between
/// its neighbours) lie well above the linear frequency.
pub const FLOATING_RATIOS: [f64; 2] = [1.2, 1.5];

/// Further amplitudes of the start, relative to the grazing seed's, for a system with
/// rigid-body modes.
pub const FLOATING_AMPLITUDES: [f64; 2] = [1.5, 3.0];

/// Amplitudes, in units of the smallest gap, of each rigid-body mode added to the seed (on
/// the seed's harmonic): a floating bar set moving, which the seed of a mode of its
/// neighbours leaves at rest.
pub const RIGID_AMPLITUDES: [f64; 6] = [-2.0, -1.0, -0.5, 0.5, 1.0, 2.0];

/// Depth, relative to each gap, by which the closing guesses of a system with rigid-body
/// modes overshoot: every gap next to a floating bar is closed by this fraction more than
/// grazing, so that no contact of the guess is left just open.
pub const CLOSING_DEPTH: f64 = 0.01;

/// Most unilateral laws next to floating bars for which the closing guesses are formed (the
/// subsets of laws to close grow as `2^laws`).
const MAX_CLOSING_LAWS: usize = 12;

/// The guesses of a branch's start for a system: [`START_RATIOS`] x [`START_AMPLITUDES`] of
/// the grazing seed; for a system with rigid-body modes (a bar held only by contacts) also
/// [`FLOATING_RATIOS`] and [`FLOATING_AMPLITUDES`], and each guess with each rigid-body mode
/// added at the amplitudes of [`RIGID_AMPLITUDES`].
#[derive(Debug, Clone)]
pub(crate) struct StartGuesses {
    rigid: Vec<Vec<f64>>,
    gap: f64,
    /// The gap offset `g0` of each law.
    offsets: Vec<f64>,
    /// Per law, the motion of its gap per unit of each rigid-body mode.
    rigid_gaps: Vec<Vec<f64>>,
}

impl StartGuesses {
    pub(crate) fn new(system: &BarSystem) -> Self {
        let rigid = rigid_body_modes(system, ContactState::Open).map_or(Vec::new(), |m| m.shapes);
        let gap = system
            .laws()
            .map(|l| l.gap().offset.abs())
            .fold(f64::INFINITY, f64::min);
        let offsets: Vec<f64> = system.laws().map(|l| l.gap().offset).collect();
        let rows = HarmonicRows::new(system, 0.0);
        let rigid_gaps = (0..offsets.len())
            .map(|l| rigid.iter().map(|r| dot(rows.gap_row(l), r)).collect())
            .collect();
        Self {
            rigid,
            gap,
            offsets,
            rigid_gaps,
        }
    }

    /// The laws whose gap a rigid-body mode moves (those next to a floating bar).
    pub(crate) fn touched_laws(&self) -> Vec<usize> {
        let biggest = self
            .rigid_gaps
            .iter()
            .flatten()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        (0..self.offsets.len())
            .filter(|&l| self.rigid_gaps[l].iter().any(|v| v.abs() > 1e-9 * biggest))
            .collect()
    }

    /// The ways of closing every gap next to a floating bar with the seed's motion and the
    /// rigid-body modes: `(s, d)` such that the seed scaled by `s > 0` with the rigid-body
    /// offsets `d` (on the constant term) makes each law of a subset of `R + 1` of the laws
    /// that a rigid-body mode moves (`R` modes) just graze, the laws the seed moves at the
    /// extreme of their motion, the others (a floating bar packed against an obstacle) at
    /// rest; no law is left penetrated. In a chain a run of `k` floating bars has `k + 1`
    /// such laws and `k` rigid-body modes, so with one run there is one way: a floating bar
    /// vibrating in its own mode offset so that it grazes both neighbours (the impulses of
    /// both sides can balance over a period), or a held bar's mode grazing the floating
    /// bars packed against the far obstacle. `seed` is a motion on harmonic `harmonic` only,
    /// at `omega`.
    fn closing<B: Basis>(
        &self,
        problem: &NonsmoothSystem<B>,
        (seed, harmonic): (&[f64], usize),
        omega: f64,
    ) -> Vec<(f64, Vec<f64>)> {
        let r = self.rigid.len();
        let laws = self.offsets.len();
        let touched = self.touched_laws();
        if r == 0 || touched.len() <= r || touched.len() > MAX_CLOSING_LAWS {
            return Vec::new();
        }
        // The seed's motion of each gap at its extreme (the seed is `shape cos(h theta)`).
        let basis = problem.basis();
        let mut phi = vec![0.0; basis.len()];
        basis.functions_at(0.0, &mut phi);
        let Some(i) = (0..basis.len()).find(|&i| basis.harmonic(i) == harmonic && phi[i] != 0.0)
        else {
            return Vec::new();
        };
        let n = problem.system().unknowns_per_harmonic();
        let start = problem.index(i, 0, 0);
        let shape: Vec<f64> = seed[start..start + n].iter().map(|v| v * phi[i]).collect();
        let rows = HarmonicRows::new(problem.system(), harmonic as f64 * omega);
        let swing: Vec<f64> = (0..laws)
            .map(|l| dot(rows.gap_row(l), &shape).abs())
            .collect();
        let mut found: Vec<(f64, Vec<f64>)> = Vec::new();
        for mask in 0u32..(1u32 << touched.len()) {
            if mask.count_ones() as usize != r + 1 {
                continue;
            }
            let chosen: Vec<usize> = (0..touched.len())
                .filter(|k| mask >> k & 1 == 1)
                .map(|k| touched[k])
                .collect();
            // g0_l - s swing_l + r_l . d = 0 for each chosen law.
            let mut a = DenseMatrix::zeros(r + 1, r + 1);
            let mut z: Vec<f64> = Vec::with_capacity(r + 1);
            for (row, &l) in chosen.iter().enumerate() {
                a[(row, 0)] = -swing[l];
                for j in 0..r {
                    a[(row, j + 1)] = self.rigid_gaps[l][j];
                }
                z.push(-self.offsets[l]);
            }
            let Ok(lu) = Lu::factor(&a, 1e-10) else {
                continue;
            };
            lu.solve_in_place(&mut z);
            let (s, d) = (z[0], &z[1..]);
            let open = |l: usize| self.offsets[l] - s * swing[l] + dot(&self.rigid_gaps[l], d);
            let tolerance = 1e-9 * self.gap;
            let fits = s.is_finite() && s > 0.0 && (0..laws).all(|l| open(l) >= -tolerance);
            let known = found.iter().any(|(t, e)| {
                (t - s).abs() <= 1e-9 * s
                    && e.iter().zip(d).all(|(a, b)| (a - b).abs() <= tolerance)
            });
            if fits && !known {
                found.push((s, d.to_vec()));
            }
        }
        found
    }

    /// Whether the system has a bar held only by contacts (a rigid-body mode) and a gap.
    pub(crate) fn floating(&self) -> bool {
        !self.rigid.is_empty() && self.gap.is_finite()
    }

    /// The frequencies to try, relative to the linear mode's.
    pub(crate) fn ratios(&self) -> Vec<f64> {
        let extra = if self.floating() {
            &FLOATING_RATIOS[..]
        } else {
            &[]
        };
        START_RATIOS.iter().chain(extra).copied().collect()
    }

    fn amplitudes(&self) -> Vec<f64> {
        let extra = if self.floating() {
            &FLOATING_AMPLITUDES[..]
        } else {
            &[]
        };
        START_AMPLITUDES.iter().chain(extra).copied().collect()
    }

    /// Guesses tried at all frequencies together, the closing guesses (which depend on the
    /// seed) aside.
    pub(crate) fn count(&self) -> usize {
        self.ratios().len() * self.per_frequency()
    }

    /// Guesses tried at one frequency, the closing guesses aside.
    pub(crate) fn per_frequency(&self) -> usize {
        self.amplitudes().len() * (1 + self.rigid.len() * RIGID_AMPLITUDES.len())
    }

    /// The seed at each of the amplitudes, without rigid-body motions.
    pub(crate) fn scaled(&self, seed: &[f64]) -> Vec<Vec<f64>> {
        self.amplitudes()
            .into_iter()
            .map(|a| seed.iter().map(|v| a * v).collect())
            .collect()
    }

    /// The guesses around `seed` (a seed on harmonic `harmonic`, solved at `omega`), each
    /// rigid-body motion added at the amplitudes `rigid` (in units of the smallest gap); then,
    /// for a system with rigid-body modes, the closing guesses ([`StartGuesses::closing`]):
    /// each way of closing the gaps next to the floating bars, at each amplitude, every gap
    /// overshot by [`CLOSING_DEPTH`].
    pub(crate) fn around<B: Basis>(
        &self,
        problem: &NonsmoothSystem<B>,
        (seed, harmonic): (&[f64], usize),
        omega: f64,
        rigid: &[f64],
    ) -> Vec<Vec<f64>> {
        let mut guesses = Vec::with_capacity(self.count() / self.ratios().len());
        for base in self.scaled(seed) {
            guesses.push(base.clone());
            if !self.floating() {
                continue;
            }
            for shape in &self.rigid {
                for &c in rigid {
                    let mut guess = base.clone();
                    add_on_harmonic(problem, shape, harmonic, c * self.gap, &mut guess);
                    guesses.push(guess);
                }
            }
        }
        if self.floating() {
            for (s, d) in self.closing(problem, (seed, harmonic), omega) {
                for amplitude in self.amplitudes() {
                    let scale = (1.0 + CLOSING_DEPTH) * s * amplitude;
                    let mut guess: Vec<f64> = seed.iter().map(|v| scale * v).collect();
                    for (shape, &c) in self.rigid.iter().zip(&d) {
                        add_on_harmonic(problem, shape, 0, (1.0 + CLOSING_DEPTH) * c, &mut guess);
                    }
                    guesses.push(guess);
                }
            }
        }
        guesses
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bar::Bar;
    use crate::modal::linear::{open_mode, seed_from_mode};
    use crate::system::{AssemblyBuilder, HarmonicBalanceSettings};

    /// A unit bar clamped at its left, a free-free unit bar of wave speed `floating_speed`,
    /// a unit bar of wave speed `far_speed` clamped at its right, gaps `g1` and `g2`.
    fn floating_between((g1, g2): (f64, f64), floating_speed: f64, far_speed: f64) -> BarSystem {
        let mut b = AssemblyBuilder::new();
        let a = b.add_bar(Bar::unit());
        let f = b.add_bar(Bar::new(1.0, floating_speed, 1.0).unwrap());
        let c = b.add_bar(Bar::new(1.0, far_speed, 1.0).unwrap());
        b.dirichlet(a.left()).unwrap();
        b.contact(a.right(), f.left(), g1).unwrap();
        b.contact(f.right(), c.left(), g2).unwrap();
        b.dirichlet(c.right()).unwrap();
        b.build().unwrap()
    }

    /// What the closing guesses of `system` start from: its first open mode, which must lie
    /// at `omega1`, seeded at the first start ratio on 4 harmonics.
    struct Closing {
        problem: NonsmoothSystem,
        seed: Vec<f64>,
        omega: f64,
        guesses: StartGuesses,
        ways: Vec<(f64, Vec<f64>)>,
    }

    fn closing_of(system: &BarSystem, omega1: f64) -> Closing {
        let settings = HarmonicBalanceSettings {
            harmonics: 4,
            ..HarmonicBalanceSettings::default()
        };
        let mut problem = NonsmoothSystem::new(system, settings).unwrap();
        let mode = open_mode(system, 1).unwrap();
        assert!((mode.omega - omega1).abs() < 1e-9, "{}", mode.omega);
        let omega = mode.omega * START_RATIOS[0];
        let seed = seed_from_mode(&mut problem, &mode, 1, omega).unwrap();
        let guesses = StartGuesses::new(system);
        assert!(guesses.floating());
        let ways = guesses.closing(&problem, (&seed, 1), omega);
        assert_eq!(ways.len(), 1, "{ways:?}");
        Closing {
            problem,
            seed,
            omega,
            guesses,
            ways,
        }
    }

    /// The floating bar's own mode (the first open mode, `omega = 0.4 pi`) closes both gaps:
    /// offset `(g2 - g1) / 2` towards the larger gap and amplitude `(g1 + g2) / 2`, each law
    /// just grazing.
    #[test]
    fn a_floating_bar_mode_is_offset_to_graze_both_neighbours() {
        let (g1, g2) = (1e-3, 3e-3);
        let system = floating_between((g1, g2), 0.4, 1.0);
        let mut c = closing_of(&system, 0.4 * std::f64::consts::PI);
        let (s, d) = &c.ways[0];
        // The seed grazes the nearer gap `g1` alone: scaled by `s` it swings by `(g1+g2)/2`
        // (exactly so at the mode's frequency; its ends swing by slightly different
        // amounts off it).
        assert!((s - 2.0).abs() < 1e-2, "{s}");
        // The floating bar's offset (its translation, whichever sign the basis has).
        let offset = d[0] * c.guesses.rigid[0][2];
        assert!((offset - 0.5 * (g2 - g1)).abs() < 1e-2 * g1, "{offset}");
        // And the guesses built on it penetrate both gaps by the closing depth.
        let tries = c.guesses.around(&c.problem, (&c.seed, 1), c.omega, &[]);
        let closing = &tries[tries.len() - c.guesses.amplitudes().len()];
        for l in 0..2 {
            let gap = c.problem.gap_history(closing, c.omega, l);
            let least = gap.iter().copied().fold(f64::INFINITY, f64::min);
            let g0 = [g1, g2][l];
            assert!(
                (least + CLOSING_DEPTH * g0).abs() < 1e-9 * g0,
                "{l}: {least}"
            );
        }
    }

    /// A held bar's mode (the first open mode is the clamped-free bar's, at `pi / 2`) with
    /// the floating bar packed against the far neighbour: the amplitude closes both gaps.
    #[test]
    fn a_held_bar_mode_packs_the_floating_bar_against_the_far_side() {
        let (g1, g2) = (2e-3, 1e-3);
        let system = floating_between((g1, g2), 3.0, 2.0);
        let c = closing_of(&system, 0.5 * std::f64::consts::PI);
        let (s, d) = &c.ways[0];
        // The seed grazes `g1`; closing `g1 + g2` takes `1.5` times it.
        assert!((s - 1.5).abs() < 1e-9, "{s}");
        let offset = d[0] * c.guesses.rigid[0][2];
        assert!((offset - g2).abs() < 1e-9 * g2, "{offset}");
    }
}
