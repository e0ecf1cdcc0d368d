//! The square nonsmooth system `F(x; Omega) = 0` of harmonic balance.
//!
//! Unknowns: for each basis coefficient `i` and bar `b`, the Helmholtz coefficients
//! `(A, B)` of that harmonic, at index `(i * n_bars + b) * 2 + {0, 1}`.
//!
//! Equations, in this order:
//! 1. for each coefficient `i`, the linear rows of its harmonic (conditions and contact force
//!    balances): `2 n_bars - n_contacts` rows;
//! 2. for each unilateral law `l`, the projections `R_j = (2/N) sum_k psi_j(theta_k) r(theta_k)`
//!    of its pointwise residual `r = law(gap(theta_k), force(theta_k))`: one per coefficient.
//!
//! The generalised Jacobian of block 2 is `G(w_gap) * gap_rows + G(w_force) * force_rows`, where
//! `G(w)` is the basis' weighted Gram matrix of the law's generalised gradient `w` sampled in time
//! (Toeplitz + Hankel for cosines: formulation §6). `dF/dOmega` at fixed `x` comes only through
//! the wave numbers `k = n Omega / c` in the rows.

mod step;

use crate::bc::LawSamples;
use crate::continuation::ContinuationProblem;
use crate::error::{Error, SettingsError};
use crate::fourier::{Basis, CosineBasis};
use crate::linalg::DenseMatrix;
use crate::solve::{point_on_ray, Problem, SingularStep, Structured};
use crate::system::condense::{CondenseScratch, Condensed};
use crate::system::rows::{dot, HarmonicRows, RowsScratch};
use crate::system::{BarSystem, Layout};
use step::Reduced;

/// Harmonic-balance settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HarmonicBalanceSettings {
    /// Number of harmonics `m` (default 20).
    pub harmonics: usize,
    /// Time samples per harmonic `n_h`; the period has `N = n_h m` samples (default 30).
    pub samples_per_harmonic: usize,
    /// Complementarity parameter `a_c > 0` of `r = -min(lambda, a_c g)` (default 4).
    pub complementarity: f64,
    /// Width, relative to the largest gap, of the band around each kink of the law in which
    /// the Jacobian blends the two one-sided derivatives (default 0: an exact element of the
    /// generalised Jacobian at every sample). The residual is never blended. The blend (the
    /// derivative of the smoothed law of [`crate::bc::smoothed_complementarity`]) acts like the
    /// finite-difference Jacobian of the paper's solver: it can converge steps whose exact
    /// Jacobian jumps between iterations, but branches near internal resonances are sensitive
    /// to it (`docs/performance.md` has the measurements), hence the exact default.
    pub kink_blend: f64,
}

impl Default for HarmonicBalanceSettings {
    fn default() -> Self {
        Self {
            harmonics: 20,
            samples_per_harmonic: 30,
            complementarity: 4.0,
            kink_blend: 0.0,
        }
    }
}

impl HarmonicBalanceSettings {
    /// The constant + cosine basis of these settings.
    ///
    /// # Errors
    /// See [`CosineBasis::new`].
    pub fn cosine_basis(&self) -> Result<CosineBasis, SettingsError> {
        CosineBasis::new(self.harmonics, self.samples_per_harmonic)
    }
}

/// Relative singular-value threshold under which a harmonic's linear rows count as
/// rank-deficient (see [`HarmonicRows::regularise`]).
const RANK_TOLERANCE: f64 = 1e-9;

/// Time samples of the laws' observables and generalised gradients.
#[derive(Debug, Clone, Default)]
struct Workspace {
    coefficients: Vec<f64>,
    gap: Vec<f64>,
    force: Vec<f64>,
    values: Vec<f64>,
    w_gap: Vec<f64>,
    w_force: Vec<f64>,
    scratch: Vec<f64>,
    /// Samples of `d gap / d Omega` (scratch of `dF/dOmega`).
    d_samples: Vec<f64>,
    projection: Vec<f64>,
    /// `G(w_gap)` of every law, `len x len` row-major each, one after the other.
    gram_gap: Vec<f64>,
    /// `G(w_force)` of every law, laid out as `gram_gap`.
    gram_force: Vec<f64>,
    /// The unknowns the law samples (`values`, `w_gap`, `w_force`) were computed for, at the
    /// current `Omega`, smoothing and blend; `None` when they are stale. Newton evaluates the
    /// residual at the accepted point and then its Jacobian there: the second sampling is
    /// skipped. `gap` and `force` hold that point's samples too.
    sampled: Option<Vec<f64>>,
    along: LineSamples,
}

/// Samples of a line search `x + t dx` at the current `Omega`: gap, force and linear rows of
/// `x` and of `dx` (see `residual_along`).
#[derive(Debug, Clone, Default)]
struct LineSamples {
    start: Option<Vec<f64>>,
    direction: Option<Vec<f64>>,
    gap: Vec<f64>,
    force: Vec<f64>,
    d_gap: Vec<f64>,
    d_force: Vec<f64>,
    linear: Vec<f64>,
    d_linear: Vec<f64>,
}

impl Workspace {
    /// Forgets every cached sample (after a change of `Omega`, smoothing or blend).
    fn invalidate(&mut self) {
        self.sampled = None;
        self.along.start = None;
    }

    /// The Gram matrices `(G(w_gap), G(w_force))` of law `l` (`len x len` each).
    fn grams(&self, l: usize, len: usize) -> (&[f64], &[f64]) {
        let range = l * len * len..(l + 1) * len * len;
        (&self.gram_gap[range.clone()], &self.gram_force[range])
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

/// Sets a cache key to a copy of `v`, reusing its storage.
fn set_key(key: &mut Option<Vec<f64>>, v: &[f64]) {
    let mut k = key.take().unwrap_or_default();
    k.clear();
    k.extend_from_slice(v);
    *key = Some(k);
}

/// A bar system under harmonic balance at a variable fundamental frequency `Omega`.
///
/// It is a [`Problem`] at its current frequency (residual and generalised Jacobian, analytic),
/// a [`ContinuationProblem`] in `Omega` (set with
/// [`ContinuationProblem::set_parameter`]; `dF/dOmega` analytic), and offers every
/// [`Structured`] capability: the condensed Newton step, cheap line searches, smoothing,
/// energy weights and active sets.
///
/// # Panics
/// The [`Problem`] and [`ContinuationProblem`] methods panic if `x` (or an output slice) does
/// not have length [`NonsmoothSystem::dimension`]: a programmer contract, which the solvers
/// and drivers check before calling them (they return
/// [`SolveError::Dimension`](crate::SolveError::Dimension) /
/// [`ContinuationError::Dimension`](crate::ContinuationError::Dimension) instead). Before the
/// first [`ContinuationProblem::set_parameter`] the frequency is NaN and so is the residual
/// (solvers report it as [`SolveError::NonFinite`](crate::SolveError::NonFinite)).
#[derive(Debug, Clone)]
pub struct NonsmoothSystem<B: Basis = CosineBasis> {
    system: BarSystem,
    basis: B,
    complementarity: f64,
    /// Smoothing of the unilateral laws (0: the nonsmooth problem).
    smoothing: f64,
    /// See [`HarmonicBalanceSettings::kink_blend`].
    kink_blend: f64,
    unknowns: usize,
    linear_count: usize,
    laws: usize,
    offsets: Vec<(f64, f64)>,
    omega: f64,
    rows: Vec<HarmonicRows>,
    rows_scratch: RowsScratch,
    /// Null bases and pseudo-inverses of `rows` (storage kept across frequencies).
    condensed: Vec<Condensed>,
    /// Whether `condensed` is up to date (`None`: stale) and every harmonic's rows had full
    /// rank.
    condensed_state: Option<bool>,
    condense_scratch: CondenseScratch,
    reduced: Reduced,
    /// `G(1)`, the Gram matrix of the unit weight (see [`affine_relation`]).
    unit_gram: Vec<f64>,
    ws: Workspace,
}

impl NonsmoothSystem<CosineBasis> {
    /// The system with the paper's constant + cosine basis.
    ///
    /// # Errors
    /// Invalid settings ([`SettingsError`]) or a system without unilateral condition
    /// ([`SettingsError::NoContact`]).
    pub fn new(system: &BarSystem, settings: HarmonicBalanceSettings) -> Result<Self, Error> {
        let mut problem =
            Self::with_basis(system, settings.cosine_basis()?, settings.complementarity)?;
        problem.set_kink_blend(settings.kink_blend)?;
        Ok(problem)
    }
}

impl<B: Basis> NonsmoothSystem<B> {
    /// The system with any basis.
    ///
    /// # Errors
    /// [`SettingsError::NotPositive`] for a bad complementarity parameter `a_c`,
    /// [`SettingsError::NoContact`] for a
    /// linear system.
    pub fn with_basis(system: &BarSystem, basis: B, a_c: f64) -> Result<Self, Error> {
        if !(a_c.is_finite() && a_c > 0.0) {
            return Err(SettingsError::NotPositive {
                what: "complementarity parameter a_c",
                value: a_c,
            }
            .into());
        }
        let laws = system.contact_count();
        if laws == 0 {
            return Err(SettingsError::NoContact.into());
        }
        let unknowns = system.unknowns_per_harmonic();
        let offsets = system
            .laws()
            .map(|l| (l.gap().offset, l.force().offset))
            .collect();
        // Laws are evaluated on the basis' folded samples only (the others repeat them).
        let n = basis.folded_samples();
        let len = basis.len();
        let mut unit_gram = vec![0.0; len * len];
        basis.weighted_gram_folded(&vec![1.0; n], &mut unit_gram);
        let ws = Workspace {
            coefficients: vec![0.0; len],
            gap: vec![0.0; laws * n],
            force: vec![0.0; laws * n],
            values: vec![0.0; laws * n],
            w_gap: vec![0.0; laws * n],
            w_force: vec![0.0; laws * n],
            scratch: vec![0.0; n],
            d_samples: vec![0.0; n],
            projection: vec![0.0; len],
            gram_gap: vec![0.0; laws * len * len],
            gram_force: vec![0.0; laws * len * len],
            sampled: None,
            along: LineSamples {
                gap: vec![0.0; laws * n],
                force: vec![0.0; laws * n],
                d_gap: vec![0.0; laws * n],
                d_force: vec![0.0; laws * n],
                ..Default::default()
            },
        };
        Ok(Self {
            system: system.clone(),
            basis,
            complementarity: a_c,
            smoothing: 0.0,
            kink_blend: 0.0,
            unknowns,
            linear_count: unknowns - laws,
            laws,
            offsets,
            omega: f64::NAN,
            rows: Vec::new(),
            rows_scratch: RowsScratch::default(),
            condensed: Vec::new(),
            condensed_state: None,
            condense_scratch: CondenseScratch::default(),
            reduced: Reduced::default(),
            unit_gram,
            ws,
        })
    }

    /// Sets [`HarmonicBalanceSettings::kink_blend`] (0 for the exact generalised Jacobian).
    ///
    /// # Errors
    /// [`SettingsError::NotPositive`] if `blend` is negative or not finite.
    pub fn set_kink_blend(&mut self, blend: f64) -> Result<(), SettingsError> {
        if !(blend.is_finite() && blend >= 0.0) {
            return Err(SettingsError::NotPositive {
                what: "kink blend (non-negative)",
                value: blend,
            });
        }
        self.kink_blend = blend;
        self.ws.invalidate();
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

    /// Number of unknowns (and equations).
    pub fn dimension(&self) -> usize {
        self.basis.len() * self.unknowns
    }

    /// Index in `x` of coefficient `i`, bar `bar`, Helmholtz component `which` (0: `A`, 1: `B`),
    /// as in [`Layout`].
    pub fn index(&self, i: usize, bar: usize, which: usize) -> usize {
        self.layout().index(i, bar, which)
    }

    /// Where each unknown lives.
    pub fn layout(&self) -> Layout {
        Layout::of(&self.system)
    }

    /// The per-harmonic rows at fundamental frequency `omega` (the problem moves to `omega`).
    pub fn rows_at(&mut self, omega: f64) -> &[HarmonicRows] {
        self.prepare(omega);
        &self.rows
    }

    /// Rebuilds the per-harmonic rows when `omega` changed.
    fn prepare(&mut self, omega: f64) {
        if omega == self.omega && !self.rows.is_empty() {
            return;
        }
        self.omega = omega;
        self.condensed_state = None;
        self.ws.invalidate();
        // Rebuild every harmonic's rows in their own storage.
        let (system, scratch) = (&self.system, &mut self.rows_scratch);
        let harmonics = self.basis.harmonics() + 1;
        self.rows.truncate(harmonics);
        for (h, rows) in self.rows.iter_mut().enumerate() {
            rows.rebuild(system, h as f64 * omega, scratch);
            rows.regularise(RANK_TOLERANCE);
        }
        for h in self.rows.len()..harmonics {
            let mut rows = HarmonicRows::new(system, h as f64 * omega);
            rows.regularise(RANK_TOLERANCE);
            self.rows.push(rows);
        }
    }

    /// Coefficients of the gap (`gap == true`) or force of law `l`, one per basis function.
    fn observable_coefficients(
        &self,
        x: &[f64],
        l: usize,
        gap: bool,
        derivative: bool,
        out: &mut [f64],
    ) {
        let n = self.unknowns;
        for (i, o) in out.iter_mut().enumerate() {
            let h = self.basis.harmonic(i);
            let rows = &self.rows[h];
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

    /// Samples gap, force, pointwise residual and its generalised gradient of every law
    /// (law `l` occupies `l * N..(l + 1) * N` of each buffer).
    fn sample_laws(&mut self, x: &[f64]) {
        if self.ws.sampled.as_deref() == Some(x) {
            return;
        }
        let mut ws = std::mem::take(&mut self.ws);
        self.synthesize_observables(x, true, &mut ws.coefficients, &mut ws.gap, &mut ws.force);
        self.evaluate_laws(&mut ws, x);
        self.ws = ws;
    }

    /// Time samples of every law's gap and force for the unknowns `x` (with the offsets of
    /// the observables if `offsets`, else their linear part only, as for a direction).
    fn synthesize_observables(
        &self,
        x: &[f64],
        offsets: bool,
        coefficients: &mut [f64],
        gap: &mut [f64],
        force: &mut [f64],
    ) {
        let n = self.basis.folded_samples();
        for l in 0..self.laws {
            let range = l * n..(l + 1) * n;
            for (is_gap, out) in [(true, &mut gap[range.clone()]), (false, &mut force[range])] {
                self.observable_coefficients(x, l, is_gap, false, coefficients);
                self.basis.synthesize_folded(coefficients, out);
                if offsets {
                    let (g0, f0) = self.offsets[l];
                    let offset = if is_gap { g0 } else { f0 };
                    out.iter_mut().for_each(|v| *v += offset);
                }
            }
        }
    }

    /// Evaluates every law on the gap and force samples of `ws` (those of the unknowns `x`),
    /// and marks the samples as those of `x`.
    fn evaluate_laws(&self, ws: &mut Workspace, x: &[f64]) {
        let n = self.basis.folded_samples();
        let blend = self.kink_blend * self.residual_scale();
        for (l, law) in self.system.laws().enumerate() {
            let range = l * n..(l + 1) * n;
            let (gaps, forces) = (&ws.gap[range.clone()], &ws.force[range.clone()]);
            let (w_gap, w_force) = (&mut ws.w_gap[range.clone()], &mut ws.w_force[range.clone()]);
            law.sample(
                gaps,
                forces,
                self.complementarity,
                self.smoothing,
                LawSamples {
                    values: &mut ws.values[range],
                    d_gap: w_gap,
                    d_force: w_force,
                },
            );
            if blend > 0.0 && self.smoothing == 0.0 {
                // Residual exact, Jacobian weights from the blended law.
                law.sample(
                    gaps,
                    forces,
                    self.complementarity,
                    blend,
                    LawSamples {
                        values: &mut ws.scratch,
                        d_gap: w_gap,
                        d_force: w_force,
                    },
                );
            }
        }
        let mut sampled = ws.sampled.take().unwrap_or_default();
        sampled.clear();
        sampled.extend_from_slice(x);
        ws.sampled = Some(sampled);
    }

    /// The law block of `F` from the sampled law values, into `f`.
    fn project_laws(&self, f: &mut [f64]) {
        let (len, n) = (self.basis.len(), self.basis.folded_samples());
        let base = len * self.linear_count;
        for l in 0..self.laws {
            self.basis.project_folded(
                &self.ws.values[l * n..(l + 1) * n],
                &mut f[base + l * len..base + (l + 1) * len],
            );
        }
    }

    /// The Gram matrices `G(w_gap)` and `G(w_force)` of law `l` (after [`Self::sample_laws`]),
    /// into the workspace ([`Workspace::grams`]): the two halves of the law's Jacobian block.
    ///
    /// When the force weight is an affine function of the gap weight (complementarity laws),
    /// `G(w_force)` is formed from `G(w_gap)` and `G(1)` instead of by a transform.
    fn law_grams(&self, ws: &mut Workspace, l: usize) {
        let (n, len) = (self.basis.folded_samples(), self.basis.len());
        let range = l * n..(l + 1) * n;
        let (w_gap, w_force) = (&ws.w_gap[range.clone()], &ws.w_force[range]);
        let grams = l * len * len..(l + 1) * len * len;
        let gram_gap = &mut ws.gram_gap[grams.clone()];
        let gram_force = &mut ws.gram_force[grams];
        self.basis.weighted_gram_folded(w_gap, gram_gap);
        match affine_relation(w_gap, w_force) {
            Some((alpha, beta)) => {
                let terms = self.unit_gram.iter().zip(gram_gap.iter());
                for (g, (u, w)) in gram_force.iter_mut().zip(terms) {
                    *g = alpha * u + beta * w;
                }
            }
            None => self.basis.weighted_gram_folded(w_force, gram_force),
        }
    }

    /// Gap samples of law `l` over one period at `omega` (the `N` instants of the grid); the
    /// problem moves to `omega`.
    ///
    /// # Panics
    /// If `l` is not below the number of unilateral conditions or `x` has the wrong length
    /// ([`crate::modal::law_history`] returns an error instead).
    pub fn gap_history(&mut self, x: &[f64], omega: f64, l: usize) -> Vec<f64> {
        self.history(x, omega, l, true)
    }

    /// Contact-force samples of law `l` over one period at `omega`.
    ///
    /// # Panics
    /// If `l` is not below the number of unilateral conditions or `x` has the wrong length
    /// ([`crate::modal::law_history`] returns an error instead).
    pub fn force_history(&mut self, x: &[f64], omega: f64, l: usize) -> Vec<f64> {
        self.history(x, omega, l, false)
    }

    /// Pointwise law residual `r(theta_k)` of law `l` over one period at `omega`.
    ///
    /// # Panics
    /// If `l` is not below the number of unilateral conditions or `x` has the wrong length
    /// ([`crate::modal::law_history`] returns an error instead).
    pub fn law_residual_history(&mut self, x: &[f64], omega: f64, l: usize) -> Vec<f64> {
        let g = self.gap_history(x, omega, l);
        let f = self.force_history(x, omega, l);
        let law = self.system.laws().nth(l).expect("law index in range");
        g.iter()
            .zip(&f)
            .map(|(&g, &f)| law.residual(g, f, self.complementarity).value)
            .collect()
    }

    fn history(&mut self, x: &[f64], omega: f64, l: usize, gap: bool) -> Vec<f64> {
        self.prepare(omega);
        let mut c = vec![0.0; self.basis.len()];
        self.observable_coefficients(x, l, gap, false, &mut c);
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

    fn linear_block(&self, x: &[f64], derivative: bool, f: &mut [f64]) {
        let (n, rpc) = (self.unknowns, self.linear_count);
        for i in 0..self.basis.len() {
            let h = self.basis.harmonic(i);
            let rows = &self.rows[h];
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
}

impl<B: Basis> Problem for NonsmoothSystem<B> {
    fn dimension(&self) -> usize {
        self.dimension()
    }

    /// Samples `x` afresh: the value depends on `x` and `Omega` alone.
    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        self.linear_block(x, false, f);
        self.ws.sampled = None;
        self.sample_laws(x);
        self.project_laws(f);
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix) {
        let (len, un, rpc) = (self.basis.len(), self.unknowns, self.linear_count);
        jac.reset(self.dimension(), self.dimension());
        for i in 0..len {
            let rows = &self.rows[self.basis.harmonic(i)];
            for r in 0..rpc {
                for (c, &v) in rows.linear_row(r).iter().enumerate() {
                    jac[(i * rpc + r, i * un + c)] = v;
                }
            }
        }
        self.sample_laws(x);
        let base = len * rpc;
        let mut ws = std::mem::take(&mut self.ws);
        for l in 0..self.laws {
            self.law_grams(&mut ws, l);
            let (gram_gap, gram_force) = ws.grams(l, len);
            // Column by column (the matrix is column-major): contiguous writes.
            for i in 0..len {
                let rows = &self.rows[self.basis.harmonic(i)];
                let (grow, frow) = (rows.gap_row(l), rows.force_row(l));
                for c in 0..un {
                    let (gc, fc) = (grow[c], frow[c]);
                    for j in 0..len {
                        let (gg, gf) = (gram_gap[j * len + i], gram_force[j * len + i]);
                        if gg == 0.0 && gf == 0.0 {
                            continue;
                        }
                        jac[(base + l * len + j, i * un + c)] = gg * gc + gf * fc;
                    }
                }
            }
        }
        self.ws = ws;
    }

    fn structure(&mut self) -> Option<&mut dyn Structured> {
        Some(self)
    }
}

impl<B: Basis> ContinuationProblem for NonsmoothSystem<B> {
    /// The fundamental frequency `Omega` (NaN before the first [`Self::set_parameter`]).
    fn parameter(&self) -> f64 {
        self.omega
    }

    /// Moves to fundamental frequency `omega`: the per-harmonic rows are rebuilt when it
    /// changes.
    fn set_parameter(&mut self, omega: f64) {
        self.prepare(omega);
    }

    fn parameter_derivative(&mut self, x: &[f64], df: &mut [f64]) {
        self.linear_block(x, true, df);
        self.sample_laws(x);
        let (len, n) = (self.basis.len(), self.basis.folded_samples());
        let base = len * self.linear_count;
        let mut ws = std::mem::take(&mut self.ws);
        for l in 0..self.laws {
            let dg = &mut ws.d_samples;
            self.observable_coefficients(x, l, true, true, &mut ws.coefficients);
            self.basis.synthesize_folded(&ws.coefficients, dg);
            self.observable_coefficients(x, l, false, true, &mut ws.coefficients);
            self.basis
                .synthesize_folded(&ws.coefficients, &mut ws.scratch);
            let (w_gap, w_force) = (
                &ws.w_gap[l * n..(l + 1) * n],
                &ws.w_force[l * n..(l + 1) * n],
            );
            for (((s, d), wg), wf) in ws.scratch.iter_mut().zip(dg.iter()).zip(w_gap).zip(w_force) {
                *s = wg * d + wf * *s;
            }
            self.basis.project_folded(&ws.scratch, &mut ws.projection);
            df[base + l * len..base + (l + 1) * len].copy_from_slice(&ws.projection);
        }
        self.ws = ws;
    }
}

impl<B: Basis> Structured for NonsmoothSystem<B> {
    /// The largest gap of the unilateral laws: residual entries are gaps and forces of that
    /// order.
    fn residual_scale(&self) -> f64 {
        self.offsets
            .iter()
            .map(|o| o.0.abs())
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE)
    }

    /// The Newton step with the linear rows condensed (formulation §5): only a dense LU of
    /// size `len * n_contacts` is factorised, once for all right-hand sides.
    fn solve_jacobian(
        &mut self,
        x: &[f64],
        rhs: &mut [f64],
        columns: usize,
    ) -> Option<Result<(), SingularStep>> {
        self.condensed_solve(x, rhs, columns)
    }

    /// Along a line search the observables are affine in `t`: the samples of `x` (kept from
    /// its residual) and of `dx` are synthesised once per direction, and each trial costs the
    /// law evaluation and one projection instead of three transforms.
    fn residual_along(
        &mut self,
        x: &[f64],
        dx: &[f64],
        t: f64,
        trial: &mut [f64],
        f: &mut [f64],
    ) -> bool {
        point_on_ray(x, dx, t, trial);
        let mut ws = std::mem::take(&mut self.ws);
        let same = |v: &Option<Vec<f64>>, w: &[f64]| v.as_deref() == Some(w);
        if !(same(&ws.along.start, x) && same(&ws.along.direction, dx)) {
            let along = &mut ws.along;
            if same(&ws.sampled, x) {
                // The samples of x move to the line search: the trials overwrite `ws` next.
                std::mem::swap(&mut along.gap, &mut ws.gap);
                std::mem::swap(&mut along.force, &mut ws.force);
                ws.sampled = None;
            } else {
                self.synthesize_observables(
                    x,
                    true,
                    &mut ws.coefficients,
                    &mut along.gap,
                    &mut along.force,
                );
            }
            self.synthesize_observables(
                dx,
                false,
                &mut ws.coefficients,
                &mut along.d_gap,
                &mut along.d_force,
            );
            along
                .linear
                .resize(self.basis.len() * self.linear_count, 0.0);
            along
                .d_linear
                .resize(self.basis.len() * self.linear_count, 0.0);
            self.linear_block(x, false, &mut along.linear);
            self.linear_block(dx, false, &mut along.d_linear);
            set_key(&mut along.start, x);
            set_key(&mut along.direction, dx);
        }
        let along = &ws.along;
        for (g, (a, d)) in ws.gap.iter_mut().zip(along.gap.iter().zip(&along.d_gap)) {
            *g = a + t * d;
        }
        for (g, (a, d)) in ws
            .force
            .iter_mut()
            .zip(along.force.iter().zip(&along.d_force))
        {
            *g = a + t * d;
        }
        for (o, (a, d)) in f.iter_mut().zip(along.linear.iter().zip(&along.d_linear)) {
            *o = a + t * d;
        }
        self.evaluate_laws(&mut ws, trial);
        self.ws = ws;
        self.project_laws(f);
        true
    }

    fn set_smoothing(&mut self, smoothing: f64) -> bool {
        self.smoothing = smoothing.max(0.0);
        self.ws.invalidate();
        true
    }

    /// Energy weights: a harmonic `A cos(kx) + B sin(kx)/k` of bar `b` stores about
    /// `EA l (A^2 k^2 + B^2) / 4` of strain energy, so `w_A = EA l (k^2 + 1/l^2)` (the `1/l^2`
    /// keeps rigid displacements weighted) and `w_B = EA l`.
    fn state_weights(&mut self) -> Option<Vec<f64>> {
        let bars = self.system.bars();
        let mut w = Vec::with_capacity(self.dimension());
        for i in 0..self.basis.len() {
            let n = self.basis.harmonic(i) as f64;
            for bar in bars {
                let (l, ea) = (bar.length(), bar.stiffness());
                let k = bar.wavenumber(n * self.omega);
                w.push(ea * l * (k * k + 1.0 / (l * l)));
                w.push(ea * l);
            }
        }
        Some(w)
    }

    fn active_set(&mut self, x: &[f64]) -> Option<Vec<usize>> {
        self.sample_laws(x);
        let n = self.basis.folded_samples();
        Some(
            (0..self.laws)
                .map(|l| {
                    self.ws.w_gap[l * n..(l + 1) * n]
                        .iter()
                        .enumerate()
                        .filter(|(_, w)| **w != 0.0)
                        .map(|(k, _)| self.basis.multiplicity(k))
                        .sum()
                })
                .collect(),
        )
    }
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
