//! The paper's three systems and the exact results to test against (formulation §8–§9).

use crate::bar::Bar;
use crate::error::{ModelError, SettingsError};
use crate::fourier::frequency_of_period;
use crate::system::{AssemblyBuilder, BarSystem};
use std::f64::consts::PI;

/// Unit bar clamped at `x = 0` facing a rigid obstacle at gap `g0` at `x = 1` (the paper's
/// Dirichlet–Signorini system, its Fig. 1a).
///
/// # Errors
/// If `gap` is not positive and finite.
pub fn clamped_bar_with_obstacle(gap: f64) -> Result<BarSystem, ModelError> {
    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::unit());
    b.dirichlet(bar.left())?.signorini(bar.right(), gap)?;
    b.build()
}

/// Unit bar on a ground spring `k_s` at `x = 0` facing a rigid obstacle at gap `g0` at
/// `x = 1` (the paper's Robin–Signorini system, its Fig. 1b; the paper uses `k_s = 0.5`).
///
/// # Errors
/// If `spring_stiffness` or `gap` is not positive and finite.
pub fn robin_bar_with_obstacle(spring_stiffness: f64, gap: f64) -> Result<BarSystem, ModelError> {
    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::unit());
    b.robin(bar.left(), spring_stiffness)?
        .signorini(bar.right(), gap)?;
    b.build()
}

/// Bar 2 of the paper's two-bar configuration `(l, c, alpha)`, read with the paper's own
/// definition (§2.1) `alpha = E1 A1 / (E2 A2)`: length `l`, wave speed `c`, axial stiffness
/// `EA_2 = 1 / alpha` (bar 1 is the unit bar).
///
/// The paper's balance `u_x(1) = alpha w_y(l)` (eq. 30) is the force balance only for the
/// inverse ratio; that equation is the slip, not the definition. Read as `EA_2/EA_1 = alpha`,
/// configuration 2 `(3.8, 4, 4)` gives bar 2 the impedance `EA/c = 1` and travel time
/// `l/c = 0.95` of configuration 1 `(0.95, 1, 1)`: the contact sees the same bar, every
/// backbone coincides, and the configuration could not show what the paper chose it for
/// (a different design at equal natural frequencies). `docs/theory.md` §3 says more;
/// `tests/two_bars.rs` checks that the other reading reproduces configuration 1.
///
/// # Errors
/// [`ModelError::NotPositive`] naming `alpha` for a non-positive or non-finite ratio, and
/// the errors of [`Bar::new`].
pub fn paper_second_bar(length: f64, wave_speed: f64, alpha: f64) -> Result<Bar, ModelError> {
    let alpha = crate::check::positive("paper stiffness ratio alpha = E1A1/(E2A2)", alpha)?;
    Bar::new(length, wave_speed, 1.0 / alpha)
}

/// Two bars clamped at their left ends whose right ends face each other across a gap `g0`
/// (the paper's two-bar system, its Fig. 1c): bar 1 is the unit bar, bar 2 is `second`.
///
/// The paper's triplets `(l, c, alpha)` give `second` through [`paper_second_bar`].
///
/// # Errors
/// If `gap` is not positive and finite.
pub fn two_bars_in_contact(second: Bar, gap: f64) -> Result<BarSystem, ModelError> {
    let mut b = AssemblyBuilder::new();
    let one = b.add_bar(Bar::unit());
    let two = b.add_bar(second);
    b.dirichlet(one.left())?
        .dirichlet(two.left())?
        .contact(one.right(), two.right(), gap)?;
    b.build()
}

/// A chain of `bars` unit bars: the first clamped at its left end, each right end facing the
/// next bar's left end across `gap`, the last held by a ground spring of stiffness
/// `robin_stiffness` at its right end. The inner bars are held only by their contacts (they
/// have a rigid-body mode while the contacts are open). `bars = 3` is the three-bar chain of
/// `examples/assemblies/three_bar_chain.toml` with `robin_stiffness = 0.5`.
///
/// # Errors
/// [`ModelError::NoBars`] for `bars = 0`; a gap or stiffness that is not positive and finite.
pub fn contact_chain(bars: usize, gap: f64, robin_stiffness: f64) -> Result<BarSystem, ModelError> {
    let mut b = AssemblyBuilder::new();
    let ids: Vec<_> = (0..bars).map(|_| b.add_bar(Bar::unit())).collect();
    let (Some(first), Some(last)) = (ids.first(), ids.last()) else {
        return Err(ModelError::NoBars);
    };
    b.dirichlet(first.left())?;
    for pair in ids.windows(2) {
        b.contact(pair[0].right(), pair[1].left(), gap)?;
    }
    b.robin(last.right(), robin_stiffness)?;
    b.build()
}

/// Natural frequency `i >= 1` of a clamped-free bar: `(2i - 1) pi c / (2 l)`.
pub fn clamped_free_frequency(i: usize, length: f64, wave_speed: f64) -> f64 {
    (2.0 * i as f64 - 1.0) * PI * wave_speed / (2.0 * length)
}

/// Natural frequency `i >= 1` of a clamped-clamped bar: `i pi c / l`.
pub fn clamped_clamped_frequency(i: usize, length: f64, wave_speed: f64) -> f64 {
    i as f64 * PI * wave_speed / length
}

/// First four roots of `omega tan(omega) = 0.5` (Robin–free unit bar, `k_s = 0.5`).
pub const ROBIN_FREE_FREQUENCIES: [f64; 4] = [0.653271, 3.292310, 6.361620, 9.477486];

/// First four roots of `omega cos(omega) + 0.5 sin(omega) = 0` (Robin–clamped unit bar).
pub const ROBIN_CLAMPED_FREQUENCIES: [f64; 4] = [1.836597, 4.815842, 7.917053, 11.040830];

/// First grazing energy of the clamped bar: `pi^2 g0^2 / 16`.
pub fn clamped_grazing_energy(gap: f64) -> f64 {
    PI * PI * gap * gap / 16.0
}

/// First grazing energy of the Robin bar with `k_s = 0.5`, per unit `g0^2`
/// (spring energy included).
pub const ROBIN_GRAZING_ENERGY_PER_GAP2: f64 = 0.185515;

/// The exact first nonsmooth mode of the clamped bar against an obstacle at gap `g0 > 0`,
/// for a period `T in (3, 4)` (formulation §9). Time is measured from the middle of the
/// contact phase, so the motion is even in time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClampedFirstMode {
    /// Gap at rest `g0`.
    pub gap: f64,
    /// Period `T`.
    pub period: f64,
}

impl ClampedFirstMode {
    /// The mode at period `T` (meaningful for `3 < T < 4`).
    pub fn new(gap: f64, period: f64) -> Self {
        Self { gap, period }
    }

    fn slope(&self) -> f64 {
        self.gap / (2.0 * (self.period - 3.0))
    }

    /// Contact duration per period `t_c = 4 - T`.
    pub fn contact_duration(&self) -> f64 {
        4.0 - self.period
    }

    /// Energy `g0^2 / (2 (T - 3)^2)`.
    pub fn energy(&self) -> f64 {
        self.gap * self.gap / (2.0 * (self.period - 3.0).powi(2))
    }

    /// `E / E_g = 8 / (pi^2 (T - 3)^2)`.
    pub fn energy_normalized(&self) -> f64 {
        8.0 / (PI * PI * (self.period - 3.0).powi(2))
    }

    /// Contact-end displacement `u(1, t)`.
    pub fn end_displacement(&self, t: f64) -> f64 {
        let tau = wrap(t, self.period).abs();
        self.gap - 2.0 * self.slope() * (tau - 0.5 * self.contact_duration()).max(0.0)
    }

    /// Contact force `lambda(t) = -u_x(1, t)`: `g0 / (T - 3)` in contact, 0 in flight.
    pub fn contact_force(&self, t: f64) -> f64 {
        if wrap(t, self.period).abs() < 0.5 * self.contact_duration() {
            self.gap / (self.period - 3.0)
        } else {
            0.0
        }
    }

    /// Mean of `u(1, t)`: `g0 - a (2T - 4)^2 / (2T)`.
    pub fn displacement_mean(&self) -> f64 {
        let t = self.period;
        self.gap - self.slope() * (2.0 * t - 4.0).powi(2) / (2.0 * t)
    }

    /// Cosine coefficient `j >= 1` of `u(1, t)`:
    /// `(2 a T / (pi^2 j^2)) (cos(pi j t_c / T) - (-1)^j)`.
    pub fn displacement_harmonic(&self, j: usize) -> f64 {
        let (t, jf) = (self.period, j as f64);
        let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
        2.0 * self.slope() * t / (PI * PI * jf * jf)
            * ((PI * jf * self.contact_duration() / t).cos() - sign)
    }

    /// Cosine coefficient `j >= 1` of the outward strain `p(1, t) = u_x(1, t)` (a rectangular
    /// pulse of height `-g0/(T - 3)`): `-(g0/(T-3)) (2/(pi j)) sin(pi j t_c / T)`.
    pub fn strain_harmonic(&self, j: usize) -> f64 {
        let jf = j as f64;
        -self.gap / (self.period - 3.0) * 2.0 / (PI * jf)
            * (PI * jf * self.contact_duration() / self.period).sin()
    }

    /// The first `harmonics` harmonics of the exact mode as the unknown vector of
    /// [`NonsmoothSystem`](crate::system::NonsmoothSystem) for
    /// [`clamped_bar_with_obstacle`] with the cosine basis: `A_j = 0` (the clamp) and `B_j`
    /// from `u_j(1) = B_j sin(k_j)/k_j` or `u_x,j(1) = B_j cos(k_j)`, whichever is better
    /// conditioned (`k_j = 2 pi j / T`). The constant basis function is `1/2`, so harmonic 0
    /// carries twice the mean. A starting point for Newton and an oracle for tests.
    ///
    /// # Panics
    /// If `2 (harmonics + 1)` values overflow `usize` (or do not fit in memory).
    pub fn unknowns(&self, harmonics: usize) -> Vec<f64> {
        let omega = frequency_of_period(self.period);
        let len = (harmonics.checked_add(1))
            .and_then(|n| n.checked_mul(2))
            .expect("ClampedFirstMode::unknowns: 2 (harmonics + 1) overflows usize");
        let mut x = vec![0.0; len];
        x[1] = 2.0 * self.displacement_mean();
        for j in 1..=harmonics {
            let k = j as f64 * omega;
            let (s, c) = (k.sin() / k, k.cos());
            x[2 * j + 1] = if s.abs() > c.abs() {
                self.displacement_harmonic(j) / s
            } else {
                self.strain_harmonic(j) / c
            };
        }
        x
    }

    /// Mean of `p(1, t)`: `-(g0/(T-3)) t_c / T`.
    pub fn strain_mean(&self) -> f64 {
        -self.gap / (self.period - 3.0) * self.contact_duration() / self.period
    }
}

/// The `i`-th exact family of nonsmooth modes of the clamped bar against an obstacle at gap
/// `g0 > 0` (the paper's exact solutions; family 1 is [`ClampedFirstMode`]): it exists for
/// periods `T in ((2i + 1)/i^2, 4/(2i - 1))`, where its energy is
/// `E = g0^2 / (2 (i^2 T - 2i - 1)^2)` and, with the grazing energy
/// `E_g = pi^2 g0^2 / 16` ([`clamped_grazing_energy`]),
/// `E / E_g = 8 / (pi^2 (i^2 T - 2i - 1)^2)`.
///
/// Its `k`-th subharmonic branch (period `k T`, frequency `Omega / k`) has the same energy at
/// the same motion: evaluate the family at `T / k`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClampedFamily {
    gap: f64,
    index: usize,
}

impl ClampedFamily {
    /// Family `index` for the gap `gap`.
    ///
    /// # Errors
    /// [`SettingsError::ZeroIndex`] for `index = 0` (families are numbered from 1) and
    /// [`SettingsError::NotPositive`] for a gap that is not positive and finite.
    pub fn new(gap: f64, index: usize) -> Result<Self, SettingsError> {
        if index == 0 {
            return Err(SettingsError::ZeroIndex {
                what: "exact family index",
                value: 0,
            });
        }
        if !(gap.is_finite() && gap > 0.0) {
            return Err(SettingsError::NotPositive {
                what: "gap",
                value: gap,
            });
        }
        Ok(Self { gap, index })
    }

    /// Gap at rest `g0`.
    pub fn gap(&self) -> f64 {
        self.gap
    }

    /// Family index `i >= 1`.
    pub fn index(&self) -> usize {
        self.index
    }

    /// `i^2 T - 2i - 1`, the factor the energy is built on.
    fn factor(&self, period: f64) -> f64 {
        let i = self.index as f64;
        i * i * period - 2.0 * i - 1.0
    }

    /// Open interval of periods `((2i + 1)/i^2, 4/(2i - 1))` on which the family exists.
    pub fn periods(&self) -> (f64, f64) {
        let i = self.index as f64;
        ((2.0 * i + 1.0) / (i * i), 4.0 / (2.0 * i - 1.0))
    }

    /// Energy `g0^2 / (2 (i^2 T - 2i - 1)^2)` at period `T`.
    pub fn energy(&self, period: f64) -> f64 {
        self.gap * self.gap / (2.0 * self.factor(period).powi(2))
    }

    /// `E / E_g = 8 / (pi^2 (i^2 T - 2i - 1)^2)` at period `T` (independent of `g0`).
    pub fn energy_normalized(&self, period: f64) -> f64 {
        8.0 / (PI * PI * self.factor(period).powi(2))
    }

    /// The exact backbone `(Omega / omega_1, E / E_g)` on `points` periods spaced evenly from
    /// `from` to `to` (both included, in that order; one point at `from` if `points` is 1),
    /// with `omega_1 = pi / 2` the first natural frequency of the clamped-free unit bar, so
    /// that `Omega / omega_1 = 4 / T`.
    pub fn backbone(&self, from: f64, to: f64, points: usize) -> Vec<(f64, f64)> {
        let last = points.saturating_sub(1).max(1) as f64;
        (0..points)
            .map(|k| {
                let t = from + (to - from) * k as f64 / last;
                (4.0 / t, self.energy_normalized(t))
            })
            .collect()
    }
}

/// `t` brought into `[-T/2, T/2)`.
fn wrap(t: f64, period: f64) -> f64 {
    (t + 0.5 * period).rem_euclid(period) - 0.5 * period
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn family_one_is_the_first_mode() {
        let (gap, family) = (1e-3, ClampedFamily::new(1e-3, 1).unwrap());
        assert_eq!(family.periods(), (3.0, 4.0));
        for period in [3.04, 3.2, 3.5, 3.55, 3.9, 3.99] {
            let first = ClampedFirstMode::new(gap, period);
            assert_eq!(family.energy_normalized(period), first.energy_normalized());
            assert!((family.energy(period) / first.energy() - 1.0).abs() < 1e-14);
            let ratio = family.energy(period) / clamped_grazing_energy(gap);
            assert!((ratio / family.energy_normalized(period) - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn higher_families_and_their_backbones() {
        let family = ClampedFamily::new(1e-3, 2).unwrap();
        let (lo, hi) = family.periods();
        assert!((lo - 1.25).abs() < 1e-15 && (hi - 4.0 / 3.0).abs() < 1e-15);
        // At the upper end i^2 T - 2i - 1 = 1/(2i - 1): E/E_g = 8 (2i - 1)^2 / pi^2.
        let at_hi = 8.0 * 9.0 / (PI * PI);
        assert!((family.energy_normalized(hi) / at_hi - 1.0).abs() < 1e-12);
        assert!((family.energy(hi) / (9.0 * 1e-6 / 2.0) - 1.0).abs() < 1e-12);
        let curve = family.backbone(1.26, 1.33, 8);
        assert_eq!(curve.len(), 8);
        assert_eq!(curve[0], (4.0 / 1.26, family.energy_normalized(1.26)));
        assert!((curve[7].0 - 4.0 / 1.33).abs() < 1e-12);
        // The energy grows as the period shrinks towards (2i + 1)/i^2.
        assert!(curve.windows(2).all(|w| w[1].1 < w[0].1));
        assert_eq!(
            family.backbone(1.3, 1.2, 1),
            vec![(4.0 / 1.3, family.energy_normalized(1.3))]
        );
    }

    #[test]
    fn family_zero_and_bad_gaps_are_typed_errors() {
        assert!(matches!(
            ClampedFamily::new(1e-3, 0),
            Err(SettingsError::ZeroIndex { .. })
        ));
        for gap in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                ClampedFamily::new(gap, 1),
                Err(SettingsError::NotPositive { .. })
            ));
        }
        let family = ClampedFamily::new(2e-3, 3).unwrap();
        assert_eq!((family.gap(), family.index()), (2e-3, 3));
    }
}
