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

/// The Signorini complementarity `g >= 0, lambda >= 0, g lambda = 0` as one equation
/// (formulation §3): `r = -min(lambda, a_c g)`, `a_c > 0` (the paper's `penalty`, default 4).
///
/// For a right end with `EA = 1` this is the paper's
/// `r = p + max(a_c (v - g0) - p, 0)`. Where `lambda < a_c g` the force branch is active
/// (`r = -lambda`); elsewhere, including the kink, the gap branch (`r = -a_c g`).
pub fn complementarity(gap: f64, force: f64, penalty: f64) -> LawValue {
    if force < penalty * gap {
        LawValue {
            value: -force,
            d_gap: 0.0,
            d_force: -1.0,
        }
    } else {
        LawValue {
            value: -penalty * gap,
            d_gap: -penalty,
            d_force: 0.0,
        }
    }
}

/// A nonsmooth law between a gap and a force, enforced in time by harmonic balance.
///
/// The system samples `gap` and `force` on the time grid, evaluates [`UnilateralLaw::residual`]
/// at each instant and projects the result on the harmonic basis: one equation per basis
/// function. The linearised open state (`force = 0`) and closed state (gap motion `= 0`) used
/// by linear modal analysis come from the same two observables.
pub trait UnilateralLaw: Debug + Send + Sync {
    /// The gap as an affine function of end quantities (its offset is the gap at rest).
    fn gap(&self) -> Observable;

    /// The contact force as a linear function of end quantities (offset normally zero).
    fn force(&self) -> Observable;

    /// The pointwise residual; defaults to [`complementarity`].
    fn residual(&self, gap: f64, force: f64, penalty: f64) -> LawValue {
        complementarity(gap, force, penalty)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
