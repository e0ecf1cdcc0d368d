//! What [`compute`](crate::branches::compute) runs for a request: the driver of a method
//! with its options, each point handed to an [`Annotator`].

use crate::branches::backbone::{
    arclength_backbone_observed, backbone_from, backbone_speculative_with, backbone_with,
    ArclengthBackboneOptions, BackboneObserver, BackboneOptions, PointSink,
};
use crate::branches::energy_backbone::{energy_backbone_with, EnergyBackboneOptions};
use crate::branches::judge::Judge;
use crate::branches::point::BackbonePoint;
use crate::branches::request::{Method, Request};
use crate::branches::result::Annotator;
use crate::branches::start::BackboneStart;
use crate::branches::subharmonic::genuine_subharmonic_backbone_with;
use crate::continuation::{EndReason, Rejection};
use crate::error::Error;
use crate::solve::Solver;
use crate::system::{BarSystem, NonsmoothSystem};
use std::cell::RefCell;
use std::ops::ControlFlow;

/// What [`compute`](crate::branches::compute) runs: the driver, with its options built from the system and the
/// request's mode and order in them.
pub(crate) enum Plan {
    /// A period grid, from a start found beforehand or searching its own.
    Grid(BackboneOptions, Option<BackboneStart>),
    /// A period grid from the unsolved seed, after a start search that failed with the
    /// error kept: the grid may still enter its branch further on.
    FromSeed(BackboneOptions, BackboneStart, Error),
    Genuine(BackboneOptions),
    Energy(EnergyBackboneOptions),
    /// Pseudo-arclength, from a start found beforehand or searching its own.
    Arclength(ArclengthBackboneOptions, Option<BackboneStart>),
}

/// A run whose points were annotated but not yet shown to the user's observer.
pub(crate) struct QuietRun {
    pub points: Vec<BackbonePoint>,
    pub e_g: f64,
    pub end: EndReason,
    pub rejected: usize,
    /// The judge of the run's points ([`crate::branches::judge`]), marched as far as the
    /// questions asked of the run need.
    judge: RefCell<Judge>,
}

impl QuietRun {
    /// The run of `points` annotated on `problem`, to be judged.
    pub(crate) fn new(
        points: Vec<BackbonePoint>,
        (e_g, end, rejected): (f64, EndReason, usize),
        problem: &NonsmoothSystem,
    ) -> Self {
        let judge = RefCell::new(Judge::new(&points, problem));
        Self {
            points,
            e_g,
            end,
            rejected,
            judge,
        }
    }

    /// Converged points, scaled by the share of the judge's sample that passed
    /// ([`crate::branches::judge`]).
    pub(crate) fn good(&self) -> usize {
        self.judge.borrow_mut().good(&self.points)
    }

    /// Whether [`QuietRun::good`] is below half of `steps`, from as few of the judge's
    /// marches as decide it.
    pub(crate) fn falls_short_of(&self, steps: usize) -> bool {
        self.judge.borrow_mut().falls_short(&self.points, steps)
    }
}

/// Runs `plan` with `solver`, keeping the points annotated on `problem` (without the
/// time-domain check) to be judged; gives the problem back.
pub(crate) fn quiet_run(
    system: &BarSystem,
    request: &Request,
    (plan, solver): (Plan, Solver),
    problem: NonsmoothSystem,
) -> Result<(QuietRun, NonsmoothSystem), Error> {
    let quiet = |_: &BackbonePoint| ControlFlow::Continue(());
    let mut annotator = Annotator::unchecked(problem, request, quiet);
    let (e_g, end, rejected) = run_plan(system, request, plan, solver, &mut annotator)?;
    let (points, problem) = annotator.into_parts();
    let run = QuietRun::new(points, (e_g, end, rejected), &problem);
    Ok((run, problem))
}

/// Runs `plan` with `solver`, handing every point to `annotator`; returns `E_g`, the end
/// reason and the rejected steps.
pub(crate) fn run_plan<O: BackboneObserver>(
    system: &BarSystem,
    request: &Request,
    plan: Plan,
    solver: Solver,
    annotator: &mut Annotator<O>,
) -> Result<(f64, EndReason, usize), Error> {
    let settings = request.settings;
    let spec = request.speculation;
    let see = |p: BackbonePoint| annotator.point(p);
    Ok(match plan {
        Plan::Grid(options, Some(start)) => {
            let (e_g, end) = backbone_from(system, settings, &options, start, spec, solver, see)?;
            (e_g, end, 0)
        }
        Plan::Grid(options, None) => {
            let (e_g, end) = match spec {
                Some(spec) => {
                    backbone_speculative_with(system, settings, &options, spec, solver, see)?
                }
                None => backbone_with(system, settings, &options, solver, see)?,
            };
            (e_g, end, 0)
        }
        Plan::Genuine(options) => {
            let (e_g, end) =
                genuine_subharmonic_backbone_with(system, settings, &options, solver, see)?;
            (e_g, end, 0)
        }
        Plan::Energy(options) => {
            let (e_g, end) = energy_backbone_with(system, settings, &options, solver, see)?;
            (e_g, end, 0)
        }
        Plan::Arclength(options, given) => {
            let seen = Forward(annotator);
            let (e_g, branch) =
                arclength_backbone_observed(system, settings, (&options, given), solver, seen)?;
            (e_g, branch.end, branch.rejections)
        }
        Plan::FromSeed(options, start, not_found) => {
            let (e_g, end) = backbone_from(system, settings, &options, start, spec, solver, see)?;
            if annotator.converged() == 0 {
                return Err(not_found);
            }
            (e_g, end, 0)
        }
    })
}

/// A sink that hands what it receives to the annotator (the arclength backbone takes its
/// sink by value).
struct Forward<'a, O>(&'a mut Annotator<O>);

impl<O: BackboneObserver> PointSink for Forward<'_, O> {
    fn point(&mut self, point: BackbonePoint) -> ControlFlow<()> {
        self.0.point(point)
    }
    fn rejected(&mut self, rejection: &Rejection) -> ControlFlow<()> {
        self.0.rejected(rejection)
    }
}

/// The plan of a `request` that names its method, and the method it stands for, with the
/// request's mode and order in its options; for [`Method::Auto`], which chooses its own
/// runs ([`judged_auto`](super::auto::judged_auto)), the grid it was given (`Err`).
pub(crate) fn asked(request: &Request) -> Result<(Plan, Method), Option<BackboneOptions>> {
    let (mode, subharmonic) = (request.mode, request.subharmonic);
    let grid = |o: &BackboneOptions| BackboneOptions {
        mode,
        subharmonic,
        ..*o
    };
    let arclength = |o: &ArclengthBackboneOptions| ArclengthBackboneOptions {
        mode,
        subharmonic,
        ..*o
    };
    let (plan, method) = match &request.method {
        Method::Auto(given) => return Err(*given),
        Method::PeriodGrid(o) => (Plan::Grid(grid(o), None), Method::PeriodGrid(grid(o))),
        Method::GenuineSubharmonic(o) => {
            (Plan::Genuine(grid(o)), Method::GenuineSubharmonic(grid(o)))
        }
        Method::Arclength(o) => (
            Plan::Arclength(arclength(o), None),
            Method::Arclength(arclength(o)),
        ),
        Method::Switch(o, at) => {
            let options = ArclengthBackboneOptions {
                switch: Some(*at),
                ..arclength(o)
            };
            (Plan::Arclength(options, None), Method::Switch(options, *at))
        }
        Method::Energy(o) => {
            let options = EnergyBackboneOptions {
                mode,
                subharmonic,
                ..*o
            };
            (Plan::Energy(options), Method::Energy(options))
        }
    };
    Ok((plan, method))
}
