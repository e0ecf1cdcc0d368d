//! Unilateral laws enforced in time, and the complementarity function they share.

use super::Term;
use std::fmt::Debug;

/// An affine function of end quantities in time: `offset + sum(coefficient * quantity(t))`.
#[derive(Debug, Clone, PartialEq)]
pub struct Observable {
    /// Constant part (a gap at rest, for instance).
    pub offset: f64,
    /// Linear part.
    pub terms: Vec<Term>,
}

/// Value and generalised gradient of a pointwise law `r(gap, force)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawValue {
    /// `r`.
    pub value: f64,
    /// `dr / d gap` (an element of the generalised gradient at a kink).
    pub d_gap: f64,
    /// `dr / d force`.
    pub d_force: f64,
}

/// Output buffers of [`UnilateralLaw::sample`], one entry per time sample.
#[derive(Debug)]
pub struct LawSamples<'a> {
    /// `r` at each sample.
    pub values: &'a mut [f64],
    /// `dr / d gap` at each sample.
    pub d_gap: &'a mut [f64],
    /// `dr / d force` at each sample.
    pub d_force: &'a mut [f64],
}

/// The Signorini complementarity `g >= 0, lambda >= 0, g lambda = 0` as one equation
/// (formulation §3): `r = -min(lambda, a_c g)`, `a_c > 0` (the paper's complementarity parameter, default 4).
///
/// For a right end with `EA = 1` this is the paper's
/// `r = p + max(a_c (v - g0) - p, 0)`. Where `lambda < a_c g` the force branch is active
/// (`r = -lambda`); elsewhere, including the kink, the gap branch (`r = -a_c g`).
pub fn complementarity(gap: f64, force: f64, a_c: f64) -> LawValue {
    if force < a_c * gap {
        LawValue {
            value: -force,
            d_gap: 0.0,
            d_force: -1.0,
        }
    } else {
        LawValue {
            value: -a_c * gap,
            d_gap: -a_c,
            d_force: 0.0,
        }
    }
}

/// The smoothed complementarity `r = -min_eps(lambda, a_c g)` with the Chen–Harker–Kanzow–Smale
/// smoothing `min_eps(a, b) = (a + b - sqrt((a - b)^2 + 4 eps^2)) / 2`: smooth for `eps > 0`,
/// equal to [`complementarity`] for `eps = 0` (up to the choice at the kink). Solvers use it
/// for homotopies `eps -> 0` ([`crate::solve::SmoothingHomotopy`]).
pub fn smoothed_complementarity(gap: f64, force: f64, a_c: f64, smoothing: f64) -> LawValue {
    if smoothing <= 0.0 {
        return complementarity(gap, force, a_c);
    }
    let (a, b) = (force, a_c * gap);
    let root = ((a - b) * (a - b) + 4.0 * smoothing * smoothing).sqrt();
    let t = (a - b) / root;
    LawValue {
        value: -0.5 * (a + b - root),
        d_gap: -0.5 * a_c * (1.0 + t),
        d_force: -0.5 * (1.0 - t),
    }
}

/// Panics unless the samples and the outputs all have the same length.
fn check_lengths(gaps: &[f64], forces: &[f64], out: &LawSamples<'_>) {
    let n = gaps.len();
    assert!(
        forces.len() == n
            && out.values.len() == n
            && out.d_gap.len() == n
            && out.d_force.len() == n,
        "law samples of unequal lengths"
    );
}

/// `law` at every sample `(gaps[k], forces[k])` into `out`.
fn sample_pointwise(
    gaps: &[f64],
    forces: &[f64],
    out: LawSamples<'_>,
    law: impl Fn(f64, f64) -> LawValue,
) {
    check_lengths(gaps, forces, &out);
    let outputs = out
        .values
        .iter_mut()
        .zip(out.d_gap.iter_mut())
        .zip(out.d_force.iter_mut());
    for ((&g, &f), ((value, d_gap), d_force)) in gaps.iter().zip(forces).zip(outputs) {
        let v = law(g, f);
        (*value, *d_gap, *d_force) = (v.value, v.d_gap, v.d_force);
    }
}

/// [`smoothed_complementarity`] at every sample `(gaps[k], forces[k])` into `out`: the
/// [`UnilateralLaw::sample`] of Signorini and contact conditions. Without smoothing the loop
/// is branch-free (selects), so the compiler vectorises it; values are those of
/// [`complementarity`], bit for bit.
///
/// # Panics
/// If the slices do not all have the same length.
pub fn complementarity_samples(
    gaps: &[f64],
    forces: &[f64],
    a_c: f64,
    smoothing: f64,
    out: LawSamples<'_>,
) {
    if smoothing > 0.0 {
        let law = |g, f| smoothed_complementarity(g, f, a_c, smoothing);
        return sample_pointwise(gaps, forces, out, law);
    }
    check_lengths(gaps, forces, &out);
    let samples = gaps.iter().zip(forces);
    let outputs = out
        .values
        .iter_mut()
        .zip(out.d_gap.iter_mut())
        .zip(out.d_force.iter_mut());
    for ((&g, &f), ((value, d_gap), d_force)) in samples.zip(outputs) {
        // The branch of `complementarity`: the force branch where `lambda < a_c g`.
        let b = a_c * g;
        let force_branch = f < b;
        *value = if force_branch { -f } else { -b };
        *d_gap = if force_branch { 0.0 } else { -a_c };
        *d_force = if force_branch { -1.0 } else { 0.0 };
    }
}

/// A nonsmooth law between a gap and a force, enforced in time by harmonic balance.
///
/// The system samples `gap` and `force` on the time grid, evaluates [`UnilateralLaw::residual`]
/// at each instant and projects the result on the harmonic basis: one equation per basis
/// function. The linearised open state (`force = 0`) and closed state (gap motion `= 0`) used
/// by linear modal analysis come from the same two observables.
///
/// # Contract
///
/// - The law is returned by [`BoundaryCondition::unilateral`](super::BoundaryCondition) of a
///   condition on `n` ends, which then pushes `n - 1` linear rows (none for one end, the force
///   balance for two).
/// - [`gap`](UnilateralLaw::gap) and [`force`](UnilateralLaw::force) are affine in the
///   [`Quantity`](super::Quantity)s of the condition's ends, any of them: a gap may contain
///   force terms (a compliant obstacle, below), a force may combine several ends. Their
///   coefficients must be finite; [`AssemblyBuilder::add_condition`] checks them.
/// - [`residual`](UnilateralLaw::residual) is zero exactly on the law's graph and returns an
///   element of its generalised gradient; `a_c > 0` is the complementarity parameter, which
///   scales a gap against a force. The default is [`complementarity`], Signorini's
///   `g >= 0, lambda >= 0, g lambda = 0`, so a law that only moves the gap (as below) keeps it.
/// - [`smoothed_residual`](UnilateralLaw::smoothed_residual) equals `residual` at
///   `smoothing = 0`; [`sample`](UnilateralLaw::sample) is only a faster loop over it.
/// - A spring in the law stores energy: give it through
///   [`BoundaryCondition::stored_energy`](super::BoundaryCondition::stored_energy), from the
///   force it carries.
///
/// The time-domain check [`verify::periodicity_check`](crate::verify::periodicity_check)
/// marches the law the condition declares
/// ([`BoundaryCondition::time_domain_form`](super::BoundaryCondition::time_domain_form)), never
/// one inferred from the observables: a law without a declared form is not marched
/// ([`VerifyError::NoTimeDomainForm`](crate::error::VerifyError::NoTimeDomainForm)), and
/// the points of [`compute`](crate::branches::compute) are then unchecked. The example below
/// declares the integrator's compliant obstacle.
///
/// # Example: a compliant obstacle
///
/// The end meets a spring of stiffness `k` whose free end is at `g0`. Carrying the force
/// `lambda`, the spring is compressed by `lambda / k`, so the gap between the end and the
/// spring is `g = g0 - v + lambda / k` (`v` the outward displacement), and Signorini holds
/// between `g` and `lambda`: the default residual, with a force term in the gap. Closed, the
/// contact is a ground spring of stiffness `k` (a [`Robin`](super::Robin) end); as `k` grows
/// the law tends to the rigid obstacle.
///
/// ```
/// use nonsmooth_modes::bar::{Bar, EndRef};
/// use nonsmooth_modes::bc::{
///     BoundaryCondition, Observable, Quantity, Term, TimeDomainForm, UnilateralLaw,
/// };
/// use nonsmooth_modes::branches::{
///     compute, BackboneOptions, CheckOutcome, Method, PeriodGrid, Request, TimeDomainCheck,
/// };
/// use nonsmooth_modes::modal::{natural_frequencies, ContactState};
/// use nonsmooth_modes::solve::Solver;
/// use nonsmooth_modes::system::AssemblyBuilder;
///
/// #[derive(Debug)]
/// struct CompliantObstacle {
///     end: EndRef,
///     gap: f64,
///     stiffness: f64,
/// }
///
/// impl BoundaryCondition for CompliantObstacle {
///     fn name(&self) -> String {
///         format!("compliant obstacle (gap {}, k {}) at {}", self.gap, self.stiffness, self.end)
///     }
///     fn ends(&self) -> Vec<EndRef> {
///         vec![self.end]
///     }
///     // One end and a law: no linear row.
///     fn unilateral(&self) -> Option<&dyn UnilateralLaw> {
///         Some(self)
///     }
///     // The spring's energy lambda^2 / (2 k), zero while the contact is open.
///     fn stored_energy(&self, value: &dyn Fn(EndRef, Quantity) -> f64) -> f64 {
///         let force = value(self.end, Quantity::ContactForce).max(0.0);
///         0.5 * force * force / self.stiffness
///     }
///     // In time: the integrator's compliant obstacle, same gap and stiffness.
///     fn time_domain_form(&self) -> Option<TimeDomainForm> {
///         Some(TimeDomainForm::CompliantObstacle {
///             end: self.end,
///             gap: self.gap,
///             stiffness: self.stiffness,
///         })
///     }
/// }
///
/// impl UnilateralLaw for CompliantObstacle {
///     // g = g0 - v + lambda / k: a force term in the gap.
///     fn gap(&self) -> Observable {
///         Observable {
///             offset: self.gap,
///             terms: vec![
///                 Term::new(self.end, Quantity::OutwardDisplacement, -1.0),
///                 Term::new(self.end, Quantity::ContactForce, 1.0 / self.stiffness),
///             ],
///         }
///     }
///     fn force(&self) -> Observable {
///         Observable {
///             offset: 0.0,
///             terms: vec![Term::new(self.end, Quantity::ContactForce, 1.0)],
///         }
///     }
///     // `residual` is left to its default: Signorini between this gap and this force.
/// }
///
/// let k = 50.0;
/// let mut b = AssemblyBuilder::new();
/// let bar = b.add_bar(Bar::unit());
/// b.dirichlet(bar.left())?
///     .add_condition(CompliantObstacle { end: bar.right(), gap: 1e-3, stiffness: k })?;
/// let system = b.build()?;
///
/// // Closed, the obstacle is a ground spring of stiffness k.
/// let mut springy = AssemblyBuilder::new();
/// let other = springy.add_bar(Bar::unit());
/// springy.dirichlet(other.left())?.robin(other.right(), k)?;
/// let closed = natural_frequencies(&system, ContactState::Closed, 10.0)?;
/// let spring = natural_frequencies(&springy.build()?, ContactState::Open, 10.0)?;
/// assert_eq!(closed.len(), spring.len());
/// for (a, b) in closed.iter().zip(&spring) {
///     assert!((a.omega - b.omega).abs() < 1e-9 * b.omega);
/// }
///
/// // A backbone of its first nonsmooth mode, as for a built-in condition: it hardens (the
/// // energy grows as the period falls). Each point is marched one period against the
/// // declared compliant obstacle, and comes back.
/// let grid = PeriodGrid { start: 3.95, end: 3.6, steps: 8 };
/// let request = Request {
///     solver: Some(Solver::default()),
///     ..Request::new(1)
///         .harmonics(10)
///         .method(Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)))
///         .checked(TimeDomainCheck::for_system(&system))
/// };
/// let points = compute(&system, &request)?.points;
/// assert!(points.iter().all(|p| p.converged()));
/// assert!(points.windows(2).all(|w| w[1].energy_normalized > w[0].energy_normalized));
/// assert!(points.iter().all(|p| p.check == Some(CheckOutcome::Passed)));
/// # Ok::<(), nonsmooth_modes::Error>(())
/// ```
///
/// `tests/custom_condition.rs` writes the same obstacle with its own residual instead (the
/// complementarity of `g + lambda / k`, or a penalty `lambda - k max(0, -g)`) and checks that
/// its backbone tends to the rigid obstacle's as `k` grows, that its points pass the check,
/// and that the penalty law without a declared form is unchecked rather than marched as a
/// rigid wall.
///
/// [`AssemblyBuilder::add_condition`]: crate::system::AssemblyBuilder::add_condition
pub trait UnilateralLaw: Debug + Send + Sync {
    /// The gap as an affine function of end quantities (its offset is the gap at rest).
    fn gap(&self) -> Observable;

    /// The contact force as a linear function of end quantities (offset normally zero).
    fn force(&self) -> Observable;

    /// The pointwise residual; defaults to [`complementarity`].
    fn residual(&self, gap: f64, force: f64, a_c: f64) -> LawValue {
        complementarity(gap, force, a_c)
    }

    /// A smoothed version of [`UnilateralLaw::residual`] with smoothing `smoothing >= 0`
    /// (a force), used by smoothing homotopies; it must equal `residual` at `smoothing = 0`.
    /// The default ignores the smoothing (a law that overrides `residual` keeps its own
    /// nonsmooth form); Signorini and contact use [`smoothed_complementarity`].
    fn smoothed_residual(&self, gap: f64, force: f64, a_c: f64, smoothing: f64) -> LawValue {
        let _ = smoothing;
        self.residual(gap, force, a_c)
    }

    /// [`UnilateralLaw::smoothed_residual`] at every sample `(gaps[k], forces[k])` of a time
    /// grid. The default loops over `smoothed_residual`; being a provided method, the loop is
    /// compiled for each law type, so the system's sampling makes one dynamic call per law
    /// instead of one per sample, and the per-sample law can be inlined and vectorised.
    ///
    /// # Panics
    /// If the slices do not all have the same length (a programmer contract of the caller).
    fn sample(&self, gaps: &[f64], forces: &[f64], a_c: f64, smoothing: f64, out: LawSamples<'_>) {
        let law = |g, f| self.smoothed_residual(g, f, a_c, smoothing);
        sample_pointwise(gaps, forces, out, law);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampled_law_equals_the_pointwise_law() {
        // Both branches, the kink (force == a_c gap), negative gaps and forces.
        let gaps = [0.3, 0.01, -0.2, 0.5, 0.25, 0.0, -1.0];
        let forces = [0.1, 2.0, 0.5, -0.3, 1.0, 0.0, -4.0];
        for smoothing in [0.0, 1e-3] {
            let (mut v, mut dg, mut df) = ([f64::NAN; 7], [f64::NAN; 7], [f64::NAN; 7]);
            complementarity_samples(
                &gaps,
                &forces,
                4.0,
                smoothing,
                LawSamples {
                    values: &mut v,
                    d_gap: &mut dg,
                    d_force: &mut df,
                },
            );
            for k in 0..7 {
                let want = smoothed_complementarity(gaps[k], forces[k], 4.0, smoothing);
                assert_eq!((v[k], dg[k], df[k]), (want.value, want.d_gap, want.d_force));
            }
        }
    }

    #[test]
    fn smoothing_tends_to_the_nonsmooth_law_with_consistent_derivatives() {
        for (g, l) in [(0.3, 0.1), (0.01, 2.0), (-0.2, 0.5), (0.5, -0.3)] {
            let exact = complementarity(g, l, 4.0);
            let smooth = smoothed_complementarity(g, l, 4.0, 1e-9);
            assert!((exact.value - smooth.value).abs() < 1e-8);
            let eps = 0.05;
            let v = smoothed_complementarity(g, l, 4.0, eps);
            let h = 1e-7;
            let dg = (smoothed_complementarity(g + h, l, 4.0, eps).value
                - smoothed_complementarity(g - h, l, 4.0, eps).value)
                / (2.0 * h);
            let dl = (smoothed_complementarity(g, l + h, 4.0, eps).value
                - smoothed_complementarity(g, l - h, 4.0, eps).value)
                / (2.0 * h);
            assert!((v.d_gap - dg).abs() < 1e-6 && (v.d_force - dl).abs() < 1e-6);
        }
        assert_eq!(
            smoothed_complementarity(0.2, 0.1, 4.0, 0.0),
            complementarity(0.2, 0.1, 4.0)
        );
    }

    #[test]
    fn complementarity_zero_exactly_on_the_signorini_graph() {
        for (g, l) in [(0.5, 0.0), (0.0, 2.0), (0.0, 0.0)] {
            assert_eq!(complementarity(g, l, 4.0).value, 0.0);
        }
        for (g, l) in [(0.5, 0.1), (-0.1, 0.0), (0.0, -1.0), (1.0, 1.0)] {
            assert!(complementarity(g, l, 4.0).value != 0.0);
        }
    }
}
