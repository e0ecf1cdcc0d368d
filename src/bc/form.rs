//! The time-domain form a condition declares: the end rule the exact integrator
//! ([`crate::verify`]) advances for it.
//!
//! # Why a declaration
//!
//! Harmonic balance sees a nonsmooth condition only through its two observables and its
//! residual `r(g, lambda)`, which is zero on the law's graph. The observables do not say what
//! the graph is: a rigid obstacle (`g = g0 - v`, `lambda = -EA u_x`, Signorini) and a penalty
//! law (`lambda - k max(0, -g)` on the same two observables) differ only inside `residual`,
//! which is an opaque function. Read from the observables, the penalty law would be marched
//! as a rigid wall: the check would then judge a motion of another system. So a condition
//! says which law holds in time, and one that does not is not marched at all (the check
//! reports it unchecked). The form's parameters are those of the law in time, which the
//! condition knows: the obstacle's gap, the spring's stiffness.

use crate::bar::EndRef;

/// How a condition acts in time: one of the end rules that
/// [`verify`](crate::verify) advances exactly (or to a documented order), declared by
/// [`BoundaryCondition::time_domain_form`](super::BoundaryCondition::time_domain_form).
///
/// With outward normal `n`, outward displacement `v = n u` and compressive force
/// `lambda = -EA u_x`:
///
/// | form | law in time | built-in condition |
/// |---|---|---|
/// | `Clamped` | `u = 0` | [`Dirichlet`](super::Dirichlet) |
/// | `Free` | `u_x = 0` | [`Neumann`](super::Neumann) |
/// | `Spring` | `EA n u_x + k_s u = 0`, stores `k_s u^2 / 2` | [`Robin`](super::Robin) |
/// | `Obstacle` | `g = g0 - v >= 0`, `lambda >= 0`, `g lambda = 0` | [`Signorini`](super::Signorini) |
/// | `CompliantObstacle` | `lambda = k max(0, v - g0)`, stores `k max(0, v - g0)^2 / 2` | none (a downstream law) |
/// | `Contact` | `g = g0 - v_A - v_B >= 0`, `lambda_A = lambda_B >= 0`, `g lambda = 0` | [`Contact`](super::Contact) |
///
/// In [`verify`](crate::verify) this type is [`verify::Condition`](crate::verify::Condition),
/// where gaps may also be zero or negative (an end pressed into its obstacle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeDomainForm {
    /// `u = 0`: the outgoing wave is minus the incoming one.
    Clamped {
        /// The end.
        end: EndRef,
    },
    /// `u_x = 0`: the outgoing wave equals the incoming one.
    Free {
        /// The end.
        end: EndRef,
    },
    /// Ground spring `EA n u_x + k_s u = 0`, storing `k_s u^2 / 2`.
    Spring {
        /// The end.
        end: EndRef,
        /// `k_s > 0`.
        stiffness: f64,
    },
    /// Rigid obstacle: gap `g = g0 - n u >= 0`, force `lambda = -EA u_x >= 0`, `g lambda = 0`.
    /// Unlike [`Signorini`](super::Signorini), `g0` may be zero or negative (an end pressed
    /// into the obstacle, the bar pre-stressed).
    Obstacle {
        /// The end.
        end: EndRef,
        /// `g0`, any finite value.
        gap: f64,
    },
    /// Obstacle backed by a spring of stiffness `k` whose free end is at gap `g0`: the end
    /// moves freely while `v = n u < g0`, and beyond it compresses the spring by
    /// `p = v - g0`, which pushes back with `lambda = -EA u_x = k p`. The spring stores
    /// `k p^2 / 2`. As `k` grows it tends to [`TimeDomainForm::Obstacle`].
    CompliantObstacle {
        /// The end.
        end: EndRef,
        /// `g0`, any finite value.
        gap: f64,
        /// `k > 0`.
        stiffness: f64,
    },
    /// Two ends facing each other: `g = g0 - v_A - v_B >= 0`, `lambda_A = lambda_B >= 0`,
    /// `g lambda = 0`.
    Contact {
        /// End `A`.
        first: EndRef,
        /// End `B`.
        second: EndRef,
        /// `g0`, any finite value.
        gap: f64,
    },
}

impl TimeDomainForm {
    /// The ends it acts on.
    pub fn ends(&self) -> Vec<EndRef> {
        match *self {
            TimeDomainForm::Clamped { end }
            | TimeDomainForm::Free { end }
            | TimeDomainForm::Spring { end, .. }
            | TimeDomainForm::Obstacle { end, .. }
            | TimeDomainForm::CompliantObstacle { end, .. } => vec![end],
            TimeDomainForm::Contact { first, second, .. } => vec![first, second],
        }
    }

    /// Whether it is unilateral (an obstacle, rigid or compliant, or a contact): it carries a
    /// contact force and has a gap.
    pub fn is_unilateral(&self) -> bool {
        matches!(
            self,
            TimeDomainForm::Obstacle { .. }
                | TimeDomainForm::CompliantObstacle { .. }
                | TimeDomainForm::Contact { .. }
        )
    }

    /// A short description.
    pub fn name(&self) -> String {
        match *self {
            TimeDomainForm::Clamped { end } => format!("clamped {end}"),
            TimeDomainForm::Free { end } => format!("free {end}"),
            TimeDomainForm::Spring { end, stiffness } => {
                format!("spring k = {stiffness} at {end}")
            }
            TimeDomainForm::Obstacle { end, gap } => format!("obstacle at gap {gap} from {end}"),
            TimeDomainForm::CompliantObstacle {
                end,
                gap,
                stiffness,
            } => format!("compliant obstacle (k = {stiffness}) at gap {gap} from {end}"),
            TimeDomainForm::Contact { first, second, gap } => {
                format!("contact (gap {gap}) between {first} and {second}")
            }
        }
    }
}
