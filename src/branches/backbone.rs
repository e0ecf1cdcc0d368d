//! Backbone curves: a nonsmooth-mode branch computed by sequential continuation in the
//! period, with energies normalised by the first grazing energy.

pub use crate::status::MAX_CONSECUTIVE_FAILURES;

use crate::branches::escape::{EscapingArclength, StallEscape};
use crate::branches::point::{BackbonePoint, PointStatus, Timescale};
use crate::branches::start::{
    check_trivial_energy, grazing_and_seed, usable_start, walk_back, BackboneStart,
};
use crate::branches::switch::{Runner, SwitchAt};
use crate::continuation::{
    linspace, Arclength, ArclengthOptions, Branch, Direction, EndReason, Ends, Observer,
    PeriodParametrised, Point, Predictor, Range, Rejection, Selection, Sequential,
    SequentialOptions, Speculation, Speculative, Step,
};
use crate::error::{BadRange, ContinuationError, Error};
use crate::fourier::frequency_of_period;
use crate::modal::energy::energy;
use crate::solve::NonlinearSolver;
use crate::system::inputs::check_frequency_of;
use crate::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};
use std::cell::RefCell;
use std::ops::ControlFlow;

/// `steps` equispaced periods from `start` to `end` (both included).
///
/// The grid may run either way: from long periods to short ones (the derived grids, from just
/// below the linear period into the hardening range) or back (from inside the nonlinear
/// range towards the linear mode). [`PeriodGrid::validate`] says which grids are refused.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PeriodGrid {
    /// First period `T0`.
    pub start: f64,
    /// Last period `T1`.
    pub end: f64,
    /// Number of periods (at least 2).
    pub steps: usize,
}

impl PeriodGrid {
    /// Checks the grid as given, before anything is computed.
    ///
    /// # Errors
    /// [`BadRange`] quoting the grid: a period that is not finite
    /// ([`RangeDefect::NotFinite`](crate::RangeDefect::NotFinite)) or not positive
    /// ([`NotPositive`](crate::RangeDefect::NotPositive)), fewer than 2 steps
    /// ([`SinglePoint`](crate::RangeDefect::SinglePoint)), or equal ends
    /// ([`Empty`](crate::RangeDefect::Empty)): every step would compute the same point. Its
    /// direction is free.
    pub fn validate(&self) -> Result<(), BadRange> {
        Range::grid("period grid", self.start, self.end, self.steps)
            .check(Ends::Positive, Direction::Either)
    }
}

/// Options of a period-grid backbone ([`Method::PeriodGrid`](crate::branches::Method::PeriodGrid)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BackboneOptions {
    /// Periods to visit ([`PeriodGrid::for_mode`] derives them from the system).
    pub grid: PeriodGrid,
    /// Linear mode the branch starts from (1-based, default 1).
    pub mode: usize,
    /// Period multiple `k` of the seed (NSM `mode` sub `k`; default 1).
    pub subharmonic: usize,
    /// Predictor of the sequential driver (default constant).
    pub predictor: Predictor,
    /// Consecutive failures before the run stops (default 40).
    pub max_consecutive_failures: usize,
    /// Retry a failed step from up to this many earlier converged points
    /// ([`SequentialOptions::retry_depth`]; default 1; [`BackboneOptions::for_mode`] derives
    /// it from the system).
    pub retry_depth: usize,
    /// How a step chooses among the solutions reached from the prediction and the
    /// `retry_depth` earlier converged points ([`SequentialOptions::selection`]; default
    /// [`Selection::FirstConverged`]). [`Selection::LowestMeasure`] solves every step from
    /// all of them and keeps the lowest-energy solution: near an internal resonance of the
    /// truncated system the last point can lead to a spike carrying extra energy in a
    /// resonant harmonic, while the lowest-energy solution stays on the backbone.
    ///
    /// Near internal resonances, where they are dense (high `m`), it keeps more points on the
    /// backbone, at the cost of about `retry_depth` extra solves on every step;
    /// `docs/performance.md` has the measured trade-off on the clamped bar. It is not the
    /// default for that cost, and because it changes the points of existing runs.
    /// A request with [`speculation`](crate::branches::Request::speculation) runs it
    /// serially.
    pub selection: Selection,
    /// Converged points with `E < trivial_energy * E_g` count as collapsed to rest and are
    /// not accepted (default `1e-6`).
    pub trivial_energy: f64,
}

impl BackboneOptions {
    /// The options of the sequential driver these options ask for.
    pub fn sequential(&self) -> SequentialOptions {
        SequentialOptions {
            predictor: self.predictor,
            max_consecutive_failures: self.max_consecutive_failures,
            retry_depth: self.retry_depth,
            selection: self.selection,
        }
    }
}

/// The energy below which a converged point counts as the state of rest, as a fraction of
/// `E_g` (the default [`BackboneOptions::trivial_energy`]).
pub const TRIVIAL_ENERGY: f64 = 1e-6;

impl BackboneOptions {
    /// The library's settings of a period grid `grid` for NSM `mode` sub `subharmonic`:
    /// constant predictor, 40 consecutive failures, one retry, the first converged solution,
    /// [`TRIVIAL_ENERGY`]. [`BackboneOptions::for_mode`] derives the grid from the system.
    pub fn on_grid(grid: PeriodGrid, mode: usize, subharmonic: usize) -> Self {
        Self {
            grid,
            mode,
            subharmonic,
            predictor: Predictor::Constant,
            max_consecutive_failures: MAX_CONSECUTIVE_FAILURES,
            retry_depth: 1,
            selection: Selection::FirstConverged,
            trivial_energy: TRIVIAL_ENERGY,
        }
    }
}

/// Computes a backbone with the constant + cosine basis: seeds the branch from the linear mode
/// at the first period and continues sequentially in the period, handing each point,
/// converged or not, to `observer` (which may stop the run). Returns the first grazing energy
/// `E_g` used for normalisation and why the run ended (a stalled run is
/// [`EndReason::Stalled`], not an error: its points have been handed over).
///
/// # Errors
/// Invalid settings or options, a failed seed or an assembly with a bar that can drift away
/// ([`SettingsError::Unconfined`](crate::SettingsError::Unconfined)): nothing was computed.
/// [`SettingsError::StartNotFound`](crate::SettingsError::StartNotFound) if the start search
/// found no motion in contact near the first period and no step of the grid converged
/// either (the steps were handed to `observer`, each with its status).
pub(crate) fn backbone_with<S: NonlinearSolver>(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    options: &BackboneOptions,
    solver: S,
    observer: impl FnMut(BackbonePoint) -> ControlFlow<()>,
) -> Result<(f64, EndReason), Error> {
    let run = |mut driver: Sequential<'_, _, S>, see: &mut dyn Observer| driver.run(see);
    drive_backbone(system, settings, (options, None), solver, run, observer)
}

/// [`backbone_with`] with the first retry of each failing step run on a second thread beside
/// the first attempt ([`Speculative`]): the same points, bit for bit, in
/// less wall time when steps fail and a second core is free. The retries run on a worker
/// thread with clones of the problem and the solver, so the solver must be `Clone + Send +
/// 'static` (the crate's solvers are).
///
/// # Errors
/// See [`backbone_with`].
pub(crate) fn backbone_speculative_with<S: NonlinearSolver + Clone + Send + 'static>(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    options: &BackboneOptions,
    speculation: Speculation,
    solver: S,
    observer: impl FnMut(BackbonePoint) -> ControlFlow<()>,
) -> Result<(f64, EndReason), Error> {
    let run = |driver: Sequential<'_, _, S>, see: &mut dyn Observer| {
        Speculative::new(driver, speculation).run(see)
    };
    drive_backbone(system, settings, (options, None), solver, run, observer)
}

/// [`backbone_with`] (`speculation = None`) or [`backbone_speculative_with`] from a start
/// found beforehand by [`backbone_start`](crate::branches::backbone_start) at the grid's first
/// frequency, instead of searching it again: a caller who looked at the start (for instance
/// to choose between this and [`arclength_backbone`] by
/// [`BackboneStart::moved_from`]) does not pay for the search twice. The start's unknowns are
/// the first step's guess.
///
/// # Errors
/// See [`backbone_with`]; a start of the wrong size is
/// [`ContinuationError::Dimension`].
pub(crate) fn backbone_from<S: NonlinearSolver + Clone + Send + 'static>(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    options: &BackboneOptions,
    start: BackboneStart,
    speculation: Option<Speculation>,
    solver: S,
    observer: impl FnMut(BackbonePoint) -> ControlFlow<()>,
) -> Result<(f64, EndReason), Error> {
    let run = |mut driver: Sequential<'_, _, S>, see: &mut dyn Observer| match speculation {
        Some(speculation) => Speculative::new(driver, speculation).run(see),
        None => driver.run(see),
    };
    drive_backbone(
        system,
        settings,
        (options, Some(start)),
        solver,
        run,
        observer,
    )
}

/// The driver of a sequential backbone (seed, grid, acceptance test, energies) with the loop
/// itself left to `run`.
fn drive_backbone<S: NonlinearSolver>(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    (options, start): (&BackboneOptions, Option<BackboneStart>),
    solver: S,
    run: impl FnOnce(
        Sequential<'_, PeriodParametrised<NonsmoothSystem>, S>,
        &mut dyn Observer,
    ) -> Branch,
    mut observer: impl FnMut(BackbonePoint) -> ControlFlow<()>,
) -> Result<(f64, EndReason), Error> {
    let grid = options.grid;
    grid.validate()?;
    let mut problem = NonsmoothSystem::new(system, settings)?;
    check_trivial_energy(options.trivial_energy)?;
    for v in [grid.start, grid.end] {
        check_frequency_of(&problem, frequency_of_period(v))?;
    }
    let values = linspace(grid.start, grid.end, grid.steps)?;
    let first = frequency_of_period(grid.start);
    let (e_g, seed) = grazing_and_seed(&mut problem, options.mode, options.subharmonic, first)?;
    let basis = problem.basis().clone();
    let floor = options.trivial_energy * e_g;
    // Where no start is found near the first period, the grid itself searches on from the
    // seed: it may enter the branch further on. A run that never does ends on the search's
    // error, not on points at rest.
    let (start, not_found) = match start {
        Some(given) => (given.x, None),
        None => {
            let guess = (seed.clone(), options.subharmonic);
            match usable_start(&mut problem, &solver, guess, first, floor) {
                Ok((x, _)) => (x, None),
                Err(e) => (seed, Some(e)),
            }
        }
    };
    let seq_options = options.sequential();
    // The driver's parameter is the period: the acceptance test derives each converged
    // point's frequency from it (once) and computes its energy; the observer reuses both for
    // the point it builds. The measure of `Selection::LowestMeasure` is called right after
    // the acceptance test took the same point: it reuses the energy the test computed.
    let last_energy = RefCell::new(Taken::default());
    let driver = Sequential::new(
        PeriodParametrised::new(problem),
        solver,
        start,
        values,
        seq_options,
    )?
    // The energy floor below decides what counts as rest.
    .with_rest_accepted()
    .with_acceptance(|x, period| {
        let time = Timescale::of_period(period);
        let e = energy(system, &basis, x, time.omega);
        last_energy.borrow_mut().keep(x, time, e);
        e > floor
    })
    .with_measure(|x, period| {
        last_energy
            .borrow()
            .energy_of(x, period)
            .unwrap_or(f64::NAN)
    });
    // Converged points and the solver's last iterates of failed steps alike.
    let mut entered = false;
    let branch = run(driver, &mut |step: &Step| {
        let Some(p) = step.point() else {
            return ControlFlow::Continue(());
        };
        entered |= p.converged;
        let known = last_energy.borrow().time_and_energy(&p.x, p.parameter);
        let (time, e) = known.unwrap_or_else(|| {
            let time = Timescale::of_period(p.parameter);
            (time, energy(system, &basis, &p.x, time.omega))
        });
        let status = PointStatus::of(p);
        observer(BackbonePoint::from_parts(p, (&p.x, time), e, e_g, status))
    });
    match not_found {
        Some(e) if !entered => Err(e.into()),
        _ => Ok((e_g, branch.end)),
    }
}

/// The last solution a period grid's acceptance test took: its unknowns (copied into a
/// buffer kept from step to step), time scale and energy, for the observer and the measure
/// to reuse instead of computing them again.
pub(super) struct Taken {
    x: Vec<f64>,
    time: Timescale,
    energy: f64,
}

impl Default for Taken {
    fn default() -> Self {
        let time = Timescale {
            period: f64::NAN,
            omega: f64::NAN,
        };
        Self {
            x: Vec::new(),
            time,
            energy: f64::NAN,
        }
    }
}

impl Taken {
    /// Keeps `(x, time)` and its energy.
    pub(super) fn keep(&mut self, x: &[f64], time: Timescale, energy: f64) {
        self.x.clear();
        self.x.extend_from_slice(x);
        (self.time, self.energy) = (time, energy);
    }

    /// The time scale and energy kept, if they are those of `x` at `period`.
    pub(super) fn time_and_energy(&self, x: &[f64], period: f64) -> Option<(Timescale, f64)> {
        (self.time.period == period && self.x == x).then_some((self.time, self.energy))
    }

    /// The energy kept, if it is that of `x` at `period`.
    fn energy_of(&self, x: &[f64], period: f64) -> Option<f64> {
        self.time_and_energy(x, period).map(|(_, e)| e)
    }
}

/// Options of an arclength backbone ([`Method::Arclength`](crate::branches::Method::Arclength)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArclengthBackboneOptions {
    /// Period at which the branch is seeded ([`ArclengthBackboneOptions::for_mode`] derives
    /// it and `omega_range` from the system).
    pub start_period: f64,
    /// The run stays inside this range of `Omega`.
    pub omega_range: (f64, f64),
    /// Linear mode the branch starts from (1-based).
    pub mode: usize,
    /// Period multiple of the seed (1 for the main branch).
    pub subharmonic: usize,
    /// Driver options ([`ArclengthOptions::default`] in the constructors: `direction = +1`, towards
    /// higher `Omega`); their `parameter_range` is replaced by `omega_range`.
    pub arclength: ArclengthOptions,
    /// Escape from stalls ([`EscapingArclength`]; `Some(StallEscape::default())` in the constructors, so
    /// that internal-resonance branches do not stall the backbone; `None` follows the branch
    /// wherever it goes).
    pub escape: Option<StallEscape>,
    /// As [`BackboneOptions::trivial_energy`] ([`TRIVIAL_ENERGY`] in the constructors).
    pub trivial_energy: f64,
    /// Leave the branch at one of its branch points for the branch crossing there (default
    /// `None`: follow the branch seeded). The run's points are those of both branches; the
    /// switched point is numbered as the next step.
    pub switch: Option<SwitchAt>,
}

impl ArclengthBackboneOptions {
    /// The arclength backbone over the range of a period grid: seeded at its first period,
    /// towards its last, inside the frequencies of its periods widened by `0.1 %` at the
    /// first period's end (so that the walk back to the first period ends beyond it).
    pub fn over_grid(options: &BackboneOptions) -> Self {
        let PeriodGrid { start, end, .. } = options.grid;
        let (first, last) = (frequency_of_period(start), frequency_of_period(end));
        let range = if first <= last {
            (first * 0.999, last)
        } else {
            (last, first * 1.001)
        };
        let mut arclength = Self::seeded_at(start, range, (options.mode, options.subharmonic));
        arclength.arclength.direction = if end < start { 1.0 } else { -1.0 };
        arclength.trivial_energy = options.trivial_energy;
        arclength
    }

    /// The library's settings of an arclength backbone of NSM `mode` sub `subharmonic` seeded
    /// at `start_period` inside `omega_range`: the driver's default options, the default
    /// stall escape, [`TRIVIAL_ENERGY`], no switch. [`ArclengthBackboneOptions::for_mode`]
    /// derives the period and range from the system.
    pub fn seeded_at(
        start_period: f64,
        omega_range: (f64, f64),
        (mode, subharmonic): (usize, usize),
    ) -> Self {
        Self {
            start_period,
            omega_range,
            mode,
            subharmonic,
            arclength: ArclengthOptions::default(),
            escape: Some(StallEscape::default()),
            trivial_energy: TRIVIAL_ENERGY,
            switch: None,
        }
    }
}

/// What an arclength backbone tells its observer: each accepted point and each rejected
/// corrector step, either of which may stop the run.
///
/// Closures `FnMut(&BackbonePoint) -> ControlFlow<()>` observe the points only; implement
/// the trait to see the rejections too (for instance to stop a run whose shrink factor is
/// close to 1 after a budget of your own).
///
/// The runs of [`compute`](crate::branches::compute) show each point with the label and
/// branch index the result gives it, in the run's order: a point whose energy leaves the
/// branch's secant (a possible one-point spike, [`SPIKE_ENERGY`](crate::branches::SPIKE_ENERGY))
/// is shown, with the failed steps after it, once the next converged point has said whether
/// it came back: an observer that stops the run there stops it one point later, and the
/// result ends at the point where it stopped. An observer that stops the run on a rejected
/// step while a point is held is not shown that point (nor anything else): the result ends
/// at the last point it saw.
pub trait BackboneObserver {
    /// Called with every accepted point.
    fn point(&mut self, point: &BackbonePoint) -> ControlFlow<()>;

    /// Called with every rejected step (default: go on).
    fn rejected(&mut self, rejection: &Rejection) -> ControlFlow<()> {
        let _ = rejection;
        ControlFlow::Continue(())
    }
}

impl<F: FnMut(&BackbonePoint) -> ControlFlow<()>> BackboneObserver for F {
    fn point(&mut self, point: &BackbonePoint) -> ControlFlow<()> {
        self(point)
    }
}

/// What an arclength backbone hands its points and rejected steps to inside the crate: as
/// [`BackboneObserver`], but each point by value, so that a receiver that keeps the points
/// (the annotator of [`compute`](crate::branches::compute)) does not copy them.
pub(crate) trait PointSink {
    /// Called with every accepted point.
    fn point(&mut self, point: BackbonePoint) -> ControlFlow<()>;

    /// Called with every rejected step.
    fn rejected(&mut self, rejection: &Rejection) -> ControlFlow<()>;
}

/// [`arclength_backbone`] whose observer sees every accepted point and every rejected step,
/// and may stop the run on either
/// ([`EndReason::StoppedByObserver`](crate::continuation::EndReason::StoppedByObserver));
/// from `given` where a start was found beforehand, else from the start search's.
///
/// # Errors
/// Invalid settings or options, a failed seed or a failed start.
pub(crate) fn arclength_backbone_observed<S: NonlinearSolver>(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    (options, given): (&ArclengthBackboneOptions, Option<BackboneStart>),
    solver: S,
    mut observer: impl PointSink,
) -> Result<(f64, Branch), Error> {
    let mut problem = NonsmoothSystem::new(system, settings)?;
    if !(options.start_period.is_finite() && options.start_period > 0.0) {
        return Err(ContinuationError::InvalidOption {
            what: "start period",
            value: options.start_period,
        }
        .into());
    }
    let arclength = ArclengthOptions {
        parameter_range: options.omega_range,
        ..options.arclength
    };
    // The range (empty, reversed: named as the frequencies it bounds) and the driver's steps
    // are refused before the start search.
    Range::bounds("frequency range", options.omega_range).check(Ends::NotNan, Direction::Rising)?;
    arclength.validate()?;
    // The driver's parameter is the frequency: the asked start period is converted once.
    let asked = frequency_of_period(options.start_period);
    let omega0 = asked;
    let (lo, hi) = options.omega_range;
    if hi.is_finite() {
        check_frequency_of(&problem, hi.max(lo))?;
    }
    let (e_g, start) = grazing_and_seed(&mut problem, options.mode, options.subharmonic, omega0)?;
    let basis = problem.basis().clone();
    if let Some(escape) = options.escape {
        escape.validate()?;
    }
    let floor = check_trivial_energy(options.trivial_energy)? * e_g;
    // A floating bar's branch may start only at a higher frequency than asked.
    let (start, omega0) = match given {
        Some(given) => (given.x, given.omega),
        None => usable_start(
            &mut problem,
            &solver,
            (start, options.subharmonic),
            omega0,
            floor,
        )?,
    };
    // Where the start lies beyond the asked frequency, the branch is first walked back to it.
    let (walked, walk_rejections) = walk_back(
        &problem,
        &solver,
        (&start, omega0),
        asked,
        arclength,
        (options.escape, floor),
    );
    // The energy floor decides what counts as rest.
    let driver = Arclength::new(problem, solver, start, omega0, arclength)?
        .with_rest_accepted()
        .with_acceptance(|x, omega| energy(system, &basis, x, omega) > floor);
    let offset = walked.len();
    let backbone_point = |p: &Point, offset: usize| {
        let e = energy(system, &basis, &p.x, p.parameter);
        let mut point = BackbonePoint::from_point(p, p.parameter, e, e_g);
        point.step += offset;
        point
    };
    // The observer sees the walk once it is over: its rejected steps (counted in the run's
    // rejections, so seen as well), then its points. It may stop the run on either.
    let stopped_on_rejection = (walk_rejections.iter())
        .position(|r| observer.rejected(r).is_break())
        .map(|k| (0, k + 1));
    let stopped = stopped_on_rejection.or_else(|| {
        (walked.iter())
            .position(|p| observer.point(backbone_point(p, 0)).is_break())
            .map(|k| (k + 1, walk_rejections.len()))
    });
    if let Some((kept, rejections)) = stopped {
        let mut points = walked;
        points.truncate(kept);
        let end = EndReason::StoppedByObserver;
        return Ok((
            e_g,
            Branch {
                points,
                rejections,
                end,
            },
        ));
    }
    let mut see = |step: &Step| match step {
        Step::Accepted(p) => observer.point(backbone_point(p, offset)),
        Step::Rejected(r) => observer.rejected(r),
        Step::Finished(_) => ControlFlow::Continue(()),
    };
    let mut runner = match options.escape {
        Some(escape) => Runner::Escaping(EscapingArclength::new(driver, escape)?),
        None => Runner::Plain(driver),
    };
    let mut branch = runner.run_switching(options.switch, &mut see)?;
    for p in &mut branch.points {
        p.step += offset;
    }
    branch.points.splice(0..0, walked);
    branch.rejections += walk_rejections.len();
    Ok((e_g, branch))
}
