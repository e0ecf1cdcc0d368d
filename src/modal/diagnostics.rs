//! Diagnostics of one computed periodic motion: end histories, fields on a space-time grid,
//! the Signorini residual and its norm `R^(m)`, penetration, contact force and energy drift.
//!
//! Time signals are evaluated on a grid finer than the harmonic-balance grid (by default
//! `8 N` instants), so that the residual norm measures the motion between the collocation
//! instants too.

use crate::bar::{End, EndRef};
use crate::check::check_finite;
use crate::error::SettingsError;
use crate::fourier::{check_memory, period_of_frequency, Basis};
use crate::modal::energy::energy_at;
use crate::modal::field::FieldEvaluator;
use crate::system::inputs::check_motion;
use crate::system::rows::{dot, HarmonicRows};
use crate::system::{BarSystem, NonsmoothSystem};
use std::f64::consts::PI;

/// Time histories of one end over a period.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct EndHistory {
    /// Instants `t_k = k T / samples`.
    pub time: Vec<f64>,
    /// Displacement `u`.
    pub displacement: Vec<f64>,
    /// Strain `u_x`.
    pub strain: Vec<f64>,
    /// Compressive force `-EA u_x`.
    pub contact_force: Vec<f64>,
}

/// An empty vector with room for exactly `n` values (so that what a budget check counted
/// is what is allocated: pushing into a vector without it may double its capacity), or
/// [`SettingsError::AllocationFailed`] naming `what` if the allocator refuses.
pub(crate) fn reserve_exact(what: &'static str, n: usize) -> Result<Vec<f64>, SettingsError> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| SettingsError::AllocationFailed {
            what,
            bytes: n as f64 * std::mem::size_of::<f64>() as f64,
        })?;
    Ok(v)
}

/// Histories of the end `end` over one period, on `samples` instants.
///
/// Neither `omega` nor the size of the histories is checked here;
/// [`Solution::end_history`](crate::solution::Solution::end_history) checks both.
///
/// # Panics
/// If `end.bar` is not a bar of the system or `x` has the wrong length; if the `4 samples`
/// values do not fit in memory (`samples` near `usize::MAX`).
pub fn end_history<B: Basis>(
    system: &BarSystem,
    basis: &B,
    x: &[f64],
    omega: f64,
    end: EndRef,
    samples: usize,
) -> EndHistory {
    let h = EndHistory {
        time: Vec::with_capacity(samples),
        displacement: Vec::with_capacity(samples),
        strain: Vec::with_capacity(samples),
        contact_force: Vec::with_capacity(samples),
    };
    fill_end_history(system, basis, (x, omega), end, samples, h)
}

/// [`end_history`] with its checks: a bar of the system, `4 samples` values within the
/// memory budget and allocated exactly (or [`SettingsError::AllocationFailed`]), finite
/// values.
pub(crate) fn checked_end_history<B: Basis>(
    system: &BarSystem,
    basis: &B,
    (x, omega): (&[f64], f64),
    end: EndRef,
    samples: usize,
) -> Result<EndHistory, SettingsError> {
    check_index("bar index", end.bar.index(), system.bars().len())?;
    let what = "the samples of an end history";
    check_memory(what, 4.0 * samples as f64)?;
    let h = EndHistory {
        time: reserve_exact(what, samples)?,
        displacement: reserve_exact(what, samples)?,
        strain: reserve_exact(what, samples)?,
        contact_force: reserve_exact(what, samples)?,
    };
    let h = fill_end_history(system, basis, (x, omega), end, samples, h);
    let values = h.time.iter().chain(&h.displacement).chain(&h.strain);
    check_finite("a value of an end history", omega, values)?;
    Ok(h)
}

/// Pushes the `samples` values of each history of [`end_history`] into `h`.
fn fill_end_history<B: Basis>(
    system: &BarSystem,
    basis: &B,
    (x, omega): (&[f64], f64),
    end: EndRef,
    samples: usize,
    mut h: EndHistory,
) -> EndHistory {
    let fields = FieldEvaluator::new(system, basis, x, omega);
    let bar = system.bar(end.bar);
    let position = match end.end {
        End::Left => 0.0,
        End::Right => bar.length(),
    };
    let period = period_of_frequency(omega);
    let (mut phi, mut dphi) = (vec![0.0; basis.len()], vec![0.0; basis.len()]);
    for k in 0..samples {
        let t = period * k as f64 / samples as f64;
        // `FieldEvaluator::at` with the buffers reused.
        basis.functions_at(omega * t, &mut phi);
        basis.derivatives_at(omega * t, &mut dphi);
        let v = fields.with_functions(end.bar.index(), position, &phi, &dphi);
        h.time.push(t);
        h.displacement.push(v.displacement);
        h.strain.push(v.strain);
        h.contact_force.push(-bar.stiffness() * v.strain);
    }
    h
}

/// Checks that `index` names one of `count` items ([`SettingsError::IndexOutOfRange`]),
/// by a comparison that cannot overflow.
pub(crate) fn check_index(
    what: &'static str,
    index: usize,
    count: usize,
) -> Result<(), SettingsError> {
    if index < count {
        Ok(())
    } else {
        Err(SettingsError::IndexOutOfRange { what, index, count })
    }
}

/// Displacement `u(x, t)` of one bar on a space-time grid.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct FieldGrid {
    /// Positions `x_i` (uniform on `[0, l]`).
    pub position: Vec<f64>,
    /// Instants `t_k` (uniform on `[0, T)`).
    pub time: Vec<f64>,
    /// `u[k * position.len() + i] = u(x_i, t_k)`.
    pub displacement: Vec<f64>,
}

/// `u(x, t)` of bar `bar` on `positions x instants` points over one period.
///
/// Neither `omega` nor the size of the grid is checked here;
/// [`Solution::displacement_grid`](crate::solution::Solution::displacement_grid) checks both.
///
/// # Panics
/// If `bar` is out of range or `x` has the wrong length; if the `positions instants` values
/// do not fit in memory (their product overflows `usize`, or the allocation fails).
pub fn displacement_grid<B: Basis>(
    system: &BarSystem,
    basis: &B,
    x: &[f64],
    omega: f64,
    bar: usize,
    positions: usize,
    instants: usize,
) -> FieldGrid {
    let values = positions
        .checked_mul(instants)
        .expect("displacement_grid: positions x instants overflows usize");
    let g = FieldGrid {
        position: Vec::with_capacity(positions),
        time: Vec::with_capacity(instants),
        displacement: Vec::with_capacity(values),
    };
    fill_displacement_grid(system, basis, (x, omega), bar, (positions, instants), g)
}

/// [`displacement_grid`] with its checks: a bar of the system, `positions instants` values
/// (with the axes) within the memory budget and allocated exactly (or
/// [`SettingsError::AllocationFailed`]), finite values.
pub(crate) fn checked_displacement_grid<B: Basis>(
    system: &BarSystem,
    basis: &B,
    (x, omega): (&[f64], f64),
    bar: usize,
    (positions, instants): (usize, usize),
) -> Result<FieldGrid, SettingsError> {
    check_index("bar index", bar, system.bars().len())?;
    let what = "the values of a displacement grid";
    let (p, i) = (positions as f64, instants as f64);
    check_memory(what, p * i + p + i)?;
    // Within the budget the product fits in `usize`; checked all the same.
    let values = positions
        .checked_mul(instants)
        .ok_or(SettingsError::AllocationFailed {
            what,
            bytes: p * i * std::mem::size_of::<f64>() as f64,
        })?;
    let g = FieldGrid {
        position: reserve_exact(what, positions)?,
        time: reserve_exact(what, instants)?,
        displacement: reserve_exact(what, values)?,
    };
    let g = fill_displacement_grid(system, basis, (x, omega), bar, (positions, instants), g);
    let values = g.time.iter().chain(&g.position).chain(&g.displacement);
    check_finite("a value of a displacement grid", omega, values)?;
    Ok(g)
}

/// Pushes the axes and values of [`displacement_grid`] into `g`.
fn fill_displacement_grid<B: Basis>(
    system: &BarSystem,
    basis: &B,
    (x, omega): (&[f64], f64),
    bar: usize,
    (positions, instants): (usize, usize),
    mut g: FieldGrid,
) -> FieldGrid {
    let fields = FieldEvaluator::new(system, basis, x, omega);
    let l = system.bars()[bar].length();
    let period = period_of_frequency(omega);
    let spacing = (positions.max(2) - 1) as f64;
    g.position
        .extend((0..positions).map(|i| l * i as f64 / spacing));
    g.time
        .extend((0..instants).map(|k| period * k as f64 / instants as f64));
    let (mut phi, mut dphi) = (vec![0.0; basis.len()], vec![0.0; basis.len()]);
    for &t in &g.time {
        basis.functions_at(omega * t, &mut phi);
        basis.derivatives_at(omega * t, &mut dphi);
        for &p in &g.position {
            g.displacement
                .push(fields.with_functions(bar, p, &phi, &dphi).displacement);
        }
    }
    g
}

/// Gap, force and pointwise residual of one unilateral law over a period.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct LawHistory {
    /// Instants.
    pub time: Vec<f64>,
    /// Gap `g(t)`.
    pub gap: Vec<f64>,
    /// Contact force `lambda(t)`.
    pub force: Vec<f64>,
    /// Residual `r(t)` of the law (`-min(lambda, a_c g)` for Signorini).
    pub residual: Vec<f64>,
}

/// Histories of law `law` over one period on `samples` instants, from the same per-harmonic
/// gap and force rows ([`HarmonicRows`]) as the residual, evaluated at any phase.
///
/// # Errors
/// [`SettingsError::IndexOutOfRange`] if `law` is out of range; [`SettingsError::Length`] if
/// `x` has the wrong length;
/// [`SettingsError::NotPositive`] or [`SettingsError::FrequencyTooSmall`] for an `omega`
/// that is not positive and finite or below [`MIN_FREQUENCY`](crate::modal::MIN_FREQUENCY), and `NotPositive` for
/// unknowns that are not finite; [`SettingsError::TooLarge`] if the `4 samples` values of
/// the histories do not fit in the memory budget
/// ([`MEMORY_BUDGET_BYTES`](crate::fourier::MEMORY_BUDGET_BYTES)), and
/// [`SettingsError::AllocationFailed`] if they do but the allocator refuses them;
/// [`SettingsError::NonFiniteResult`] if an instant, gap, force or residual comes out NaN or
/// infinite (a frequency whose harmonics overflow or whose period is near `f64::MAX`, huge
/// unknowns).
pub fn law_history<B: Basis>(
    problem: &NonsmoothSystem<B>,
    x: &[f64],
    omega: f64,
    law: usize,
    samples: usize,
) -> Result<LawHistory, SettingsError> {
    let system = problem.system();
    let laws: Vec<_> = system.laws().collect();
    check_index("law index", law, laws.len())?;
    let law_ref = laws[law];
    check_motion(problem, x, omega)?;
    let what = "the samples of a law history";
    check_memory(what, 4.0 * samples as f64)?;
    // Exactly what the budget counted: pushing into empty vectors could double it.
    let mut h = LawHistory {
        time: reserve_exact(what, samples)?,
        gap: reserve_exact(what, samples)?,
        force: reserve_exact(what, samples)?,
        residual: reserve_exact(what, samples)?,
    };
    let basis = problem.basis();
    let unknowns = system.unknowns_per_harmonic();
    let rows: Vec<HarmonicRows> = (0..=basis.harmonics())
        .map(|h| HarmonicRows::new(system, h as f64 * omega))
        .collect();
    // Coefficients of the gap and force signals on the basis.
    let (gap, force): (Vec<f64>, Vec<f64>) = (0..basis.len())
        .map(|i| {
            let r = &rows[basis.harmonic(i)];
            let xi = &x[i * unknowns..(i + 1) * unknowns];
            (dot(r.gap_row(law), xi), dot(r.force_row(law), xi))
        })
        .unzip();
    let (g0, f0) = (law_ref.gap().offset, law_ref.force().offset);
    let mut phi = vec![0.0; basis.len()];
    let period = period_of_frequency(omega);
    for k in 0..samples {
        let t = period * k as f64 / samples as f64;
        basis.functions_at(omega * t, &mut phi);
        let g = g0 + dot(&phi, &gap);
        let l = f0 + dot(&phi, &force);
        h.time.push(t);
        h.gap.push(g);
        h.force.push(l);
        h.residual
            .push(law_ref.residual(g, l, problem.complementarity()).value);
    }
    let values = h
        .time
        .iter()
        .chain(&h.gap)
        .chain(&h.force)
        .chain(&h.residual);
    check_finite("a value of a law history", omega, values)?;
    Ok(h)
}

/// Summary diagnostics of a periodic motion.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PointDiagnostics {
    /// `R^(m) = sqrt(int_0^T r(t)^2 dt)` for each law (the paper's eq. 32).
    pub residual_norm: Vec<f64>,
    /// Largest penetration `max(0, -min_t g(t))` over all laws.
    pub max_penetration: f64,
    /// Smallest contact force `min_t lambda(t)` over all laws (negative: tensile).
    pub min_contact_force: f64,
    /// `(max_t E - min_t E) / E(0)` over the period (zero for an exact motion).
    pub energy_drift: f64,
}

/// Diagnostics of the motion `x` at `omega`, on `refinement` times the harmonic-balance grid
/// (at least 1; 8 is a good default) and 16 instants for the energy drift.
///
/// # Errors
/// [`SettingsError::ZeroIndex`] for `refinement = 0`; the errors of [`law_history`] (a bad
/// `x` or `omega`, histories of `refinement N` samples beyond the memory budget, a gap or
/// force that is not finite); [`SettingsError::NonFiniteResult`] if an energy or a
/// diagnostic comes out NaN or infinite.
pub fn diagnose<B: Basis>(
    problem: &NonsmoothSystem<B>,
    x: &[f64],
    omega: f64,
    refinement: usize,
) -> Result<PointDiagnostics, SettingsError> {
    if refinement == 0 {
        return Err(SettingsError::ZeroIndex {
            what: "refinement",
            value: 0,
        });
    }
    check_motion(problem, x, omega)?;
    let what = "the samples of a law history";
    let grid = problem.basis().samples() as f64 * refinement as f64;
    check_memory(what, 4.0 * grid)?;
    // Within the budget the product fits in `usize`; checked all the same.
    let samples = (problem.basis().samples()).checked_mul(refinement).ok_or(
        SettingsError::AllocationFailed {
            what,
            bytes: grid * std::mem::size_of::<f64>() as f64,
        },
    )?;
    let period = period_of_frequency(omega);
    let mut residual_norm = Vec::with_capacity(problem.system().contact_count());
    let (mut max_penetration, mut min_contact_force) = (0.0_f64, f64::INFINITY);
    for law in 0..problem.system().contact_count() {
        let h = law_history(problem, x, omega, law, samples)?;
        let dt = period / samples as f64;
        residual_norm.push((h.residual.iter().map(|r| r * r).sum::<f64>() * dt).sqrt());
        max_penetration = h.gap.iter().fold(max_penetration, |m, g| m.max(-g));
        min_contact_force = h.force.iter().cloned().fold(min_contact_force, f64::min);
    }
    let energies: Vec<f64> = (0..16)
        .map(|k| {
            energy_at(
                problem.system(),
                problem.basis(),
                x,
                omega,
                2.0 * PI * k as f64 / 16.0,
            )
        })
        .collect();
    check_finite("the energy", omega, &energies)?;
    let (lo, hi) = energies
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &e| {
            (a.min(e), b.max(e))
        });
    let energy_drift = if energies[0] > 0.0 {
        (hi - lo) / energies[0]
    } else {
        0.0
    };
    check_finite("the residual norm R^(m)", omega, &residual_norm)?;
    check_finite("the energy drift", omega, [&energy_drift])?;
    Ok(PointDiagnostics {
        residual_norm,
        max_penetration,
        min_contact_force,
        energy_drift,
    })
}
