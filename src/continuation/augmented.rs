//! The layout of an augmented vector `y = (x, parameter)`: a problem's unknowns `x`, then one
//! scalar, last.
//!
//! Every bordered system of the crate stores its unknowns this way: the pseudo-arclength
//! corrector works on `y = (x, lambda)` (the state and the continuation parameter), and an
//! [`EnergyLevel`](crate::branches::EnergyLevel) on `y = (x, Omega)` (the state and the
//! frequency, its parameter being the energy). One layout, written in one place, keeps the
//! bordered row and column at index `n` in all of them and lets a vector of one be read with
//! the functions of the other.
//!
//! ```
//! use nonsmooth_modes::continuation::augmented;
//!
//! let y = augmented::join(vec![1.0, 2.0], 3.0);
//! assert_eq!(y, [1.0, 2.0, 3.0]);
//! assert_eq!(augmented::split(&y), Some((&[1.0, 2.0][..], 3.0)));
//! assert_eq!(augmented::split(&[]), None);
//! ```

/// The unknowns `x` and the parameter of `y = (x, parameter)`; `None` for an empty `y`, which
/// holds no parameter.
pub fn split(y: &[f64]) -> Option<(&[f64], f64)> {
    let (parameter, x) = y.split_last()?;
    Some((x, *parameter))
}

/// `y = (x, parameter)`: `x` with `parameter` appended.
pub fn join(mut x: Vec<f64>, parameter: f64) -> Vec<f64> {
    x.push(parameter);
    x
}

/// [`split`] for the problems built on the layout, whose methods take `y` from a solver: an
/// empty `y` reads as no unknowns at a NaN parameter, which makes the residual non-finite (as
/// [`ContinuationProblem::set_parameter`](super::ContinuationProblem::set_parameter) says of a
/// value the problem cannot take) instead of panicking here.
pub(crate) fn split_or_nan(y: &[f64]) -> (&[f64], f64) {
    split(y).unwrap_or((y, f64::NAN))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn join_then_split_gives_back_the_parts() {
        let y = join(vec![0.5, -1.0], 2.0);
        assert_eq!(split(&y), Some((&[0.5, -1.0][..], 2.0)));
        assert_eq!(split(&[4.0]), Some((&[][..], 4.0)));
        assert_eq!(split(&[]), None);
        let (x, parameter) = split_or_nan(&[]);
        assert!(x.is_empty() && parameter.is_nan());
    }
}
