//! Bars and their ends.

use crate::check::positive;
use crate::error::ModelError;

pub use crate::end::{BarId, End, EndRef};

/// A homogeneous elastic bar: `u_tt = c^2 u_xx` on `x in [0, length]`.
///
/// All quantities are non-dimensional (formulation §1): the paper scales by bar 1, so bar 1 is
/// usually `Bar::unit()`. The mass per unit length is `stiffness / wave_speed^2`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bar {
    length: f64,
    wave_speed: f64,
    stiffness: f64,
}

impl Bar {
    /// A bar of the given length `l`, wave speed `c` and axial stiffness `EA`.
    ///
    /// # Errors
    /// [`ModelError::NotPositive`] if any value is not strictly positive and finite.
    pub fn new(length: f64, wave_speed: f64, stiffness: f64) -> Result<Self, ModelError> {
        Ok(Self {
            length: positive("bar length", length)?,
            wave_speed: positive("bar wave speed", wave_speed)?,
            stiffness: positive("bar axial stiffness", stiffness)?,
        })
    }

    /// The reference bar: length 1, wave speed 1, stiffness 1.
    pub fn unit() -> Self {
        Self {
            length: 1.0,
            wave_speed: 1.0,
            stiffness: 1.0,
        }
    }

    /// Length `l`.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// Wave speed `c`.
    pub fn wave_speed(&self) -> f64 {
        self.wave_speed
    }

    /// Travel time `l / c` of a wave across the bar.
    pub fn travel_time(&self) -> f64 {
        self.length / self.wave_speed
    }

    /// Axial stiffness `EA`.
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// Mass per unit length `EA / c^2`.
    pub fn mass_per_length(&self) -> f64 {
        self.stiffness / (self.wave_speed * self.wave_speed)
    }

    /// Wave number `k = omega / c` of a harmonic of angular frequency `omega`.
    pub fn wavenumber(&self, omega: f64) -> f64 {
        omega / self.wave_speed
    }
}

/// The shortest travel time `l / c` of `bars` (`+inf` for none): the time scale of grids that
/// must resolve every bar.
pub fn shortest_travel_time(bars: &[Bar]) -> f64 {
    bars.iter()
        .map(Bar::travel_time)
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_bars() {
        assert!(matches!(
            Bar::new(0.0, 1.0, 1.0),
            Err(ModelError::NotPositive {
                what: "bar length",
                ..
            })
        ));
        assert!(Bar::new(1.0, f64::NAN, 1.0).is_err());
        assert!(Bar::new(1.0, 1.0, f64::INFINITY).is_err());
        assert!(Bar::new(1.0, 1.0, -2.0).is_err());
        let b = Bar::new(2.0, 2.0, 8.0).unwrap();
        assert_eq!(b.mass_per_length(), 2.0);
    }
}
