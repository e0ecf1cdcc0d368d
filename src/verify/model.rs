//! The assembly as the integrator sees it: bars and one exact end rule per condition.

use super::VerifyError;
use crate::bar::{Bar, BarId, End, EndRef};
use crate::bc::{BoundaryCondition, LinearRows, Observable, Term};
use crate::error::ModelError;
use crate::system::rows::quantity_weights_in_strain;
use crate::system::BarSystem;

/// An end rule the integrator advances exactly (see the [module docs](super)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Condition {
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
    /// Unlike [`Signorini`](crate::bc::Signorini), `g0` may be zero or negative (an end pressed
    /// into the obstacle, the bar pre-stressed).
    Obstacle {
        /// The end.
        end: EndRef,
        /// `g0`, any finite value.
        gap: f64,
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

impl Condition {
    /// The ends it acts on.
    pub fn ends(&self) -> Vec<EndRef> {
        match *self {
            Condition::Clamped { end }
            | Condition::Free { end }
            | Condition::Spring { end, .. }
            | Condition::Obstacle { end, .. } => vec![end],
            Condition::Contact { first, second, .. } => vec![first, second],
        }
    }

    /// Whether it is unilateral (an obstacle or a contact).
    pub fn is_unilateral(&self) -> bool {
        matches!(self, Condition::Obstacle { .. } | Condition::Contact { .. })
    }

    /// A short description.
    pub fn name(&self) -> String {
        match *self {
            Condition::Clamped { end } => format!("clamped {end}"),
            Condition::Free { end } => format!("free {end}"),
            Condition::Spring { end, stiffness } => format!("spring k = {stiffness} at {end}"),
            Condition::Obstacle { end, gap } => format!("obstacle at gap {gap} from {end}"),
            Condition::Contact { first, second, gap } => {
                format!("contact (gap {gap}) between {first} and {second}")
            }
        }
    }
}

/// Bars and exact end rules: the input of the integrator.
///
/// Build it from a validated [`BarSystem`] with [`Model::from_system`], or directly with
/// [`Model::new`] (which, unlike the harmonic-balance conditions, accepts gaps `g0 <= 0`).
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    bars: Vec<Bar>,
    conditions: Vec<Condition>,
}

/// A linear form of end quantities collapsed to `(end, weight of u, weight of u_x)` per end.
fn collapse(terms: &[Term], ends: &[EndRef], system: &BarSystem) -> Option<Vec<(f64, f64)>> {
    let mut out = vec![(0.0, 0.0); ends.len()];
    for t in terms {
        if t.d_coefficient != 0.0 {
            return None;
        }
        let i = ends.iter().position(|e| *e == t.end)?;
        let (wu, wx) =
            quantity_weights_in_strain(t.quantity, t.end.end, system.stiffness_at(t.end));
        out[i].0 += t.coefficient * wu;
        out[i].1 += t.coefficient * wx;
    }
    Some(out)
}

fn unsupported(c: &dyn BoundaryCondition, reason: &'static str) -> VerifyError {
    VerifyError::Unsupported {
        condition: c.name(),
        reason,
    }
}

/// Relative closeness of two reals.
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs())
}

impl Model {
    /// Bars and conditions given directly. Bar ids are minted by
    /// [`AssemblyBuilder::add_bar`](crate::system::AssemblyBuilder::add_bar) (bar `i` is the
    /// `i`-th bar added); the simplest route is often [`Model::from_system`] followed by
    /// [`Model::with_gap`].
    ///
    /// # Errors
    /// [`ModelError::NoBars`], [`ModelError::UnknownBar`], [`ModelError::RepeatedEnd`],
    /// [`ModelError::OverconstrainedEnd`], [`ModelError::UnconstrainedEnd`] (wrapped in
    /// [`VerifyError::Model`]) for a malformed assembly; [`VerifyError::InvalidParameter`] for a
    /// non-finite gap or a spring stiffness that is not positive and finite.
    pub fn new(bars: Vec<Bar>, conditions: Vec<Condition>) -> Result<Self, VerifyError> {
        if bars.is_empty() {
            return Err(ModelError::NoBars.into());
        }
        let mut owner: Vec<[Option<usize>; 2]> = vec![[None, None]; bars.len()];
        for (index, c) in conditions.iter().enumerate() {
            match *c {
                Condition::Spring { stiffness, .. }
                    if !(stiffness.is_finite() && stiffness > 0.0) =>
                {
                    return Err(VerifyError::InvalidParameter {
                        what: "spring stiffness",
                        value: stiffness,
                    })
                }
                Condition::Obstacle { gap, .. } | Condition::Contact { gap, .. }
                    if !gap.is_finite() =>
                {
                    return Err(VerifyError::InvalidParameter {
                        what: "contact gap",
                        value: gap,
                    })
                }
                _ => {}
            }
            let ends = c.ends();
            for (i, end) in ends.iter().enumerate() {
                let b = end.bar.index();
                if b >= bars.len() {
                    return Err(ModelError::UnknownBar {
                        condition: c.name(),
                        bar: b,
                        bars: bars.len(),
                    }
                    .into());
                }
                if ends[..i].contains(end) {
                    return Err(ModelError::RepeatedEnd {
                        condition: c.name(),
                        end: *end,
                    }
                    .into());
                }
                let slot = &mut owner[b][usize::from(end.end == End::Right)];
                if let Some(first) = *slot {
                    return Err(ModelError::OverconstrainedEnd {
                        end: *end,
                        first: conditions[first].name(),
                        second: c.name(),
                    }
                    .into());
                }
                *slot = Some(index);
            }
        }
        for (b, o) in owner.iter().enumerate() {
            let id = BarId(b);
            for (slot, end) in o.iter().zip([id.left(), id.right()]) {
                if slot.is_none() {
                    return Err(ModelError::UnconstrainedEnd { end }.into());
                }
            }
        }
        Ok(Self { bars, conditions })
    }

    /// Reads every condition of `system` from its rows and observables (module docs).
    ///
    /// # Errors
    /// [`VerifyError::Unsupported`] naming the first condition that is not of a supported form.
    pub fn from_system(system: &BarSystem) -> Result<Self, VerifyError> {
        let conditions = system
            .conditions()
            .map(|c| classify(c, system))
            .collect::<Result<Vec<_>, _>>()?;
        Self::new(system.bars().to_vec(), conditions)
    }

    /// A unit bar clamped at `x = 0` facing a rigid obstacle at gap `g0` (any finite value) at
    /// `x = 1`: the system of [`reference::clamped_bar_with_obstacle`](crate::reference::clamped_bar_with_obstacle)
    /// without the restriction `g0 > 0`.
    ///
    /// # Errors
    /// [`VerifyError::InvalidParameter`] if `g0` is not finite.
    pub fn clamped_bar_with_obstacle(gap: f64) -> Result<Self, VerifyError> {
        let bar = BarId(0);
        Self::new(
            vec![Bar::unit()],
            vec![
                Condition::Clamped { end: bar.left() },
                Condition::Obstacle {
                    end: bar.right(),
                    gap,
                },
            ],
        )
    }

    /// The same model with the gap of condition `index` (an obstacle or a contact) set to
    /// `gap`, which may be zero or negative.
    ///
    /// # Errors
    /// [`VerifyError::InvalidParameter`] if `index` is not a unilateral condition or `gap` is
    /// not finite.
    pub fn with_gap(mut self, index: usize, gap: f64) -> Result<Self, VerifyError> {
        if !gap.is_finite() {
            return Err(VerifyError::InvalidParameter {
                what: "contact gap",
                value: gap,
            });
        }
        match self.conditions.get_mut(index) {
            Some(Condition::Obstacle { gap: g, .. }) | Some(Condition::Contact { gap: g, .. }) => {
                *g = gap;
                Ok(self)
            }
            _ => Err(VerifyError::InvalidParameter {
                what: "index of a unilateral condition",
                value: index as f64,
            }),
        }
    }

    /// The bars.
    pub fn bars(&self) -> &[Bar] {
        &self.bars
    }

    /// The conditions, in the order of the system they came from.
    pub fn conditions(&self) -> &[Condition] {
        &self.conditions
    }
}

/// Reads one condition (module docs of [`super`]).
fn classify(c: &dyn BoundaryCondition, system: &BarSystem) -> Result<Condition, VerifyError> {
    let ends = c.ends();
    let stiffness = |e: EndRef| system.stiffness_at(e);
    let mut rows = LinearRows::new();
    c.linear_rows(1.0, &stiffness, &mut rows);
    let mut other = LinearRows::new();
    c.linear_rows(2.7, &stiffness, &mut other);
    let same = rows.len() == other.len() && (0..rows.len()).all(|i| rows.row(i) == other.row(i));
    if !same {
        return Err(unsupported(c, "its rows depend on the frequency"));
    }
    let law = c.unilateral();
    match (ends.len(), rows.len(), law) {
        (1, 1, None) => {
            let end = ends[0];
            let w = collapse(rows.row(0), &ends, system).ok_or_else(|| {
                unsupported(c, "a row term has a frequency-dependent coefficient")
            })?;
            let (alpha, gamma) = w[0];
            if gamma == 0.0 && alpha != 0.0 {
                Ok(Condition::Clamped { end })
            } else if alpha == 0.0 && gamma != 0.0 {
                Ok(Condition::Free { end })
            } else if alpha != 0.0 && gamma != 0.0 {
                // alpha u + gamma u_x = 0 and EA n u_x + k u = 0: k = n EA alpha / gamma.
                let k = end.end.normal() * stiffness(end) * alpha / gamma;
                if k > 0.0 && k.is_finite() {
                    Ok(Condition::Spring { end, stiffness: k })
                } else {
                    Err(unsupported(c, "a ground spring of negative stiffness"))
                }
            } else {
                Err(unsupported(c, "an empty row"))
            }
        }
        (1, 0, Some(law)) => {
            let end = ends[0];
            let n = end.end.normal();
            let (gap_scale, g0) = gap_form(c, &law.gap(), &ends, system)?;
            force_form(c, &law.force(), &ends, system)?;
            let kappa = -n * gap_scale[0];
            if !(kappa.is_finite() && kappa > 0.0) {
                return Err(unsupported(
                    c,
                    "the gap does not close as the end moves outward",
                ));
            }
            Ok(Condition::Obstacle {
                end,
                gap: g0 / kappa,
            })
        }
        (2, 1, Some(law)) => {
            let (a, b) = (ends[0], ends[1]);
            let (gap_scale, g0) = gap_form(c, &law.gap(), &ends, system)?;
            let ka = -a.end.normal() * gap_scale[0];
            let kb = -b.end.normal() * gap_scale[1];
            if !(ka > 0.0 && close(ka, kb)) {
                return Err(unsupported(
                    c,
                    "the gap is not g0 - v_A - v_B (up to a factor)",
                ));
            }
            force_form(c, &law.force(), &ends, system)?;
            // Balance: mu_A lambda_A + mu_B lambda_B = 0 with mu_A = -mu_B.
            let w = collapse(rows.row(0), &ends, system).ok_or_else(|| {
                unsupported(c, "a row term has a frequency-dependent coefficient")
            })?;
            let mu_a = w[0].1 / -stiffness(a);
            let mu_b = w[1].1 / -stiffness(b);
            if w[0].0 != 0.0 || w[1].0 != 0.0 || mu_a == 0.0 || !close(mu_a, -mu_b) {
                return Err(unsupported(
                    c,
                    "its row is not the force balance lambda_A = lambda_B",
                ));
            }
            Ok(Condition::Contact {
                first: a,
                second: b,
                gap: g0 / ka,
            })
        }
        _ => Err(unsupported(
            c,
            "only one-end rows, one-end laws and two-end contacts are supported",
        )),
    }
}

/// The gap as `g0 + sum_i s_i u_i` (no strain terms): returns `(s, g0)`.
fn gap_form(
    c: &dyn BoundaryCondition,
    gap: &Observable,
    ends: &[EndRef],
    system: &BarSystem,
) -> Result<(Vec<f64>, f64), VerifyError> {
    let w = collapse(&gap.terms, ends, system).ok_or_else(|| {
        unsupported(
            c,
            "the gap involves another end or a frequency-dependent term",
        )
    })?;
    if w.iter().any(|(_, x)| *x != 0.0) {
        return Err(unsupported(c, "the gap depends on a strain"));
    }
    if !gap.offset.is_finite() {
        return Err(unsupported(c, "the gap at rest is not finite"));
    }
    Ok((w.iter().map(|(u, _)| *u).collect(), gap.offset))
}

/// Checks that the force is a positive multiple of the compressive force `-EA u_x`.
fn force_form(
    c: &dyn BoundaryCondition,
    force: &Observable,
    ends: &[EndRef],
    system: &BarSystem,
) -> Result<(), VerifyError> {
    let w = collapse(&force.terms, ends, system).ok_or_else(|| {
        unsupported(
            c,
            "the force involves another end or a frequency-dependent term",
        )
    })?;
    let total: f64 = w
        .iter()
        .zip(ends)
        .map(|((_, x), e)| x / -system.stiffness_at(*e))
        .sum();
    if force.offset != 0.0
        || w.iter().any(|(u, _)| *u != 0.0)
        || !(total.is_finite() && total > 0.0)
    {
        return Err(unsupported(
            c,
            "the force is not a positive multiple of -EA u_x",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bc::Quantity;
    use crate::reference::{
        clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact,
    };
    use crate::system::AssemblyBuilder;

    #[test]
    fn reads_the_built_in_conditions() {
        let m = Model::from_system(&clamped_bar_with_obstacle(0.1).unwrap()).unwrap();
        let bar = BarId(0);
        assert_eq!(
            m.conditions(),
            &[
                Condition::Clamped { end: bar.left() },
                Condition::Obstacle {
                    end: bar.right(),
                    gap: 0.1
                }
            ]
        );
        let m = Model::from_system(&robin_bar_with_obstacle(0.5, 0.2).unwrap()).unwrap();
        assert_eq!(
            m.conditions()[0],
            Condition::Spring {
                end: bar.left(),
                stiffness: 0.5
            }
        );
        let second = Bar::new(0.95, 2.0, 3.0).unwrap();
        let m = Model::from_system(&two_bars_in_contact(second, 0.3).unwrap()).unwrap();
        assert!(matches!(m.conditions()[2], Condition::Contact { gap, .. } if gap == 0.3));
        // Robin at a right end on a stiff bar, Neumann at the left.
        let mut b = AssemblyBuilder::new();
        let id = b.add_bar(Bar::new(1.0, 1.0, 4.0).unwrap());
        b.neumann(id.left())
            .unwrap()
            .robin(id.right(), 2.0)
            .unwrap();
        let m = Model::from_system(&b.build().unwrap()).unwrap();
        assert_eq!(m.conditions()[0], Condition::Free { end: id.left() });
        assert_eq!(
            m.conditions()[1],
            Condition::Spring {
                end: id.right(),
                stiffness: 2.0
            }
        );
    }

    #[derive(Debug)]
    struct EndMass(EndRef);
    impl BoundaryCondition for EndMass {
        fn name(&self) -> String {
            "end mass".into()
        }
        fn ends(&self) -> Vec<EndRef> {
            vec![self.0]
        }
        fn linear_rows(&self, omega: f64, _: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
            rows.push(&[
                Term::new(self.0, Quantity::OutwardStrain, 1.0),
                Term::new(self.0, Quantity::Displacement, -omega * omega),
            ]);
        }
    }

    #[test]
    fn rejects_what_it_cannot_advance() {
        let mut b = AssemblyBuilder::new();
        let id = b.add_bar(Bar::unit());
        b.dirichlet(id.left())
            .unwrap()
            .add_condition(EndMass(id.right()))
            .unwrap();
        let err = Model::from_system(&b.build().unwrap()).unwrap_err();
        assert!(
            matches!(err, VerifyError::Unsupported { ref condition, .. } if condition == "end mass")
        );
        let bar = BarId(0);
        assert!(matches!(
            Model::new(
                vec![Bar::unit()],
                vec![Condition::Clamped { end: bar.left() }]
            ),
            Err(VerifyError::Model(ModelError::UnconstrainedEnd { .. }))
        ));
        assert!(matches!(
            Model::clamped_bar_with_obstacle(f64::NAN),
            Err(VerifyError::InvalidParameter { .. })
        ));
        assert!(Model::clamped_bar_with_obstacle(-0.5).is_ok());
    }
}
