//! What drives and what damps a forced response: viscous damping per bar, and harmonic
//! excitations at bar ends, each the right-hand side of its end's condition row.
//!
//! An end held alone by a linear condition has one row `sum_j a_j q_j = 0` over its end
//! quantities; written in the displacement `u` and the outward strain `p`, it is
//! `a_u u + a_p p = 0`. An excitation at harmonic 1 changes it to:
//!
//! - **a force** `F cos(Omega t)` along `+x` on the end: the end balance `EA p = F + ...` puts
//!   `a_p F / EA` on the right (a free end: `p = F / EA`; a spring `EA p + k u = F`);
//! - **a base motion** `U cos(Omega t)` of the ground the end is tied to: `u` is measured
//!   from the ground, which puts `a_u U` on the right (a clamped end: `u = U`; a spring to a
//!   moving base: `EA p + k (u - U) = 0`).
//!
//! The obstacles stay fixed in space.

use crate::bar::EndRef;
use crate::bc::{BoundaryCondition, LinearRows};
use crate::error::ForcingError;
use crate::system::rows::quantity_weights;
use crate::system::BarSystem;

/// What an [`Excitation`] prescribes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum ExcitationKind {
    /// A force along `+x` applied to the end.
    Force,
    /// A prescribed motion of the ground the end's condition ties it to (base excitation).
    BaseMotion,
}

impl ExcitationKind {
    /// `a force` or `a base motion`, for messages.
    fn description(self) -> &'static str {
        match self {
            Self::Force => "a force",
            Self::BaseMotion => "a base motion",
        }
    }
}

/// A harmonic excitation `amplitude cos(Omega t)` at one bar end (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Excitation {
    /// Force or base motion.
    pub kind: ExcitationKind,
    /// The end.
    pub end: EndRef,
    /// Its amplitude: a force (in the units of `EA` times a strain) or a displacement.
    pub amplitude: f64,
}

impl Excitation {
    /// A force `amplitude cos(Omega t)` along `+x` on `end`.
    pub fn force(end: EndRef, amplitude: f64) -> Self {
        Self {
            kind: ExcitationKind::Force,
            end,
            amplitude,
        }
    }

    /// A base motion `amplitude cos(Omega t)` of the ground `end` is tied to.
    pub fn base_motion(end: EndRef, amplitude: f64) -> Self {
        Self {
            kind: ExcitationKind::BaseMotion,
            end,
            amplitude,
        }
    }
}

/// Viscous damping `eta` of `u_tt + eta u_t = c^2 u_xx`, per bar.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Damping {
    /// The same `eta` in every bar.
    Uniform(f64),
    /// One `eta` per bar, in the order of the system's bars.
    PerBar(Vec<f64>),
}

impl Damping {
    /// One checked value per bar of `system`.
    ///
    /// # Errors
    /// [`ForcingError::DampingLength`] for a vector with another length than the bars,
    /// [`ForcingError::Damping`] for a negative or non-finite value.
    pub fn per_bar(&self, system: &BarSystem) -> Result<Vec<f64>, ForcingError> {
        let bars = system.bars().len();
        let values = match self {
            Self::Uniform(eta) => vec![*eta; bars],
            Self::PerBar(v) if v.len() == bars => v.clone(),
            Self::PerBar(v) => {
                return Err(ForcingError::DampingLength {
                    got: v.len(),
                    expected: bars,
                })
            }
        };
        match values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            Some(bar) => Err(ForcingError::Damping {
                bar,
                value: values[bar],
            }),
            None => Ok(values),
        }
    }
}

/// An excitation resolved on a system: the linear row it drives, and the condition there.
#[derive(Debug, Clone)]
pub(super) struct Driven {
    pub(super) excitation: Excitation,
    /// Index of the condition in the system's list.
    condition: usize,
    /// Index, among one harmonic's linear rows, of that condition's row.
    pub(super) row: usize,
}

/// The condition holding `end` alone, with its index and the index of its first row.
fn condition_at(
    system: &BarSystem,
    end: EndRef,
) -> Result<(usize, usize, &dyn BoundaryCondition), ForcingError> {
    let stiffness = |e: EndRef| system.stiffness_at(e);
    let mut rows = LinearRows::new();
    for (index, condition) in system.conditions().enumerate() {
        let first = rows.len();
        condition.linear_rows(1.0, &stiffness, &mut rows);
        if !condition.ends().contains(&end) {
            continue;
        }
        let reason = if condition.unilateral().is_some() {
            format!(
                "it is held by the unilateral condition `{}`",
                condition.name()
            )
        } else if condition.ends().len() > 1 || rows.len() != first + 1 {
            format!("its condition `{}` holds other ends too", condition.name())
        } else {
            return Ok((index, first, condition));
        };
        return Err(ForcingError::NoConditionRow {
            end: end.to_string(),
            reason,
        });
    }
    Err(ForcingError::NoConditionRow {
        end: end.to_string(),
        reason: "no condition names it".to_string(),
    })
}

/// The weights `(a_u, a_p)` of the condition's row at `end`, and their derivatives in the
/// harmonic's frequency, at frequency `omega`.
fn row_weights(system: &BarSystem, condition: &dyn BoundaryCondition, omega: f64) -> [f64; 4] {
    let stiffness = |e: EndRef| system.stiffness_at(e);
    let mut rows = LinearRows::new();
    condition.linear_rows(omega, &stiffness, &mut rows);
    let mut w = [0.0; 4];
    for t in rows.row(0) {
        let (wu, wp) = quantity_weights(t.quantity, t.end.end, system.stiffness_at(t.end));
        w[0] += t.coefficient * wu;
        w[1] += t.coefficient * wp;
        w[2] += t.d_coefficient * wu;
        w[3] += t.d_coefficient * wp;
    }
    w
}

impl Driven {
    /// `excitation` resolved on `system`.
    ///
    /// # Errors
    /// [`ForcingError::Amplitude`] for a non-finite amplitude,
    /// [`ForcingError::NoConditionRow`] for an end no linear condition holds alone,
    /// [`ForcingError::NothingToExcite`] for a force at a clamped end or a base motion at an
    /// end tied to no ground.
    pub(super) fn new(system: &BarSystem, excitation: Excitation) -> Result<Self, ForcingError> {
        let end = excitation.end;
        if !excitation.amplitude.is_finite() {
            return Err(ForcingError::Amplitude {
                end: end.to_string(),
                value: excitation.amplitude,
            });
        }
        let (condition, row, held_by) = condition_at(system, end)?;
        let driven = Self {
            excitation,
            condition,
            row,
        };
        // The weight must not vanish identically: checked at two frequencies, as the
        // assembly checks its conditions.
        let zero = |omega| {
            let w = row_weights(system, held_by, omega);
            driven.weight_of(w, system.stiffness_at(end)) == 0.0
        };
        if zero(0.0) && zero(1.0) {
            let missing = match excitation.kind {
                ExcitationKind::Force => "strain",
                ExcitationKind::BaseMotion => "displacement",
            };
            return Err(ForcingError::NothingToExcite {
                what: excitation.kind.description(),
                end: end.to_string(),
                condition: held_by.name(),
                missing,
            });
        }
        Ok(driven)
    }

    /// The right-hand side per unit amplitude from the row weights `w` (or from their
    /// derivatives, shifted by two).
    fn weight_of(&self, w: [f64; 4], stiffness: f64) -> f64 {
        match self.excitation.kind {
            ExcitationKind::Force => w[1] / stiffness,
            ExcitationKind::BaseMotion => w[0],
        }
    }

    /// The right-hand side of its row at harmonic 1 and fundamental frequency `omega`, and
    /// its derivative in `omega`.
    pub(super) fn right_hand_side(&self, system: &BarSystem, omega: f64) -> (f64, f64) {
        let condition = system
            .conditions()
            .nth(self.condition)
            .expect("the condition resolved on this system");
        let w = row_weights(system, condition, omega);
        let stiffness = system.stiffness_at(self.excitation.end);
        let a = self.excitation.amplitude;
        (
            a * self.weight_of(w, stiffness),
            a * self.weight_of([w[2], w[3], 0.0, 0.0], stiffness),
        )
    }
}
