//! The solvers of the crate with any options, and solves with them.

use super::valid_problem;
use crate::checks::{typed, CaseResult, Checks};
use crate::draw::Draw;
use nonsmooth_modes::continuation::ContinuationProblem;
use nonsmooth_modes::modal::branch_seed;
use nonsmooth_modes::solve::{
    Dogleg, DoglegOptions, NewtonOptions, NonlinearSolver, Problem, SemismoothNewton,
    SmoothingHomotopy, SolveInfo, SolveMonitor, Solver,
};
use nonsmooth_modes::SolveError;
use std::f64::consts::PI;
use std::ops::ControlFlow;

/// A solver of the crate, chosen at run time, that stays `Clone + Send` for the speculative
/// drivers.
#[derive(Debug, Clone)]
pub(crate) enum AnySolver {
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

/// An iteration budget: small, at the edges, or (with probability `unbounded`) `usize::MAX`,
/// the budget a careless user gives a solver asked for a tolerance it cannot reach.
fn iterations(d: &mut Draw, valid: std::ops::RangeInclusive<usize>, unbounded: f64) -> usize {
    if d.flag("unbounded iterations", unbounded) {
        usize::MAX
    } else {
        d.size("max_iterations", valid)
    }
}

fn newton_options(d: &mut Draw) -> NewtonOptions {
    NewtonOptions {
        tolerance: d.tolerance("tolerance", 1e-12..=1e-3),
        max_iterations: iterations(d, 0..=40, 0.1),
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
pub(crate) fn solver(d: &mut Draw, c: &mut Checks) -> Result<AnySolver, String> {
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
        "dogleg" => Ok(AnySolver::Dogleg(dogleg(d, c)?)),
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

/// A dogleg with random options (a typed error when invalid).
fn dogleg(d: &mut Draw, c: &mut Checks) -> Result<Dogleg, String> {
    let o = DoglegOptions {
        tolerance: d.tolerance("tolerance", 1e-12..=1e-3),
        max_iterations: iterations(d, 0..=60, 0.15),
        initial_radius: d.real("initial_radius", 1e-3..=10.0),
        min_radius: d.real("min_radius", 1e-14..=1e-2),
    };
    typed(c, "Dogleg::new", Dogleg::new(o))
}

/// The solver of a request ([`Solver`], which has no smoothing homotopy): the method's own
/// (`None`), the defaults, `fail_fast`, or random options (a typed error when invalid).
pub(crate) fn request_solver(d: &mut Draw, c: &mut Checks) -> Result<Option<Solver>, String> {
    Ok(Some(
        match d.pick(
            "request solver",
            &["method's", "default", "fail_fast", "newton", "dogleg"],
        ) {
            "method's" => return Ok(None),
            "default" => Solver::default(),
            "fail_fast" => Solver::Newton(
                SemismoothNewton::new(NewtonOptions::fail_fast()).expect("fail_fast is valid"),
            ),
            "newton" => {
                let o = newton_options(d);
                Solver::Newton(typed(c, "SemismoothNewton::new", SemismoothNewton::new(o))?)
            }
            _ => Solver::Dogleg(dogleg(d, c)?),
        },
    ))
}

/// A solve from a scaled seed with any solver and options, at any frequency; or a
/// cancelled one.
pub(crate) fn solver_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
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
