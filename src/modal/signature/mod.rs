//! The signature of a computed periodic motion, for reports: how its energy is spread over the
//! harmonics (and so how much of it lies outside the multiples of a subharmonic order `K`),
//! and how many separate contact intervals each unilateral law has per period.
//!
//! Both are post-processing of one point, computed when it is written out, never inside the
//! continuation loops: [`harmonic_energies`] costs `O(m)` flops, [`contact_intervals`] one
//! law history per law.

use crate::bc::LawSamples;
use crate::check::check_finite;
use crate::check::check_frequency;
use crate::check::check_length;
use crate::check::check_unknowns_finite;
use crate::error::SettingsError;
use crate::fourier::Basis;
use crate::modal::energy::Diagonal;
use crate::system::inputs::check_motion;
use crate::system::{BarSystem, Layout, NonsmoothSystem};
use std::cell::Cell;

/// The time-averaged mechanical energy of the bars carried by each harmonic `n = 0..=m` of
/// the motion `x` at fundamental frequency `omega` (entry `n`; `m` the basis' highest
/// harmonic).
///
/// # The maths
/// The motion is `u_b(x, t) = sum_i u_(b,i)(x) phi_i(theta)`, `theta = Omega t`, with each
/// `u_(b,i) = A cos(k x) + B sin(k x)/k` a Helmholtz solution at `k = n_i Omega / c_b`
/// (`n_i` the harmonic of basis function `i`). Its energy is
/// `E(t) = sum_b EA_b/2 int (u_x^2 + u_t^2 / c_b^2) dx`, a quadratic form in the
/// `phi_i(theta)` and `Omega phi_i'(theta)`. Over a period, functions of distinct harmonics
/// are orthogonal (`<cos(n theta) cos(n' theta)> = 0` for `n != n'`, and likewise with
/// sines), so the time average `<E>` is a sum over harmonics of
///
/// ```text
/// E_n = sum_b EA_b/2 sum_(i,j: n_i = n_j = n) ( <phi_i phi_j> int u_i' u_j' dx
///                                           + (Omega/c_b)^2 <phi_i' phi_j'> int u_i u_j dx ),
/// ```
///
/// the time-averaged energy of harmonic `n` moving alone (bar by bar:
/// [`harmonic_energies_by_bar`]). For the cosine basis
/// (`phi_n = cos(n theta)`, `phi_0 = 1/2`) this is
/// `EA/4 (int u_n'^2 dx + (n Omega/c)^2 int u_n^2 dx)` for `n >= 1` and `EA/8 int u_0'^2 dx`
/// for the constant (`EA/2 int (u_0/2)'^2`: the constant function is `1/2`). The space
/// integrals are the closed forms the energy uses for equal wavenumbers
/// ([`mod@crate::modal::energy`]). The time averages come from the basis itself, so that any
/// [`Basis`] is handled with its own normalisation: a function of harmonic `n`
/// ([`Basis::harmonic`]) is `phi_i = c_i cos(n theta) + s_i sin(n theta)` with
/// `c_i = phi_i(0)` and `s_i = phi_i'(0) / n`, whence
/// `<phi_i phi_j> = (c_i c_j + s_i s_j) / 2` and `<phi_i' phi_j'> = n^2 <phi_i phi_j>`
/// (`c_i c_j` and 0 for `n = 0`): one evaluation of the basis, `O(m)` flops in all (more
/// only for a basis with several functions per harmonic). Each `E_n` is the
/// average of a non-negative energy, so it is non-negative (it is clamped at 0 against the
/// rounding of the closed forms).
///
/// The energies stored in conditions (ground springs) are left out: they are quadratic in the
/// end displacements and would split over the harmonics in the same way, but they are a small
/// part of the energy of the paper's systems, and a share of the bars' energy is what the
/// reports need. The sum over `n` is thus the time average of the bars' energy, which for an
/// exact motion without springs is the constant energy [`crate::modal::energy()`] returns.
///
/// # Errors
/// [`SettingsError::Length`] if `x` is not `basis.len()` times the system's unknowns per
/// harmonic; [`SettingsError::NotPositive`] or [`SettingsError::FrequencyTooSmall`] for an
/// `omega` that is not positive and finite or below
/// [`MIN_FREQUENCY`](crate::modal::MIN_FREQUENCY), and `NotPositive` for
/// unknowns that are not finite; [`SettingsError::NonFiniteResult`] if an energy overflows.
pub fn harmonic_energies<B: Basis>(
    system: &BarSystem,
    basis: &B,
    x: &[f64],
    omega: f64,
) -> Result<Vec<f64>, SettingsError> {
    let by_bar = harmonic_energies_by_bar(system, basis, x, omega)?;
    let mut energies = vec![0.0; basis.harmonics() + 1];
    for bar in &by_bar {
        energies.iter_mut().zip(bar).for_each(|(e, b)| *e += b);
    }
    Ok(energies)
}

/// The energies of [`harmonic_energies`] bar by bar: entry `[b][n]` is bar `b`'s share of
/// `E_n` (the sum over `b` is `E_n`). What identifies a motion in an assembly is often one
/// bar's harmonic content (bar 1 in its sixth mode on harmonic 5 while bar 2 is in its first).
///
/// # Errors
/// Those of [`harmonic_energies`].
pub fn harmonic_energies_by_bar<B: Basis>(
    system: &BarSystem,
    basis: &B,
    x: &[f64],
    omega: f64,
) -> Result<Vec<Vec<f64>>, SettingsError> {
    // A product beyond `usize` is no length `x` can have.
    check_length(
        x,
        basis.len().saturating_mul(system.unknowns_per_harmonic()),
    )?;
    check_frequency(omega)?;
    check_unknowns_finite(x)?;
    let (len, m) = (basis.len(), basis.harmonics());
    // Each basis function is `phi_i = c_i cos(n theta) + s_i sin(n theta)`, `n = n_i`:
    // `c_i = phi_i(0)`, `s_i = phi_i'(0) / n`.
    let (mut c, mut s) = (vec![0.0; len], vec![0.0; len]);
    basis.functions_at(0.0, &mut c);
    basis.derivatives_at(0.0, &mut s);
    // Coefficients grouped by harmonic (one each for the cosine basis).
    let mut groups: Vec<Vec<usize>> = vec![Vec::new(); m + 1];
    for (i, s) in s.iter_mut().enumerate() {
        let n = basis.harmonic(i);
        *s = if n == 0 { 0.0 } else { *s / n as f64 };
        groups[n].push(i);
    }
    let layout = Layout::of(system);
    let mut energies = vec![vec![0.0; m + 1]; system.bars().len()];
    for (n, group) in groups.iter().enumerate() {
        // `<phi_i phi_j> = (c_i c_j + s_i s_j) / 2` for `n >= 1`, `c_i c_j` for `n = 0`;
        // `<phi_i' phi_j'> = n^2 <phi_i phi_j>`.
        let half = if n == 0 { 1.0 } else { 0.5 };
        for (b, bar) in system.bars().iter().enumerate() {
            let k = bar.wavenumber(n as f64 * omega);
            let diagonal = Diagonal::at(k, bar.length());
            let mut sum = 0.0;
            for &i in group {
                for &j in group {
                    let average = half * (c[i] * c[j] + s[i] * s[j]);
                    let (int_uu, int_dd) =
                        diagonal.integrals(layout.pair(x, i, b), layout.pair(x, j, b));
                    sum += average * (int_dd + k * k * int_uu);
                }
            }
            energies[b][n] = (0.5 * bar.stiffness() * sum).max(0.0);
        }
    }
    for bar in &energies {
        check_finite("a harmonic's energy", omega, bar)?;
    }
    Ok(energies)
}

/// The share, in `[0, 1]`, of the time-averaged energy of the bars carried by the harmonics
/// that are not multiples of `k`: `sum_(n mod k != 0) E_n / sum_n E_n` with the energies
/// `E_n` of [`harmonic_energies`] (whose doc has the maths; the energies stored in ground
/// springs are left out).
///
/// A motion computed on a `k`-subharmonic branch (period `k T` of a mode of period `T`) that
/// is still the `T`-periodic motion run `k` times has only harmonics that are multiples of
/// `k` and a share of 0: a share away from 0 measures how much the branch has left it, i.e.
/// the genuinely subharmonic content. Energies rather than coefficients, so that the share is
/// independent of the normalisation of the basis and of the bars, and weighs each harmonic by
/// what it carries of the motion (its strain and kinetic energy). `k = 1` gives 0 (every
/// harmonic is a multiple of 1); the share is invariant under a scaling of `x`; a motion at
/// rest (zero energy) has share 0.
///
/// # Errors
/// [`SettingsError::ZeroIndex`] for `k = 0`; those of [`harmonic_energies`].
pub fn subharmonic_share<B: Basis>(
    system: &BarSystem,
    basis: &B,
    x: &[f64],
    omega: f64,
    k: usize,
) -> Result<f64, SettingsError> {
    if k == 0 {
        return Err(SettingsError::ZeroIndex {
            what: "subharmonic order",
            value: 0,
        });
    }
    let energies = harmonic_energies(system, basis, x, omega)?;
    let (mut outside, mut inside) = (0.0, 0.0);
    for (n, e) in energies.iter().enumerate() {
        if n % k == 0 {
            inside += e;
        } else {
            outside += e;
        }
    }
    // Both sums are non-negative, so `outside <= outside + inside` in floating point too.
    let total = outside + inside;
    Ok(if total > 0.0 { outside / total } else { 0.0 })
}

/// The number of contact intervals per period of each unilateral law of `problem` (in the
/// order of [`BarSystem::laws`]) for the motion `x` at `omega`: the number of maximal runs of
/// consecutive time samples in contact, the samples being the `N` instants
/// `theta_k = 2 pi k / N` of the harmonic-balance grid over the whole period, taken
/// periodically (a run through `theta = 0` counts once). A law in contact at every sample
/// counts 1, a law never in contact 0. Summed over the laws, it is the number of contact
/// intervals per period of the assembly.
///
/// # Contact criterion
/// A sample is in contact when the law's gap branch is active there: a nonzero
/// `d r / d gap` of the law sampled by [`UnilateralLaw::sample`](crate::bc::UnilateralLaw::sample)
/// without smoothing, which for Signorini and contact laws (`r = -min(lambda, a_c g)`) means
/// `lambda >= a_c g`. It is the criterion of the active sets the continuation drivers watch
/// for grazing ([`Structured::active_set`](crate::solve::Structured::active_set)), which
/// count the same samples (with the default `kink_blend = 0`; a blended Jacobian counts the
/// samples of its blend band too).
///
/// # Whole period, not half
/// The cosine basis is even in time, so the solver evaluates its laws on the folded grid
/// `theta_0..theta_(N/2)` only (`[0, pi]`, each inner sample standing for itself and its
/// mirror `theta_(N-k)`), and its active set counts samples with that multiplicity. Runs
/// cannot be counted on the folded grid directly: a contact run through `theta = 0` or
/// `theta = pi` is one interval of the period but is cut in half by the fold, while a run
/// inside `(0, pi)` has a mirror image in `(pi, 2 pi)` and counts twice. Here the gap and
/// force are synthesised on the full grid
/// ([`NonsmoothSystem::gap_history`], [`NonsmoothSystem::force_history`], for any basis), so
/// every interval is counted once; for the cosine basis the count is even unless an interval
/// is centred on `theta = 0` or `pi`.
///
/// An interval shorter than the sample spacing `T / N` may fall between samples and be
/// missed; the harmonic-balance grid is where the law is enforced, so it is also the
/// resolution at which the solution says anything about contact.
///
/// The problem moves to `omega` (as with [`NonsmoothSystem::gap_history`]); the histories
/// are synthesised by the basis' transform, `O(N log N)` per law, cheap enough to run for
/// every point a continuation writes out.
///
/// # Errors
/// [`SettingsError::Length`] if `x` does not have the problem's dimension;
/// [`SettingsError::NotPositive`], [`SettingsError::FrequencyTooSmall`] or
/// [`SettingsError::FrequencyTooLarge`] for an `omega` that is not positive and finite or
/// outside the problem's range, and `NotPositive` for unknowns that are not finite;
/// [`SettingsError::NonFiniteResult`] if a gap or force sample overflows.
pub fn contact_intervals<B: Basis>(
    problem: &mut NonsmoothSystem<B>,
    x: &[f64],
    omega: f64,
) -> Result<Vec<usize>, SettingsError> {
    Ok(contact_samples(problem, x, omega)?
        .iter()
        .map(|contact| periodic_runs(contact))
        .collect())
}

/// For each law, whether each of the `N` instants of the full grid is in contact (the
/// criterion of [`contact_intervals`]).
pub(crate) fn contact_samples<B: Basis>(
    problem: &mut NonsmoothSystem<B>,
    x: &[f64],
    omega: f64,
) -> Result<Vec<Vec<bool>>, SettingsError> {
    let laws = contact_and_gap_samples(problem, x, omega)?;
    Ok(laws.into_iter().map(|(contact, _)| contact).collect())
}

/// One law's samples over a period: in contact or not, and the gap.
pub(crate) type ContactAndGap = (Vec<bool>, Vec<f64>);

/// For each law, [`contact_samples`] and the gap history it was computed from.
///
/// The laws are sampled on the folded grid ([`Basis::folded_samples`]), where the solver
/// samples them, and each instant of the period takes the values of its folded sample
/// ([`Basis::folded_index`]): the gap and force there are those of a synthesis on the full
/// grid bit for bit, and the law is pointwise, so the outcome is that of sampling the law at
/// every instant at a fraction of the cost (half for the cosine basis).
pub(crate) fn contact_and_gap_samples<B: Basis>(
    problem: &mut NonsmoothSystem<B>,
    x: &[f64],
    omega: f64,
) -> Result<Vec<ContactAndGap>, SettingsError> {
    check_motion(problem, x, omega)?;
    let (folded, samples) = (problem.basis().folded_samples(), problem.basis().samples());
    let laws = problem.system().contact_count();
    // Every buffer is written whole before it is read, so the buffers of an earlier call
    // serve as they are; only their growth is zeroed.
    let mut scratch = LAW_SCRATCH.take();
    let [gap, force, values, d_gap, d_force, coefficients] = &mut scratch;
    for buffer in [&mut *gap, &mut *force] {
        buffer.resize(laws * folded, 0.0);
    }
    for buffer in [&mut *values, &mut *d_gap, &mut *d_force] {
        buffer.resize(folded, 0.0);
    }
    coefficients.resize(problem.basis().len(), 0.0);
    // The histories first: they move the problem to `omega`, the laws then borrow it.
    let per_law = gap
        .chunks_exact_mut(folded)
        .zip(force.chunks_exact_mut(folded));
    for (l, (g, f)) in per_law.enumerate() {
        problem.folded_histories((x, omega, l), coefficients, (g, f));
    }
    // Law by law, its gaps then its forces: a sample past the middle of the period repeats
    // one before it, so the first value that is not finite is the full grid's first.
    let histories = gap.chunks_exact(folded).zip(force.chunks_exact(folded));
    let finite = check_finite(
        "a gap or contact force sample",
        omega,
        histories.flat_map(|(g, f)| g.iter().chain(f)),
    );
    if let Err(e) = finite {
        LAW_SCRATCH.set(scratch);
        return Err(e);
    }
    let a_c = problem.complementarity();
    let basis = problem.basis();
    let histories = gap.chunks_exact(folded).zip(force.chunks_exact(folded));
    let described = (problem.system().laws().zip(histories))
        .map(|(law, (gaps, forces))| {
            let out = LawSamples {
                values: &mut *values,
                d_gap: &mut *d_gap,
                d_force: &mut *d_force,
            };
            law.sample(gaps, forces, a_c, 0.0, out);
            (0..samples)
                .map(|k| {
                    let k = basis.folded_index(k);
                    (d_gap[k] != 0.0, gaps[k])
                })
                .unzip()
        })
        .collect();
    LAW_SCRATCH.set(scratch);
    Ok(described)
}

thread_local! {
    /// The folded histories, law values and derivatives and coefficients of
    /// [`contact_and_gap_samples`], kept between calls on a thread: a run describes every
    /// point it computes, and zeroed buffers per point were a few per cent of a labelled run.
    static LAW_SCRATCH: Cell<[Vec<f64>; 6]> = const {
        Cell::new([Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new()])
    };
}

/// The number of maximal runs of `true` in the periodic sequence `values` (the last value
/// precedes the first): the rises from `false` to `true`, or 1 if every value is `true`.
pub(crate) fn periodic_runs(values: &[bool]) -> usize {
    let Some(&last) = values.last() else {
        return 0;
    };
    let mut previous = last;
    let mut rises = 0;
    for &v in values {
        rises += usize::from(v && !previous);
        previous = v;
    }
    if rises == 0 && last {
        1
    } else {
        rises
    }
}

#[cfg(test)]
mod tests;
