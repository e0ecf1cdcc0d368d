//! The forced, damped harmonic-balance system `F(x; Omega) = 0` in the full Fourier basis.

use crate::bc::{LawSamples, Observable};
use crate::continuation::ContinuationProblem;
use crate::error::{Error, SettingsError};
use crate::forced::excitation::{Damping, Driven, Excitation};
use crate::forced::rows::{real_form, DampedRows};
use crate::forced::tether::{mean_observables, MEAN_TETHER};
use crate::fourier::{check_memory, Basis, SineCosineBasis};
use crate::linalg::DenseMatrix;
use crate::solve::{Problem, Structured};
use crate::system::problem::selection::{Selection, Shape};
use crate::system::problem::{check_complementarity, law_grams, law_offsets, unit_gram};
use crate::system::{BarSystem, HarmonicBalanceSettings};
use crate::ForcingError;

/// What damps and drives a system: [`Damping`] and the [`Excitation`]s at its ends.
#[derive(Debug, Clone, PartialEq)]
pub struct Forcing {
    /// Viscous damping per bar.
    pub damping: Damping,
    /// The excitations, all at the forcing frequency `Omega`, in phase (`cos(Omega t)`).
    pub excitations: Vec<Excitation>,
}

/// A bar system with damping and harmonic excitation under harmonic balance, at a variable
/// forcing frequency `Omega`: a [`Problem`] and a [`ContinuationProblem`] in `Omega`, with an
/// analytic generalised Jacobian and `dF/dOmega`.
///
/// Unknowns are those of [`crate::system::NonsmoothSystem`] in a
/// [`SineCosineBasis`] (for each coefficient `i` and bar `b`, the Helmholtz coefficients
/// `(A, B)` at `(i n_bars + b) 2 + {0, 1}`), and so are the equations (the linear rows of
/// every coefficient, then the projected laws). The forcing fixes the time origin: no phase
/// condition is needed.
///
/// # Panics
/// As [`crate::system::NonsmoothSystem`], the [`Problem`] methods panic on slices of the
/// wrong length (the drivers check them first).
#[derive(Debug, Clone)]
pub struct ForcedSystem {
    pub(super) system: BarSystem,
    pub(super) basis: SineCosineBasis,
    complementarity: f64,
    damping: Vec<f64>,
    driven: Vec<Driven>,
    pub(super) omega: f64,
    /// Rows of harmonics `0..=m` at `omega`.
    pub(super) rows: Vec<DampedRows>,
    /// `(row, value, d value / d Omega)` of the right-hand side at harmonic 1.
    pub(super) rhs: Vec<(usize, f64, f64)>,
    pub(super) unknowns: usize,
    pub(super) linear_count: usize,
    pub(super) offsets: Vec<(f64, f64)>,
    /// Each law's observables `(gap, force)` (fixed for a system).
    observables: Vec<(Observable, Observable)>,
    /// The observables of harmonic 0, floating bars' laws tethered ([`mean_observables`]).
    pub(super) mean_observables: Vec<(Observable, Observable)>,
    /// `G(1)`, for the law Gram matrices ([`law_grams`]).
    unit_gram: Vec<f64>,
    /// Harmonic selection, if asked ([`HarmonicBalanceSettings::resonance_band`]).
    pub(super) selection: Option<Selection>,
    /// Whether a new frequency keeps the dropped harmonics ([`ForcedSystem::hold_selection`]).
    pub(super) selection_held: bool,
}

/// Time samples of every law at one state: gap, force, the law's residual and gradient.
struct LawState {
    gap: Vec<f64>,
    force: Vec<f64>,
    values: Vec<f64>,
    d_gap: Vec<f64>,
    d_force: Vec<f64>,
}

impl ForcedSystem {
    /// `system` with `forcing`, `settings.harmonics` harmonics of a full basis of
    /// `settings.samples_per_harmonic` samples each, and the complementarity parameter and
    /// the harmonic selection of `settings` (its kink blend does not apply). Its frequency is
    /// NaN until [`ContinuationProblem::set_parameter`].
    ///
    /// # Errors
    /// - [`SettingsError`] for bad harmonic settings, a linear system
    ///   ([`SettingsError::NoContact`]), an offset beyond
    ///   [`MAX_OFFSET`](crate::system::MAX_OFFSET) or a problem beyond
    ///   the memory budget;
    /// - [`ForcingError`] for bad damping, no excitation, or an excitation no condition can
    ///   carry.
    pub fn new(
        system: &BarSystem,
        settings: HarmonicBalanceSettings,
        forcing: &Forcing,
    ) -> Result<Self, Error> {
        let mut free = Self::free(system, settings)?;
        free.damping = forcing.damping.per_bar(system)?;
        if forcing.excitations.is_empty() {
            return Err(ForcingError::NoExcitation.into());
        }
        free.driven = (forcing.excitations.iter())
            .map(|&e| Driven::new(system, e))
            .collect::<Result<Vec<_>, _>>()?;
        free.mean_observables = mean_observables(system, &free.observables, MEAN_TETHER);
        free.selection = Selection::for_band(settings.resonance_band, settings.harmonics)?
            .map(Selection::dropping_low_harmonics);
        Ok(free)
    }

    /// The autonomous harmonic-balance system of `system` in the full basis without a
    /// phase condition: no damping, no excitation, no harmonic selection, at the
    /// frequency set by [`ContinuationProblem::set_parameter`]. Its Jacobian at a point of a
    /// backbone is the Hill matrix at exponent 0 ([`fn@crate::stability::hill`]).
    ///
    /// # Errors
    /// As [`ForcedSystem::new`] for the harmonic settings and the system.
    pub(crate) fn free(
        system: &BarSystem,
        settings: HarmonicBalanceSettings,
    ) -> Result<Self, Error> {
        let basis = SineCosineBasis::new(settings.harmonics, settings.samples_per_harmonic)?;
        let a_c = settings.complementarity;
        check_complementarity(a_c)?;
        if system.contact_count() == 0 {
            return Err(SettingsError::NoContact.into());
        }
        let offsets = law_offsets(system)?;
        let unknowns = system.unknowns_per_harmonic();
        let (len, laws) = (basis.len() as f64, offsets.len() as f64);
        let dimension = len * unknowns as f64;
        // Dense Jacobian (and its factors), two Gram matrices per law, law samples.
        check_memory(
            "forced harmonic-balance problem",
            3.0 * dimension * dimension
                + 2.0 * laws * len * len
                + 5.0 * laws * basis.samples() as f64,
        )?;
        Ok(Self::unforced(system, basis, a_c, offsets))
    }

    fn unforced(
        system: &BarSystem,
        basis: SineCosineBasis,
        a_c: f64,
        offsets: Vec<(f64, f64)>,
    ) -> Self {
        let unknowns = system.unknowns_per_harmonic();
        let linear_count = unknowns - system.contact_count();
        Self {
            system: system.clone(),
            complementarity: a_c,
            damping: vec![0.0; system.bars().len()],
            driven: Vec::new(),
            omega: f64::NAN,
            rows: Vec::new(),
            rhs: Vec::new(),
            unknowns,
            linear_count,
            offsets,
            observables: system.laws().map(|l| (l.gap(), l.force())).collect(),
            mean_observables: system.laws().map(|l| (l.gap(), l.force())).collect(),
            unit_gram: unit_gram(&basis),
            basis,
            selection: None,
            selection_held: false,
        }
    }

    /// The bar system.
    pub fn system(&self) -> &BarSystem {
        &self.system
    }

    /// The basis.
    pub fn basis(&self) -> &SineCosineBasis {
        &self.basis
    }

    /// The damping of each bar.
    pub fn damping(&self) -> &[f64] {
        &self.damping
    }

    /// The complementarity parameter `a_c`.
    pub fn complementarity(&self) -> f64 {
        self.complementarity
    }

    /// Offsets `(gap, force)` of each law's observables.
    pub(super) fn offsets(&self) -> &[(f64, f64)] {
        &self.offsets
    }

    /// Unknowns per coefficient (`2 n_bars`).
    pub(crate) fn unknowns(&self) -> usize {
        self.unknowns
    }

    /// The unknowns of coefficient `i` of `x`, and those of its partner with its sign.
    pub(super) fn blocks<'x>(
        &self,
        x: &'x [f64],
        i: usize,
    ) -> (&'x [f64], Option<(&'x [f64], f64)>) {
        let u = self.unknowns;
        let block = |j: usize| &x[j * u..(j + 1) * u];
        (
            block(i),
            self.basis.partner(i).map(|(p, sigma)| (block(p), sigma)),
        )
    }

    /// Coefficients of the gap (`gap`) or force of law `l` at `x` (their `Omega`-derivatives
    /// if `derivative`), one per basis function.
    pub(super) fn observable(&self, x: &[f64], l: usize, gap: bool, derivative: bool) -> Vec<f64> {
        (0..self.basis.len())
            .map(|i| {
                let rows = &self.rows[self.basis.harmonic(i)];
                let block = if gap { &rows.gap } else { &rows.force };
                let (value, d) = block.row(l);
                let (own, partner) = self.blocks(x, i);
                real_form(if derivative { d } else { value }, own, partner)
            })
            .collect()
    }

    /// The laws' samples at `x`.
    fn law_state(&self, x: &[f64]) -> LawState {
        let (n, laws) = (self.basis.samples(), self.offsets.len());
        let mut s = LawState {
            gap: vec![0.0; n * laws],
            force: vec![0.0; n * laws],
            values: vec![0.0; n * laws],
            d_gap: vec![0.0; n * laws],
            d_force: vec![0.0; n * laws],
        };
        for (l, law) in self.system.laws().enumerate() {
            let range = l * n..(l + 1) * n;
            let (g0, f0) = self.offsets[l];
            for (is_gap, offset, out) in [
                (true, g0, &mut s.gap[range.clone()]),
                (false, f0, &mut s.force[range.clone()]),
            ] {
                self.basis
                    .synthesize(&self.observable(x, l, is_gap, false), out);
                out.iter_mut().for_each(|v| *v += offset);
            }
            law.sample(
                &s.gap[range.clone()],
                &s.force[range.clone()],
                self.complementarity,
                0.0,
                LawSamples {
                    values: &mut s.values[range.clone()],
                    d_gap: &mut s.d_gap[range.clone()],
                    d_force: &mut s.d_force[range],
                },
            );
        }
        s
    }

    /// The Gram matrices `(G(w_gap), G(w_force))` of law `l` from the samples `s`.
    fn grams(&self, s: &LawState, l: usize) -> (Vec<f64>, Vec<f64>) {
        let (n, len) = (self.basis.samples(), self.basis.len());
        let range = l * n..(l + 1) * n;
        let (mut g, mut f) = (vec![0.0; len * len], vec![0.0; len * len]);
        let weights = (&s.d_gap[range.clone()], &s.d_force[range]);
        law_grams(&self.basis, &self.unit_gram, weights, (&mut g, &mut f));
        (g, f)
    }

    /// The Gram matrices `(G(w_gap), G(w_force))` of every law's generalised gradient at
    /// `x` (`len x len` each, row-major): the law block of the Jacobian is
    /// `G(w_gap) D_gap + G(w_force) D_force` with `D` the observables' rows.
    pub(crate) fn law_gram_pairs(&self, x: &[f64]) -> Vec<(Vec<f64>, Vec<f64>)> {
        let s = self.law_state(x);
        (0..self.offsets.len()).map(|l| self.grams(&s, l)).collect()
    }

    /// The laws' observables `(gap, force)`.
    pub(crate) fn observables(&self) -> &[(Observable, Observable)] {
        &self.observables
    }

    /// The linear block (its `Omega`-derivative if `derivative`) minus the right-hand side.
    fn linear_block(&self, x: &[f64], derivative: bool, f: &mut [f64]) {
        let rc = self.linear_count;
        for i in 0..self.basis.len() {
            let rows = &self.rows[self.basis.harmonic(i)];
            let (own, partner) = self.blocks(x, i);
            for r in 0..rc {
                let (value, d) = rows.linear.row(r);
                f[i * rc + r] = real_form(if derivative { d } else { value }, own, partner);
            }
        }
        for &(r, value, d) in &self.rhs {
            f[rc + r] -= if derivative { d } else { value };
        }
    }

    /// Adds `scale` times the derivative of `real_form(row, x_i, partner)` in `x` to row
    /// `target` of `jac`.
    fn add_real_form(
        &self,
        jac: &mut DenseMatrix,
        target: usize,
        i: usize,
        row: &[num_complex::Complex64],
        scale: f64,
    ) {
        let u = self.unknowns;
        for (k, a) in row.iter().enumerate() {
            jac[(target, i * u + k)] += scale * a.re;
        }
        if let Some((p, sigma)) = self.basis.partner(i) {
            for (k, a) in row.iter().enumerate() {
                jac[(target, p * u + k)] += scale * sigma * a.im;
            }
        }
    }

    /// The layout the harmonic selection edits.
    fn shape(&self) -> Shape {
        Shape {
            per: self.unknowns,
            linear: self.linear_count,
            len: self.basis.len(),
            laws: self.offsets.len(),
        }
    }

    /// `eval` into `out` at `x`, or at `x` with the dropped harmonics zeroed while the
    /// selection drops some; then `edit` replaces the dropped harmonics' equations in `out`.
    fn selected<O: ?Sized>(
        &mut self,
        x: &[f64],
        out: &mut O,
        eval: impl FnOnce(&Self, &[f64], &mut O),
        edit: impl FnOnce(&Selection, Shape, &mut O),
    ) {
        let shape = self.shape();
        let masked = self.selection.as_mut().filter(|s| s.active());
        let Some(masked) = masked.map(|s| s.mask(shape, x)) else {
            return eval(self, x, out);
        };
        eval(self, &masked, out);
        if let Some(s) = &mut self.selection {
            edit(s, shape, out);
            s.restore(masked);
        }
    }

    /// The harmonics held at zero at the current frequency by the harmonic selection,
    /// ascending; empty without it.
    pub fn dropped_harmonics(&self) -> Vec<usize> {
        (self.selection.as_ref()).map_or_else(Vec::new, |s| s.dropped_harmonics(&self.basis))
    }

    /// The linear rows' part of the Jacobian (the rest zero).
    fn linear_jacobian(&self, jac: &mut DenseMatrix) {
        let dim = self.dimension();
        jac.reset(dim, dim);
        let rc = self.linear_count;
        for i in 0..self.basis.len() {
            let rows = &self.rows[self.basis.harmonic(i)];
            for r in 0..rc {
                let (value, _) = rows.linear.row(r);
                self.add_real_form(jac, i * rc + r, i, value, 1.0);
            }
        }
    }
}

impl Problem for ForcedSystem {
    fn dimension(&self) -> usize {
        self.basis.len() * self.unknowns
    }

    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        self.selected(x, f, Self::full_residual, |s, shape, f| {
            s.residual(shape, x, f)
        });
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix) {
        self.selected(x, jac, Self::full_jacobian, |s, shape, jac| {
            s.jacobian(shape, jac)
        });
    }

    fn structure(&mut self) -> Option<&mut dyn Structured> {
        Some(self)
    }
}

impl ForcedSystem {
    /// The residual with every harmonic.
    fn full_residual(&self, x: &[f64], f: &mut [f64]) {
        self.linear_block(x, false, f);
        let s = self.law_state(x);
        let (n, len) = (self.basis.samples(), self.basis.len());
        let base = len * self.linear_count;
        for l in 0..self.offsets.len() {
            self.basis.project(
                &s.values[l * n..(l + 1) * n],
                &mut f[base + l * len..base + (l + 1) * len],
            );
        }
    }

    /// The Jacobian with every harmonic.
    fn full_jacobian(&self, x: &[f64], jac: &mut DenseMatrix) {
        self.linear_jacobian(jac);
        let s = self.law_state(x);
        let len = self.basis.len();
        let base = len * self.linear_count;
        for l in 0..self.offsets.len() {
            let (gram_gap, gram_force) = self.grams(&s, l);
            for i in 0..len {
                let rows = &self.rows[self.basis.harmonic(i)];
                let (gap_row, _) = rows.gap.row(l);
                let (force_row, _) = rows.force.row(l);
                for j in 0..len {
                    let target = base + l * len + j;
                    let (wg, wf) = (gram_gap[j * len + i], gram_force[j * len + i]);
                    if wg != 0.0 {
                        self.add_real_form(jac, target, i, gap_row, wg);
                    }
                    if wf != 0.0 {
                        self.add_real_form(jac, target, i, force_row, wf);
                    }
                }
            }
        }
    }
}

impl Structured for ForcedSystem {
    /// The largest gap at rest, as for [`crate::system::NonsmoothSystem`]: the law rows are
    /// of the size `a_c g` and a motion that touches moves by about the gap. (A forcing so
    /// weak that its right-hand side lies below the solver's tolerance times this scale
    /// leaves the state of rest converged: its response cannot reach the obstacles.)
    fn residual_scale(&self) -> f64 {
        self.offsets
            .iter()
            .map(|o| o.0.abs())
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE)
    }
}

impl ContinuationProblem for ForcedSystem {
    /// The forcing frequency `Omega`.
    fn parameter(&self) -> f64 {
        self.omega
    }

    fn set_parameter(&mut self, omega: f64) {
        if omega.to_bits() == self.omega.to_bits() {
            return;
        }
        self.omega = omega;
        if !self.selection_held {
            self.reselect();
        }
        let m = self.basis.harmonics();
        self.rows = (0..=m)
            .map(|n| {
                let laws = if n == 0 {
                    &self.mean_observables
                } else {
                    &self.observables
                };
                DampedRows::new(&self.system, laws, n, omega, &self.damping)
            })
            .collect();
        self.rhs = (self.driven.iter())
            .map(|d| {
                let (value, derivative) = d.right_hand_side(&self.system, omega);
                (d.row, value, derivative)
            })
            .collect();
    }

    fn parameter_derivative(&mut self, x: &[f64], df: &mut [f64]) {
        self.selected(x, df, Self::full_parameter_derivative, |s, shape, df| {
            s.parameter_derivative(shape, df)
        });
    }
}

impl ForcedSystem {
    /// `dF/dOmega` with every harmonic.
    fn full_parameter_derivative(&self, x: &[f64], df: &mut [f64]) {
        self.linear_block(x, true, df);
        let s = self.law_state(x);
        let len = self.basis.len();
        let base = len * self.linear_count;
        for l in 0..self.offsets.len() {
            let (gram_gap, gram_force) = self.grams(&s, l);
            let d_gap = self.observable(x, l, true, true);
            let d_force = self.observable(x, l, false, true);
            for j in 0..len {
                df[base + l * len + j] = (0..len)
                    .map(|i| {
                        gram_gap[j * len + i] * d_gap[i] + gram_force[j * len + i] * d_force[i]
                    })
                    .sum();
            }
        }
    }
}
