//! The runs: sequential or arclength in the period, and continuation in a system parameter.

use crate::args::{Args, Parameter};
use crate::output::{header, Sink};
use crate::systems::{build_system, clamped_gap, default_periods, parameter_value, SystemKind};
use nonsmooth_modes::branches::{
    arclength_backbone, backbone, backbone_from, backbone_speculative_with, backbone_start,
    backbone_with, energy_backbone_with, genuine_subharmonic_backbone_with, parameter_branch,
    ArclengthBackboneOptions, BackboneOptions, BackbonePoint, BackboneStart, EnergyBackboneOptions,
    EnergyGrid, ParameterSteps, PeriodGrid,
};
use nonsmooth_modes::continuation::{linspace, ArclengthOptions, SequentialOptions, Speculation};
use nonsmooth_modes::solve::{Dogleg, NewtonOptions, SemismoothNewton};
use nonsmooth_modes::system::NonsmoothSystem;
// A plain enum of the crate's solvers: it can be cloned onto the thread of speculative retries.
use nonsmooth_modes::sweep::Solver;
use nonsmooth_modes::system::BarSystem;
use std::f64::consts::PI;
use std::io::Write;
use std::ops::ControlFlow;

pub fn run(a: &Args, out: &mut dyn Write) -> Result<(usize, usize), Box<dyn std::error::Error>> {
    let system = build_system(a, Parameter::Omega, f64::NAN)?;
    let (t0, t1) = match (a.period_start, a.period_end) {
        (Some(t0), Some(t1)) => (t0, t1),
        _ => default_periods(a)?,
    };
    let (t0, t1) = (a.period_start.unwrap_or(t0), a.period_end.unwrap_or(t1));
    writeln!(out, "{}", header(a.verify, a.subharmonic))?;
    let mut sink = Sink {
        out,
        verify: a.verify,
        exact: (a.mode == 1 && a.subharmonic == 1 && a.parameter != Parameter::Gap)
            .then(|| clamped_gap(&system))
            .flatten(),
        total: 0,
        converged: 0,
        error: None,
        progress: a.progress,
        subharmonic: a.subharmonic,
    };
    let (arclength, start) = match a.arclength {
        Some(arclength) => (arclength, None),
        None => method_by_default(a, &system, t0)?,
    };
    let solver = solver_for(a, arclength)?;
    if a.parameter == Parameter::Energy {
        run_energy(a, &system, solver, &mut sink)?;
    } else if a.parameter != Parameter::Omega {
        run_parameter(a, t0, solver, &mut sink)?;
    } else if arclength {
        let (lo, hi) = (2.0 * PI / t0, 2.0 * PI / t1);
        let options = ArclengthBackboneOptions {
            start_period: t0,
            omega_range: a.omega_range.unwrap_or((lo.min(hi) * 0.999, lo.max(hi))),
            mode: a.mode,
            subharmonic: a.subharmonic,
            switch: a.switch,
            arclength: ArclengthOptions {
                direction: if t1 < t0 { 1.0 } else { -1.0 },
                ..a.driver
            },
            ..Default::default()
        };
        let mut problem = NonsmoothSystem::new(&system, a.settings)?;
        let (_, branch) = arclength_backbone(&system, a.settings, &options, solver, |p| {
            sink.row(&mut problem, p, f64::NAN)
        })?;
        eprintln!(
            "backbone: arclength ended: {:?}; {} rejected steps",
            branch.end, branch.rejections
        );
    } else {
        // The system's own defaults for a file; the shorthands hold no floating bar and keep
        // the library's defaults without a linear analysis.
        let defaults = match a.system {
            SystemKind::File(_) => BackboneOptions::for_mode(&system, a.mode, a.subharmonic)?,
            _ => BackboneOptions::default(),
        };
        let options = BackboneOptions {
            grid: PeriodGrid {
                start: t0,
                end: t1,
                steps: a.steps,
            },
            mode: a.mode,
            subharmonic: a.subharmonic,
            retry_depth: a.retry_depth.unwrap_or(defaults.retry_depth),
            max_consecutive_failures: a.max_failures,
            selection: a.selection,
            ..defaults
        };
        // The problem the rows are evaluated with (the runs keep their own).
        let mut problem = NonsmoothSystem::new(&system, a.settings)?;
        let see = |p: &BackbonePoint| sink.row(&mut problem, p, f64::NAN);
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let (_, end) = if a.subharmonic > 1 && !a.repeated {
            genuine_subharmonic_backbone_with(&system, a.settings, &options, solver, see)?
        } else if let Some(start) = start {
            let speculation = (!a.serial && cores >= 2).then(Speculation::default);
            backbone_from(
                &system,
                a.settings,
                &options,
                start,
                speculation,
                solver,
                see,
            )?
        } else if a.serial || cores < 2 {
            backbone_with(&system, a.settings, &options, solver, see)?
        } else {
            let speculation = Speculation::default();
            backbone_speculative_with(&system, a.settings, &options, speculation, solver, see)?
        };
        // Every point computed is written; a run that stalled then exits non-zero.
        if let (None, Some(e)) = (&sink.error, end.error()) {
            return Err(e.into());
        }
    }
    if let Some(e) = sink.error {
        return Err(e.into());
    }
    Ok((sink.total, sink.converged))
}

/// The solver of a run: `--solver`, with Newton's budget from `--newton` or, by default,
/// fail-fast for sequential runs (each step starts from a converged neighbour) and full for
/// arclength runs (their stall escapes solve from far starts).
fn solver_for(a: &Args, arclength: bool) -> Result<Solver, Box<dyn std::error::Error>> {
    Ok(if a.dogleg {
        Solver::Dogleg(Dogleg::default())
    } else if a.fail_fast.unwrap_or(!arclength) {
        Solver::Newton(SemismoothNewton::new(NewtonOptions::fail_fast())?)
    } else {
        Solver::Newton(SemismoothNewton::default())
    })
}

/// The method of a backbone in the period when `--method` is not given: sequential, except
/// for an assembly file whose branch cannot be entered at the grid's first period `t0`
/// (`branches::backbone_start` gets back to a higher frequency only, as on the three-bar chain,
/// whose floating bar must be pushed hard enough to shuttle within a period). A period grid
/// from `t0` would start off its branch; pseudo-arclength walks the branch back to `t0` and
/// follows it through its folds. The shorthands (`--system`) have no floating bar and are
/// always sequential; so are subharmonic runs and continuation in other parameters. Returns
/// whether to use arclength and, for a sequential run, the start found (not searched again).
fn method_by_default(
    a: &Args,
    system: &BarSystem,
    t0: f64,
) -> Result<(bool, Option<BackboneStart>), Box<dyn std::error::Error>> {
    if !matches!(a.system, SystemKind::File(_))
        || a.parameter != Parameter::Omega
        || a.subharmonic != 1
    {
        return Ok((false, None));
    }
    let omega = 2.0 * PI / t0;
    let floor = BackboneOptions::default().trivial_energy;
    let solver = solver_for(a, false)?;
    let start = backbone_start(system, a.settings, (a.mode, 1), omega, floor, &solver)?;
    if !start.moved_from(omega) {
        return Ok((false, Some(start)));
    }
    eprintln!(
        "backbone: the branch is entered at T = {:.6}, not at the grid's first period \
         {t0:.6}: it is followed by pseudo-arclength from T0 (--method sequential keeps \
         the period grid)",
        2.0 * PI / start.omega
    );
    Ok((true, None))
}

/// Continuation in the energy level `E / E_g` (the frequency an unknown).
fn run_energy(
    a: &Args,
    system: &BarSystem,
    solver: Solver,
    sink: &mut Sink<'_>,
) -> Result<(), Box<dyn std::error::Error>> {
    let levels = match a.energy_range {
        Some((start, end)) => EnergyGrid {
            start,
            end,
            steps: a.steps,
        },
        None => EnergyGrid {
            steps: a.steps,
            ..EnergyGrid::for_mode(system, a.mode)?
        },
    };
    let options = EnergyBackboneOptions {
        levels,
        mode: a.mode,
        subharmonic: a.subharmonic,
        retry_depth: a
            .retry_depth
            .unwrap_or(EnergyBackboneOptions::default().retry_depth),
        max_consecutive_failures: a.max_failures,
        ..Default::default()
    };
    let mut problem = NonsmoothSystem::new(system, a.settings)?;
    let see = |p: &BackbonePoint| sink.row(&mut problem, p, f64::NAN);
    let (_, end) = energy_backbone_with(system, a.settings, &options, solver, see)?;
    eprintln!("backbone: energy run ended: {end:?}");
    match (&sink.error, end.error()) {
        (None, Some(e)) => Err(e.into()),
        _ => Ok(()),
    }
}

/// Continuation in a system parameter at the fixed period `period`.
fn run_parameter(
    a: &Args,
    period: f64,
    solver: Solver,
    sink: &mut Sink<'_>,
) -> Result<(), Box<dyn std::error::Error>> {
    let parameter = a.parameter;
    let value = parameter_value(a, parameter);
    let system = build_system(a, parameter, value)?;
    // Reach the branch at `period` from the system's default start.
    let start_period = default_periods(a)?.0;
    let options = BackboneOptions {
        grid: PeriodGrid {
            start: start_period,
            end: period,
            steps: ((start_period - period).abs() / 0.005).ceil().max(1.0) as usize + 1,
        },
        mode: a.mode,
        subharmonic: a.subharmonic,
        ..Default::default()
    };
    let reached = backbone(&system, a.settings, &options, SemismoothNewton::default())?;
    let start = reached
        .iter()
        .rev()
        .find(|p| p.converged)
        .ok_or("no converged point on the way to the starting period")?
        .clone();
    let family = move |v: f64| build_system(a, parameter, v);
    let (lo, hi) = a.parameter_range.unwrap_or((value / 10.0, value * 10.0));
    let steps = if a.arclength == Some(true) {
        ParameterSteps::Arclength(ArclengthOptions {
            parameter_range: (lo, hi),
            ..a.driver
        })
    } else {
        // Sequential parameter runs go from the current value to the far end of the range.
        let far = if (hi - value).abs() >= (value - lo).abs() {
            hi
        } else {
            lo
        };
        let options = SequentialOptions {
            retry_depth: a
                .retry_depth
                .unwrap_or(SequentialOptions::default().retry_depth),
            max_consecutive_failures: a.max_failures,
            ..Default::default()
        };
        ParameterSteps::Values(linspace(value, far, a.steps)?, options)
    };
    let branch = parameter_branch(
        family,
        a.settings,
        (start.x, start.omega),
        value,
        steps,
        solver,
        |v, point| match build_system(a, parameter, v) {
            // The system changes with the parameter: a problem per row.
            Ok(system) => match NonsmoothSystem::new(&system, a.settings) {
                Ok(mut problem) => sink.row(&mut problem, point, v),
                Err(_) => ControlFlow::Continue(()),
            },
            Err(_) => ControlFlow::Continue(()),
        },
    )?;
    eprintln!(
        "backbone: {} ended: {:?}; {} rejected steps",
        if a.arclength == Some(true) {
            "arclength"
        } else {
            "sequential"
        },
        branch.end,
        branch.rejections
    );
    match branch.end.error() {
        Some(e) => Err(e.into()),
        None => Ok(()),
    }
}
