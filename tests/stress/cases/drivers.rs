//! The continuation drivers (sequential, speculative, pseudo-arclength and its stall escape),
//! driven with an observer, as iterators or step by step.

use super::solvers::solver;
use super::valid_problem;
use crate::checks::{typed, CaseResult, Checks};
use crate::draw::Draw;
use nonsmooth_modes::branches::{EscapingArclength, StallEscape};
use nonsmooth_modes::continuation::{
    linspace, Arclength, ArclengthOptions, ArclengthScale, Branch, ContinuationProblem,
    PeriodParametrised, Point, Predictor, Selection, Sequential, SequentialOptions, Speculation,
    Speculative, Step, TangentPredictor,
};
use nonsmooth_modes::modal::branch_seed;
use nonsmooth_modes::solve::NonlinearSolver;
use std::f64::consts::PI;
use std::ops::ControlFlow;

/// Most steps (accepted and rejected) a driven run may take before it counts as a run
/// without end: every run below is bounded far below this by its options or its observer.
pub(crate) const STEP_CAP: usize = 5_000;

/// When an observer stops a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Stop {
    Never,
    FirstPoint,
    FirstRejection,
    /// After this many steps of any kind.
    After(usize),
}

/// An observer policy: `Never` only when the run is bounded by its own options (`bounded`).
pub(crate) fn stop_policy(d: &mut Draw, bounded: bool) -> Stop {
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
pub(crate) struct Watcher {
    stop: Stop,
    pub(crate) seen: usize,
    pub(crate) stopped: bool,
}

impl Watcher {
    pub(crate) fn new(stop: Stop) -> Self {
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
    pub(crate) fn count(&mut self, accepted: bool) -> ControlFlow<()> {
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
driver!(Sequential<'_, P, S>);
driver!(Speculative<'_, P, S>);
driver!(Arclength<'_, P, S>);
driver!(EscapingArclength<'_, P, S>);

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

/// Options of the sequential driver: predictor, failure budget, retries and selection (the
/// backbones draw the same, in the same order).
pub(crate) fn sequential_options(d: &mut Draw) -> SequentialOptions {
    SequentialOptions {
        predictor: d.pick("predictor", &[Predictor::Constant, Predictor::Secant]),
        max_consecutive_failures: d.size("max_consecutive_failures", 0..=5),
        retry_depth: d.size("retry_depth", 0..=3),
        selection: d.pick(
            "selection",
            &[Selection::FirstConverged, Selection::LowestMeasure],
        ),
    }
}

pub(crate) fn arclength_options(d: &mut Draw) -> ArclengthOptions {
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
        branch_points: d.flag("branch points", 0.5),
    }
}

/// Whether arclength options bound a run by themselves to a few hundred steps: few accepted
/// points and few rejections (a shrink factor close to 1 takes millions of rejections to
/// reach `ds_min`, each a corrector solve).
pub(crate) fn arclength_bounded(o: &ArclengthOptions) -> bool {
    o.max_steps <= 50 && o.max_rejections <= 50
}

pub(crate) fn stall_escape(d: &mut Draw) -> StallEscape {
    StallEscape {
        window: d.size("escape window", 2..=6),
        min_progress: d.real("escape min_progress", 1e-4..=1e-1),
        jump: d.real("escape jump", 1e-4..=1e-1),
        max_attempts: d.size("escape max_attempts", 1..=3).min(4),
        max_norm_ratio: d.real("escape max_norm_ratio", 1.0..=10.0),
    }
}

/// The sequential driver (or its speculative wrapper) on a period grid or any list of
/// values, with any options, acceptance test and measure, driven every way.
pub(crate) fn sequential_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
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
    let options = sequential_options(d);
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
pub(crate) fn arclength_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
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
