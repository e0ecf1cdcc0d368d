//! The runs: a branch of the mode by `branches::compute` (the method from the flags, or
//! chosen by the library), and continuation in a system parameter.

use crate::args::{Args, Parameter};
use crate::full::run_full_basis;
use crate::output::{header, Sink};
use crate::systems::{build_system, clamped_gap, default_periods, parameter_value};
use nonsmooth_modes::branches::{
    compute, compute_observed, parameter_branch, ArclengthBackboneOptions, AutoChoice,
    BackboneOptions, BackbonePoint, EnergyBackboneOptions, EnergyGrid, Method, ParameterSteps,
    PeriodGrid, Request, TimeDomainCheck,
};
use nonsmooth_modes::continuation::{linspace, ArclengthOptions, SequentialOptions, Speculation};
use nonsmooth_modes::exact::ExactOptions;
use nonsmooth_modes::solve::{Dogleg, NewtonOptions, SemismoothNewton, Solver};
use nonsmooth_modes::stability::{HillOptions, StabilityOptions};
use nonsmooth_modes::system::{BarSystem, NonsmoothSystem};
use std::io::Write;
use std::ops::ControlFlow;

pub fn run(a: &Args, out: &mut dyn Write) -> Result<(usize, usize), Box<dyn std::error::Error>> {
    let system = build_system(a, Parameter::Omega, f64::NAN)?;
    let (t0, t1) = match (a.period_start, a.period_end) {
        (Some(t0), Some(t1)) => (t0, t1),
        _ => default_periods(a)?,
    };
    let (t0, t1) = (a.period_start.unwrap_or(t0), a.period_end.unwrap_or(t1));
    if a.full_basis {
        return run_full_basis(a, &system, &request(a, &system, (t0, t1))?, (t0, t1), out);
    }
    writeln!(
        out,
        "{}",
        header(
            a.verify,
            a.subharmonic,
            a.stability || a.exact,
            a.hill,
            a.exact
        )
    )?;
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
        stability: a.stability || a.exact,
        hill: a.hill,
        exact_branch: a.exact,
    };
    if a.exact {
        run_exact(a, &system, &request(a, &system, (t0, t1))?, &mut sink)?;
    } else if a.parameter != Parameter::Omega && a.parameter != Parameter::Energy {
        run_parameter(a, t0, &mut sink)?;
    } else {
        let request = request(a, &system, (t0, t1))?;
        // The problem the signature columns are evaluated with.
        let mut problem = NonsmoothSystem::new(&system, a.settings)?;
        let see = |p: &BackbonePoint| sink.row(&mut problem, p, f64::NAN);
        let run = compute_observed(&system, &request, see)?;
        match run.auto {
            Some(AutoChoice::EnteredAtShorterPeriod { entered_at }) => eprintln!(
                "backbone: the branch is entered at T = {entered_at:.6}, not at the grid's first \
                 period {t0:.6}: it is followed by pseudo-arclength from T0 (--method sequential \
                 keeps the period grid)"
            ),
            Some(AutoChoice::GridFellShort { good, steps }) => eprintln!(
                "backbone: the period grid gave {good} good points of {steps} steps: the \
                 branch is followed by pseudo-arclength over its range instead (--method \
                 sequential keeps the period grid)"
            ),
            Some(AutoChoice::Tethered {
                good,
                searched_good,
            }) => eprintln!(
                "backbone: the start reached through the tethered system gave {good} good \
                 points, the searched start {searched_good}: its run is kept"
            ),
            Some(AutoChoice::Lifted {
                harmonics,
                good,
                direct_good,
            }) => eprintln!(
                "backbone: the runs at {} harmonics gave {direct_good} good points; the run at \
                 {harmonics} harmonics, each point lifted to {} harmonics and solved there, gave \
                 {good}: its run is kept",
                a.settings.harmonics, a.settings.harmonics
            ),
            _ => {}
        }
        if let Some(j) = run.selection {
            let kept = if j.selected() {
                "the selected equations are kept"
            } else {
                "every harmonic is kept"
            };
            eprintln!(
                "backbone: skeleton points cover {} of {} periods with harmonic selection (band \
                 {}), {} without: {kept}",
                j.covered_selected, j.steps, j.width, j.covered_full
            );
        }
        eprintln!(
            "backbone: {} ended: {:?}; {} rejected steps",
            run.method.name(),
            run.end,
            run.rejected_steps
        );
        // Every point computed is written; a grid or energy run that stalled then exits
        // non-zero. An arclength run's end (a stall, a failed switch) is reported above: its
        // points are the branch as far as it could be followed.
        let arclength = matches!(run.method, Method::Arclength(_) | Method::Switch(..));
        if let (None, Some(e), false) = (&sink.error, run.error(), arclength) {
            return Err(e.into());
        }
    }
    if let Some(e) = sink.error {
        return Err(e.into());
    }
    Ok((sink.total, sink.converged))
}

/// `--exact`: the request with its exact branch ([`Request::with_exact`]): the
/// harmonic-balance run (its rows not written), then the exact branch seeded by it over the
/// same period grid, one row per exact point.
fn run_exact(
    a: &Args,
    system: &BarSystem,
    request: &Request,
    sink: &mut Sink<'_>,
) -> Result<(), Box<dyn std::error::Error>> {
    // The grid the system can afford, unless `--cells-per-travel` names one.
    let options = match a.cells_per_travel {
        Some(cells_per_travel) => ExactOptions {
            stability: StabilityOptions {
                cells_per_travel,
                ..StabilityOptions::default()
            },
            ..ExactOptions::default()
        },
        None => ExactOptions::for_request(system, request)?,
    };
    let exact = Request {
        stability: None,
        ..request.clone()
    }
    .with_exact(options);
    let start = std::time::Instant::now();
    let run = compute(system, &exact)?;
    let Some(branch) = run.exact else {
        return Err("the run returned no exact branch".into());
    };
    let branch = branch?;
    let mut problem = NonsmoothSystem::new(system, a.settings)?;
    for p in &branch.points {
        if sink.exact_row(&mut problem, p).is_break() {
            break;
        }
    }
    let count = |stable: Option<bool>| {
        branch
            .points
            .iter()
            .filter(|p| matches!(&p.point.stability, Some(Ok(f)) if f.verdict.stable() == stable))
            .count()
    };
    eprintln!(
        "backbone: exact branch of {} points ({} stable, {} unstable, {} unresolved) on a grid \
         of dt = {:.6e} ({} coordinates) in {:.1} s; {} periods skipped; ended: {:?}",
        branch.points.len(),
        count(Some(true)),
        count(Some(false)),
        count(None),
        branch.dt,
        branch.dimension,
        start.elapsed().as_secs_f64(),
        branch.skipped.len(),
        branch.end
    );
    for s in &branch.skipped {
        eprintln!(
            "backbone: no exact point at T = {:.6}: {}",
            s.period, s.reason
        );
    }
    Ok(())
}

/// The request of the flags: the method of `--method` and `--parameter energy`, or the
/// library's choice ([`Method::Auto`]) over the period grid `t0 -> t1`.
fn request(
    a: &Args,
    system: &BarSystem,
    (t0, t1): (f64, f64),
) -> Result<Request, Box<dyn std::error::Error>> {
    let defaults = BackboneOptions::for_mode(system, a.mode, a.subharmonic)?;
    let grid = BackboneOptions {
        grid: PeriodGrid {
            start: t0,
            end: t1,
            steps: a.steps,
        },
        retry_depth: a.retry_depth.unwrap_or(defaults.retry_depth),
        max_consecutive_failures: a.max_failures,
        selection: a.selection,
        ..defaults
    };
    let method = if a.parameter == Parameter::Energy {
        Method::Energy(energy_options(a, system)?)
    } else if a.arclength == Some(true) {
        let over_grid = ArclengthBackboneOptions::over_grid(&grid);
        let options = ArclengthBackboneOptions {
            omega_range: a.omega_range.unwrap_or(over_grid.omega_range),
            arclength: ArclengthOptions {
                direction: over_grid.arclength.direction,
                ..a.driver
            },
            ..over_grid
        };
        match a.switch {
            Some(at) => Method::Switch(options, at),
            None => Method::Arclength(options),
        }
    } else if (a.subharmonic > 1 && a.repeated)
        || ((a.arclength == Some(false) || a.full_basis) && a.subharmonic == 1)
    {
        // The repeated branch of a subharmonic, or the grid asked for (a full-basis run
        // continues the grid).
        Method::PeriodGrid(grid)
    } else {
        Method::Auto(Some(grid))
    };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut request = Request {
        settings: a.settings,
        method,
        solver: solver(a)?,
        speculation: (!a.serial && cores >= 2).then(Speculation::default),
        ..Request::new(a.mode).subharmonic(a.subharmonic)
    };
    if a.verify && !a.full_basis {
        request.check = Some(TimeDomainCheck::for_system(system));
    }
    if a.stability {
        request.stability = Some(StabilityOptions::default());
    }
    if a.hill {
        request.hill = Some(HillOptions::default());
    }
    Ok(request)
}

/// The solver of `--solver` and `--newton`; `None` leaves it to the method (fail-fast
/// Newton on a period grid, where each step starts from a converged neighbour; full Newton
/// for arclength and energy runs, whose escapes solve from far starts).
fn solver(a: &Args) -> Result<Option<Solver>, Box<dyn std::error::Error>> {
    Ok(if a.dogleg {
        Some(Solver::Dogleg(Dogleg::default()))
    } else {
        match a.fail_fast {
            Some(true) => Some(Solver::Newton(SemismoothNewton::new(
                NewtonOptions::fail_fast(),
            )?)),
            Some(false) => Some(Solver::Newton(SemismoothNewton::default())),
            None => None,
        }
    })
}

/// The options of `--parameter energy`: levels from `--energy-range` (default the system's)
/// in `--steps` levels.
fn energy_options(
    a: &Args,
    system: &BarSystem,
) -> Result<EnergyBackboneOptions, Box<dyn std::error::Error>> {
    let defaults = EnergyBackboneOptions::for_mode(system, a.mode, a.subharmonic)?;
    let levels = match a.energy_range {
        Some((start, end)) => EnergyGrid {
            start,
            end,
            steps: a.steps,
        },
        None => EnergyGrid {
            steps: a.steps,
            ..defaults.levels
        },
    };
    Ok(EnergyBackboneOptions {
        levels,
        retry_depth: a.retry_depth.unwrap_or(defaults.retry_depth),
        max_consecutive_failures: a.max_failures,
        ..defaults
    })
}

/// Continuation in a system parameter at the fixed period `period`.
fn run_parameter(
    a: &Args,
    period: f64,
    sink: &mut Sink<'_>,
) -> Result<(), Box<dyn std::error::Error>> {
    let solver = solver(a)?.unwrap_or_default();
    let parameter = a.parameter;
    let value = parameter_value(a, parameter);
    let system = build_system(a, parameter, value)?;
    // Reach the branch at `period` from the system's default start.
    let start_period = default_periods(a)?.0;
    let grid = PeriodGrid {
        start: start_period,
        end: period,
        steps: ((start_period - period).abs() / 0.005).ceil().max(1.0) as usize + 1,
    };
    let request = Request {
        settings: a.settings,
        method: Method::PeriodGrid(BackboneOptions::on_grid(grid, a.mode, a.subharmonic)),
        solver: Some(Solver::default()),
        ..Request::new(a.mode).subharmonic(a.subharmonic)
    };
    let reached = compute(&system, &request)?;
    let start = reached
        .points
        .iter()
        .rev()
        .find(|p| p.converged())
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
