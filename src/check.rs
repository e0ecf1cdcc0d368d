//! Validation of model parameters, shared by bars, boundary conditions and the assembly
//! builder.

use crate::error::ModelError;

/// Checks that `value` is strictly positive and finite; the error names the parameter `what`
/// and carries the rejected value.
pub(crate) fn positive(what: &'static str, value: f64) -> Result<f64, ModelError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ModelError::NotPositive { what, value })
    }
}
