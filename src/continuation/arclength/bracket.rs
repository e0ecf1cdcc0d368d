//! The step of the pseudo-arclength driver that crossed a branch point: what the driver
//! keeps of it ([`super::Arclength`]) and what the switch onto the crossing branch starts
//! from (`branching`).

/// The two accepted points between which the sign of the determinant changed, and the
/// tangent at the second.
#[derive(Debug, Clone)]
pub(super) struct Bracket {
    pub(super) before: Vec<f64>,
    pub(super) after: Vec<f64>,
    pub(super) tangent: Vec<f64>,
}

impl Bracket {
    pub(super) fn new(before: &[f64], after: &[f64], tangent: &[f64]) -> Self {
        Self {
            before: before.to_vec(),
            after: after.to_vec(),
            tangent: tangent.to_vec(),
        }
    }
}
