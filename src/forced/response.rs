//! Frequency-response curves: continuation of a [`ForcedSystem`] in the forcing frequency,
//! natural-parameter or pseudo-arclength (through folds), from the open-contact linear
//! response at the first frequency.

use crate::continuation::{
    linspace, ArclengthOptions, ArclengthScale, Branch, ContinuationProblem, Direction, EndReason,
    Ends, Predictor, Range, Sequential, SequentialOptions, Step,
};
use crate::error::{ContinuationError, Error, SettingsError};
use crate::forced::arclength::{trace, Traced};
use crate::forced::point::{measured, ResponsePoint};
use crate::forced::{ForcedSystem, Forcing};
use crate::fourier::check_memory;
use crate::modal::grazing_energy;
use crate::solve::{norm, Problem, Solver};
use crate::status::MAX_CONSECUTIVE_FAILURES;
use crate::system::{BarSystem, HarmonicBalanceSettings};
use std::ops::ControlFlow;

/// How a response curve is followed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum ResponseMethod {
    /// Natural-parameter continuation over an even grid of frequencies (default); it cannot
    /// pass a fold, where the curve turns back in frequency.
    #[default]
    Sequential,
    /// [`ResponseMethod::Sequential`] down the grid, from the high end of the range: the
    /// sweep that finds the other jump of a curve that bends over.
    SweepDown,
    /// Pseudo-arclength continuation in `(x, Omega)`, through folds, with the harmonic
    /// selection held while a step is corrected and moved between points (the equations
    /// jump where it changes); the folds are marked on the points.
    Arclength,
}

/// What response curve to compute.
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseRequest {
    /// Harmonic-balance settings (harmonics, samples, `a_c`, harmonic selection; the kink
    /// blend does not apply).
    pub settings: HarmonicBalanceSettings,
    /// Damping and excitations.
    pub forcing: Forcing,
    /// Forcing frequencies `(lo, hi)`, `0 < lo < hi`: the curve starts at `lo` (at `hi` for
    /// [`ResponseMethod::SweepDown`]).
    pub omega_range: (f64, f64),
    /// Grid steps (sequential), or the number of steps the arclength is sized for: it takes
    /// steps of about `4 / steps` of the curve's scaled length, at most `4 steps` of them.
    pub steps: usize,
    /// Sequential or arclength.
    pub method: ResponseMethod,
    /// The corrector (semismooth Newton by default).
    pub solver: Solver,
}

/// A computed response curve.
#[derive(Debug, Clone)]
pub struct ForcedResponse {
    problem: ForcedSystem,
    /// The grazing energy `E_g` the energies are normalised by.
    pub grazing_energy: f64,
    /// Every point computed, in order (the failed steps of a sequential run included).
    pub points: Vec<ResponsePoint>,
    /// Rejected corrector steps of an arclength run.
    pub rejected_steps: usize,
    /// The frequencies where a sweep left the branch it followed, in order: its last
    /// converged point before the steps that failed (empty for arclength).
    pub jumps: Vec<f64>,
    /// Why the run ended.
    pub end: EndReason,
}

impl ForcedResponse {
    /// The problem the points solve (at the frequency of the last point measured).
    pub fn problem(&self) -> &ForcedSystem {
        &self.problem
    }

    /// The converged points.
    pub fn converged(&self) -> impl Iterator<Item = &ResponsePoint> {
        self.points.iter().filter(|p| p.converged)
    }

    /// The folds of the curve, in order along it.
    pub fn folds(&self) -> impl Iterator<Item = &ResponsePoint> {
        self.points.iter().filter(|p| p.fold)
    }

    /// The converged point of largest energy (the resonance peak), if any.
    pub fn peak(&self) -> Option<&ResponsePoint> {
        self.converged()
            .max_by(|a, b| a.energy.total_cmp(&b.energy))
    }
}

/// The frequency-response curve `request` asks for: the response of `system` under the
/// request's forcing, continued in the forcing frequency over its range.
///
/// The start is the open-contact linear response at `lo`
/// ([`ForcedSystem::open_response`]) solved with the laws. The arclength norm is scaled by
/// the range in `Omega` and, in the state, by the largest open-contact response over the
/// range, cut to the size that just closes the first gap: both come from the system.
///
/// # Errors
/// [`SettingsError`] and [`ForcingError`](crate::ForcingError) as [`ForcedSystem::new`];
/// [`SettingsError::Range`] for a frequency range that is not positive and finite, empty
/// or reversed (`lo > hi`), quoting it;
/// [`ContinuationError`] for zero steps or a start that does not converge, and
/// [`ContinuationError::TooLarge`] for more steps than the memory budget holds (the grid's
/// values, or the arclength's `4 steps` points). A run that stops
/// part-way returns its points and its [`EndReason`].
pub fn forced_response(
    system: &BarSystem,
    request: &ResponseRequest,
) -> Result<ForcedResponse, Error> {
    let (lo, hi) = request.omega_range;
    // A range given downwards is refused: the method says which way a sweep goes.
    Range::bounds("forcing frequency range", (lo, hi)).check(Ends::Positive, Direction::Rising)?;
    if request.steps == 0 {
        return Err(ContinuationError::InvalidOption {
            what: "steps",
            value: 0.0,
        }
        .into());
    }
    let mut problem = ForcedSystem::new(system, request.settings, &request.forcing)?;
    let (e_g, _) = grazing_energy(system)?;
    let solver = request.solver;
    let down = request.method == ResponseMethod::SweepDown;
    problem.set_parameter(if down { hi } else { lo });
    let start = problem.open_response()?;
    let traced = match request.method {
        ResponseMethod::Sequential | ResponseMethod::SweepDown => {
            let mut steps: Vec<Step> = Vec::new();
            let mut values = linspace(lo, hi, request.steps)?;
            if down {
                values.reverse();
            }
            let (branch, jumps) = sweep(&mut problem, &solver, start, &values, &mut |s: &Step| {
                steps.push(s.clone());
                ControlFlow::Continue(())
            })?;
            let points = (steps.iter().filter_map(Step::point).enumerate())
                .map(|(step, p)| measured(&mut problem, step, p, e_g))
                .collect();
            Traced {
                points,
                rejections: branch.rejections,
                end: branch.end,
                jumps,
            }
        }
        ResponseMethod::Arclength => {
            let options = arclength_options(&mut problem, request)?;
            problem.set_parameter(lo);
            let step = (hi - lo) / request.steps as f64;
            trace(&mut problem, &solver, start, options, (e_g, step))?
        }
    };
    Ok(ForcedResponse {
        problem,
        grazing_energy: e_g,
        points: traced.points,
        rejected_steps: traced.rejections,
        jumps: traced.jumps,
        end: traced.end,
    })
}

/// The options of an arclength run over the request's range, sized for its steps.
///
/// # Errors
/// [`ContinuationError::TooLarge`] for more points than the memory budget holds;
/// [`SettingsError::NotPositive`] for a range with no open-contact response to scale by.
fn arclength_options(
    problem: &mut ForcedSystem,
    request: &ResponseRequest,
) -> Result<ArclengthOptions, Error> {
    let (lo, hi) = request.omega_range;
    let steps = request.steps;
    // The run keeps every point it takes, up to `4 steps` of them: a budget checked
    // before it starts, as the sequential grid's values are (an unbounded count
    // would run for ever).
    let dimension = problem.dimension() as f64 + 1.0;
    check_memory(
        "the points of an arclength response",
        4.0 * steps as f64 * dimension,
    )
    .map_err(ContinuationError::TooLarge)?;
    let scale = state_scale(problem, (lo, hi), steps)?;
    let ds_max = 4.0 / steps as f64;
    let options = ArclengthOptions {
        ds: 0.5 * ds_max,
        ds_min: 1e-4 * ds_max,
        ds_max,
        max_steps: steps.saturating_mul(4),
        parameter_range: (lo, hi),
        scale: ArclengthScale::Fixed(scale, hi - lo),
        branch_points: false,
        ..Default::default()
    };
    Ok(options)
}

/// Natural-parameter continuation over `values`, as a frequency sweep of an experiment: where
/// the branch followed ends (a resonant branch past its peak, a fold), its steps fail over a
/// span of frequencies ([`allowed_failures`]), and the sweep drops to the open-contact
/// response at the next value and goes on from there. The branch's end reason is the last
/// run's; its points and rejections are every run's. Also returns the frequencies of the last
/// converged points of the runs that ended so (the sweep's jumps).
fn sweep(
    problem: &mut ForcedSystem,
    solver: &Solver,
    start: Vec<f64>,
    values: &[f64],
    observer: &mut impl FnMut(&Step) -> ControlFlow<()>,
) -> Result<(Branch, Vec<f64>), Error> {
    let grid_step = match values {
        [a, b, ..] => (b - a).abs(),
        _ => 0.0,
    };
    let eta = problem.damping().iter().copied().fold(0.0, f64::max);
    let options = SequentialOptions {
        predictor: Predictor::Secant,
        max_consecutive_failures: allowed_failures(grid_step, eta),
        ..Default::default()
    };
    let mut all = Branch {
        points: Vec::new(),
        rejections: 0,
        end: EndReason::Completed,
    };
    let (mut start, mut at, mut jumps) = (start, 0, Vec::new());
    loop {
        let mut seen = 0;
        let mut driver =
            Sequential::new(&mut *problem, solver, start, values[at..].to_vec(), options)?;
        let branch = driver.run(&mut |s: &Step| {
            if let Step::Accepted(_) | Step::Rejected(_) = s {
                seen += 1;
            }
            observer(s)
        });
        let left = (branch.points.iter().rev())
            .find(|p| p.converged)
            .map(|p| p.parameter);
        all.points.extend(branch.points);
        all.rejections += branch.rejections;
        all.end = branch.end;
        at += seen;
        if !matches!(all.end, EndReason::Stalled { .. }) || at >= values.len() {
            return Ok((all, jumps));
        }
        jumps.extend(left);
        problem.set_parameter(values[at]);
        match problem.open_response() {
            Ok(x) => start = x,
            // The open system is singular there (an undamped natural frequency): the sweep
            // ends stalled, with what it has.
            Err(_) => return Ok((all, jumps)),
        }
    }
}

/// Consecutive failed steps a sweep in steps of `grid_step` allows before it leaves the
/// branch: as many as span [`MAX_CONSECUTIVE_FAILURES`] widths `eta` of a linear resonance
/// peak (`eta` the largest damping of the bars), so that the branch is given up over the same
/// frequencies on any grid (counted in steps, a fine grid left it early). Without damping, or
/// on a one-value grid, [`MAX_CONSECUTIVE_FAILURES`] steps.
fn allowed_failures(grid_step: f64, eta: f64) -> usize {
    let span = MAX_CONSECUTIVE_FAILURES as f64 * eta;
    let steps = span / grid_step;
    if steps.is_finite() && steps > 0.0 {
        // At most the grid's own length counts: `u32::MAX` steps bound any grid in memory.
        steps.ceil().min(f64::from(u32::MAX)) as usize
    } else {
        MAX_CONSECUTIVE_FAILURES
    }
}

/// The state scale of the arclength norm: the largest open-contact response over a grid of
/// the range, divided by its amplitude at the first contact when that exceeds 1 (contact
/// caps the response near the gap).
fn state_scale(
    problem: &mut ForcedSystem,
    (lo, hi): (f64, f64),
    steps: usize,
) -> Result<f64, Error> {
    let mut largest: (f64, f64) = (0.0, 0.0);
    for omega in linspace(lo, hi, steps.clamp(2, 64))? {
        problem.set_parameter(omega);
        // A frequency where the open system is singular (no damping, a natural frequency)
        // is skipped: its neighbours size the scale.
        if let Ok(x) = problem.open_response() {
            let size = norm(&x);
            if size.is_finite() && size > largest.0 {
                largest = (size, problem.amplitude(&x));
            }
        }
    }
    let (size, amplitude) = largest;
    let scale = if amplitude > 1.0 {
        size / amplitude
    } else {
        size
    };
    if scale.is_finite() && scale > 0.0 {
        Ok(scale)
    } else {
        Err(SettingsError::NotPositive {
            what: "open-contact response over the frequency range",
            value: scale,
        }
        .into())
    }
}
