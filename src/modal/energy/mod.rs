//! Mechanical energy of a harmonic-balance solution (formulation §7), in closed form from
//! boundary values.
//!
//! Each harmonic of a bar is a Helmholtz solution `u_i = A_i cos(k_i x) + B_i sin(k_i x)/k_i`,
//! so `u_i'' = -k_i^2 u_i` and Green's identity turns the integrals of products into boundary
//! terms:
//!
//! ```text
//! (k_i^2 - k_j^2) int u_i u_j dx = [u_i u_j' - u_j u_i']_0^l          (k_i != k_j)
//! int u_i' u_j' dx = [u_i u_j']_0^l + k_j^2 int u_i u_j dx
//! ```
//!
//! and the diagonal terms (`k_i = k_j`) have elementary closed forms. The energy of a motion is
//! then a quadratic form in the harmonics: `O(m^2)` flops per bar, no quadrature.
//!
//! The pair sum is the hot part (it runs once per continuation point), so its data is laid
//! out for SIMD: the harmonics of a bar are stored `LANES` at a time, field by field
//! (`Block`), and each row `sum_{j<i}` runs over whole blocks with one independent
//! accumulator per lane, with no branch and no bounds check. Green's identity does not apply
//! to equal wavenumbers, so the row loop ignores them: the diagonal `j = i` is added from its
//! closed form, and a row that meets a duplicate `k_j = k_i` (`j < i`; never with the cosine
//! basis at `omega != 0`, but e.g. at `omega = 0` or with a basis holding both the cosine and
//! the sine of one harmonic) divides by zero, comes out infinite or NaN, and is redone pair by
//! pair with the diagonal closed form for the duplicates.

use crate::bar::{Bar, End, EndRef};
use crate::bc::Quantity;
use crate::bem::sinc;
use crate::fourier::Basis;
use crate::system::rows::quantity_weights_in_strain;
use crate::system::{BarSystem, Layout};

/// Energy `E = sum_b EA_b/2 int (u_t^2/c_b^2 + u_x^2) dx + energy stored in conditions`,
/// evaluated at `t = 0` (phase `theta = 0`) for the solution `x` of a system with basis
/// `basis` at fundamental frequency `omega`. With the cosine basis velocities vanish at
/// `t = 0` and `E` is the potential energy there.
///
/// A low-level function for hot loops (it runs once per continuation point): it returns the
/// number as computed, which is infinite or NaN when the energy exceeds the range of `f64`
/// (from `Omega ~ 1e150` for unit-sized coefficients) or `omega` is not finite;
/// [`crate::Solution::energy`] checks its inputs and returns a typed error instead.
///
/// # Panics
/// If `x.len()` is not `basis.len()` times the system's unknowns per harmonic (the
/// dimension of its [`crate::system::NonsmoothSystem`]).
pub fn energy<B: Basis>(system: &BarSystem, basis: &B, x: &[f64], omega: f64) -> f64 {
    energy_at(system, basis, x, omega, 0.0)
}

/// The energy of [`energy`] at phase `theta = Omega t` instead of `t = 0`. The exact periodic
/// motion keeps it constant; a truncated one drifts by the work of its complementarity
/// residual, which [`crate::modal::diagnostics`] reports.
///
/// # Panics
/// As [`energy`].
pub fn energy_at<B: Basis>(
    system: &BarSystem,
    basis: &B,
    x: &[f64],
    omega: f64,
    theta: f64,
) -> f64 {
    energy_of(system, basis, x, (omega, theta), Conditions::All)
}

/// Which conditions' stored energies [`energy_of`] adds.
#[derive(Clone, Copy, PartialEq)]
pub(crate) enum Conditions {
    /// Every condition's.
    All,
    /// The linear conditions' only: the energy form of the linear (open-contact) modes.
    Linear,
}

/// The energy of [`energy_at`] at `(omega, theta)`, with the stored energies of `conditions`.
pub(crate) fn energy_of<B: Basis>(
    system: &BarSystem,
    basis: &B,
    x: &[f64],
    (omega, theta): (f64, f64),
    conditions: Conditions,
) -> f64 {
    let len = basis.len();
    let nb = system.bars().len();
    let layout = Layout::of(system);
    assert_eq!(
        x.len(),
        len * system.unknowns_per_harmonic(),
        "modal::energy: the unknowns have the wrong length"
    );
    // Two allocations per call: the time weights `w_i = phi_i(theta)`,
    // `v_i = omega phi_i'(theta)` with the end values `(u, u_x)` at `x = 0` and `x = l_b`
    // that the conditions read, and the harmonics of one bar, refilled bar after bar.
    let mut buffer = vec![0.0; 2 * len + 4 * nb];
    let (weights, ends) = buffer.split_at_mut(2 * len);
    let (w, v) = weights.split_at_mut(len);
    time_weights(basis, (omega, theta), w, v);
    // With the cosine basis at theta = 0 (the common call) every velocity weight vanishes:
    // skip the kinetic sums altogether.
    let moving = v.iter().any(|&v| v != 0.0);
    let mut harmonics = Harmonics::new(len);
    let mut total = 0.0;
    for (b, bar) in system.bars().iter().enumerate() {
        harmonics.fill(bar, basis, x, (b, layout), omega, (w, v));
        let (strain, kinetic) = if moving {
            harmonics.quadratic_forms::<true>()
        } else {
            harmonics.quadratic_forms::<false>()
        };
        let c2 = bar.wave_speed() * bar.wave_speed();
        total += 0.5 * bar.stiffness() * (strain + kinetic / c2);
        ends[4 * b..4 * b + 4].copy_from_slice(&harmonics.end_values());
    }
    total + stored_energy(system, ends, conditions)
}

/// The time weights `w_i = phi_i(theta)` and `v_i = omega phi_i'(theta)` of the basis
/// functions: displacement and velocity of each coefficient at phase `theta`.
fn time_weights<B: Basis>(basis: &B, (omega, theta): (f64, f64), w: &mut [f64], v: &mut [f64]) {
    basis.functions_at(theta, w);
    basis.derivatives_at(theta, v);
    for v in v.iter_mut() {
        *v *= omega;
    }
}

/// The energy stored in the conditions of `system` (those of `conditions`), given the end
/// values `ends[4 b..4 b + 4] = (u(0), u_x(0), u(l_b), u_x(l_b))` of each bar `b`.
pub(crate) fn stored_energy(system: &BarSystem, ends: &[f64], conditions: Conditions) -> f64 {
    let value = |e: EndRef, quantity: Quantity| {
        let at = 4 * e.bar.index()
            + match e.end {
                End::Left => 0,
                End::Right => 2,
            };
        let (u, strain) = (ends[at], ends[at + 1]);
        let (wu, wx) = quantity_weights_in_strain(quantity, e.end, system.stiffness_at(e));
        wu * u + wx * strain
    };
    system
        .conditions()
        .filter(|c| conditions == Conditions::All || c.unilateral().is_none())
        .map(|c| c.stored_energy(&value))
        .sum::<f64>()
}

/// Harmonics per [`Block`]: the SIMD lanes (and independent accumulators, which hide the
/// latency of the divisions and additions) of the pair sums.
const LANES: usize = 4;

/// One harmonic of one bar, `u = a cos(kx) + b sin(kx)/k` on `[0, l]`, with its boundary
/// values `u(0) = a`, `u'(0) = b`, `u(l)`, `u'(l)` and its time weights `w = phi(theta)`,
/// `v = omega phi'(theta)`.
#[derive(Clone, Copy)]
struct Harmonic {
    k: f64,
    k2: f64,
    a: f64,
    b: f64,
    ul: f64,
    dl: f64,
    w: f64,
    v: f64,
    /// `sinc(k l)`, shared by `u(l)` and the diagonal closed form.
    sinc_kl: f64,
}

/// [`LANES`] consecutive harmonics of one bar, field by field (the fields of [`Harmonic`]).
#[derive(Clone, Copy, Default)]
struct Block {
    k: [f64; LANES],
    k2: [f64; LANES],
    a: [f64; LANES],
    b: [f64; LANES],
    ul: [f64; LANES],
    dl: [f64; LANES],
    w: [f64; LANES],
    v: [f64; LANES],
    sinc_kl: [f64; LANES],
}

/// The harmonics of one bar of length `l`, `len` of them in blocks (the last one padded).
struct Harmonics {
    l: f64,
    len: usize,
    blocks: Vec<Block>,
}

impl Harmonics {
    fn new(len: usize) -> Self {
        Self {
            l: 0.0,
            len,
            blocks: vec![Block::default(); len.div_ceil(LANES)],
        }
    }

    /// Fills in bar `b` (laid out by `layout`) of the solution `x` at fundamental frequency
    /// `omega`, with the time weights `(w, v)`.
    fn fill<B: Basis>(
        &mut self,
        bar: &Bar,
        basis: &B,
        x: &[f64],
        (b, layout): (usize, Layout),
        omega: f64,
        (w, v): (&[f64], &[f64]),
    ) {
        let l = bar.length();
        self.l = l;
        for i in 0..self.len {
            let (a, bi) = layout.pair(x, i, b);
            let k = bar.wavenumber(basis.harmonic(i) as f64 * omega);
            let z = k * l;
            let (s, c) = z.sin_cos();
            let sinc_kl = sinc_from_sin(z, s);
            let (block, lane) = (&mut self.blocks[i / LANES], i % LANES);
            block.k[lane] = k;
            block.k2[lane] = k * k;
            block.a[lane] = a;
            block.b[lane] = bi;
            block.ul[lane] = a * c + bi * l * sinc_kl;
            block.dl[lane] = -a * k * s + bi * c;
            block.w[lane] = w[i];
            block.v[lane] = v[i];
            block.sinc_kl[lane] = sinc_kl;
        }
    }

    /// The end values `(u(0), u_x(0), u(l), u_x(l))` of the bar's field at the time weights
    /// `w` it was filled with.
    fn end_values(&self) -> [f64; 4] {
        let each = || (0..self.len).map(|i| self.get(i));
        [
            each().map(|h| h.w * h.a).sum(),
            each().map(|h| h.w * h.b).sum(),
            each().map(|h| h.w * h.ul).sum(),
            each().map(|h| h.w * h.dl).sum(),
        ]
    }

    /// Harmonic `i`.
    fn get(&self, i: usize) -> Harmonic {
        let (block, lane) = (&self.blocks[i / LANES], i % LANES);
        Harmonic {
            k: block.k[lane],
            k2: block.k2[lane],
            a: block.a[lane],
            b: block.b[lane],
            ul: block.ul[lane],
            dl: block.dl[lane],
            w: block.w[lane],
            v: block.v[lane],
            sinc_kl: block.sinc_kl[lane],
        }
    }

    /// `(sum_ij w_i w_j int u_i' u_j' dx, sum_ij v_i v_j int u_i u_j dx)`; the second is 0
    /// unless `KINETIC`. Rows with `w_i = v_i = 0` contribute nothing and are skipped.
    fn quadratic_forms<const KINETIC: bool>(&self) -> (f64, f64) {
        let (mut strain, mut kinetic) = (0.0, 0.0);
        for i in 0..self.len {
            let hi = self.get(i);
            let vi = if KINETIC { hi.v } else { 0.0 };
            if hi.w == 0.0 && vi == 0.0 {
                continue;
            }
            let diagonal = Diagonal::new(hi.k, self.l, hi.sinc_kl);
            let (mut row_strain, mut row_kinetic) = self.row::<KINETIC>(i, &hi);
            if !(row_strain.is_finite() && row_kinetic.is_finite()) {
                (row_strain, row_kinetic) = self.row_pairwise::<KINETIC>(i, &hi, &diagonal);
            }
            let (int_uu, int_dd) = diagonal.integrals((hi.a, hi.b), (hi.a, hi.b));
            strain += hi.w * (hi.w * int_dd + 2.0 * row_strain);
            if KINETIC {
                kinetic += vi * (vi * int_uu + 2.0 * row_kinetic);
            }
        }
        (strain, kinetic)
    }

    /// `(sum_{j<i} w_j int u_i' u_j' dx, sum_{j<i} v_j int u_i u_j dx)` by Green's identity,
    /// block by block: infinite or NaN if some `k_j = k_i`. On baseline x86-64 (SSE2) the
    /// compiler turns the strain-only loop into packed divisions; with the kinetic sum too, its
    /// cost model keeps the `LANES` lanes scalar, which still overlap their divisions.
    fn row<const KINETIC: bool>(&self, i: usize, hi: &Harmonic) -> (f64, f64) {
        let mut strain = [0.0; LANES];
        let mut kinetic = [0.0; LANES];
        let (full, rest) = (i / LANES, i % LANES);
        for block in &self.blocks[..full] {
            for lane in 0..LANES {
                let (int_uu, int_dd) = green(hi, block, lane);
                strain[lane] += block.w[lane] * int_dd;
                if KINETIC {
                    kinetic[lane] += block.v[lane] * int_uu;
                }
            }
        }
        if rest > 0 {
            // The first `rest` lanes of the block of `i` itself.
            let block = &self.blocks[full];
            for lane in 0..rest {
                let (int_uu, int_dd) = green(hi, block, lane);
                strain[lane] += block.w[lane] * int_dd;
                if KINETIC {
                    kinetic[lane] += block.v[lane] * int_uu;
                }
            }
        }
        (strain.iter().sum(), kinetic.iter().sum())
    }

    /// [`Self::row`] pair by pair, with the closed form `diagonal` of `k_i` for the pairs
    /// with `k_j = k_i`.
    #[cold]
    fn row_pairwise<const KINETIC: bool>(
        &self,
        i: usize,
        hi: &Harmonic,
        diagonal: &Diagonal,
    ) -> (f64, f64) {
        let (mut strain, mut kinetic) = (0.0, 0.0);
        for j in 0..i {
            let hj = self.get(j);
            let (int_uu, int_dd) = if hj.k2 == hi.k2 {
                diagonal.integrals((hi.a, hi.b), (hj.a, hj.b))
            } else {
                green(hi, &self.blocks[j / LANES], j % LANES)
            };
            strain += hj.w * int_dd;
            if KINETIC {
                kinetic += hj.v * int_uu;
            }
        }
        (strain, kinetic)
    }
}

/// `(int u_i u_j dx, int u_i' u_j' dx)` over `[0, l]` for `k_i != k_j` by Green's identity,
/// `u_j` being lane `lane` of `block`.
#[inline(always)]
fn green(hi: &Harmonic, block: &Block, lane: usize) -> (f64, f64) {
    let bracket_ij = hi.ul * block.dl[lane] - hi.a * block.b[lane];
    let bracket_ji = block.ul[lane] * hi.dl - block.a[lane] * hi.b;
    let int_uu = (bracket_ij - bracket_ji) / (hi.k2 - block.k2[lane]);
    (int_uu, bracket_ij + block.k2[lane] * int_uu)
}

/// The integrals of `cos^2, sin^2, sin cos` products at one wavenumber `k` over `[0, l]`,
/// for the pairs with `k_i = k_j = k` (here, and for the energy of each harmonic alone in
/// [`crate::modal::signature`]).
pub(crate) struct Diagonal {
    k: f64,
    /// `int sin^2(kx) dx / k^2`.
    sin2_over_k2: f64,
    /// `int cos^2(kx) dx`.
    cos2: f64,
    /// `int sin(kx) cos(kx) dx / k`.
    sc_over_k: f64,
}

impl Diagonal {
    /// The integrals at wavenumber `k` over `[0, l]`.
    pub(crate) fn at(k: f64, l: f64) -> Self {
        Self::new(k, l, sinc(k * l))
    }

    /// [`Diagonal::at`] given `sinc_kl = sinc(k l)`.
    fn new(k: f64, l: f64, sinc_kl: f64) -> Self {
        // int sin^2(kx) = l/2 - sin(2kl)/(4k) = k^2 l^3 g(2kl) * 2, int cos^2 = l - that,
        // int sin cos = sin^2(kl)/(2k), with g(z) = (1 - sinc z)/z^2.
        let sin2_over_k2 = 2.0 * l * l * l * one_minus_sinc_over_z2(2.0 * k * l);
        Self {
            k,
            sin2_over_k2,
            cos2: l - k * k * sin2_over_k2,
            sc_over_k: 0.5 * (l * sinc_kl).powi(2),
        }
    }

    /// `(int u_1 u_2 dx, int u_1' u_2' dx)` of two harmonics at this wavenumber,
    /// `u_j = a_j cos(kx) + b_j sin(kx)/k` given as `(a_j, b_j)`.
    pub(crate) fn integrals(&self, (a1, b1): (f64, f64), (a2, b2): (f64, f64)) -> (f64, f64) {
        let Self {
            k,
            sin2_over_k2,
            cos2,
            sc_over_k,
        } = *self;
        let int_uu = a1 * a2 * cos2 + b1 * b2 * sin2_over_k2 + (a1 * b2 + a2 * b1) * sc_over_k;
        // `k^2 (k^2 sin2_over_k2)`, not `k^4 sin2_over_k2`: finite up to `k ~ 1e154`, not 1e77.
        let int_dd = a1 * a2 * (k * k * (k * k * sin2_over_k2)) + b1 * b2 * cos2
            - (a1 * b2 + a2 * b1) * k * k * sc_over_k;
        (int_uu, int_dd)
    }
}

/// [`sinc`]`(z)` given `s = sin z`, bit for bit: saves a `sin` per harmonic.
fn sinc_from_sin(z: f64, s: f64) -> f64 {
    if z.abs() < 1e-2 {
        sinc(z)
    } else {
        s / z
    }
}

/// `(1 - sinc z) / z^2`, accurate near `z = 0`.
fn one_minus_sinc_over_z2(z: f64) -> f64 {
    if z.abs() < 1e-2 {
        let z2 = z * z;
        1.0 / 6.0 - z2 / 120.0 + z2 * z2 / 5040.0
    } else {
        (1.0 - sinc(z)) / (z * z)
    }
}

mod gradient;
pub(crate) use gradient::energy_frequency_derivative;
pub use gradient::energy_gradient;

#[cfg(test)]
mod tests;
