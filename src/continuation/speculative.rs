//! Speculative retries: the first retry of a sequential step runs on a second thread beside
//! the first attempt, so that a failed step costs the wall time of one solve instead of two.
//!
//! The result is the serial one, bit for bit: the first attempt decides as before, the retry
//! solves the same system from the same start with a clone of the problem, and its outcome is
//! used only if the first attempt fails. What changes is when the retry runs: it is launched
//! once the first attempt has spent [`Speculation::after_evaluations`] residual evaluations
//! (a step that converges quickly never starts a thread), and it is cancelled as soon as the
//! first attempt joins the branch.

use super::driver::{next_point, run_with};
use super::sequential::Attempt;
use super::{Branch, ContinuationProblem, Observer, Point, Sequential, Step};
use crate::error::{ContinuationError, SolveError};
use crate::solve::{NonlinearSolver, SolveInfo, SolveMonitor};
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{mpsc, Arc};

/// When [`Speculative`] starts the retry on a second thread.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Speculation {
    /// Residual evaluations (line-search trials included) the first attempt spends before the
    /// retry is launched beside it (default 10). A solve that converges from the prediction
    /// needs few evaluations and a failing one many more (`docs/performance.md` has the
    /// counts): a small value launches the retry early in hopeless steps while leaving quick
    /// steps alone; 0 launches it with the first attempt at every step.
    pub after_evaluations: usize,
}

impl Default for Speculation {
    fn default() -> Self {
        Self {
            after_evaluations: 10,
        }
    }
}

/// What the speculative retries of a run did ([`Speculative::stats`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SpeculationStats {
    /// Retries handed to the worker (first attempts that reached
    /// [`Speculation::after_evaluations`]).
    pub launched: usize,
    /// Handed-over retries whose first attempt joined the branch: cancelled, never used.
    pub cancelled: usize,
    /// Retries the worker solved and the driver used (the first attempt failed).
    pub used: usize,
    /// Retries the driver took back and solved itself, because the first attempt failed
    /// before the worker had started them.
    pub taken_back: usize,
}

/// A solve's monitor: fires a hook once at a given count of residual evaluations, and cancels
/// the solve once its flag says [`CANCELLED`].
struct Watch<'a> {
    hook: Option<(usize, &'a mut dyn FnMut())>,
    cancel: Option<&'a AtomicU8>,
}

impl SolveMonitor for Watch<'_> {
    fn evaluated(&mut self, evaluations: usize) -> ControlFlow<()> {
        if let Some((at, hook)) = self.hook.as_mut() {
            if evaluations >= *at {
                hook();
                self.hook = None;
            }
        }
        match self.cancel {
            Some(c) if c.load(Ordering::Acquire) == CANCELLED => ControlFlow::Break(()),
            _ => ControlFlow::Continue(()),
        }
    }
}

/// Life of a speculative retry, shared by the driver and the worker thread.
const PENDING: u8 = 0;
const RUNNING: u8 = 1;
/// The first attempt joined the branch: the retry is not needed.
const CANCELLED: u8 = 2;
/// The first attempt failed before the worker picked the retry up: the driver runs it.
const TAKEN: u8 = 3;

/// A retry handed to the worker: solve at `lambda` from `start`.
struct Job {
    step: usize,
    lambda: f64,
    start: Vec<f64>,
    state: Arc<AtomicU8>,
}

/// What the worker sends back: the step, where the solve ended, and how.
type Finished = (usize, Vec<f64>, Result<SolveInfo, SolveError>);

/// A thread that solves retries with its own clone of the problem and of the solver. It
/// lives as long as the driver; dropping it closes its queue and joins it.
pub(super) struct Worker {
    jobs: Option<mpsc::Sender<Job>>,
    results: mpsc::Receiver<Finished>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Worker {
    /// Starts the thread; `None` if the system refuses one (the driver then retries serially).
    fn spawn<P, S>(mut problem: P, solver: S) -> Option<Self>
    where
        P: ContinuationProblem + Send + 'static,
        S: NonlinearSolver + Send + 'static,
    {
        let (jobs, queue) = mpsc::channel::<Job>();
        let (done, results) = mpsc::channel();
        let thread = std::thread::Builder::new()
            .name("nonsmooth-modes-retry".into())
            .spawn(move || {
                for job in queue {
                    let claimed = job
                        .state
                        .compare_exchange(PENDING, RUNNING, Ordering::AcqRel, Ordering::Acquire)
                        .is_ok();
                    if !claimed {
                        continue;
                    }
                    let mut x = job.start;
                    let mut watch = Watch {
                        hook: None,
                        cancel: Some(&job.state),
                    };
                    problem.set_parameter(job.lambda);
                    let result = solver.solve_monitored(&mut problem, &mut x, &mut watch);
                    if done.send((job.step, x, result)).is_err() {
                        break;
                    }
                }
            })
            .ok()?;
        Some(Self {
            jobs: Some(jobs),
            results,
            thread: Some(thread),
        })
    }

    /// The worker's outcome of the retry of `step` (stale outcomes of cancelled retries are
    /// skipped); `None` if the worker is gone.
    fn outcome(&self, step: usize) -> Option<(Vec<f64>, Result<SolveInfo, SolveError>)> {
        loop {
            let (s, x, result) = self.results.recv().ok()?;
            if s == step {
                return Some((x, result));
            }
        }
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        drop(self.jobs.take());
        if let Some(thread) = self.thread.take() {
            // A panic on the worker has already been reported by its thread.
            let _ = thread.join();
        }
    }
}

impl std::fmt::Debug for Worker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Worker")
    }
}

/// [`Sequential`] with the first retry of each failing step run speculatively on a worker
/// thread (see [`Speculation`]): the same steps as the serial driver, bit for bit, in less
/// wall time when steps fail and a second core is free. The worker is started on first use
/// with clones of the problem and the solver, and stopped when this driver is dropped. The
/// driver never waits for a retry it does not need: a cancelled retry is dropped, and one the
/// worker has not started when the first attempt fails is run by the driver itself. Deeper
/// retries ([`SequentialOptions::retry_depth`](super::SequentialOptions::retry_depth) above 1)
/// run serially after it.
///
/// With [`Selection::LowestMeasure`](super::Selection::LowestMeasure) and a measure
/// ([`Sequential::with_measure`]) a step is the serial [`Sequential::step`]: every start of
/// every step is solved anyway, so a retry is never speculative.
///
/// It has the drivers' shape: [`Speculative::step`], [`Speculative::run`] and an iterator of
/// `Result<Point, ContinuationError>`.
///
/// The problem and the solver must be `Clone + Send + 'static`: the worker thread is spawned
/// with clones of them ([`std::thread::spawn`] takes only `'static` data) and outlives any
/// one step. The acceptance test and the measure stay on the caller's thread (the driver
/// judges the worker's solutions itself), so they may borrow for the driver's lifetime `'a`
/// like those of [`Sequential`].
pub struct Speculative<'a, P, S> {
    driver: Sequential<'a, P, S>,
    speculation: Speculation,
    /// The thread of speculative retries (started on first use).
    worker: Option<Worker>,
    stats: SpeculationStats,
    /// Whether the iterator has handed out the end.
    done: bool,
}

impl<'a, P, S> Speculative<'a, P, S> {
    /// `driver` with speculative retries as `speculation` says.
    pub fn new(driver: Sequential<'a, P, S>, speculation: Speculation) -> Self {
        Self {
            driver,
            speculation,
            worker: None,
            stats: SpeculationStats::default(),
            done: false,
        }
    }

    /// Counts of the speculative retries so far.
    pub fn stats(&self) -> SpeculationStats {
        self.stats
    }

    /// The serial driver underneath (its problem, its last converged point).
    pub fn driver_mut(&mut self) -> &mut Sequential<'a, P, S> {
        &mut self.driver
    }
}

impl<P, S> Speculative<'_, P, S>
where
    P: ContinuationProblem + Clone + Send + 'static,
    S: NonlinearSolver + Clone + Send + 'static,
{
    /// The next step: the outcome of [`Sequential::step`], with the first retry run beside
    /// the first attempt.
    pub fn step(&mut self) -> Step {
        let d = &mut self.driver;
        if d.selects_lowest() {
            return d.step();
        }
        let (step, lambda) = match d.next_value() {
            Ok(next) => next,
            Err(end) => return Step::Finished(end),
        };
        let mut x = d.predict(lambda);
        if d.retry_count() > 0 && self.worker.is_none() {
            self.worker = Worker::spawn(d.problem.clone(), d.solver.clone());
        }
        // The retry's start is copied, and its state allocated, only if it is handed over.
        let retries = d.retry_count() > 0;
        let mut pending = match (&self.worker, d.history.front()) {
            (Some(worker), Some((start, _))) if retries => {
                worker.jobs.as_ref().map(|jobs| (jobs, start))
            }
            _ => None,
        };
        let mut handed: Option<Arc<AtomicU8>> = None;
        let speculation = self.speculation;
        let result = {
            let mut launch = || {
                if let Some((jobs, start)) = pending.take() {
                    let state = Arc::new(AtomicU8::new(PENDING));
                    let job = Job {
                        step,
                        lambda,
                        start: start.clone(),
                        state: Arc::clone(&state),
                    };
                    handed = jobs.send(job).is_ok().then_some(state);
                }
            };
            // At 0 the retry starts with the first attempt (also beside a solver that does not
            // report its evaluations).
            if speculation.after_evaluations == 0 {
                launch();
            }
            let mut watch = Watch {
                hook: Some((speculation.after_evaluations, &mut launch)),
                cancel: None,
            };
            d.problem.set_parameter(lambda);
            d.solver.solve_monitored(&mut d.problem, &mut x, &mut watch)
        };
        let accepted = d.admits(&result, &x, lambda);
        let first = Attempt {
            x,
            result,
            accepted,
            from_history: None,
        };
        let stats = &mut self.stats;
        let sent = handed.is_some();
        stats.launched += usize::from(sent);
        if first.joins() {
            if let Some(state) = &handed {
                state.store(CANCELLED, Ordering::Release);
            }
            stats.cancelled += usize::from(sent);
            return d.conclude(step, lambda, first);
        }
        let taken = handed.as_ref().is_none_or(|state| {
            state
                .compare_exchange(PENDING, TAKEN, Ordering::AcqRel, Ordering::Acquire)
                .is_ok()
        });
        stats.taken_back += usize::from(sent && taken);
        let speculated = match (taken, &self.worker) {
            (false, Some(worker)) => worker.outcome(step),
            _ => None,
        };
        stats.used += usize::from(speculated.is_some());
        let chosen = match speculated {
            // The worker ran the first retry: judge it as `step` would have, then go deeper.
            Some((y, result)) => {
                let accepted = d.admits(&result, &y, lambda);
                let retried = Attempt {
                    x: y,
                    result,
                    accepted,
                    from_history: Some(0),
                };
                let best = if retried.joins() { retried } else { first };
                d.retry_from(lambda, 1, best)
            }
            None => d.retry_from(lambda, 0, first),
        };
        d.conclude(step, lambda, chosen)
    }

    /// Runs to the end like [`Sequential::run`]: the same branch, in less wall time when
    /// steps fail.
    pub fn run(&mut self, observer: &mut (impl Observer + ?Sized)) -> Branch {
        run_with(self, Self::step, |s| s.driver.stop(), observer)
    }
}

impl<P, S> Iterator for Speculative<'_, P, S>
where
    P: ContinuationProblem + Clone + Send + 'static,
    S: NonlinearSolver + Clone + Send + 'static,
{
    type Item = Result<Point, ContinuationError>;

    /// The converged points; then, if the run stalled, its error; then `None`.
    fn next(&mut self) -> Option<Self::Item> {
        next_point(self, |d| &mut d.done, Self::step)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::DenseMatrix;
    use crate::solve::{NewtonOptions, Problem, SemismoothNewton};

    /// `F(x) = x^2 - 2` in one unknown.
    struct Square;

    impl Problem for Square {
        fn dimension(&self) -> usize {
            1
        }
        fn residual(&mut self, x: &[f64], f: &mut [f64]) {
            f[0] = x[0] * x[0] - 2.0;
        }
        fn jacobian(&mut self, x: &[f64], jac: &mut DenseMatrix) {
            jac.reset(1, 1);
            jac[(0, 0)] = 2.0 * x[0];
        }
    }

    #[test]
    fn the_hook_fires_once_at_its_count_and_leaves_the_solve_alone() {
        let solver = SemismoothNewton::new(NewtonOptions::default()).unwrap();
        let mut plain = [3.0];
        let info = solver.solve(&mut Square, &mut plain).unwrap();
        let mut watched = [3.0];
        let mut count = 0;
        let mut hook = || count += 1;
        let mut watch = Watch {
            hook: Some((2, &mut hook)),
            cancel: None,
        };
        let watched_info = solver
            .solve_monitored(&mut Square, &mut watched, &mut watch)
            .unwrap();
        assert_eq!(watched, plain);
        assert_eq!(watched_info, info);
        assert_eq!(count, 1);
    }

    #[test]
    fn a_cancelled_solve_stops_at_once() {
        let solver = SemismoothNewton::default();
        let state = AtomicU8::new(CANCELLED);
        let watch = |state| Watch {
            hook: None,
            cancel: Some(state),
        };
        let mut x = [3.0];
        let result = solver.solve_monitored(&mut Square, &mut x, &mut watch(&state));
        assert_eq!(
            result,
            Err(SolveError::Cancelled {
                iteration: 0,
                evaluations: 1
            })
        );
        // Running, not cancelled: the solve goes on.
        state.store(RUNNING, Ordering::Release);
        let mut x = [3.0];
        solver
            .solve_monitored(&mut Square, &mut x, &mut watch(&state))
            .unwrap();
        assert!((x[0] - 2f64.sqrt()).abs() < 1e-9);
    }
}
