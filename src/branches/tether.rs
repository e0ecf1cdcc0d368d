//! Tethered starts: the branch of a system with floating bars entered from a held system's
//! grazing point.
//!
//! A bar held only by contacts has no branch leaving the grazing point of a linear mode: the
//! floating bar can rest anywhere between its obstacles, and its periodic motions shuttle at a
//! finite energy. Tie every unilateral law that a rigid-body mode moves with a linear spring
//! `kappa` across its gap (the *tether*: the law's force becomes `lambda - kappa c`, with `c =
//! g0 - g` the closure of the gap) and the system is held. Its linear mode that continues the
//! asked one has a grazing point, and a branch leaves it as on any held assembly. Lowering
//! `kappa` to zero while moving the frequency to the asked one carries that motion to a
//! motion of the system itself: the homotopy replaces the lottery of guesses by a path.

use crate::bar::EndRef;
use crate::bc::{
    BoundaryCondition, LawSamples, LawValue, LinearRows, Observable, Quantity, Term, UnilateralLaw,
};
use crate::continuation::ContinuationProblem;
use crate::modal::energy::energy;
use crate::modal::linear::{natural_frequencies, seed_from_mode, ContactState, LinearMode};
use crate::solve::{norm, NonlinearSolver, SmoothingHomotopy};
use crate::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};
use std::sync::Arc;

/// A condition whose unilateral law has a linear spring of stiffness `kappa` across its gap;
/// its ends, rows and residual are the inner condition's.
#[derive(Debug)]
struct Tethered {
    inner: Arc<dyn BoundaryCondition>,
    gap: Observable,
    force: Observable,
    /// `c = g0 - g` restricted to displacement terms: the closure the spring resists.
    closure: Vec<Term>,
    kappa: f64,
}

impl Tethered {
    /// `condition` with its law tethered by `kappa` (`None` for a condition without a law).
    fn new(condition: &Arc<dyn BoundaryCondition>, kappa: f64) -> Option<Self> {
        let law = condition.unilateral()?;
        let (gap, mut force) = (law.gap(), law.force());
        let closure: Vec<Term> = (gap.terms.iter())
            .filter(|t| is_displacement(t.quantity))
            .map(|t| Term::new(t.end, t.quantity, -t.coefficient))
            .collect();
        let spring = closure
            .iter()
            .map(|t| Term::new(t.end, t.quantity, -kappa * t.coefficient));
        force.terms.extend(spring);
        Some(Self {
            inner: condition.clone(),
            gap,
            force,
            closure,
            kappa,
        })
    }

    fn inner_law(&self) -> &dyn UnilateralLaw {
        self.inner
            .unilateral()
            .expect("built from a condition with a law (Tethered::new)")
    }
}

impl UnilateralLaw for Tethered {
    fn gap(&self) -> Observable {
        self.gap.clone()
    }
    fn force(&self) -> Observable {
        self.force.clone()
    }
    fn residual(&self, gap: f64, force: f64, a_c: f64) -> LawValue {
        self.inner_law().residual(gap, force, a_c)
    }
    fn smoothed_residual(&self, gap: f64, force: f64, a_c: f64, smoothing: f64) -> LawValue {
        self.inner_law()
            .smoothed_residual(gap, force, a_c, smoothing)
    }
    fn sample(&self, gaps: &[f64], forces: &[f64], a_c: f64, smoothing: f64, out: LawSamples<'_>) {
        self.inner_law().sample(gaps, forces, a_c, smoothing, out);
    }
}

impl BoundaryCondition for Tethered {
    fn name(&self) -> String {
        format!("{} tethered by {}", self.inner.name(), self.kappa)
    }
    fn ends(&self) -> Vec<EndRef> {
        self.inner.ends()
    }
    fn linear_rows(&self, omega: f64, stiffness: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
        self.inner.linear_rows(omega, stiffness, rows);
    }
    fn unilateral(&self) -> Option<&dyn UnilateralLaw> {
        Some(self)
    }
    fn stored_energy(&self, value: &dyn Fn(EndRef, Quantity) -> f64) -> f64 {
        let c: f64 = (self.closure.iter())
            .map(|t| t.coefficient * value(t.end, t.quantity))
            .sum();
        self.inner.stored_energy(value) + 0.5 * self.kappa * c * c
    }
}

fn is_displacement(q: Quantity) -> bool {
    matches!(q, Quantity::Displacement | Quantity::OutwardDisplacement)
}

/// `system` with the laws of `laws` (indices among the system's laws) tethered, each by
/// `scale` times the smaller axial stiffness `EA / l` of the bars it touches.
fn tethered_system(system: &BarSystem, laws: &[usize], scale: f64) -> BarSystem {
    let mut law = 0;
    system.map_conditions(|c| {
        if c.unilateral().is_none() {
            return c.clone();
        }
        let index = law;
        law += 1;
        if !laws.contains(&index) {
            return c.clone();
        }
        let kappa = (c.ends().iter())
            .map(|e| {
                let bar = system.bars()[e.bar.index()];
                bar.stiffness() / bar.length()
            })
            .fold(f64::INFINITY, f64::min);
        match Tethered::new(c, scale * kappa) {
            Some(tethered) => Arc::new(tethered),
            None => c.clone(),
        }
    })
}

/// Tether stiffness, relative to the bars' `EA / l`, at which the homotopy starts.
pub(crate) const TETHER_SCALE: f64 = 0.1;

/// The homotopy from the tethered system at `t = 0` to the system itself at `t = 1`: the
/// tether `scale (1 - t)`, the frequency moved linearly from `from` to `to`.
struct TetherPath {
    system: BarSystem,
    laws: Vec<usize>,
    settings: HarmonicBalanceSettings,
    scale: f64,
    from: f64,
    to: f64,
}

impl TetherPath {
    /// The problem at `t` (`None` if the tethered system refuses the settings, which the
    /// system itself took).
    fn problem_at(&self, t: f64) -> Option<NonsmoothSystem> {
        let held = tethered_system(&self.system, &self.laws, self.scale * (1.0 - t));
        NonsmoothSystem::new(&held, self.settings).ok()
    }
    fn omega(&self, t: f64) -> f64 {
        self.from + t * (self.to - self.from)
    }
}

/// The start of NSM `original` sub `subharmonic` of `system` at `omega` reached from the
/// tethered system's (laws `laws` tethered): the tethered mode that continues `original`
/// (largest overlap of shapes), its branch entered near its grazing point at the same ratio
/// to its linear frequency as `omega` to the system's, then the tether lowered to zero and the
/// frequency moved to `omega` together, in steps of the homotopy parameter each solved from
/// the last (by `solver`, then inside a [`SmoothingHomotopy`]), a step that fails halved.
/// Returns the solution at `omega` if every step is solved to a motion of energy above
/// `floor`.
pub(crate) fn tethered_start<S: NonlinearSolver>(
    (system, settings): (&BarSystem, HarmonicBalanceSettings),
    solver: &S,
    (original, subharmonic): (&LinearMode, usize),
    (omega, laws): (f64, &[usize]),
    floor: f64,
) -> Option<Vec<f64>> {
    let shape = original.shapes.first()?;
    let scale = TETHER_SCALE;
    let held = tethered_system(system, laws, scale);
    let candidates = natural_frequencies(&held, ContactState::Open, 2.0 * original.omega).ok()?;
    let overlap = |s: &[f64]| -> f64 { s.iter().zip(shape).map(|(a, b)| a * b).sum::<f64>().abs() };
    let linear = candidates.into_iter().max_by(|a, b| {
        let of = |m: &LinearMode| m.shapes.first().map_or(0.0, |s| overlap(s));
        of(a).total_cmp(&of(b))
    })?;
    let from = linear.omega * omega / original.omega;
    // The problems at both ends of the path are built once; those between at each step.
    let mut first = NonsmoothSystem::new(&held, settings).ok()?;
    let seed = seed_from_mode(&mut first, &linear, subharmonic, from).ok()?;
    let mut last = NonsmoothSystem::new(system, settings).ok()?;
    let basis = last.basis().clone();
    let path = TetherPath {
        system: system.clone(),
        laws: laws.to_vec(),
        settings,
        scale,
        from,
        to: omega,
    };
    let homotopy = SmoothingHomotopy::new(solver);
    let solvers: [&dyn NonlinearSolver; 2] = [solver, &homotopy];
    let solve_on = |p: &mut NonsmoothSystem, at: f64, x: &mut Vec<f64>| -> bool {
        p.set_parameter(at);
        solvers.iter().any(|s| {
            let mut y = x.clone();
            let ok = s.solve(p, &mut y).is_ok() && energy(system, &basis, &y, at) > floor;
            if ok {
                *x = y;
            }
            ok
        })
    };
    let mut solve_at = |t: f64, x: &mut Vec<f64>| -> bool {
        if t <= 0.0 {
            solve_on(&mut first, from, x)
        } else if t >= 1.0 {
            solve_on(&mut last, omega, x)
        } else {
            (path.problem_at(t)).is_some_and(|mut p| solve_on(&mut p, path.omega(t), x))
        }
    };
    // Amplitudes that solve to a start already tried would follow its path again.
    let mut tried: Vec<Vec<f64>> = Vec::new();
    for amplitude in TETHERED_AMPLITUDES {
        let mut x: Vec<f64> = seed.iter().map(|v| v * amplitude).collect();
        if !solve_at(0.0, &mut x) || tried.iter().any(|y| same_state(&x, y)) {
            continue;
        }
        tried.push(x.clone());
        let (mut t, mut dt) = (0.0f64, 0.05f64);
        while t < 1.0 {
            let next = (t + dt).min(1.0);
            let mut y = x.clone();
            if solve_at(next, &mut y) {
                (x, t) = (y, next);
                dt = (dt * 1.5).min(0.25);
            } else {
                dt *= 0.5;
                if dt < MIN_HOMOTOPY_STEP {
                    break;
                }
            }
        }
        if t >= 1.0 {
            return Some(x);
        }
    }
    None
}

/// Whether two solutions are the same state to `1e-6` of the larger's norm.
fn same_state(x: &[f64], y: &[f64]) -> bool {
    let gap = x.iter().zip(y).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
    gap.sqrt() <= 1e-6 * norm(x).max(norm(y))
}

/// Amplitudes of the tethered start, relative to the grazing seed's (as
/// [`START_AMPLITUDES`](crate::branches::START_AMPLITUDES), a seed that only grazes may slide
/// to rest).
const TETHERED_AMPLITUDES: [f64; 3] = [1.01, 1.1, 1.5];

/// Smallest step of the homotopy parameter before the path is given up.
const MIN_HOMOTOPY_STEP: f64 = 1e-3;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::branches::guesses::StartGuesses;
    use crate::modal::linear::rigid_body_modes;
    use crate::reference::contact_chain;
    use crate::solve::Problem;

    fn chain() -> (BarSystem, Vec<usize>) {
        let system = contact_chain(3, 1e-3, 0.5).unwrap();
        let laws = StartGuesses::new(&system).touched_laws();
        (system, laws)
    }

    #[test]
    fn the_chain_floats_and_its_tethered_system_is_held() {
        let (system, laws) = chain();
        assert_eq!(laws, vec![0, 1], "both contacts of the floating middle bar");
        assert!(rigid_body_modes(&system, ContactState::Open).is_some());
        let held = tethered_system(&system, &laws, TETHER_SCALE);
        assert!(rigid_body_modes(&held, ContactState::Open).is_none());
    }

    #[test]
    fn a_tether_of_zero_stiffness_changes_nothing() {
        let (system, laws) = chain();
        let settings = HarmonicBalanceSettings {
            harmonics: 6,
            ..HarmonicBalanceSettings::default()
        };
        let mut plain = NonsmoothSystem::new(&system, settings).unwrap();
        let mut slack =
            NonsmoothSystem::new(&tethered_system(&system, &laws, 0.0), settings).unwrap();
        let mut stiff =
            NonsmoothSystem::new(&tethered_system(&system, &laws, 1.0), settings).unwrap();
        let n = plain.dimension();
        let x: Vec<f64> = (0..n)
            .map(|i| 1e-3 * ((i * 7919 % 13) as f64 - 6.0) / 6.0)
            .collect();
        let (mut f0, mut f1, mut f2) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for p in [&mut plain, &mut slack, &mut stiff] {
            p.set_parameter(1.3);
        }
        plain.residual(&x, &mut f0);
        slack.residual(&x, &mut f1);
        stiff.residual(&x, &mut f2);
        assert_eq!(f0, f1);
        let moved = f0.iter().zip(&f2).filter(|(a, b)| a != b).count();
        assert!(moved > 0, "a stiff tether changes the laws' rows");
    }

    #[test]
    fn states_are_the_same_to_a_millionth() {
        let x = [1.0, -2.0, 3.0];
        let near: Vec<f64> = x.iter().map(|v| v * (1.0 + 1e-8)).collect();
        let far: Vec<f64> = x.iter().map(|v| v * 1.01).collect();
        assert!(same_state(&x, &near));
        assert!(!same_state(&x, &far));
        assert!(same_state(&[0.0; 3], &[0.0; 3]));
    }

    #[test]
    fn a_tether_stores_its_spring_energy() {
        let (system, laws) = chain();
        let held = tethered_system(&system, &laws, 2.0);
        let condition = held
            .conditions()
            .find(|c| c.unilateral().is_some())
            .unwrap();
        // Both ends moved 1e-3 towards each other: the gap closes by 2e-3.
        let value = |_: EndRef, q: Quantity| match q {
            Quantity::OutwardDisplacement => 1e-3,
            _ => 0.0,
        };
        // `kappa = 2 EA / l` of the unit bars.
        let want = 0.5 * 2.0 * 2e-3 * 2e-3;
        assert!((condition.stored_energy(&value) - want).abs() < 1e-15);
    }
}
