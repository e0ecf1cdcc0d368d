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
//!
//! [`NonsmoothSystem`] is a [`Discretization`] (what the problem is: system, basis, law
//! settings, layout; never changed by an evaluation) and a workspace (what its evaluations
//! change: the rows at the current frequency and their condensation, time samples, the
//! structured step's factorisation), in files of their own:
//!
//! - `discretization.rs`: [`Discretization`] and its evaluations into given buffers;
//! - `state.rs`: the rows at one frequency and the law samples, with the record of how the
//!   samples were made (its docs state when a Jacobian-type evaluation reuses them);
//! - `shared_rows.rs`: the rows of the last few frequencies, copied by the problems on the
//!   same system instead of rebuilt;
//! - `step.rs`: the structured (condensed) Newton step;
//! - `band.rs`: the staircase Newton step of assemblies with several contacts, at a cost linear
//!   in the number of bars of a chain.

mod band;
mod discretization;
pub(crate) mod selection;
mod shared_rows;
mod staircase;
mod state;
mod step;

pub(crate) use discretization::{
    check_complementarity, law_grams, law_offsets, max_frequency, unit_gram,
};
pub use discretization::{Discretization, COMPLEMENTARITY_RANGE, MAX_OFFSET, MAX_PHASE};

use crate::continuation::ContinuationProblem;
use crate::error::{Error, SettingsError};
use crate::fourier::{Basis, CosineBasis};
use crate::linalg::DenseMatrix;
use crate::solve::{point_on_ray, Problem, SingularStep, Structured};
use crate::system::rows::HarmonicRows;
use crate::system::{BarSystem, Layout};
use band::Banded;
use selection::Selection;
use state::{Frequency, Samples};
use step::Reduced;

/// The largest swing of every gap, as a fraction of its offset, of a state of rest
/// ([`Structured::at_rest`]): `sqrt(TRIVIAL_ENERGY)`, the backbone's floor of `E / E_g` in
/// amplitude.
pub const REST_AMPLITUDE: f64 = 1e-3;

/// Harmonic-balance settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HarmonicBalanceSettings {
    /// Number of harmonics `m` (default 20).
    pub harmonics: usize,
    /// Time samples per harmonic `n_h`; the period has `N = n_h m` samples (default 30).
    pub samples_per_harmonic: usize,
    /// Complementarity parameter `a_c > 0` of `r = -min(lambda, a_c g)` (default 4), in
    /// [`COMPLEMENTARITY_RANGE`].
    pub complementarity: f64,
    /// Width, relative to the largest gap, of the band around each kink of the law in which
    /// the Jacobian blends the two one-sided derivatives (default 0: an exact element of the
    /// generalised Jacobian at every sample). The residual is never blended. The blend (the
    /// derivative of the smoothed law of [`crate::bc::smoothed_complementarity`]) acts like the
    /// finite-difference Jacobian of the paper's solver: it can converge steps whose exact
    /// Jacobian jumps between iterations, but branches near internal resonances are sensitive
    /// to it (`docs/performance.md` has the measurements), hence the exact default.
    pub kink_blend: f64,
    /// Harmonic selection: the width `c` of the band `|n Omega / omega_k - 1| < c / m` around
    /// every open- and closed-contact natural frequency `omega_k` in which a harmonic
    /// `n >= 2` is held at zero (0, the default: every harmonic kept, the paper's equations;
    /// [`RESONANCE_BAND`] is the measured choice; at most `m`). It removes the internal
    /// resonances of the truncation, so that the skeleton converges as `m` grows
    /// (`docs/theory.md`, "Harmonic selection"). With 0,
    /// [`Method::Auto`](crate::branches::Method::Auto) also runs the branch with
    /// [`RESONANCE_BAND`] and keeps the run whose skeleton covers more of its grid
    /// ([`SelectionJudgement`](crate::branches::SelectionJudgement)).
    pub resonance_band: f64,
}

/// The width `c` of [`HarmonicBalanceSettings::resonance_band`] measured on both exact
/// families (`docs/validation.md`, "Convergence in the number of harmonics"): narrower bands
/// let resonances through at large `m`, wider ones drop harmonics the motion needs. On chains
/// of several bars, whose natural frequencies are dense, it can drop too many
/// (`docs/assemblies.md`, the census), which is why
/// [`Method::Auto`](crate::branches::Method::Auto) compares it with the paper's equations
/// instead of always applying it.
pub const RESONANCE_BAND: f64 = 0.1;

impl Default for HarmonicBalanceSettings {
    fn default() -> Self {
        Self {
            harmonics: 20,
            samples_per_harmonic: 30,
            complementarity: 4.0,
            kink_blend: 0.0,
            resonance_band: 0.0,
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
///
/// # Samples reused
/// [`Problem::residual`] at `x` depends on `x` and the frequency alone. A Jacobian-type
/// evaluation at `x` (Jacobian, structured solve, `dF/dOmega`, active set) right after a
/// residual evaluation at the same `x` and frequency uses the time samples of that
/// evaluation. After [`Structured::residual_along`] these are the line search's samples of
/// the trial point, formed along the ray, which equal a synthesis of the trial to rounding
/// only: the Newton step at an accepted trial is that of the residual the line search
/// accepted. For the complementarity laws this matters only where a sample lies within
/// rounding of the law's kink (their gradient is piecewise constant); with a smoothing or a
/// custom law the Jacobian differs from a synthesis' in the last bits.
#[derive(Debug, Clone)]
pub struct NonsmoothSystem<B: Basis = CosineBasis> {
    description: Discretization<B>,
    ws: Workspace,
    /// Harmonic selection, if asked ([`HarmonicBalanceSettings::resonance_band`]).
    selection: Option<Selection>,
}

/// What the evaluations of a [`NonsmoothSystem`] change.
#[derive(Debug, Clone)]
struct Workspace {
    frequency: Frequency,
    samples: Samples,
    reduced: Reduced,
    banded: Banded,
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
        problem.set_resonance_band(settings.resonance_band)?;
        Ok(problem)
    }
}

impl<B: Basis> NonsmoothSystem<B> {
    /// The system with any basis.
    ///
    /// # Errors
    /// [`SettingsError::NotPositive`] for a bad complementarity parameter `a_c`,
    /// [`SettingsError::NoContact`] for a linear system, [`SettingsError::TooLarge`] for a
    /// problem beyond the memory budget ([`crate::fourier::MEMORY_BUDGET_BYTES`]: the Gram
    /// matrices, law samples, reduced matrix and the dense Jacobian a solver may form).
    pub fn with_basis(system: &BarSystem, basis: B, a_c: f64) -> Result<Self, Error> {
        let description = Discretization::new(system, basis, a_c)?;
        let ws = Workspace {
            frequency: Frequency::new(),
            samples: Samples::new(&description),
            reduced: Reduced::default(),
            banded: Banded::default(),
        };
        Ok(Self {
            description,
            ws,
            selection: None,
        })
    }

    /// Sets [`HarmonicBalanceSettings::resonance_band`] (0: every harmonic kept).
    ///
    /// # Errors
    /// [`SettingsError::OutOfRange`] for a width that is not finite, negative or above `m`.
    pub fn set_resonance_band(&mut self, width: f64) -> Result<(), SettingsError> {
        let m = self.description.basis().harmonics();
        self.selection = Selection::for_band(width, m)?;
        let omega = self.ws.frequency.omega;
        if let Some(s) = &mut self.selection {
            s.select((self.description.system(), self.description.basis()), omega);
        }
        self.ws.samples.invalidate();
        Ok(())
    }

    /// The width `c` of the harmonic selection's band `c / m`
    /// ([`HarmonicBalanceSettings::resonance_band`]; 0 without selection).
    pub fn resonance_band(&self) -> f64 {
        self.selection.as_ref().map_or(0.0, |s| s.width)
    }

    /// The harmonics held at zero at the current frequency by the harmonic selection
    /// ([`HarmonicBalanceSettings::resonance_band`]), ascending; empty without it.
    pub fn dropped_harmonics(&self) -> Vec<usize> {
        self.selection
            .as_ref()
            .map_or_else(Vec::new, |s| s.dropped_harmonics(self.description.basis()))
    }

    /// The basis coefficients the harmonic selection holds at zero at `omega`, ascending
    /// (empty without selection); the problem stays at its own frequency.
    pub(crate) fn held_at(&mut self, omega: f64) -> Vec<usize> {
        let (system, basis) = (self.description.system(), self.description.basis());
        (self.selection.as_mut()).map_or_else(Vec::new, |s| s.dropped_at((system, basis), omega))
    }

    /// The selection when it drops a harmonic at the current frequency.
    fn active_selection(&self) -> Option<&Selection> {
        self.selection.as_ref().filter(|s| s.active())
    }

    /// `eval` at `x`, or at `x` with the dropped harmonics zeroed while the selection drops
    /// some.
    fn at_selected<R>(&mut self, x: &[f64], eval: impl FnOnce(&mut Self, &[f64]) -> R) -> R {
        let masked = match self.selection.as_mut().filter(|s| s.active()) {
            Some(s) => s.mask((&self.description).into(), x),
            None => return eval(self, x),
        };
        let out = eval(self, &masked);
        if let Some(s) = &mut self.selection {
            s.restore(masked);
        }
        out
    }

    /// Sets [`HarmonicBalanceSettings::kink_blend`] (0 for the exact generalised Jacobian).
    ///
    /// # Errors
    /// [`SettingsError::NotPositive`] if `blend` is negative or not finite.
    pub fn set_kink_blend(&mut self, blend: f64) -> Result<(), SettingsError> {
        self.description.set_kink_blend(blend)?;
        self.ws.samples.invalidate();
        Ok(())
    }

    /// What the problem is, apart from its frequency and the state of its evaluations: the
    /// system, basis, law settings and layout, for read-only users.
    pub fn description(&self) -> &Discretization<B> {
        &self.description
    }

    /// The bar system.
    pub fn system(&self) -> &BarSystem {
        self.description.system()
    }

    /// The harmonic basis.
    pub fn basis(&self) -> &B {
        self.description.basis()
    }

    /// The complementarity parameter `a_c`.
    pub fn complementarity(&self) -> f64 {
        self.description.complementarity()
    }

    /// Number of unknowns (and equations).
    pub fn dimension(&self) -> usize {
        self.description.dimension()
    }

    /// Index in `x` of coefficient `i`, bar `bar`, Helmholtz component `which` (0: `A`, 1: `B`),
    /// as in [`Layout`].
    ///
    /// # Panics
    /// As [`Layout::index`]: for a bar or component out of range, or an index beyond `usize`.
    pub fn index(&self, i: usize, bar: usize, which: usize) -> usize {
        self.layout().index(i, bar, which)
    }

    /// Where each unknown lives.
    pub fn layout(&self) -> Layout {
        self.description.layout()
    }

    /// The per-harmonic rows at fundamental frequency `omega` (the problem moves to `omega`).
    pub fn rows_at(&mut self, omega: f64) -> &[HarmonicRows] {
        self.prepare(omega);
        &self.ws.frequency.rows
    }

    /// Moves to `omega`: the rows are rebuilt and every sample forgotten when it changed.
    fn prepare(&mut self, omega: f64) {
        if self.ws.frequency.prepare(&self.description, omega) {
            self.ws.samples.invalidate();
            if let Some(s) = &mut self.selection {
                s.select((self.description.system(), self.description.basis()), omega);
            }
        }
    }

    /// Makes the workspace's law samples those of `x` (see [`Samples::at`]).
    fn sample_laws(&mut self, x: &[f64]) {
        let Workspace {
            frequency, samples, ..
        } = &mut self.ws;
        samples.at(&self.description, &frequency.rows, x);
    }

    /// Gap samples of law `l` over one period at `omega` (the `N` instants of the grid); the
    /// problem moves to `omega`.
    ///
    /// # Panics
    /// If `l` is not below the number of unilateral conditions or `x` has the wrong length
    /// ([`crate::modal::law_history`] returns an error instead).
    pub fn gap_history(&mut self, x: &[f64], omega: f64, l: usize) -> Vec<f64> {
        self.prepare(omega);
        (self.description).history(&self.ws.frequency.rows, x, l, true)
    }

    /// Contact-force samples of law `l` over one period at `omega`.
    ///
    /// # Panics
    /// If `l` is not below the number of unilateral conditions or `x` has the wrong length
    /// ([`crate::modal::law_history`] returns an error instead).
    pub fn force_history(&mut self, x: &[f64], omega: f64, l: usize) -> Vec<f64> {
        self.prepare(omega);
        (self.description).history(&self.ws.frequency.rows, x, l, false)
    }

    /// The gap and force samples of law `l` at `omega` on the folded grid
    /// ([`Basis::folded_samples`]; [`Basis::folded_index`] says which one each instant of
    /// the period takes), into `gap` and `force`, with `coefficients` (one per basis
    /// function) as scratch: the values of [`NonsmoothSystem::gap_history`] and
    /// [`NonsmoothSystem::force_history`] without their repeats. The problem moves to
    /// `omega`.
    ///
    /// # Panics
    /// As [`NonsmoothSystem::gap_history`], and for buffers of other lengths.
    pub(crate) fn folded_histories(
        &mut self,
        (x, omega, l): (&[f64], f64, usize),
        coefficients: &mut [f64],
        (gap, force): (&mut [f64], &mut [f64]),
    ) {
        self.prepare(omega);
        let (d, rows) = (&self.description, &self.ws.frequency.rows);
        d.folded_history((rows, x), (l, true), coefficients, gap);
        d.folded_history((rows, x), (l, false), coefficients, force);
    }

    /// Pointwise law residual `r(theta_k)` of law `l` over one period at `omega`.
    ///
    /// # Panics
    /// If `l` is not below the number of unilateral conditions or `x` has the wrong length
    /// ([`crate::modal::law_history`] returns an error instead).
    pub fn law_residual_history(&mut self, x: &[f64], omega: f64, l: usize) -> Vec<f64> {
        let g = self.gap_history(x, omega, l);
        let f = self.force_history(x, omega, l);
        let law = self.system().laws().nth(l).expect("law index in range");
        g.iter()
            .zip(&f)
            .map(|(&g, &f)| law.residual(g, f, self.complementarity()).value)
            .collect()
    }
}

impl<B: Basis> Problem for NonsmoothSystem<B> {
    fn dimension(&self) -> usize {
        self.dimension()
    }

    /// From a synthesis of `x`: the value depends on `x` and `Omega` alone.
    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        self.at_selected(x, |p, y| p.full_residual(y, f));
        if let Some(s) = self.active_selection() {
            s.residual((&self.description).into(), x, f);
        }
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix) {
        self.at_selected(x, |p, y| p.full_jacobian(y, jac));
        if let Some(s) = self.active_selection() {
            s.jacobian((&self.description).into(), jac);
        }
    }

    fn structure(&mut self) -> Option<&mut dyn Structured> {
        Some(self)
    }
}

impl<B: Basis> NonsmoothSystem<B> {
    /// The residual of every harmonic at `x`.
    fn full_residual(&mut self, x: &[f64], f: &mut [f64]) {
        let (d, rows) = (&self.description, &self.ws.frequency.rows);
        d.linear_block(rows, x, false, f);
        self.ws.samples.synthesis(d, rows, x);
        self.ws.samples.project(d, f);
    }

    /// The generalised Jacobian of every harmonic at `x`.
    fn full_jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix) {
        self.sample_laws(x);
        let d = &self.description;
        let Workspace {
            frequency, samples, ..
        } = &mut self.ws;
        let (len, un, rpc) = (d.basis().len(), d.unknowns, d.linear_count);
        jac.reset(d.dimension(), d.dimension());
        for i in 0..len {
            let rows = &frequency.rows[d.basis().harmonic(i)];
            for r in 0..rpc {
                for (c, &v) in rows.linear_row(r).iter().enumerate() {
                    jac[(i * rpc + r, i * un + c)] = v;
                }
            }
        }
        let base = len * rpc;
        for l in 0..d.laws {
            samples.form_grams(d, l);
            let (gram_gap, gram_force) = samples.grams(l, len);
            // Column by column (the matrix is column-major): contiguous writes.
            for i in 0..len {
                let rows = &frequency.rows[d.basis().harmonic(i)];
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
    }
}

impl<B: Basis> ContinuationProblem for NonsmoothSystem<B> {
    /// The fundamental frequency `Omega` (NaN before the first [`Self::set_parameter`]).
    fn parameter(&self) -> f64 {
        self.ws.frequency.omega
    }

    /// Moves to fundamental frequency `omega`: the per-harmonic rows are rebuilt when it
    /// changes.
    fn set_parameter(&mut self, omega: f64) {
        self.prepare(omega);
    }

    fn parameter_derivative(&mut self, x: &[f64], df: &mut [f64]) {
        self.at_selected(x, |p, y| {
            p.sample_laws(y);
            let (d, rows) = (&p.description, &p.ws.frequency.rows);
            d.linear_block(rows, y, true, df);
            p.ws.samples.law_derivative((d, rows), y, df);
        });
        if let Some(s) = self.active_selection() {
            s.parameter_derivative((&self.description).into(), df);
        }
    }
}

impl<B: Basis> Structured for NonsmoothSystem<B> {
    /// The largest gap of the unilateral laws: residual entries are gaps and forces of that
    /// order.
    fn residual_scale(&self) -> f64 {
        self.description.residual_scale()
    }

    /// At rest: the gap of every unilateral law swings over the period by at most
    /// [`REST_AMPLITUDE`] times its offset `g0`. A motion that touches closes some gap by
    /// `g0`; one of energy `E` swings by about `sqrt(E / E_g) g0`, so the bound is the
    /// backbone's [`TRIVIAL_ENERGY`](crate::branches::TRIVIAL_ENERGY) of `E_g` in amplitude.
    /// `None` for a law whose offset is zero (no scale to measure against) or a state of
    /// the wrong length.
    fn at_rest(&mut self, x: &[f64]) -> Option<bool> {
        if x.len() != self.dimension() {
            return None;
        }
        let offsets: Vec<f64> = (self.description.system().laws())
            .map(|l| l.gap().offset.abs())
            .collect();
        if offsets.iter().any(|g| !(g.is_finite() && *g > 0.0)) {
            return None;
        }
        let omega = self.ws.frequency.omega;
        let mut rest = true;
        for (l, g0) in offsets.iter().enumerate() {
            let gaps = self.gap_history(x, omega, l);
            // A gap that overflows says nothing of rest (and `min`/`max` would skip a NaN).
            if gaps.iter().any(|g| !g.is_finite()) {
                return None;
            }
            let (lo, hi) = (gaps.iter()).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), g| {
                (lo.min(*g), hi.max(*g))
            });
            rest &= hi - lo <= 2.0 * REST_AMPLITUDE * g0;
        }
        Some(rest)
    }

    /// The Newton step with the linear rows condensed (formulation §5): only a dense LU of
    /// size `len * n_contacts` is factorised, once for all right-hand sides. With two contacts
    /// or more, where it is cheaper, the whole Jacobian is factorised bar by bar instead (a
    /// staircase LU: linear in the number of bars of a chain, `band.rs`).
    fn solve_jacobian(
        &mut self,
        x: &[f64],
        rhs: &mut [f64],
        columns: usize,
    ) -> Option<Result<(), SingularStep>> {
        if self.active_selection().is_some() {
            // The condensed step with the dropped coefficients held (the staircase solves
            // every harmonic's equations), at the masked point as the Jacobian is.
            return self.at_selected(x, |p, y| {
                p.sample_laws(y);
                let Workspace {
                    frequency,
                    samples,
                    reduced,
                    ..
                } = &mut p.ws;
                let dropped = p.selection.as_ref().map_or(&[][..], Selection::dropped);
                let d = &p.description;
                reduced.solve((d, frequency), samples, (rhs, columns), dropped)
            });
        }
        self.sample_laws(x);
        let Workspace {
            frequency,
            samples,
            reduced,
            banded,
        } = &mut self.ws;
        let d = &self.description;
        banded
            .solve((d, frequency), samples, rhs, columns)
            .or_else(|| reduced.solve((d, frequency), samples, (rhs, columns), &[]))
    }

    /// Along a line search the observables are affine in `t`: the samples of `x` (kept from
    /// its residual) and of `dx` are synthesised once per direction, and each trial costs the
    /// law evaluation and one projection instead of three transforms. The samples of the
    /// trial are kept for a Jacobian-type evaluation there (see [`NonsmoothSystem`]).
    fn residual_along(
        &mut self,
        x: &[f64],
        dx: &[f64],
        t: f64,
        trial: &mut [f64],
        f: &mut [f64],
    ) -> bool {
        if self.active_selection().is_some() {
            return false;
        }
        point_on_ray(x, dx, t, trial);
        let (d, rows) = (&self.description, &self.ws.frequency.rows);
        self.ws.samples.along((d, rows), (x, dx, t), trial, f);
        self.ws.samples.project(d, f);
        true
    }

    fn set_smoothing(&mut self, smoothing: f64) -> bool {
        self.ws.samples.set_smoothing(smoothing.max(0.0));
        true
    }

    /// Energy weights: a harmonic `A cos(kx) + B sin(kx)/k` of bar `b` stores about
    /// `EA l (A^2 k^2 + B^2) / 4` of strain energy, so `w_A = EA l (k^2 + 1/l^2)` (the `1/l^2`
    /// keeps rigid displacements weighted) and `w_B = EA l`.
    fn state_weights(&mut self) -> Option<Vec<f64>> {
        Some(self.description.state_weights(self.ws.frequency.omega))
    }

    fn active_set(&mut self, x: &[f64]) -> Option<Vec<usize>> {
        self.at_selected(x, |p, y| {
            p.sample_laws(y);
            Some(p.ws.samples.active_set(&p.description))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::modal::branch_seed;
    use crate::reference::clamped_bar_with_obstacle;

    /// A clamped bar with an obstacle at `T = 3.9`, and a point and a direction there that use
    /// both branches of the law.
    fn problem_and_ray() -> (NonsmoothSystem, Vec<f64>, Vec<f64>) {
        let system = clamped_bar_with_obstacle(1e-3).unwrap();
        let settings = HarmonicBalanceSettings {
            harmonics: 12,
            ..Default::default()
        };
        let mut problem = NonsmoothSystem::new(&system, settings).unwrap();
        let omega = 2.0 * std::f64::consts::PI / 3.9;
        let seed = branch_seed(&mut problem, 1, 1, omega).unwrap();
        problem.set_parameter(omega);
        let wiggle = |i: usize, k: usize| ((i * k) % 11) as f64 - 5.0;
        let x = (seed.iter().enumerate())
            .map(|(i, s)| 1.7 * s + 2e-5 * wiggle(i, 7))
            .collect();
        let dx = (0..seed.len()).map(|i| 1e-6 * wiggle(i, 3)).collect();
        (problem, x, dx)
    }

    fn jacobian(problem: &mut NonsmoothSystem, x: &[f64]) -> Vec<f64> {
        let mut jac = DenseMatrix::zeros(0, 0);
        problem.jacobian(x, &mut jac);
        let n = x.len();
        (0..n * n).map(|k| jac[(k % n, k / n)]).collect()
    }

    #[test]
    fn a_synthesis_is_a_pure_function_of_the_point() {
        let (mut problem, x, _) = problem_and_ray();
        let mut fresh = problem.clone();
        let mut f = vec![0.0; x.len()];
        problem.residual(&x, &mut f);
        // Reused samples of a residual evaluation equal those of a first synthesis.
        assert_eq!(jacobian(&mut problem, &x), jacobian(&mut fresh, &x));
    }

    #[test]
    fn after_a_line_search_the_jacobian_is_that_of_the_trial_samples() {
        let (mut problem, x, dx) = problem_and_ray();
        let n = x.len();
        // Smoothed, so that the law's gradient moves with the samples (the complementarity
        // law's is piecewise constant: there, samples that agree to rounding give the same
        // Jacobian unless one of them sits on the kink).
        problem.set_smoothing(1e-5);
        let mut fresh = problem.clone();
        let (mut trial, mut f_along, mut f) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        problem.residual(&x, &mut f);
        assert!(problem.residual_along(&x, &dx, 0.5, &mut trial, &mut f_along));
        fresh.residual(&trial, &mut f);
        let scale = problem.residual_scale();
        for (a, b) in f_along.iter().zip(&f) {
            assert!((a - b).abs() <= 1e-12 * scale, "{a:e} vs {b:e}");
        }
        // The Jacobian at the trial is evaluated at the line search's samples, which agree with
        // a synthesis to rounding; once the trial's residual is evaluated afresh it is the
        // synthesis' bit for bit.
        let (along, synthesised) = (jacobian(&mut problem, &trial), jacobian(&mut fresh, &trial));
        let size = synthesised.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (a, b) in along.iter().zip(&synthesised) {
            assert!((a - b).abs() <= 1e-12 * size, "{a:e} vs {b:e}");
        }
        problem.residual(&trial, &mut f_along);
        assert_eq!(jacobian(&mut problem, &trial), synthesised);
    }
}
