//! The mutable state of a harmonic-balance problem: the per-harmonic rows at the current
//! frequency with their condensation ([`Frequency`]), and the time samples of the laws with
//! the record of what they were made from ([`Samples`]).
//!
//! # What the samples are samples of
//!
//! [`Samples`] records the unknowns its samples belong to and how they were made ([`Origin`]):
//!
//! - [`Origin::Synthesis`]: by a synthesis of those unknowns ([`Samples::synthesis`]): a pure
//!   function of the unknowns, the frequency, the smoothing and the blend, so keeping them
//!   returns bit for bit what a new synthesis would;
//! - [`Origin::Ray`]: by a line-search evaluation ([`Samples::along`]) of the trial
//!   `x = x0 + t dx`, as `s(x0) + t s(dx)` from the samples `s` of `x0` and of `dx`. The
//!   observables are linear in the unknowns, so these equal a synthesis of `x` to rounding,
//!   not bit for bit.
//!
//! The residual ([`Samples::synthesis`]) reuses syntheses only: its value depends on `x` alone.
//! The Jacobian-type evaluations at `x` (generalised Jacobian, structured solve, `dF/dOmega`,
//! active set: [`Samples::at`]) and the start of a line search from `x` ([`Samples::along`])
//! reuse samples of `x` of either origin: they see the samples of the last residual
//! evaluation at `x`, so the Newton step after an accepted line search is the Newton step of
//! the residual the line search accepted. They synthesise when the samples are not those of
//! `x`.
//!
//! For the complementarity laws the generalised gradient is piecewise constant, so samples
//! that agree to rounding give the same Jacobian, `dF/dOmega` and active set unless one of
//! them lies within rounding of the kink; smoothed or custom laws see last-bit differences.
//! Synthesising afresh at every accepted trial instead would cost one more synthesis per
//! Newton iteration (about 8 % of the instructions of a backbone at 20 harmonics) and would
//! move converged points near internal resonances, where the solution is barely isolated.

use super::discretization::Discretization;
use super::shared_rows;
use super::staircase::staircase_of;
use crate::bc::LawSamples;
use crate::fourier::Basis;
use crate::linalg::Staircase;
use crate::system::condense::{condense_into, CondenseScratch, Condensed};
use crate::system::rows::{HarmonicRows, RowsScratch};

/// Relative singular-value threshold under which a harmonic's linear rows count as
/// rank-deficient (see [`HarmonicRows::regularise`]).
pub(super) const RANK_TOLERANCE: f64 = 1e-9;

/// The per-harmonic rows at the current fundamental frequency and their condensation.
#[derive(Debug, Clone)]
pub(super) struct Frequency {
    /// The fundamental frequency `Omega` (NaN before the first [`Frequency::prepare`]).
    pub(super) omega: f64,
    /// The rows of harmonic `h` at `h Omega`, `h = 0..=harmonics`.
    pub(super) rows: Vec<HarmonicRows>,
    rows_scratch: RowsScratch,
    /// Null bases and pseudo-inverses of `rows` (storage kept across frequencies).
    pub(super) condensed: Vec<Condensed>,
    /// Whether `condensed` is up to date (`None`: stale) and every harmonic's rows had full
    /// rank.
    condensed_state: Option<bool>,
    condense_scratch: CondenseScratch,
    /// The staircase shape of the Jacobian (`None`: stale; `Some(None)`: the structured step
    /// condenses instead), see `band.rs`.
    staircase: Option<Option<Staircase>>,
}

impl Frequency {
    /// No frequency yet.
    pub(super) fn new() -> Self {
        Self {
            omega: f64::NAN,
            rows: Vec::new(),
            rows_scratch: RowsScratch::default(),
            condensed: Vec::new(),
            condensed_state: None,
            condense_scratch: CondenseScratch::default(),
            staircase: None,
        }
    }

    /// Moves to fundamental frequency `omega`, rebuilding every harmonic's rows in their own
    /// storage when it changed (or copying those another problem on the system built there
    /// last, `shared_rows.rs`); whether it did.
    pub(super) fn prepare<B: Basis>(&mut self, d: &Discretization<B>, omega: f64) -> bool {
        if omega == self.omega && !self.rows.is_empty() {
            return false;
        }
        self.omega = omega;
        self.condensed_state = None;
        self.staircase = None;
        let (system, scratch) = (d.system(), &mut self.rows_scratch);
        let harmonics = d.basis().harmonics() + 1;
        if shared_rows::copy_into(system, omega, harmonics, &mut self.rows) {
            return true;
        }
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
        shared_rows::keep(system, omega, &self.rows);
        true
    }

    /// Brings the null bases and pseudo-inverses up to date; whether every harmonic's rows
    /// have full rank.
    pub(super) fn condense(&mut self) -> bool {
        if self.condensed_state.is_none() {
            self.condensed
                .resize_with(self.rows.len(), Default::default);
            let scratch = &mut self.condense_scratch;
            let all = self
                .rows
                .iter()
                .zip(self.condensed.iter_mut())
                .fold(true, |ok, (rows, out)| {
                    condense_into(rows, out, scratch) && ok
                });
            self.condensed_state = Some(all);
        }
        self.condensed_state == Some(true)
    }
}

impl Frequency {
    /// Brings the staircase shape of the Jacobian up to date ([`staircase_of`]); whether the
    /// structured step takes it (then [`Frequency::staircase`] is `Some`).
    pub(super) fn prepare_staircase<B: Basis>(&mut self, d: &Discretization<B>) -> bool {
        let rows = &self.rows;
        (self.staircase)
            .get_or_insert_with(|| staircase_of(d, rows))
            .is_some()
    }

    /// The staircase shape of the Jacobian, once [`Frequency::prepare_staircase`] found one.
    pub(super) fn staircase(&self) -> Option<&Staircase> {
        self.staircase.as_ref().and_then(Option::as_ref)
    }
}

/// How the law samples of [`Samples`] were made (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Origin {
    /// None is valid (after a change of frequency, smoothing or blend).
    Stale,
    /// A synthesis of the key: equal bit for bit to any other synthesis of it.
    Synthesis,
    /// A line-search trial, the key, formed along its ray: equal to a synthesis to rounding.
    Ray,
}

/// Time samples (folded) of the laws' observables, pointwise residuals and generalised
/// gradients, law `l` at `l * N..(l + 1) * N` of each buffer, with the Gram matrices formed
/// from them and scratch space.
#[derive(Debug, Clone)]
pub(super) struct Samples {
    /// Smoothing of the unilateral laws (0: the nonsmooth problem).
    smoothing: f64,
    /// The unknowns the samples belong to, and how they were made.
    key: Vec<f64>,
    origin: Origin,
    gap: Vec<f64>,
    force: Vec<f64>,
    values: Vec<f64>,
    w_gap: Vec<f64>,
    w_force: Vec<f64>,
    /// One coefficient per basis function.
    coefficients: Vec<f64>,
    /// `N` samples.
    scratch: Vec<f64>,
    /// Samples of `d gap / d Omega` (scratch of `dF/dOmega`).
    d_samples: Vec<f64>,
    /// One coefficient per basis function.
    projection: Vec<f64>,
    /// `G(w_gap)` of every law, `len x len` row-major each, one after the other.
    gram_gap: Vec<f64>,
    /// `G(w_force)` of every law, laid out as `gram_gap`.
    gram_force: Vec<f64>,
    along: LineSamples,
}

/// Samples of a line search `x + t dx` at the current frequency: gap, force and linear rows
/// of `x` and of `dx` (see [`Samples::along`]).
#[derive(Debug, Clone, Default)]
struct LineSamples {
    /// `x` and `dx`, or `None` when stale.
    start: Option<Vec<f64>>,
    direction: Option<Vec<f64>>,
    gap: Vec<f64>,
    force: Vec<f64>,
    d_gap: Vec<f64>,
    d_force: Vec<f64>,
    linear: Vec<f64>,
    d_linear: Vec<f64>,
}

/// Sets a cache key to a copy of `v`, reusing its storage.
fn set_key(key: &mut Option<Vec<f64>>, v: &[f64]) {
    let mut k = key.take().unwrap_or_default();
    k.clear();
    k.extend_from_slice(v);
    *key = Some(k);
}

impl Samples {
    /// Buffers for the laws of `d`, without valid samples and without smoothing.
    pub(super) fn new<B: Basis>(d: &Discretization<B>) -> Self {
        let (n, len, laws) = (d.basis().folded_samples(), d.basis().len(), d.laws);
        Self {
            smoothing: 0.0,
            key: Vec::new(),
            origin: Origin::Stale,
            gap: vec![0.0; laws * n],
            force: vec![0.0; laws * n],
            values: vec![0.0; laws * n],
            w_gap: vec![0.0; laws * n],
            w_force: vec![0.0; laws * n],
            coefficients: vec![0.0; len],
            scratch: vec![0.0; n],
            d_samples: vec![0.0; n],
            projection: vec![0.0; len],
            gram_gap: vec![0.0; laws * len * len],
            gram_force: vec![0.0; laws * len * len],
            along: LineSamples {
                gap: vec![0.0; laws * n],
                force: vec![0.0; laws * n],
                d_gap: vec![0.0; laws * n],
                d_force: vec![0.0; laws * n],
                ..Default::default()
            },
        }
    }

    /// Forgets every sample (after a change of frequency, smoothing or blend).
    pub(super) fn invalidate(&mut self) {
        self.origin = Origin::Stale;
        self.along.start = None;
    }

    /// Sets the smoothing of the laws (forgetting every sample).
    pub(super) fn set_smoothing(&mut self, smoothing: f64) {
        self.smoothing = smoothing;
        self.invalidate();
    }

    /// Whether the samples are those of `x` and were made in one of the ways `origins`.
    fn holds(&self, x: &[f64], origins: &[Origin]) -> bool {
        origins.contains(&self.origin) && self.key == x
    }

    /// Records that the samples are those of `x`, made as `origin` says.
    fn mark(&mut self, x: &[f64], origin: Origin) {
        self.key.clear();
        self.key.extend_from_slice(x);
        self.origin = origin;
    }

    /// Makes the samples a synthesis of `x` for a residual evaluation: kept if they are one
    /// already, synthesised otherwise.
    pub(super) fn synthesis<B: Basis>(
        &mut self,
        d: &Discretization<B>,
        rows: &[HarmonicRows],
        x: &[f64],
    ) {
        if !self.holds(x, &[Origin::Synthesis]) {
            self.synthesize(d, rows, x);
        }
    }

    /// Synthesises the samples of `x` and evaluates the laws on them.
    fn synthesize<B: Basis>(&mut self, d: &Discretization<B>, rows: &[HarmonicRows], x: &[f64]) {
        d.synthesize_observables(
            (rows, x, true),
            &mut self.coefficients,
            &mut self.gap,
            &mut self.force,
        );
        self.evaluate(d);
        self.mark(x, Origin::Synthesis);
    }

    /// Makes the samples those of `x` for a Jacobian-type evaluation: kept if they are
    /// already those of `x`, of either [`Origin`], synthesised otherwise.
    pub(super) fn at<B: Basis>(&mut self, d: &Discretization<B>, rows: &[HarmonicRows], x: &[f64]) {
        if !self.holds(x, &[Origin::Synthesis, Origin::Ray]) {
            self.synthesize(d, rows, x);
        }
    }

    /// Evaluates the laws on the gap and force samples.
    fn evaluate<B: Basis>(&mut self, d: &Discretization<B>) {
        let out = LawSamples {
            values: &mut self.values,
            d_gap: &mut self.w_gap,
            d_force: &mut self.w_force,
        };
        d.evaluate_laws(
            (&self.gap, &self.force, self.smoothing),
            out,
            &mut self.scratch,
        );
    }

    /// The law block of `F` from the samples, into `f` (the whole residual).
    pub(super) fn project<B: Basis>(&self, d: &Discretization<B>, f: &mut [f64]) {
        d.project_laws(&self.values, f);
    }

    /// A line search's evaluation at the trial `trial = x + t dx`: the linear block of
    /// `F(trial)` into `f` and the law samples of the trial, formed along the ray
    /// ([`Origin::Ray`]); the law block is then [`Samples::project`]'s.
    ///
    /// The samples and linear rows of `x` and `dx` are kept for the next trial along the same
    /// ray. Those of `x` are taken over from the current samples when they are those of `x`,
    /// of either [`Origin`] (the residual at `x` was just evaluated), and synthesised
    /// otherwise.
    pub(super) fn along<B: Basis>(
        &mut self,
        (d, rows): (&Discretization<B>, &[HarmonicRows]),
        (x, dx, t): (&[f64], &[f64], f64),
        trial: &[f64],
        f: &mut [f64],
    ) {
        let same = |v: &Option<Vec<f64>>, w: &[f64]| v.as_deref() == Some(w);
        if !(same(&self.along.start, x) && same(&self.along.direction, dx)) {
            let start_sampled = self.holds(x, &[Origin::Synthesis, Origin::Ray]);
            let along = &mut self.along;
            if start_sampled {
                // The samples of x move to the line search: the trials overwrite them next.
                std::mem::swap(&mut along.gap, &mut self.gap);
                std::mem::swap(&mut along.force, &mut self.force);
                self.origin = Origin::Stale;
            } else {
                d.synthesize_observables(
                    (rows, x, true),
                    &mut self.coefficients,
                    &mut along.gap,
                    &mut along.force,
                );
            }
            d.synthesize_observables(
                (rows, dx, false),
                &mut self.coefficients,
                &mut along.d_gap,
                &mut along.d_force,
            );
            let linear = d.basis().len() * d.linear_count;
            along.linear.resize(linear, 0.0);
            along.d_linear.resize(linear, 0.0);
            d.linear_block(rows, x, false, &mut along.linear);
            d.linear_block(rows, dx, false, &mut along.d_linear);
            set_key(&mut along.start, x);
            set_key(&mut along.direction, dx);
        }
        let along = &self.along;
        let on_ray = |out: &mut [f64], a: &[f64], d: &[f64]| {
            for (o, (a, d)) in out.iter_mut().zip(a.iter().zip(d)) {
                *o = a + t * d;
            }
        };
        on_ray(&mut self.gap, &along.gap, &along.d_gap);
        on_ray(&mut self.force, &along.force, &along.d_force);
        on_ray(f, &along.linear, &along.d_linear);
        self.evaluate(d);
        self.mark(trial, Origin::Ray);
    }

    /// Forms the Gram matrices of law `l` from its gradient samples (see
    /// [`Discretization::law_grams`]); [`Samples::grams`] reads them.
    pub(super) fn form_grams<B: Basis>(&mut self, d: &Discretization<B>, l: usize) {
        let (n, len) = (d.basis().folded_samples(), d.basis().len());
        let range = l * n..(l + 1) * n;
        let grams = l * len * len..(l + 1) * len * len;
        d.law_grams(
            (&self.w_gap[range.clone()], &self.w_force[range]),
            &mut self.gram_gap[grams.clone()],
            &mut self.gram_force[grams],
        );
    }

    /// The Gram matrices `(G(w_gap), G(w_force))` of law `l` (`len x len` each), as last
    /// formed by [`Samples::form_grams`].
    pub(super) fn grams(&self, l: usize, len: usize) -> (&[f64], &[f64]) {
        let range = l * len * len..(l + 1) * len * len;
        (&self.gram_gap[range.clone()], &self.gram_force[range])
    }

    /// The law block of `dF/dOmega` at `x` into `df` (the whole derivative), from the
    /// current gradient samples (those of `x`).
    pub(super) fn law_derivative<B: Basis>(
        &mut self,
        (d, rows): (&Discretization<B>, &[HarmonicRows]),
        x: &[f64],
        df: &mut [f64],
    ) {
        let (basis, len, n) = (d.basis(), d.basis().len(), d.basis().folded_samples());
        let base = len * d.linear_count;
        for l in 0..d.laws {
            let (c, dg, s) = (
                &mut self.coefficients,
                &mut self.d_samples,
                &mut self.scratch,
            );
            d.observable_coefficients(rows, x, (l, true, true), c);
            basis.synthesize_folded(c, dg);
            d.observable_coefficients(rows, x, (l, false, true), c);
            basis.synthesize_folded(c, s);
            let range = l * n..(l + 1) * n;
            let (w_gap, w_force) = (&self.w_gap[range.clone()], &self.w_force[range]);
            for (((s, d), wg), wf) in s.iter_mut().zip(dg.iter()).zip(w_gap).zip(w_force) {
                *s = wg * d + wf * *s;
            }
            basis.project_folded(s, &mut self.projection);
            df[base + l * len..base + (l + 1) * len].copy_from_slice(&self.projection);
        }
    }

    /// The number of time samples (with their multiplicity) in which each law's gap branch
    /// is active (nonzero gap gradient), from the current samples.
    pub(super) fn active_set<B: Basis>(&self, d: &Discretization<B>) -> Vec<usize> {
        let n = d.basis().folded_samples();
        (0..d.laws)
            .map(|l| {
                self.w_gap[l * n..(l + 1) * n]
                    .iter()
                    .enumerate()
                    .filter(|(_, w)| **w != 0.0)
                    .map(|(k, _)| d.basis().multiplicity(k))
                    .sum()
            })
            .collect()
    }
}
