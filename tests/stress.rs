//! Stress suite of the public API: seeded random cases of every kind of input (bars and
//! assemblies with built-in and downstream conditions, harmonic-balance settings, solvers and
//! their options, the continuation drivers and backbones, post-processing of valid systems),
//! valid, at the edges and bad: `0`, negative, subnormal, `1e-300`, `1e300`, `f64::MAX`,
//! infinities and NaN; sizes `0`, `1`, small, `2^40` and `usize::MAX`.
//!
//! Each case runs under `catch_unwind` on a worker thread and is classified: `Ok`, typed
//! error, panic (with its message), a non-finite number in an `Ok` result, a run without a
//! consistent end reason, or a hang (no answer within [`HANG_SECONDS`]). The tests fail on
//! any panic, non-finite result, missing end reason or hang, and print each failure with its
//! case index and the inputs drawn, so that `STRESS_SEED`/`STRESS_ONLY` reproduce it.
//!
//! - `stress_public_api`: [`QUICK_CASES`] cases (a minute in release);
//! - `stress_public_api_long` (`#[ignore]`): `STRESS_CASES` cases, 20 000 by default:
//!   `cargo test --release --all-features --test stress -- --ignored --nocapture`.
//!
//! Valid cases are cheap on purpose (at most 8 harmonics, a few continuation steps, short
//! time-domain marches), so that the long run takes minutes on one core; budgets that could
//! legitimately run for hours (`max_steps = usize::MAX`, a shrink factor of `0.9999999` with
//! an unbounded number of rejections) are always drawn together with an observer that stops
//! the run, as a user asking for them would.

use nonsmooth_modes::bar::{Bar, BarId, EndRef};
use nonsmooth_modes::bc::{BoundaryCondition, LinearRows, Quantity, Term};
use nonsmooth_modes::continuation::{
    linspace, Arclength, ArclengthOptions, ArclengthScale, Branch, ContinuationProblem, EndReason,
    Event, PeriodParametrised, Point, Predictor, Rejection, Selection, Sequential,
    SequentialOptions, Speculation, Speculative, Step, TangentPredictor,
};
use nonsmooth_modes::modal::{
    arclength_backbone_observed, backbone, backbone_speculative_with, backbone_with, branch_seed,
    diagnose, energy, grazing_energy, law_history, natural_frequencies, parameter_branch,
    ArclengthBackboneOptions, BackboneObserver, BackboneOptions, BackbonePoint, ContactState,
    EscapingArclength, ParameterSteps, PeriodGrid, PointStatus, StallEscape,
};
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact, ClampedFirstMode,
};
use nonsmooth_modes::solve::{
    Dogleg, DoglegOptions, NewtonOptions, NonlinearSolver, Problem, SemismoothNewton,
    SmoothingHomotopy, SolveInfo, SolveMonitor,
};
use nonsmooth_modes::system::{
    AssemblyBuilder, BarSystem, HarmonicBalanceSettings, NonsmoothSystem,
};
use nonsmooth_modes::verify::{periodicity_check, PeriodicityOptions, SpringUpdate};
use nonsmooth_modes::{Solution, SolveError};
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::fmt::{Debug, Write as _};
use std::ops::{ControlFlow, RangeInclusive};
use std::panic::{self, AssertUnwindSafe};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

/// Cases of the quick test.
const QUICK_CASES: usize = 1500;
/// Cases of the long test unless `STRESS_CASES` says otherwise.
const LONG_CASES: usize = 20_000;
/// A case that has not answered after this long is a hang (a valid case takes milliseconds).
const HANG_SECONDS: u64 = 60;
/// Base seed unless `STRESS_SEED` says otherwise.
const SEED: u64 = 0x5EED_2024_0BAD_CAFE;
/// Most harmonics of a valid case.
const MAX_HARMONICS: usize = 8;
/// Most steps (accepted and rejected) a driven run may take before it counts as a run
/// without end: every run below is bounded far below this by its options or its observer.
const STEP_CAP: usize = 5_000;

// ------------------------------------------------------------------------------------------
// Random numbers and the record of what was drawn

/// SplitMix64 (Steele, Lea, Flood 2014): tiny, fast, and the same on every platform.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
}

/// Values of `f64` at the edges: zeros, a negative, subnormals, tiny and huge, the extremes,
/// infinities and NaN.
const EDGE_REALS: [f64; 14] = [
    0.0,
    -0.0,
    -1.0,
    f64::MIN_POSITIVE,
    5e-324,
    1e-310,
    1e-300,
    1e300,
    f64::MAX,
    -f64::MAX,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::NAN,
    -1e-300,
];

/// Sizes at the edges: none, one, and sizes no memory holds.
const EDGE_SIZES: [usize; 5] = [0, 1, 1 << 40, usize::MAX - 1, usize::MAX];

/// Draws the inputs of one case and writes each, named, into a log shared with the harness
/// (which prints it when the case fails, even if it never returns).
struct Draw {
    rng: SplitMix,
    log: Arc<Mutex<String>>,
    /// Probability of an edge value instead of a valid one.
    edge: f64,
}

impl Draw {
    fn note(&self, name: &str, value: impl Debug) {
        let mut log = self.log.lock().unwrap_or_else(|e| e.into_inner());
        let _ = write!(log, "{name}={value:?} ");
    }

    /// A real: valid (log-uniform in `valid` when it spans decades and is positive, uniform
    /// otherwise) or, with probability `self.edge`, one of [`EDGE_REALS`].
    fn real(&mut self, name: &str, valid: RangeInclusive<f64>) -> f64 {
        let v = if self.rng.chance(self.edge) {
            EDGE_REALS[self.rng.below(EDGE_REALS.len() as u64) as usize]
        } else {
            let (lo, hi) = (*valid.start(), *valid.end());
            let u = self.rng.unit();
            if lo > 0.0 && hi / lo > 100.0 {
                lo * (hi / lo).powf(u)
            } else {
                lo + (hi - lo) * u
            }
        };
        self.note(name, v);
        v
    }

    /// A size: uniform in `valid` or, with probability `self.edge`, one of [`EDGE_SIZES`].
    fn size(&mut self, name: &str, valid: RangeInclusive<usize>) -> usize {
        let v = if self.rng.chance(self.edge) {
            EDGE_SIZES[self.rng.below(EDGE_SIZES.len() as u64) as usize]
        } else {
            let (lo, hi) = (*valid.start(), *valid.end());
            lo + self.rng.below((hi - lo + 1) as u64) as usize
        };
        self.note(name, v);
        v
    }

    fn flag(&mut self, name: &str, p: f64) -> bool {
        let v = self.rng.chance(p);
        self.note(name, v);
        v
    }

    /// One of `valid` or, with probability `self.edge`, one of `bad`.
    fn choice<T: Copy + Debug>(&mut self, name: &str, valid: &[T], bad: &[T]) -> T {
        let from = if self.rng.chance(self.edge) {
            bad
        } else {
            valid
        };
        self.pick(name, from)
    }

    fn pick<T: Copy + Debug>(&mut self, name: &str, choices: &[T]) -> T {
        let v = choices[self.rng.below(choices.len() as u64) as usize];
        self.note(name, v);
        v
    }
}

// ------------------------------------------------------------------------------------------
// What a case found

/// The findings of one case beyond its result: non-finite numbers in `Ok` results and runs
/// whose end reason is missing or contradicts what happened.
#[derive(Default)]
struct Checks {
    non_finite: Vec<String>,
    no_end: Vec<String>,
}

impl Checks {
    fn finite<'a>(&mut self, what: &str, values: impl IntoIterator<Item = &'a f64>) {
        if let Some(v) = values.into_iter().find(|v| !v.is_finite()) {
            self.non_finite.push(format!("{what} has {v}"));
        }
    }

    fn point(&mut self, what: &str, p: &Point) {
        self.finite(what, [&p.parameter, &p.residual_norm, &p.step_size]);
        self.finite(what, &p.x);
        self.events(what, &p.events);
    }

    fn events(&mut self, what: &str, events: &[Event]) {
        for e in events {
            match e {
                Event::Fold { parameter } => self.finite(what, [parameter]),
                Event::Jump { ratio } => self.finite(what, [ratio]),
                _ => {}
            }
        }
    }

    fn backbone_point(&mut self, what: &str, p: &BackbonePoint) {
        let fields = [
            ("period", p.period),
            ("omega", p.omega),
            ("energy", p.energy),
            ("E/E_g", p.energy_normalized),
            ("residual norm", p.residual_norm),
            ("step size", p.step_size),
        ];
        for (name, value) in fields {
            self.finite(&format!("{what} {name} ({})", p.status.label()), [&value]);
        }
        self.finite(what, &p.x);
        self.events(what, &p.events);
        if p.converged != (p.status == PointStatus::Converged) {
            self.no_end.push(format!(
                "{what}: converged = {} but status {:?}",
                p.converged, p.status
            ));
        }
    }

    fn solve_info(&mut self, what: &str, info: &SolveInfo, x: &[f64]) {
        self.finite(what, [&info.residual_norm]);
        self.finite(what, x);
    }

    /// The points of a branch, and its end reason against whether the observer stopped it.
    fn branch(&mut self, what: &str, branch: &Branch, stopped: bool) {
        for p in &branch.points {
            self.point(what, p);
        }
        let by_observer = branch.end == EndReason::StoppedByObserver;
        if by_observer != stopped {
            self.no_end.push(format!(
                "{what}: observer stopped = {stopped}, end = {:?}",
                branch.end
            ));
        }
    }

    /// A typed error: it displays (the message is the user's explanation).
    fn error(&mut self, what: &str, e: &impl std::fmt::Display) -> String {
        let message = e.to_string();
        if message.is_empty() {
            self.no_end
                .push(format!("{what}: an error with an empty message"));
        }
        message
    }
}

/// The result of a case's main call: `Err` carries the typed error's message.
type CaseResult = Result<(), String>;

/// Turns a typed error into the case's result, after checking that it displays.
fn typed<T, E: std::fmt::Display>(
    c: &mut Checks,
    what: &str,
    r: Result<T, E>,
) -> Result<T, String> {
    r.map_err(|e| format!("{what}: {}", c.error(what, &e)))
}

// ------------------------------------------------------------------------------------------
// Inputs shared by several kinds

/// A solver of the crate, chosen at run time, that stays `Clone + Send` for the speculative
/// drivers.
#[derive(Debug, Clone)]
enum AnySolver {
    Newton(SemismoothNewton),
    Dogleg(Dogleg),
    Homotopy(SmoothingHomotopy<SemismoothNewton>),
}

impl NonlinearSolver for AnySolver {
    fn solve_monitored(
        &self,
        problem: &mut dyn Problem,
        x: &mut [f64],
        monitor: &mut dyn SolveMonitor,
    ) -> Result<SolveInfo, SolveError> {
        match self {
            Self::Newton(s) => s.solve_monitored(problem, x, monitor),
            Self::Dogleg(s) => s.solve_monitored(problem, x, monitor),
            Self::Homotopy(s) => s.solve_monitored(problem, x, monitor),
        }
    }

    fn tolerance(&self, problem: &mut dyn Problem) -> f64 {
        match self {
            Self::Newton(s) => s.tolerance(problem),
            Self::Dogleg(s) => s.tolerance(problem),
            Self::Homotopy(s) => s.tolerance(problem),
        }
    }
}

fn newton_options(d: &mut Draw) -> NewtonOptions {
    NewtonOptions {
        tolerance: d.real("tolerance", 1e-12..=1e-3),
        max_iterations: d.size("max_iterations", 0..=40),
        armijo: d.real("armijo", 1e-6..=0.5),
        min_step: d.real("min_step", 1e-10..=0.1),
        stall_window: d.size("stall_window", 0..=20),
        stall_ratio: d.real("stall_ratio", 0.1..=1.0),
        plateau_window: d.size("plateau_window", 0..=8),
        plateau_ratio: d.real("plateau_ratio", 0.5..=1.0),
        max_evaluations: d.size("max_evaluations", 1..=200),
    }
}

/// A solver: the defaults, `fail_fast`, or random options (a typed error when invalid).
fn solver(d: &mut Draw, c: &mut Checks) -> Result<AnySolver, String> {
    match d.pick(
        "solver",
        &["default", "fail_fast", "newton", "dogleg", "homotopy"],
    ) {
        "default" => Ok(AnySolver::Newton(SemismoothNewton::default())),
        "fail_fast" => Ok(AnySolver::Newton(
            SemismoothNewton::new(NewtonOptions::fail_fast()).expect("fail_fast is valid"),
        )),
        "newton" => {
            let o = newton_options(d);
            let solver = typed(c, "SemismoothNewton::new", SemismoothNewton::new(o))?;
            Ok(AnySolver::Newton(solver))
        }
        "dogleg" => {
            let o = DoglegOptions {
                tolerance: d.real("tolerance", 1e-12..=1e-3),
                max_iterations: d.size("max_iterations", 0..=60),
                initial_radius: d.real("initial_radius", 1e-3..=10.0),
                min_radius: d.real("min_radius", 1e-14..=1e-2),
            };
            Ok(AnySolver::Dogleg(typed(c, "Dogleg::new", Dogleg::new(o))?))
        }
        _ => {
            let levels = (0..d.size("levels", 0..=4))
                .take(8)
                .map(|i| d.real(&format!("level{i}"), 1e-6..=0.1))
                .collect();
            let inner = SemismoothNewton::new(NewtonOptions::fail_fast()).expect("valid");
            Ok(AnySolver::Homotopy(SmoothingHomotopy { inner, levels }))
        }
    }
}

/// One of the paper's systems, with a random gap (and spring, or second bar).
fn reference_system(d: &mut Draw, c: &mut Checks) -> Result<BarSystem, String> {
    let gap = d.real("gap", 1e-6..=1.0);
    let system = match d.pick("system", &["clamped", "robin", "two bars"]) {
        "clamped" => clamped_bar_with_obstacle(gap),
        "robin" => robin_bar_with_obstacle(d.real("spring", 0.05..=20.0), gap),
        _ => {
            let second = typed(c, "Bar::new", random_bar(d))?;
            two_bars_in_contact(second, gap)
        }
    };
    typed(c, "reference system", system)
}

fn random_bar(d: &mut Draw) -> Result<Bar, nonsmooth_modes::ModelError> {
    Bar::new(
        d.real("length", 0.2..=5.0),
        d.real("wave speed", 0.2..=5.0),
        d.real("stiffness", 0.1..=10.0),
    )
}

fn settings(d: &mut Draw) -> HarmonicBalanceSettings {
    HarmonicBalanceSettings {
        harmonics: d.size("harmonics", 1..=MAX_HARMONICS),
        samples_per_harmonic: d.size("samples_per_harmonic", 3..=40),
        complementarity: d.real("complementarity", 0.1..=100.0),
        kink_blend: if d.flag("blend", 0.2) {
            d.real("kink_blend", 0.0..=0.1)
        } else {
            0.0
        },
    }
}

/// A valid reference system with valid small settings, for the kinds that stress something
/// else: the problem, its system and the first linear period (`2 pi / omega_1`).
fn valid_problem(d: &mut Draw, c: &mut Checks) -> Result<(NonsmoothSystem, f64), String> {
    let saved = d.edge;
    d.edge = 0.0;
    let system = reference_system(d, c);
    let s = settings(d);
    d.edge = saved;
    let system = system?;
    let problem = typed(c, "NonsmoothSystem::new", NonsmoothSystem::new(&system, s))?;
    let (_, mode) = typed(c, "grazing_energy", grazing_energy(&system))?;
    Ok((problem, 2.0 * PI / mode.omega))
}

/// When an observer stops a run.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Stop {
    Never,
    FirstPoint,
    FirstRejection,
    /// After this many steps of any kind.
    After(usize),
}

/// An observer policy: `Never` only when the run is bounded by its own options (`bounded`).
fn stop_policy(d: &mut Draw, bounded: bool) -> Stop {
    let after = d.size("stop after", 1..=30).clamp(1, 60);
    let choices: &[Stop] = if bounded {
        &[
            Stop::Never,
            Stop::FirstPoint,
            Stop::FirstRejection,
            Stop::After(after),
        ]
    } else {
        &[Stop::FirstPoint, Stop::After(after)]
    };
    d.pick("observer", choices)
}

/// Watches steps as `stop` says; records whether it stopped the run.
struct Watcher {
    stop: Stop,
    seen: usize,
    stopped: bool,
}

impl Watcher {
    fn new(stop: Stop) -> Self {
        Self {
            stop,
            seen: 0,
            stopped: false,
        }
    }

    fn observe(&mut self, step: &Step) -> ControlFlow<()> {
        match step {
            Step::Accepted(_) => self.count(true),
            Step::Rejected(_) => self.count(false),
            Step::Finished(_) => ControlFlow::Continue(()),
        }
    }

    /// Counts an accepted (`true`) or rejected step and says whether to stop.
    fn count(&mut self, accepted: bool) -> ControlFlow<()> {
        self.seen += 1;
        let stop = match self.stop {
            Stop::Never => false,
            Stop::FirstPoint => accepted,
            Stop::FirstRejection => !accepted,
            Stop::After(n) => self.seen >= n,
        } || self.seen >= STEP_CAP;
        self.stopped = stop;
        if stop {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// A driver, driven three ways: `run` with an observer, its iterator, or `step()` by hand.
trait Driver: Iterator<Item = Result<Point, nonsmooth_modes::ContinuationError>> {
    fn run_with(&mut self, w: &mut Watcher) -> Branch;
    fn one_step(&mut self) -> Step;
}

macro_rules! driver {
    ($t:ty) => {
        impl<P, S> Driver for $t
        where
            P: ContinuationProblem + Clone + Send + 'static,
            S: NonlinearSolver + Clone + Send + 'static,
        {
            fn run_with(&mut self, w: &mut Watcher) -> Branch {
                self.run(&mut |s: &Step| w.observe(s))
            }
            fn one_step(&mut self) -> Step {
                self.step()
            }
        }
    };
}
driver!(Sequential<P, S>);
driver!(Speculative<P, S>);
driver!(Arclength<P, S>);
driver!(EscapingArclength<P, S>);

/// Drives `driver` one of three ways and checks its points and that the run ends with a
/// reason consistent with how it was driven; `bounded` says whether its options alone end it.
fn drive(d: &mut Draw, c: &mut Checks, mut driver: impl Driver, bounded: bool) {
    let how = if bounded {
        d.pick("drive", &["run", "iterate", "step"])
    } else {
        "run"
    };
    match how {
        "run" => {
            let mut w = Watcher::new(stop_policy(d, bounded));
            let branch = driver.run_with(&mut w);
            if w.seen >= STEP_CAP {
                c.no_end.push(format!("run: no end after {STEP_CAP} steps"));
            }
            c.branch("run", &branch, w.stopped);
            // A run stopped or finished stays finished.
            let again = driver.one_step();
            if !matches!(again, Step::Finished(ref e) if *e == branch.end) {
                c.no_end
                    .push(format!("step after {:?}: {again:?}", branch.end));
            }
        }
        "iterate" => {
            let mut items = 0;
            for item in driver.by_ref() {
                items += 1;
                if let Ok(p) = &item {
                    c.point("iterator point", p);
                }
                if items > STEP_CAP {
                    c.no_end.push("iterator: no end".into());
                    return;
                }
            }
            if driver.next().is_some() {
                c.no_end.push("iterator: an item after None".into());
            }
        }
        _ => {
            for _ in 0..STEP_CAP {
                match driver.one_step() {
                    Step::Accepted(p) => c.point("accepted step", &p),
                    Step::Rejected(_) => {}
                    Step::Finished(end) => {
                        if driver.one_step() != Step::Finished(end.clone()) {
                            c.no_end.push(format!("a different step after {end:?}"));
                        }
                        return;
                    }
                }
            }
            c.no_end.push("step(): no end".into());
        }
    }
}

fn arclength_options(d: &mut Draw) -> ArclengthOptions {
    let ds_max = d.real("ds_max", 0.01..=0.5);
    ArclengthOptions {
        ds: d.real("ds", 1e-3..=0.2).min(ds_max),
        ds_min: d.real("ds_min", 1e-6..=1e-2),
        ds_max,
        max_steps: d.size("max_steps", 1..=12),
        parameter_range: (d.real("range lo", 0.5..=1.5), d.real("range hi", 1.6..=3.0)),
        direction: d.choice("direction", &[1.0, -1.0], &[0.0, f64::NAN, 2.0, -0.0]),
        predictor: d.pick(
            "predictor",
            &[TangentPredictor::Tangent, TangentPredictor::Secant],
        ),
        scale: if d.flag("fixed scale", 0.3) {
            ArclengthScale::Fixed(d.real("s_x", 1e-4..=1.0), d.real("s_lambda", 0.1..=10.0))
        } else {
            ArclengthScale::Automatic
        },
        fast_iterations: d.size("fast_iterations", 0..=5),
        growth: d.real("growth", 1.0..=3.0),
        shrink: d.choice(
            "shrink",
            &[0.5, 0.1, 0.9, 0.9999999],
            &[1.0, 0.0, -0.5, f64::NAN, 1e-300],
        ),
        jump_ratio: d.real("jump_ratio", 0.5..=10.0),
        max_turn: d.real("max_turn", 0.1..=3.0),
        max_rejections: d.size("max_rejections", 0..=20),
    }
}

/// Whether arclength options bound a run by themselves to a few hundred steps: few accepted
/// points and few rejections (a shrink factor close to 1 takes millions of rejections to
/// reach `ds_min`, each a corrector solve).
fn arclength_bounded(o: &ArclengthOptions) -> bool {
    o.max_steps <= 50 && o.max_rejections <= 50
}

fn stall_escape(d: &mut Draw) -> StallEscape {
    StallEscape {
        window: d.size("escape window", 2..=6),
        min_progress: d.real("escape min_progress", 1e-4..=1e-1),
        jump: d.real("escape jump", 1e-4..=1e-1),
        max_attempts: d.size("escape max_attempts", 1..=3).min(4),
        max_norm_ratio: d.real("escape max_norm_ratio", 1.0..=10.0),
    }
}

/// Whether `v` is finite and zero or of moderate size (`1e-100` to `1e100`).
fn moderate(v: f64) -> bool {
    v.is_finite() && (v == 0.0 || (1e-30..=1e30).contains(&v.abs()))
}

/// Whether a motion `x` at `omega` of `system` has moderate numbers only, so that the true
/// values of the plain-number evaluators (`energy`, the field) are representable: they
/// return numbers, not results, and are checked only there, while every `Result` API is
/// checked whatever its inputs.
fn moderate_motion(system: &BarSystem, x: &[f64], omega: f64) -> bool {
    let bars = system.bars().iter().all(|b| {
        [b.length(), b.wave_speed(), b.stiffness()]
            .into_iter()
            .all(moderate)
    });
    bars && x.iter().all(|&v| moderate(v)) && omega > 0.0 && moderate(omega)
}

// ------------------------------------------------------------------------------------------
// Downstream conditions

/// A downstream linear condition `k u + EA p = 0` (a spring of any stiffness, NaN and
/// infinities included) whose row may name another end than its own (`stranger`) or whose
/// stiffness closure may read one: the builder must refuse an end outside the assembly.
#[derive(Debug, Clone, Copy)]
struct Downstream {
    end: EndRef,
    spring: f64,
    stranger: Option<EndRef>,
    reads_stranger: bool,
}

impl BoundaryCondition for Downstream {
    fn name(&self) -> String {
        format!("downstream spring {} at {}", self.spring, self.end)
    }
    fn ends(&self) -> Vec<EndRef> {
        vec![self.end]
    }
    fn linear_rows(&self, _: f64, stiffness: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
        let read = if self.reads_stranger {
            self.stranger.unwrap_or(self.end)
        } else {
            self.end
        };
        let ea = stiffness(read);
        let mut terms = vec![
            Term::new(self.end, Quantity::Displacement, self.spring),
            Term::new(self.end, Quantity::OutwardStrain, ea),
        ];
        if let Some(other) = self.stranger {
            terms.push(Term::new(other, Quantity::Displacement, 1.0));
        }
        rows.push(&terms);
    }
    fn stored_energy(&self, value: &dyn Fn(EndRef, Quantity) -> f64) -> f64 {
        0.5 * self.spring * value(self.end, Quantity::Displacement).powi(2)
    }
}

/// An id of a bar that no assembly of this case has: the fifth bar of another builder.
fn foreign_bar() -> BarId {
    let mut other = AssemblyBuilder::new();
    for _ in 0..4 {
        let _ = other.add_bar(Bar::unit());
    }
    other.add_bar(Bar::unit())
}

// ------------------------------------------------------------------------------------------
// The kinds of cases

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Kind {
    Assembly,
    Settings,
    Solver,
    Backbone,
    Sequential,
    Arclength,
    ArclengthBackbone,
    ParameterBranch,
    PostProcessing,
}

const KINDS: [Kind; 9] = [
    Kind::Assembly,
    Kind::Settings,
    Kind::Solver,
    Kind::Backbone,
    Kind::Sequential,
    Kind::Arclength,
    Kind::ArclengthBackbone,
    Kind::ParameterBranch,
    Kind::PostProcessing,
];

impl Kind {
    fn run(self, d: &mut Draw, c: &mut Checks) -> CaseResult {
        match self {
            Kind::Assembly => assembly(d, c),
            Kind::Settings => settings_case(d, c),
            Kind::Solver => solver_case(d, c),
            Kind::Backbone => backbone_case(d, c),
            Kind::Sequential => sequential_case(d, c),
            Kind::Arclength => arclength_case(d, c),
            Kind::ArclengthBackbone => arclength_backbone_case(d, c),
            Kind::ParameterBranch => parameter_case(d, c),
            Kind::PostProcessing => post_processing(d, c),
        }
    }
}

/// Bars and conditions of every kind on every end (none, two, foreign ends, downstream
/// conditions with any spring), built; a system with contact is then discretised, its linear
/// modes and grazing energy computed and a short backbone run.
fn assembly(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let mut b = AssemblyBuilder::new();
    let bars = d.size("bars", 1..=3).min(4);
    let mut ends = Vec::new();
    for _ in 0..bars {
        let bar = match random_bar(d) {
            Ok(bar) => bar,
            Err(e) => {
                c.error("Bar::new", &e);
                Bar::unit()
            }
        };
        let id = b.add_bar(bar);
        ends.extend([id.left(), id.right()]);
    }
    let foreign = foreign_bar().right();
    for &end in &ends {
        let other = if d.flag("foreign other end", 0.1) || ends.len() < 2 {
            foreign
        } else {
            ends[d.rng.below(ends.len() as u64) as usize]
        };
        let conditions = d.size("conditions", 1..=1).min(2);
        for _ in 0..conditions {
            let kind = d.pick(
                "condition",
                &[
                    "dirichlet",
                    "neumann",
                    "robin",
                    "signorini",
                    "signorini",
                    "contact",
                    "downstream",
                    "foreign",
                ],
            );
            let result = match kind {
                "dirichlet" => b.dirichlet(end).map(|_| ()),
                "neumann" => b.neumann(end).map(|_| ()),
                "robin" => b.robin(end, d.real("robin", 0.05..=20.0)).map(|_| ()),
                "signorini" => b.signorini(end, d.real("gap", 1e-5..=1.0)).map(|_| ()),
                "contact" => b.contact(end, other, d.real("gap", 1e-5..=1.0)).map(|_| ()),
                "downstream" => {
                    let stranger = d.flag("stranger", 0.15).then_some(other);
                    let reads_stranger = stranger.is_some() && d.flag("reads stranger", 0.5);
                    b.add_condition(Downstream {
                        end,
                        spring: d.real("spring", -5.0..=5.0),
                        stranger,
                        reads_stranger,
                    })
                    .map(|_| ())
                }
                _ => b.dirichlet(foreign).map(|_| ()),
            };
            if let Err(e) = result {
                c.error("condition", &e);
            }
        }
    }
    let system = typed(c, "build", b.build())?;
    if let Ok(modes) = natural_frequencies(&system, ContactState::Open, d.real("upper", 1.0..=12.0))
    {
        for m in &modes {
            c.finite("natural frequency", [&m.omega]);
            m.shapes.iter().for_each(|s| c.finite("mode shape", s));
        }
    }
    if system.contact_count() == 0 {
        return Ok(());
    }
    let s = HarmonicBalanceSettings {
        harmonics: d.size("harmonics", 1..=4).min(MAX_HARMONICS),
        samples_per_harmonic: 8,
        ..Default::default()
    };
    let mut problem = typed(c, "NonsmoothSystem::new", NonsmoothSystem::new(&system, s))?;
    let (e_g, mode) = typed(c, "grazing_energy", grazing_energy(&system))?;
    c.finite("grazing energy", [&e_g, &mode.omega]);
    let period = 2.0 * PI / mode.omega;
    if let Ok(seed) = branch_seed(&mut problem, 1, 1, mode.omega * 1.02) {
        c.finite("seed", &seed);
        if moderate_motion(&system, &seed, mode.omega) {
            let e = energy(&system, problem.basis(), &seed, mode.omega);
            c.finite("seed energy", [&e]);
        }
    }
    let options = BackboneOptions {
        grid: PeriodGrid {
            start: period * 0.99,
            end: period * 0.9,
            steps: 3,
        },
        ..Default::default()
    };
    let fast = SemismoothNewton::new(NewtonOptions::fail_fast()).expect("valid");
    let points = typed(c, "backbone", backbone(&system, s, &options, fast))?;
    points.iter().for_each(|p| c.backbone_point("backbone", p));
    Ok(())
}

/// Harmonic-balance settings of every size and value, a frequency of any value: the problem,
/// its seed and the seed's energy.
fn settings_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let system = reference_system(d, c)?;
    let s = settings(d);
    let mut problem = typed(c, "NonsmoothSystem::new", NonsmoothSystem::new(&system, s))?;
    if d.flag("set kink blend", 0.3) {
        let blend = d.real("kink blend", 0.0..=0.5);
        let _ = typed(c, "set_kink_blend", problem.set_kink_blend(blend));
    }
    let omega = d.real("omega", 0.3..=10.0);
    let mode = d.size("mode", 1..=3);
    let sub = d.size("subharmonic", 1..=3);
    let seed = typed(
        c,
        "branch_seed",
        branch_seed(&mut problem, mode, sub, omega),
    )?;
    c.finite("seed", &seed);
    if moderate_motion(&system, &seed, omega) {
        c.finite(
            "seed energy",
            [&energy(&system, problem.basis(), &seed, omega)],
        );
    }
    Ok(())
}

/// A solve from a scaled seed with any solver and options, at any frequency; or a
/// cancelled one.
fn solver_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let (mut problem, period) = valid_problem(d, c)?;
    let solver = solver(d, c)?;
    let omega = 2.0 * PI / period * d.real("omega factor", 0.9..=1.1);
    let mut x = typed(c, "seed", branch_seed(&mut problem, 1, 1, omega))?;
    let scale = d.real("start scale", 0.1..=5.0);
    x.iter_mut().for_each(|v| *v *= scale);
    if d.flag("wrong length", 0.05) {
        x.push(0.0);
    }
    problem.set_parameter(omega);
    let result = if d.flag("cancel", 0.2) {
        let after = d.size("cancel after", 0..=20);
        let mut monitor = |n: usize| {
            if n >= after {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        };
        struct Cancel<'a>(&'a mut dyn FnMut(usize) -> ControlFlow<()>);
        impl SolveMonitor for Cancel<'_> {
            fn evaluated(&mut self, n: usize) -> ControlFlow<()> {
                (self.0)(n)
            }
        }
        solver.solve_monitored(&mut problem, &mut x, &mut Cancel(&mut monitor))
    } else {
        solver.solve(&mut problem, &mut x)
    };
    let info = typed(c, "solve", result)?;
    c.solve_info("solve", &info, &x);
    Ok(())
}

/// `modal::backbone`, `backbone_with` (an observer that may stop it) and
/// `backbone_speculative_with`, with any grid, mode, options and solver.
fn backbone_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let system = reference_system(d, c)?;
    let s = settings(d);
    let period = 3.9 * d.real("period factor", 0.5..=2.0);
    let options = BackboneOptions {
        grid: PeriodGrid {
            start: d.real("grid start", period..=period),
            end: d.real("grid end", period * 0.8..=period),
            steps: d.size("steps", 2..=8),
        },
        mode: d.size("mode", 1..=2),
        subharmonic: d.size("subharmonic", 1..=2),
        predictor: d.pick("predictor", &[Predictor::Constant, Predictor::Secant]),
        max_consecutive_failures: d.size("max_consecutive_failures", 0..=5),
        retry_depth: d.size("retry_depth", 0..=3),
        selection: d.pick(
            "selection",
            &[Selection::FirstConverged, Selection::LowestMeasure],
        ),
        trivial_energy: d.real("trivial_energy", 0.0..=1e-3),
    };
    let solver = solver(d, c)?;
    let mut points = Vec::new();
    let stop = stop_policy(d, true);
    let (mut seen, mut stopped) = (0, false);
    let collect = |p: &BackbonePoint| {
        points.push(p.clone());
        seen += 1;
        stopped = match stop {
            Stop::FirstPoint => true,
            Stop::FirstRejection => !p.converged,
            Stop::After(n) => seen >= n,
            Stop::Never => false,
        };
        if stopped {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    };
    let run = match d.pick("backbone", &["with", "speculative", "plain"]) {
        "with" => backbone_with(&system, s, &options, solver, collect),
        "speculative" => {
            let speculation = Speculation {
                after_evaluations: d.size("after_evaluations", 0..=20),
            };
            backbone_speculative_with(&system, s, &options, speculation, solver, collect)
        }
        _ => backbone(&system, s, &options, solver).map(|b| {
            points = b.points;
            (b.grazing_energy, b.end)
        }),
    };
    let (e_g, end) = typed(c, "backbone", run)?;
    c.finite("E_g", [&e_g]);
    // A run stopped by the observer says so (the plain form's observer never stops it).
    if (end == EndReason::StoppedByObserver) != stopped {
        c.no_end
            .push(format!("backbone: {} points, end {end:?}", points.len()));
    }
    points.iter().for_each(|p| c.backbone_point("backbone", p));
    Ok(())
}

/// The sequential driver (or its speculative wrapper) on a period grid or any list of
/// values, with any options, acceptance test and measure, driven every way.
fn sequential_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let (mut problem, period) = valid_problem(d, c)?;
    let solver = solver(d, c)?;
    let seed = typed(
        c,
        "seed",
        branch_seed(&mut problem, 1, 1, 2.0 * PI / period),
    )?;
    let start = if d.flag("wrong start", 0.05) {
        vec![0.0; seed.len() + 1]
    } else {
        seed
    };
    let values = if d.flag("own values", 0.3) {
        (0..d.size("values", 0..=6).min(8))
            .map(|i| d.real(&format!("value{i}"), period * 0.8..=period * 1.1))
            .collect()
    } else {
        typed(
            c,
            "linspace",
            linspace(
                d.real("from", period..=period),
                d.real("to", period * 0.8..=period),
                d.size("steps", 2..=8),
            ),
        )?
    };
    let options = SequentialOptions {
        predictor: d.pick("predictor", &[Predictor::Constant, Predictor::Secant]),
        max_consecutive_failures: d.size("max_consecutive_failures", 0..=5),
        retry_depth: d.size("retry_depth", 0..=3),
        selection: d.pick(
            "selection",
            &[Selection::FirstConverged, Selection::LowestMeasure],
        ),
    };
    let driver = typed(
        c,
        "Sequential::new",
        Sequential::new(
            PeriodParametrised::new(problem),
            solver,
            start,
            values,
            options,
        ),
    )?;
    let driver = match d.pick("acceptance", &["none", "refuse all", "nan measure"]) {
        "refuse all" => driver.with_acceptance(|_, _| false),
        "nan measure" => driver.with_measure(|_, _| f64::NAN),
        _ => driver,
    };
    if d.flag("speculative", 0.3) {
        let speculation = Speculation {
            after_evaluations: d.size("after_evaluations", 0..=20),
        };
        drive(d, c, Speculative::new(driver, speculation), true);
    } else {
        drive(d, c, driver, true);
    }
    Ok(())
}

/// The pseudo-arclength driver (or its stall escape) from a seed, with any options.
fn arclength_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let (mut problem, period) = valid_problem(d, c)?;
    let solver = solver(d, c)?;
    let omega = 2.0 * PI / period * 1.02;
    let seed = typed(c, "seed", branch_seed(&mut problem, 1, 1, omega))?;
    let mut options = arclength_options(d);
    if d.flag("long run", 0.1) {
        options.max_steps = d.pick("long max_steps", &[usize::MAX, 10_000]);
        options.max_rejections = d.pick("long max_rejections", &[usize::MAX, 10_000]);
        options.parameter_range = (f64::NEG_INFINITY, f64::INFINITY);
    }
    let lambda0 = d.real("lambda0", omega..=omega);
    let driver = typed(
        c,
        "Arclength::new",
        Arclength::new(problem, solver, seed, lambda0, options),
    )?;
    let bounded = arclength_bounded(&options);
    if d.flag("escape", 0.3) {
        let escaping = typed(
            c,
            "EscapingArclength::new",
            EscapingArclength::new(driver, stall_escape(d)),
        )?;
        drive(d, c, escaping, bounded);
    } else {
        drive(d, c, driver, bounded);
    }
    Ok(())
}

/// A [`Watcher`] of an arclength backbone's points and rejected steps, keeping the points.
struct BackboneWatcher {
    watcher: Watcher,
    points: Vec<BackbonePoint>,
}

impl BackboneObserver for &mut BackboneWatcher {
    fn point(&mut self, point: &BackbonePoint) -> ControlFlow<()> {
        self.points.push(point.clone());
        self.watcher.count(true)
    }
    fn rejected(&mut self, _: &Rejection) -> ControlFlow<()> {
        self.watcher.count(false)
    }
}

/// `modal::arclength_backbone_observed` with any options, escape and observer.
fn arclength_backbone_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let system = reference_system(d, c)?;
    let s = settings(d);
    let mut arclength = arclength_options(d);
    if d.flag("long run", 0.1) {
        arclength.max_steps = usize::MAX;
        arclength.max_rejections = usize::MAX;
    }
    let start_period = d.real("start_period", 3.0..=4.5);
    let options = ArclengthBackboneOptions {
        start_period,
        omega_range: (d.real("omega lo", 1.0..=1.6), d.real("omega hi", 1.6..=2.5)),
        mode: d.size("mode", 1..=2),
        subharmonic: d.size("subharmonic", 1..=2),
        arclength,
        escape: d.flag("escape", 0.5).then(|| stall_escape(d)),
        trivial_energy: d.real("trivial_energy", 0.0..=1e-3),
    };
    let solver = solver(d, c)?;
    // The observer sees rejected steps too, so an unbounded run (a shrink factor close to 1
    // with no rejection budget) is stopped by the watcher's step cap.
    let mut observer = BackboneWatcher {
        watcher: Watcher::new(stop_policy(d, arclength_bounded(&arclength))),
        points: Vec::new(),
    };
    let (e_g, branch) = typed(
        c,
        "arclength_backbone",
        arclength_backbone_observed(&system, s, &options, solver, &mut observer),
    )?;
    let BackboneWatcher { watcher, points } = observer;
    let stopped = watcher.stopped;
    c.finite("E_g", [&e_g]);
    if watcher.seen >= STEP_CAP {
        c.no_end
            .push(format!("arclength backbone: no end after {STEP_CAP} steps"));
    }
    c.branch("arclength backbone", &branch, stopped);
    points
        .iter()
        .for_each(|p| c.backbone_point("arclength backbone", p));
    Ok(())
}

/// `modal::parameter_branch` in the gap of the clamped bar, over values or by arclength.
fn parameter_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let gap = d.real("gap", 1e-4..=0.1);
    let harmonics = d.size("harmonics", 1..=MAX_HARMONICS).min(1 << 20);
    let s = HarmonicBalanceSettings {
        harmonics,
        samples_per_harmonic: 10,
        ..Default::default()
    };
    let period = d.real("period", 3.2..=3.9);
    let x = if harmonics <= MAX_HARMONICS && gap.is_finite() && period.is_finite() {
        ClampedFirstMode::new(gap, period).unknowns(harmonics)
    } else {
        vec![0.0; 4]
    };
    let omega = 2.0 * PI / period;
    let steps = if d.flag("values", 0.5) {
        let count = d.size("count", 1..=6).min(8);
        let mut values = vec![d.real("first value", gap..=gap)];
        values.extend((1..count).map(|i| d.real(&format!("value{i}"), gap..=2.0 * gap)));
        let options = SequentialOptions {
            max_consecutive_failures: d.size("max_consecutive_failures", 0..=5),
            retry_depth: d.size("retry_depth", 0..=2),
            ..Default::default()
        };
        ParameterSteps::Values(values, options)
    } else {
        let mut o = arclength_options(d);
        o.parameter_range = (
            d.real("range lo", gap * 0.5..=gap),
            d.real("range hi", gap..=gap * 3.0),
        );
        o.max_steps = o.max_steps.min(8);
        o.max_rejections = o.max_rejections.min(20);
        ParameterSteps::Arclength(o)
    };
    let stop = stop_policy(d, true);
    let mut seen = 0;
    let mut stopped = false;
    let mut points = Vec::new();
    let observer = |value: f64, p: &BackbonePoint| {
        seen += 1;
        points.push((value, p.clone()));
        stopped = match stop {
            Stop::FirstPoint => true,
            Stop::FirstRejection => !p.converged,
            Stop::After(n) => seen >= n,
            Stop::Never => false,
        };
        if stopped {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    };
    let solver = solver(d, c)?;
    let branch = typed(
        c,
        "parameter_branch",
        parameter_branch(
            clamped_bar_with_obstacle,
            s,
            (x, omega),
            gap,
            steps,
            solver,
            observer,
        ),
    )?;
    c.branch("parameter branch", &branch, stopped);
    // Converged points are finite; `E / E_g` is NaN, as documented, where the system at
    // the point's parameter has no grazing energy (checked against `grazing_energy`).
    for (value, p) in points.iter().filter(|(_, p)| p.converged) {
        let defined = clamped_bar_with_obstacle(*value)
            .ok()
            .is_some_and(|s| grazing_energy(&s).is_ok());
        let mut p = p.clone();
        if !defined && p.energy_normalized.is_nan() {
            p.energy_normalized = 0.0;
        }
        c.backbone_point("parameter point", &p);
    }
    Ok(())
}

/// Post-processing of a motion of a valid system at any frequency, with any sizes:
/// `Solution` and its histories, fields and diagnostics, `diagnose`, `law_history`, the
/// energy, the grazing energy and the periodicity check.
fn post_processing(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let system = reference_system(d, c)?;
    let s = HarmonicBalanceSettings {
        harmonics: d
            .size("harmonics", 1..=MAX_HARMONICS)
            .clamp(1, MAX_HARMONICS),
        samples_per_harmonic: d.size("samples", 3..=30).clamp(3, 64),
        ..Default::default()
    };
    let mut problem = typed(c, "NonsmoothSystem::new", NonsmoothSystem::new(&system, s))?;
    if let Ok((e_g, _)) = grazing_energy(&system) {
        c.finite("E_g", [&e_g]);
    }
    let omega = d.real("omega", 0.3..=50.0);
    let seed_omega = if omega.is_finite() && omega > 0.0 {
        omega
    } else {
        1.6
    };
    let mut x = branch_seed(&mut problem, 1, 1, seed_omega.clamp(1e-3, 1e3))
        .unwrap_or_else(|_| vec![0.0; problem.dimension()]);
    let scale = d.real("motion scale", 0.1..=10.0);
    x.iter_mut().for_each(|v| *v *= scale);
    if d.flag("wrong length", 0.05) {
        x.pop();
    }
    let moderate_inputs = x.len() == problem.dimension() && moderate_motion(&system, &x, omega);
    if moderate_inputs {
        c.finite("energy", [&energy(&system, problem.basis(), &x, omega)]);
    }
    let refinement = d.size("refinement", 1..=4);
    if let Ok(diag) = diagnose(&problem, &x, omega, refinement) {
        c.finite("diagnose", &diag.residual_norm);
        c.finite(
            "diagnose",
            [
                &diag.max_penetration,
                &diag.min_contact_force,
                &diag.energy_drift,
            ],
        );
    }
    let law = d.size("law", 0..=1);
    let samples = d.size("samples", 1..=64);
    if let Ok(h) = law_history(&problem, &x, omega, law, samples) {
        for v in [&h.time, &h.gap, &h.force, &h.residual] {
            c.finite("law history", v);
        }
    }
    let solution = typed(c, "Solution::new", Solution::new(&problem, &x, omega))?;
    c.finite("period", [&solution.period()]);
    let end = if d.flag("foreign end", 0.1) {
        foreign_bar().left()
    } else {
        system.bar_id(0).expect("a bar").right()
    };
    if let Ok(h) = solution.end_history(end, d.size("end samples", 1..=32)) {
        for v in [&h.time, &h.displacement, &h.strain, &h.contact_force] {
            c.finite("end history", v);
        }
    }
    let (bar, positions, instants) = (
        d.size("grid bar", 0..=1),
        d.size("positions", 1..=8),
        d.size("instants", 1..=8),
    );
    if let Ok(g) = solution.displacement_grid(bar, positions, instants) {
        for v in [&g.position, &g.time, &g.displacement] {
            c.finite("displacement grid", v);
        }
    }
    if let Ok(e) = solution.energy_normalized() {
        c.finite("E / E_g", [&e]);
    }
    let position = d.rng.unit() * system.bars()[0].length();
    if moderate_inputs {
        let field = solution.field().at(0, position, d.rng.unit() * 2.0 * PI);
        c.finite(
            "field",
            [&field.displacement, &field.velocity, &field.strain],
        );
    }
    // The march costs `periods 2 pi / (omega dt)` steps: only frequencies from 0.3 (or
    // invalid ones, rejected before marching) keep it short.
    if !(omega.is_finite() && omega < 0.3) {
        let options = PeriodicityOptions {
            dt: d.real("dt", 0.02..=0.2),
            adjust_grid: d.flag("adjust grid", 0.5),
            spring: d.pick(
                "spring update",
                &[SpringUpdate::Exact, SpringUpdate::Midpoint],
            ),
            periods: d.size("periods", 1..=2).min(3),
        };
        let report = if d.flag("via solution", 0.5) {
            solution.periodicity_check(&options)
        } else {
            periodicity_check(&system, problem.basis(), &x, omega, &options)
        };
        if let Ok(r) = report {
            c.finite(
                "periodicity",
                [
                    &r.period,
                    &r.dt,
                    &r.defect,
                    &r.initial_norm,
                    &r.displacement_defect,
                    &r.initial_energy,
                    &r.energy_drift,
                    &r.initial_penetration,
                    &r.max_penetration,
                    &r.min_contact_force,
                ],
            );
        }
    }
    Ok(())
}

// ------------------------------------------------------------------------------------------
// The harness

/// How a case ended.
#[derive(Debug, Clone, PartialEq)]
enum Outcome {
    Ok,
    TypedError,
    Panic(String),
    NonFinite(String),
    NoEnd(String),
    Hang,
}

/// One case's report.
struct Report {
    index: usize,
    kind: Kind,
    outcome: Outcome,
    inputs: String,
}

/// The message and place of the last panic, recorded by the harness' panic hook.
static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);
/// One stress run at a time: the panic hook is global.
static SUITE: Mutex<()> = Mutex::new(());

/// The seed of case `index`: a SplitMix64 step of the base seed and the index, so that a
/// case can be rerun alone (`STRESS_ONLY=index`).
fn case_seed(base: u64, index: usize) -> u64 {
    SplitMix(base ^ (index as u64).wrapping_mul(0xD1B5_4A32_D192_ED03)).next()
}

/// Draws and runs case `index`; its inputs go to `log` as they are drawn.
fn run_case(base: u64, index: usize, log: Arc<Mutex<String>>) -> Report {
    let mut rng = SplitMix(case_seed(base, index));
    let kind = KINDS[rng.below(KINDS.len() as u64) as usize];
    let edge = [0.0, 0.05, 0.15, 0.4][rng.below(4) as usize];
    let mut draw = Draw {
        rng,
        log: Arc::clone(&log),
        edge,
    };
    let mut checks = Checks::default();
    *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = None;
    let result = panic::catch_unwind(AssertUnwindSafe(|| kind.run(&mut draw, &mut checks)));
    let outcome = match result {
        Err(payload) => {
            let recorded = LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()).take();
            let message = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned());
            Outcome::Panic(recorded.or(message).unwrap_or_default())
        }
        Ok(_) if !checks.non_finite.is_empty() => Outcome::NonFinite(checks.non_finite.join("; ")),
        Ok(_) if !checks.no_end.is_empty() => Outcome::NoEnd(checks.no_end.join("; ")),
        Ok(Ok(())) => Outcome::Ok,
        Ok(Err(message)) => {
            if std::env::var_os("STRESS_ERRORS").is_some() {
                println!("typed {kind:?}: {message}");
            }
            Outcome::TypedError
        }
    };
    let inputs = log.lock().unwrap_or_else(|e| e.into_inner()).clone();
    Report {
        index,
        kind,
        outcome,
        inputs,
    }
}

/// A thread that runs the cases it is sent; replaced when a case hangs.
struct Worker {
    cases: mpsc::Sender<(usize, Arc<Mutex<String>>)>,
    reports: mpsc::Receiver<Report>,
}

impl Worker {
    fn spawn(base: u64) -> Self {
        let (cases, jobs) = mpsc::channel::<(usize, Arc<Mutex<String>>)>();
        let (done, reports) = mpsc::channel();
        std::thread::Builder::new()
            .name("stress case".into())
            .spawn(move || {
                for (index, log) in jobs {
                    if done.send(run_case(base, index, log)).is_err() {
                        break;
                    }
                }
            })
            .expect("spawn the worker");
        Self { cases, reports }
    }
}

#[derive(Default)]
struct Counts {
    cases: usize,
    ok: usize,
    typed: usize,
    panics: usize,
    non_finite: usize,
    no_end: usize,
    hangs: usize,
}

impl Counts {
    fn add(&mut self, outcome: &Outcome) {
        self.cases += 1;
        match outcome {
            Outcome::Ok => self.ok += 1,
            Outcome::TypedError => self.typed += 1,
            Outcome::Panic(_) => self.panics += 1,
            Outcome::NonFinite(_) => self.non_finite += 1,
            Outcome::NoEnd(_) => self.no_end += 1,
            Outcome::Hang => self.hangs += 1,
        }
    }

    fn row(&self, name: &str) -> String {
        format!(
            "{name:<20} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7}",
            self.cases, self.ok, self.typed, self.panics, self.non_finite, self.no_end, self.hangs
        )
    }
}

/// Runs `indices` of the suite of seed `base`, prints the summary and every failure, and
/// returns the failures.
fn run_suite(base: u64, indices: impl Iterator<Item = usize>) -> Vec<Report> {
    let _one_at_a_time = SUITE.lock().unwrap_or_else(|e| e.into_inner());
    let previous_hook = panic::take_hook();
    panic::set_hook(Box::new(|info| {
        *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = Some(info.to_string());
    }));
    let started = Instant::now();
    let mut worker = Worker::spawn(base);
    let mut per_kind: BTreeMap<Kind, Counts> = BTreeMap::new();
    let mut total = Counts::default();
    let mut failures = Vec::new();
    for index in indices {
        let log = Arc::new(Mutex::new(String::new()));
        worker
            .cases
            .send((index, Arc::clone(&log)))
            .expect("the worker takes cases");
        let report = match worker
            .reports
            .recv_timeout(Duration::from_secs(HANG_SECONDS))
        {
            Ok(report) => report,
            Err(_) => {
                // The hung thread cannot be stopped: leave it and carry on with a new one.
                worker = Worker::spawn(base);
                let inputs = log.lock().unwrap_or_else(|e| e.into_inner()).clone();
                let kind =
                    KINDS[SplitMix(case_seed(base, index)).below(KINDS.len() as u64) as usize];
                Report {
                    index,
                    kind,
                    outcome: Outcome::Hang,
                    inputs,
                }
            }
        };
        per_kind
            .entry(report.kind)
            .or_default()
            .add(&report.outcome);
        total.add(&report.outcome);
        if !matches!(report.outcome, Outcome::Ok | Outcome::TypedError) {
            // At once too: a run with hangs takes long to reach the summary.
            eprintln!("failing case {index}: {:?}", report.outcome);
            failures.push(report);
        }
    }
    let elapsed = started.elapsed();
    panic::set_hook(previous_hook);
    println!(
        "\nstress suite, seed {base:#x}: {} cases in {:.1} s",
        total.cases,
        elapsed.as_secs_f64()
    );
    println!(
        "{:<20} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7}",
        "kind", "cases", "ok", "typed", "panic", "nonfin", "no end", "hang"
    );
    for (kind, counts) in &per_kind {
        println!("{}", counts.row(&format!("{kind:?}")));
    }
    println!("{}", total.row("total"));
    println!("aborts: 0 (the process finished)");
    for f in &failures {
        println!(
            "FAILURE case {} ({:?}) STRESS_SEED={base:#x} STRESS_ONLY={}: {:?}\n    inputs: {}",
            f.index, f.kind, f.index, f.outcome, f.inputs
        );
    }
    failures
}

fn env_number(name: &str) -> Option<u64> {
    let v = std::env::var(name).ok()?;
    let v = v.trim();
    match v.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16).ok(),
        None => v.parse().ok(),
    }
}

/// Runs `cases` cases (or only `STRESS_ONLY`) and fails on any failure.
fn stress(cases: usize) {
    let base = env_number("STRESS_SEED").unwrap_or(SEED);
    let failures = match env_number("STRESS_ONLY") {
        Some(only) => run_suite(base, std::iter::once(only as usize)),
        None => run_suite(base, 0..cases),
    };
    assert!(
        failures.is_empty(),
        "{} failing cases (panics, non-finite results, runs without end reason, hangs): see above",
        failures.len()
    );
}

#[test]
fn stress_public_api() {
    stress(QUICK_CASES);
}

#[test]
#[ignore = "long: 20 000 cases by default (STRESS_CASES), run in release"]
fn stress_public_api_long() {
    let cases = env_number("STRESS_CASES").map_or(LONG_CASES, |n| n as usize);
    stress(cases);
}
