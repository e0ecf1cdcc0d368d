//! What the harmonic-balance problem is, apart from its frequency: the bar system, the basis,
//! the law settings and the unknown layout, with the constant data derived from them.
//!
//! A [`Discretization`] never changes while the problem is evaluated. Its evaluation methods
//! read the per-harmonic rows of one frequency and write into buffers they are handed: they
//! keep nothing between calls, so the same inputs give the same outputs bit for bit.

use crate::bar::Bar;
use crate::bc::LawSamples;
use crate::error::{Error, SettingsError};
use crate::fourier::{check_memory, Basis, CosineBasis};
use crate::system::rows::{dot, HarmonicRows};
use crate::system::{BarSystem, Layout};

/// A bar system under harmonic balance, independent of the frequency: system, basis,
/// complementarity parameter `a_c`, kink blend and unknown layout.
///
/// [`NonsmoothSystem`](super::NonsmoothSystem) is one of these plus the mutable state of its
/// evaluations (the rows at the current frequency, time samples, factorisations); read-only
/// users such as post-processing can hold [`NonsmoothSystem::description`](
/// super::NonsmoothSystem::description) instead of the whole problem.
#[derive(Debug, Clone)]
pub struct Discretization<B: Basis = CosineBasis> {
    system: BarSystem,
    basis: B,
    complementarity: f64,
    kink_blend: f64,
    layout: Layout,
    /// Unknowns per basis coefficient (`2 n_bars`).
    pub(crate) unknowns: usize,
    /// Linear rows per basis coefficient (`2 n_bars - n_contacts`).
    pub(super) linear_count: usize,
    /// Number of unilateral laws.
    pub(super) laws: usize,
    /// Offsets `(gap, force)` of each law's observables.
    offsets: Vec<(f64, f64)>,
    /// `G(1)`, the Gram matrix of the unit weight (see [`affine_relation`]).
    unit_gram: Vec<f64>,
}

/// Doubles a problem of `len` basis functions, `samples` folded samples, `unknowns` per
/// coefficient and `laws` unilateral laws holds or lets a solver hold, as floats so that the
/// count cannot overflow: the Gram matrices (the unit one and two per law), the law samples
/// (ten buffers per law), the reduced matrix of the structured step and the dense Jacobian a
/// solver forms where the structured step is not available.
fn problem_doubles(len: usize, samples: usize, unknowns: usize, laws: usize) -> f64 {
    let (len, samples, unknowns, laws) = (len as f64, samples as f64, unknowns as f64, laws as f64);
    let dimension = len * unknowns;
    len * len * (1.0 + 2.0 * laws)
        + 10.0 * laws * samples
        + (len * laws).powi(2)
        + dimension * dimension
}

/// The largest phase `k l` of a harmonic's wave over a bar that the problems accept, `2^52`:
/// beyond it consecutive `f64` are more than 1 apart, so `sin(k l)` and `cos(k l)` carry no
/// significant digit (and the energies, of order `(k l)^2`, approach overflow).
pub const MAX_PHASE: f64 = 4_503_599_627_370_496.0;

/// The largest gap (or force offset) of a unilateral law that a problem accepts, `1e150`: the
/// energy of a motion reaching it, of order `EA g^2 / l`, must stay within `f64`.
pub const MAX_OFFSET: f64 = 1e150;

/// The accepted complementarity parameters `a_c`, `[1e-150, 1e150]`: the law compares the
/// force with `a_c g` and its Jacobian carries `a_c`-weighted Gram sums, which stay finite
/// for gaps, forces and their sums up to `1e150` (a scale `a_c` far from the ratio of a
/// force to a gap only makes the law badly conditioned).
pub const COMPLEMENTARITY_RANGE: (f64, f64) = (1e-150, 1e150);

impl<B: Basis> Discretization<B> {
    /// `system` with `basis` and complementarity parameter `a_c`, without kink blend.
    ///
    /// # Errors
    /// [`SettingsError::NotPositive`] for a non-positive or non-finite `a_c`,
    /// [`SettingsError::OutOfRange`] for one outside [`COMPLEMENTARITY_RANGE`] or a law whose
    /// gap or force offset exceeds [`MAX_OFFSET`] in magnitude,
    /// [`SettingsError::NoContact`] for a linear system, [`SettingsError::TooLarge`] for a
    /// problem beyond the memory budget ([`crate::fourier::MEMORY_BUDGET_BYTES`]).
    pub(super) fn new(system: &BarSystem, basis: B, a_c: f64) -> Result<Self, Error> {
        check_complementarity(a_c)?;
        let laws = system.contact_count();
        if laws == 0 {
            return Err(SettingsError::NoContact.into());
        }
        let unknowns = system.unknowns_per_harmonic();
        let offsets = law_offsets(system)?;
        let len = basis.len();
        check_memory(
            "harmonic-balance problem",
            problem_doubles(len, basis.folded_samples(), unknowns, laws),
        )
        .map_err(SettingsError::TooLarge)?;
        let unit_gram = unit_gram(&basis);
        Ok(Self {
            system: system.clone(),
            basis,
            complementarity: a_c,
            kink_blend: 0.0,
            layout: Layout::of(system),
            unknowns,
            linear_count: unknowns - laws,
            laws,
            offsets,
            unit_gram,
        })
    }

    /// Sets the kink blend.
    ///
    /// # Errors
    /// [`SettingsError::NotPositive`] if `blend` is negative or not finite.
    pub(super) fn set_kink_blend(&mut self, blend: f64) -> Result<(), SettingsError> {
        if !(blend.is_finite() && blend >= 0.0) {
            return Err(SettingsError::NotPositive {
                what: "kink blend (non-negative)",
                value: blend,
            });
        }
        self.kink_blend = blend;
        Ok(())
    }

    /// The bar system.
    pub fn system(&self) -> &BarSystem {
        &self.system
    }

    /// The harmonic basis.
    pub fn basis(&self) -> &B {
        &self.basis
    }

    /// The complementarity parameter `a_c`.
    pub fn complementarity(&self) -> f64 {
        self.complementarity
    }

    /// The kink blend of
    /// [`HarmonicBalanceSettings::kink_blend`](super::HarmonicBalanceSettings::kink_blend).
    pub fn kink_blend(&self) -> f64 {
        self.kink_blend
    }

    /// Where each unknown lives.
    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// Number of unknowns (and equations).
    pub fn dimension(&self) -> usize {
        self.basis.len() * self.unknowns
    }

    /// The largest fundamental frequency whose highest harmonic `m` keeps the phase
    /// `k l = m Omega l / c` of every bar at most [`MAX_PHASE`]:
    /// `MAX_PHASE / (m max_b(l_b / c_b))`.
    pub fn max_frequency(&self) -> f64 {
        max_frequency(&self.system, self.basis.harmonics())
    }

    /// The largest gap of the unilateral laws: residual entries are gaps and forces of that
    /// order.
    pub fn residual_scale(&self) -> f64 {
        self.offsets
            .iter()
            .map(|o| o.0.abs())
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE)
    }

    /// Coefficients of the gap (`gap == true`) or force of law `l` (their `Omega`-derivatives
    /// if `derivative`), one per basis function, for the unknowns `x` and the rows of one
    /// frequency.
    pub(super) fn observable_coefficients(
        &self,
        rows: &[HarmonicRows],
        x: &[f64],
        (l, gap, derivative): (usize, bool, bool),
        out: &mut [f64],
    ) {
        let n = self.unknowns;
        for (i, o) in out.iter_mut().enumerate() {
            let h = self.basis.harmonic(i);
            let rows = &rows[h];
            let row = match (gap, derivative) {
                (true, false) => rows.gap_row(l),
                (true, true) => rows.gap_row_derivative(l),
                (false, false) => rows.force_row(l),
                (false, true) => rows.force_row_derivative(l),
            };
            let scale = if derivative { h as f64 } else { 1.0 };
            *o = scale * dot(row, &x[i * n..(i + 1) * n]);
        }
    }

    /// Time samples (folded) of every law's gap and force for the unknowns `x` (with the
    /// offsets of the observables if `offsets`, else their linear part only, as for a
    /// direction); law `l` occupies `l * N..(l + 1) * N` of `gap` and `force`.
    pub(super) fn synthesize_observables(
        &self,
        (rows, x, offsets): (&[HarmonicRows], &[f64], bool),
        coefficients: &mut [f64],
        gap: &mut [f64],
        force: &mut [f64],
    ) {
        let n = self.basis.folded_samples();
        for l in 0..self.laws {
            let range = l * n..(l + 1) * n;
            for (is_gap, out) in [(true, &mut gap[range.clone()]), (false, &mut force[range])] {
                self.observable_coefficients(rows, x, (l, is_gap, false), coefficients);
                self.basis.synthesize_folded(coefficients, out);
                if offsets {
                    let (g0, f0) = self.offsets[l];
                    let offset = if is_gap { g0 } else { f0 };
                    out.iter_mut().for_each(|v| *v += offset);
                }
            }
        }
    }

    /// Evaluates every law with smoothing `smoothing` on the gap and force samples: its
    /// pointwise residual into `out.values` and its generalised gradient (from the blended
    /// law when the kink blend is on and the law is not smoothed) into `out.d_gap` and
    /// `out.d_force`. `scratch` holds `N` samples.
    pub(super) fn evaluate_laws(
        &self,
        (gap, force, smoothing): (&[f64], &[f64], f64),
        out: LawSamples<'_>,
        scratch: &mut [f64],
    ) {
        let n = self.basis.folded_samples();
        let blend = self.kink_blend * self.residual_scale();
        for (l, law) in self.system.laws().enumerate() {
            let range = l * n..(l + 1) * n;
            let (gaps, forces) = (&gap[range.clone()], &force[range.clone()]);
            let (w_gap, w_force) = (
                &mut out.d_gap[range.clone()],
                &mut out.d_force[range.clone()],
            );
            law.sample(
                gaps,
                forces,
                self.complementarity,
                smoothing,
                LawSamples {
                    values: &mut out.values[range],
                    d_gap: w_gap,
                    d_force: w_force,
                },
            );
            if blend > 0.0 && smoothing == 0.0 {
                // Residual exact, Jacobian weights from the blended law.
                law.sample(
                    gaps,
                    forces,
                    self.complementarity,
                    blend,
                    LawSamples {
                        values: &mut *scratch,
                        d_gap: w_gap,
                        d_force: w_force,
                    },
                );
            }
        }
    }

    /// The law block of `F` from the pointwise residual samples `values` of every law, into
    /// `f` (the whole residual).
    pub(super) fn project_laws(&self, values: &[f64], f: &mut [f64]) {
        let (len, n) = (self.basis.len(), self.basis.folded_samples());
        let base = len * self.linear_count;
        for l in 0..self.laws {
            self.basis.project_folded(
                &values[l * n..(l + 1) * n],
                &mut f[base + l * len..base + (l + 1) * len],
            );
        }
    }

    /// The Gram matrices `G(w_gap)` and `G(w_force)` of one law (`len x len`, row-major) from
    /// its gradient samples: the two halves of the law's Jacobian block.
    ///
    /// When the force weight is an affine function of the gap weight (complementarity laws),
    /// `G(w_force)` is formed from `G(w_gap)` and `G(1)` instead of by a transform.
    pub(super) fn law_grams(
        &self,
        weights: (&[f64], &[f64]),
        gram_gap: &mut [f64],
        gram_force: &mut [f64],
    ) {
        law_grams(
            &self.basis,
            &self.unit_gram,
            weights,
            (gram_gap, gram_force),
        );
    }

    /// The linear block of `F` (its `Omega`-derivative if `derivative`) for the unknowns `x`
    /// and the rows of one frequency, into the first `len * linear_count` entries of `f`.
    pub(super) fn linear_block(
        &self,
        rows: &[HarmonicRows],
        x: &[f64],
        derivative: bool,
        f: &mut [f64],
    ) {
        let (n, rpc) = (self.unknowns, self.linear_count);
        for i in 0..self.basis.len() {
            let h = self.basis.harmonic(i);
            let rows = &rows[h];
            let xi = &x[i * n..(i + 1) * n];
            for r in 0..rpc {
                f[i * rpc + r] = if derivative {
                    h as f64 * dot(rows.linear_row_derivative(r), xi)
                } else {
                    dot(rows.linear_row(r), xi)
                };
            }
        }
    }

    /// The gap (`gap == true`) or force samples of law `l` over one period (the `N` instants
    /// of the grid, unfolded), for the unknowns `x` and the rows of one frequency.
    pub(super) fn history(
        &self,
        rows: &[HarmonicRows],
        x: &[f64],
        l: usize,
        gap: bool,
    ) -> Vec<f64> {
        let mut c = vec![0.0; self.basis.len()];
        self.observable_coefficients(rows, x, (l, gap, false), &mut c);
        let mut s = vec![0.0; self.basis.samples()];
        self.basis.synthesize(&c, &mut s);
        let offset = if gap {
            self.offsets[l].0
        } else {
            self.offsets[l].1
        };
        s.iter_mut().for_each(|v| *v += offset);
        s
    }

    /// The gap (`gap == true`) or force samples of law `l` on the folded grid
    /// ([`Basis::folded_samples`]) into `out`, for the unknowns `x` and the rows of one
    /// frequency, with `coefficients` (one per basis function) as scratch: the values of
    /// [`Discretization::history`] at the folded samples, bit for bit (both synthesise the
    /// same sums).
    pub(super) fn folded_history(
        &self,
        (rows, x): (&[HarmonicRows], &[f64]),
        (l, gap): (usize, bool),
        coefficients: &mut [f64],
        out: &mut [f64],
    ) {
        self.observable_coefficients(rows, x, (l, gap, false), coefficients);
        self.basis.synthesize_folded(coefficients, out);
        let offset = if gap {
            self.offsets[l].0
        } else {
            self.offsets[l].1
        };
        out.iter_mut().for_each(|v| *v += offset);
    }

    /// Energy weights at fundamental frequency `omega`: a harmonic
    /// `A cos(kx) + B sin(kx)/k` of bar `b` stores about `EA l (A^2 k^2 + B^2) / 4` of
    /// strain energy, so `w_A = EA l (k^2 + 1/l^2)` (the `1/l^2` keeps rigid displacements
    /// weighted) and `w_B = EA l`.
    pub(crate) fn state_weights(&self, omega: f64) -> Vec<f64> {
        let bars = self.system.bars();
        let mut w = Vec::with_capacity(self.dimension());
        for i in 0..self.basis.len() {
            let n = self.basis.harmonic(i) as f64;
            for bar in bars {
                let (l, ea) = (bar.length(), bar.stiffness());
                let k = bar.wavenumber(n * omega);
                w.push(ea * l * (k * k + 1.0 / (l * l)));
                w.push(ea * l);
            }
        }
        w
    }
}

/// Checks a complementarity parameter `a_c`.
///
/// # Errors
/// [`SettingsError::NotPositive`] for a non-positive or non-finite `a_c`,
/// [`SettingsError::OutOfRange`] for one outside [`COMPLEMENTARITY_RANGE`].
pub(crate) fn check_complementarity(a_c: f64) -> Result<(), SettingsError> {
    let what = "complementarity parameter a_c";
    if !(a_c.is_finite() && a_c > 0.0) {
        return Err(SettingsError::NotPositive { what, value: a_c });
    }
    let (min, max) = COMPLEMENTARITY_RANGE;
    if !(min..=max).contains(&a_c) {
        return Err(SettingsError::OutOfRange {
            what,
            value: a_c,
            min,
            max,
        });
    }
    Ok(())
}

/// `G(1)`, the Gram matrix of the unit weight on the basis' folded samples (laws are
/// evaluated there only: the other samples repeat them), for [`law_grams`].
pub(crate) fn unit_gram<B: Basis>(basis: &B) -> Vec<f64> {
    let len = basis.len();
    let mut gram = vec![0.0; len * len];
    basis.weighted_gram_folded(&vec![1.0; basis.folded_samples()], &mut gram);
    gram
}

/// The Gram matrices `G(w_gap)` and `G(w_force)` of one law (`len x len`, row-major) from
/// its gradient samples on the folded grid: the two halves of the law's Jacobian block.
///
/// When the force weight is an affine function of the gap weight (complementarity laws),
/// `G(w_force)` is formed from `G(w_gap)` and `unit_gram = G(1)` instead of by a transform.
pub(crate) fn law_grams<B: Basis>(
    basis: &B,
    unit_gram: &[f64],
    (w_gap, w_force): (&[f64], &[f64]),
    (gram_gap, gram_force): (&mut [f64], &mut [f64]),
) {
    basis.weighted_gram_folded(w_gap, gram_gap);
    match affine_relation(w_gap, w_force) {
        Some((alpha, beta)) => {
            let terms = unit_gram.iter().zip(gram_gap.iter());
            for (g, (u, w)) in gram_force.iter_mut().zip(terms) {
                *g = alpha * u + beta * w;
            }
        }
        None => basis.weighted_gram_folded(w_force, gram_force),
    }
}

/// The offsets `(gap, force)` of every law's observables.
///
/// # Errors
/// [`SettingsError::OutOfRange`] for one beyond [`MAX_OFFSET`] in magnitude: motions that
/// reach such a gap have energies beyond `f64`.
pub(crate) fn law_offsets(system: &BarSystem) -> Result<Vec<(f64, f64)>, SettingsError> {
    let offsets: Vec<(f64, f64)> = system
        .laws()
        .map(|l| (l.gap().offset, l.force().offset))
        .collect();
    let beyond = (offsets.iter())
        .flat_map(|&(g, f)| [g, f])
        .find(|v| v.abs() > MAX_OFFSET);
    match beyond {
        Some(v) => Err(SettingsError::OutOfRange {
            what: "gap or force offset of a unilateral law",
            value: v,
            min: -MAX_OFFSET,
            max: MAX_OFFSET,
        }),
        None => Ok(offsets),
    }
}

/// `(alpha, beta)` with `w_force[k] = alpha + beta w_gap[k]` at every sample (to a few
/// roundings), if there are such: the Gram matrix is linear in the weight, so then
/// `G(w_force) = alpha G(1) + beta G(w_gap)` and one transform is saved. Complementarity laws
/// (Signorini, contact) always have it: for `r = -min(lambda, a_c g)`, `w_gap` is 0 or `-a_c`
/// and `w_force = -1 - w_gap / a_c`.
fn affine_relation(w_gap: &[f64], w_force: &[f64]) -> Option<(f64, f64)> {
    let (&g0, &f0) = (w_gap.first()?, w_force.first()?);
    let (alpha, beta) = match w_gap.iter().position(|&g| g != g0) {
        Some(k) => {
            let beta = (w_force[k] - f0) / (w_gap[k] - g0);
            (f0 - beta * g0, beta)
        }
        None => (f0, 0.0),
    };
    // Branch-free, so that the scan vectorises (it runs once per Newton step).
    let fits = w_gap.iter().zip(w_force).fold(true, |fits, (&g, &f)| {
        let model = alpha + beta * g;
        fits & ((f - model).abs()
            <= 4.0 * f64::EPSILON * (f.abs() + alpha.abs() + (beta * g).abs()))
    });
    (fits && alpha.is_finite() && beta.is_finite()).then_some((alpha, beta))
}

/// The highest fundamental frequency at which the phase `k l` of harmonic `harmonics` over
/// the slowest bar of `system` stays within [`MAX_PHASE`] (the rows' sines and cosines still
/// carry digits there).
pub(crate) fn max_frequency(system: &BarSystem, harmonics: usize) -> f64 {
    let slowest = (system.bars().iter())
        .map(Bar::travel_time)
        .fold(0.0, f64::max);
    MAX_PHASE / (harmonics.max(1) as f64 * slowest)
}

#[cfg(test)]
mod tests {
    use super::affine_relation;
    use crate::fourier::{Basis, CosineBasis};

    #[test]
    fn complementarity_weights_are_affinely_related() {
        // Signorini with a_c = 4 (`r = -min(lambda, a_c g)`): gap-branch samples (-4, 0),
        // force-branch samples (0, -1).
        let (w_gap, w_force) = ([-4.0, 0.0, 0.0, -4.0], [0.0, -1.0, -1.0, 0.0]);
        let (alpha, beta) = affine_relation(&w_gap, &w_force).unwrap();
        assert!((alpha + 1.0).abs() < 1e-15 && (beta + 0.25).abs() < 1e-15);
        // One branch everywhere: the force weight is a constant.
        assert_eq!(affine_relation(&[0.0; 3], &[1.0; 3]), Some((1.0, 0.0)));
        // Not affine: three distinct pairs off one line.
        assert_eq!(affine_relation(&[0.0, 1.0, 2.0], &[1.0, 0.0, 1.0]), None);
        assert_eq!(affine_relation(&[0.0, 0.0], &[1.0, 0.5]), None);
    }

    #[test]
    fn the_gram_matrix_is_linear_in_the_weight() {
        // What the shortcut relies on: G(alpha + beta w) = alpha G(1) + beta G(w).
        let basis = CosineBasis::new(9, 5).unwrap();
        let (n, len) = (basis.samples(), basis.len());
        let w: Vec<f64> = (0..n)
            .map(|k| ((k * 37) % 13) as f64 / 13.0 - 0.3)
            .collect();
        let (alpha, beta) = (0.7, -1.9);
        let combined: Vec<f64> = w.iter().map(|v| alpha + beta * v).collect();
        let (mut g, mut g1, mut gw) = (
            vec![0.0; len * len],
            vec![0.0; len * len],
            vec![0.0; len * len],
        );
        basis.weighted_gram(&combined, &mut g);
        basis.weighted_gram(&vec![1.0; n], &mut g1);
        basis.weighted_gram(&w, &mut gw);
        for ((a, u), b) in g.iter().zip(&g1).zip(&gw) {
            assert!(
                (a - (alpha * u + beta * b)).abs() < 1e-13,
                "{a} vs {}",
                alpha * u + beta * b
            );
        }
    }
}
