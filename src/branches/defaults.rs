//! Defaults derived from the system: the period grid and the arclength range of a backbone
//! from the system's own linear mode, rather than the clamped bar's numbers, and the depth of
//! a period backbone's retries from whether a bar is held only by contacts.
//!
//! A nonsmooth mode leaves its linear mode at the grazing point, at the linear period
//! `K T_i` (`T_i = 2 pi / omega_i` of the open-contact mode `i`, `K` the subharmonic order)
//! and, for a stiffening contact, moves to shorter periods as its energy grows. The paper's
//! grid for the clamped bar (`T_1 = 4`) runs from 3.95 to 3.05: from `79/80` to `61/80` of the
//! linear period. The defaults here apply these ratios to any system, with `T_i` rounded to
//! 6 significant digits so that a linear period computed to `1e-13` lands on its decimal value
//! (`4.000000000000001 -> 4`) and the clamped bar gets the paper's grid exactly.

use crate::branches::backbone::{ArclengthBackboneOptions, BackboneOptions, PeriodGrid};
use crate::branches::start::StartGuesses;
use crate::error::SettingsError;
use crate::fourier::{frequency_of_period, period_of_frequency};
use crate::modal::linear::open_mode;
use crate::system::BarSystem;

/// Start of the default grid, as a fraction `(numerator, denominator)` of the linear period.
const START: (f64, f64) = (79.0, 80.0);
/// End of the default grid (and the short-period end of the arclength range).
const END: (f64, f64) = (61.0, 80.0);
/// Long-period end of the default arclength range (just beyond the grid's start).
const ARCLENGTH_START: (f64, f64) = (99.0, 100.0);
/// Points of the default grid.
const STEPS: usize = 181;

/// The linear period `K T_i` of mode `mode` of `system` (open contacts) with `T_i` rounded to
/// 6 significant digits.
///
/// # Errors
/// [`SettingsError::ZeroIndex`] for `mode = 0` or `subharmonic = 0`, and the errors of
/// [`open_mode`].
pub fn linear_period(
    system: &BarSystem,
    mode: usize,
    subharmonic: usize,
) -> Result<f64, SettingsError> {
    if subharmonic == 0 {
        return Err(SettingsError::ZeroIndex {
            what: "subharmonic order",
            value: 0,
        });
    }
    let omega = open_mode(system, mode)?.omega;
    Ok(subharmonic as f64 * round_significant(period_of_frequency(omega), 6))
}

impl PeriodGrid {
    /// The default grid of NSM `mode` sub `subharmonic` of `system`: 181 periods from
    /// `79/80` to `61/80` of its linear period ([`linear_period`]). For the clamped bar this
    /// is the paper's grid 3.95 -> 3.05.
    ///
    /// # Errors
    /// See [`linear_period`].
    pub fn for_mode(
        system: &BarSystem,
        mode: usize,
        subharmonic: usize,
    ) -> Result<Self, SettingsError> {
        let period = linear_period(system, mode, subharmonic)?;
        Ok(Self {
            start: fraction(period, START),
            end: fraction(period, END),
            steps: STEPS,
        })
    }
}

/// Retry depth of a period backbone on a system with a bar held only by contacts (a
/// rigid-body mode of the open-contact system): [`BackboneOptions::for_mode`].
pub const FLOATING_RETRY_DEPTH: usize = 2;

impl BackboneOptions {
    /// The default options for NSM `mode` sub `subharmonic` of `system`: the grid
    /// [`PeriodGrid::for_mode`], and failed steps retried from up to
    /// [`FLOATING_RETRY_DEPTH`] earlier converged points on a system with a bar held only by
    /// contacts (1, the default, otherwise). Such a bar's flights between impacts make the
    /// truncated branch's internal resonances frequent: on the free-free bar between two
    /// walls the second retry converges 173 of 181 steps at `m = 40` instead of 162, and 125
    /// at `m = 80` instead of 92. On the paper's systems it gains 3 to 4 steps at `m = 40`
    /// and 80 for 12 to 20 % more time, and their backbones keep one retry
    /// (`docs/performance.md`, "Retry depth"). For the clamped bar these are the defaults.
    ///
    /// # Errors
    /// See [`linear_period`].
    pub fn for_mode(
        system: &BarSystem,
        mode: usize,
        subharmonic: usize,
    ) -> Result<Self, SettingsError> {
        let floating = StartGuesses::new(system).floating();
        let grid = PeriodGrid::for_mode(system, mode, subharmonic)?;
        let options = Self::on_grid(grid, mode, subharmonic);
        Ok(Self {
            retry_depth: if floating {
                FLOATING_RETRY_DEPTH
            } else {
                options.retry_depth
            },
            ..options
        })
    }
}

impl ArclengthBackboneOptions {
    /// The default options for NSM `mode` sub `subharmonic` of `system`: seeded at `79/80` of
    /// its linear period ([`linear_period`]), inside the frequencies of the periods from
    /// `99/100` to `61/80` of it: for the clamped bar, seeded at 3.95 inside
    /// `[2 pi / 3.96, 2 pi / 3.05]`.
    ///
    /// # Errors
    /// See [`linear_period`].
    pub fn for_mode(
        system: &BarSystem,
        mode: usize,
        subharmonic: usize,
    ) -> Result<Self, SettingsError> {
        let period = linear_period(system, mode, subharmonic)?;
        let range = (
            frequency_of_period(fraction(period, ARCLENGTH_START)),
            frequency_of_period(fraction(period, END)),
        );
        let start = fraction(period, START);
        Ok(Self::seeded_at(start, range, (mode, subharmonic)))
    }
}

/// `period * numerator / denominator`, in that order: `4 * 79 / 80` is the double of 3.95.
fn fraction(period: f64, (numerator, denominator): (f64, f64)) -> f64 {
    period * numerator / denominator
}

/// `x` rounded to `digits` significant decimal digits, as the nearest `f64` to that decimal:
/// the rounded mantissa is an integer and is divided (or multiplied) by an exact power of
/// ten, one correctly rounded operation.
fn round_significant(x: f64, digits: i32) -> f64 {
    if !(x.is_finite() && x != 0.0) {
        return x;
    }
    let shift = digits - 1 - x.abs().log10().floor() as i32;
    if (0..=22).contains(&shift) {
        let scale = 10f64.powi(shift);
        (x * scale).round() / scale
    } else if (-22..0).contains(&shift) {
        let scale = 10f64.powi(-shift);
        (x / scale).round() * scale
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::{clamped_bar_with_obstacle, robin_bar_with_obstacle};
    use std::f64::consts::PI;

    /// The clamped bar's derived defaults are the paper's grid and the arclength defaults,
    /// bit for bit.
    #[test]
    fn clamped_bar_gets_the_paper_grid() {
        let system = clamped_bar_with_obstacle(1e-3).unwrap();
        assert_eq!(linear_period(&system, 1, 1).unwrap(), 4.0);
        let paper = PeriodGrid {
            start: 3.95,
            end: 3.05,
            steps: 181,
        };
        assert_eq!(PeriodGrid::for_mode(&system, 1, 1).unwrap(), paper);
        let arclength = ArclengthBackboneOptions::for_mode(&system, 1, 1).unwrap();
        assert_eq!(arclength.start_period, 3.95);
        assert_eq!(arclength.omega_range, (2.0 * PI / 3.96, 2.0 * PI / 3.05));
    }

    /// Another system gets its own period: the Robin bar's first open mode,
    /// `omega_1 = 0.653271` (`T_1 = 9.61810`), and three times it for sub 3.
    #[test]
    fn other_systems_get_their_own_linear_period() {
        let system = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
        let t1 = linear_period(&system, 1, 1).unwrap();
        assert!((t1 - 2.0 * PI / 0.653271).abs() < 1e-4, "{t1}");
        assert_eq!(linear_period(&system, 1, 3).unwrap(), 3.0 * t1);
        let grid = PeriodGrid::for_mode(&system, 1, 1).unwrap();
        assert_eq!(
            (grid.start, grid.end),
            (fraction(t1, START), fraction(t1, END))
        );
        assert!(matches!(
            linear_period(&system, 1, 0),
            Err(SettingsError::ZeroIndex { .. })
        ));
        assert!(matches!(
            linear_period(&system, 0, 1),
            Err(SettingsError::ZeroIndex { .. })
        ));
    }

    #[test]
    fn rounding_to_significant_digits_gives_the_decimal() {
        assert_eq!(round_significant(4.000000000000001, 6), 4.0);
        assert_eq!(round_significant(9.618096, 6), 9.6181);
        assert_eq!(round_significant(1234567.0, 6), 1234570.0);
        assert_eq!(round_significant(0.0012345678, 6), 0.00123457);
        assert_eq!(round_significant(-2.5e-7, 6), -2.5e-7);
    }
}
