//! What the Floquet multipliers of a motion say, as plain values: whether it is stable and,
//! when not, how a multiplier left the unit circle. The stability analysis
//! ([`crate::stability`], where they are documented for users) computes them; continuation
//! events and plots name them. This module depends on no other module of the crate.

/// Where a multiplier outside the unit circle sits: how it left the circle along a branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Crossing {
    /// Real and positive: it left through `+1` (a fold of the family or a symmetry-breaking
    /// branch point).
    ThroughPlusOne,
    /// Real and negative: it left through `-1` (a period-doubling).
    ThroughMinusOne,
    /// A complex pair (a Neimark–Sacker or, in a conservative system, Krein collision).
    ComplexPair,
}

impl Crossing {
    /// `+1`, `-1` or `complex`.
    pub fn name(&self) -> &'static str {
        match self {
            Crossing::ThroughPlusOne => "+1",
            Crossing::ThroughMinusOne => "-1",
            Crossing::ComplexPair => "complex",
        }
    }
}

/// What the multipliers say about a motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Verdict {
    /// Every multiplier lies inside the unit circle or within the tolerance outside it.
    Stable,
    /// A multiplier lies outside, where the crossing says.
    Unstable(Crossing),
    /// No verdict: the state could not be corrected to a periodic orbit of the grid's map
    /// near the point's own motion, or the differences did not find the trivial pair
    /// ([`Floquet::unresolved`](crate::stability::Floquet::unresolved) says which, with the numbers). The multipliers (still
    /// reported) support no verdict.
    Unresolved,
}

impl Verdict {
    /// `Some(true)` when stable, `Some(false)` when unstable, `None` when unresolved.
    pub fn stable(&self) -> Option<bool> {
        match self {
            Verdict::Stable => Some(true),
            Verdict::Unstable(_) => Some(false),
            Verdict::Unresolved => None,
        }
    }

    /// `stable`, `unstable` or `unresolved`.
    pub fn name(&self) -> &'static str {
        match self {
            Verdict::Stable => "stable",
            Verdict::Unstable(_) => "unstable",
            Verdict::Unresolved => "unresolved",
        }
    }
}
