//! Backbones over a period grid and by arclength, requests by any method (`branches::compute`),
//! and branches in a parameter of the system.

use super::drivers::{
    arclength_bounded, arclength_options, sequential_options, stall_escape, stop_policy, Stop,
    Watcher, STEP_CAP,
};
use super::solvers::{request_solver, solver};
use super::{reference_system, settings, MAX_HARMONICS};
use crate::checks::{typed, CaseResult, Checks};
use crate::draw::Draw;
use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{
    compute, compute_observed, lift, parameter_branch, ArclengthBackboneOptions, BackboneObserver,
    BackboneOptions, BackbonePoint, EnergyBackboneOptions, EnergyGrid, Method, ParameterSteps,
    PeriodGrid, PointStatus, Request, SwitchAt, TimeDomainCheck,
};
use nonsmooth_modes::continuation::{Rejection, SequentialOptions, Speculation};
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, contact_chain, ClampedFirstMode};
use nonsmooth_modes::system::{AssemblyBuilder, BarSystem, HarmonicBalanceSettings};
use nonsmooth_modes::{Error, ModelError, SettingsError};
use std::f64::consts::PI;
use std::ops::ControlFlow;

/// A period grid through `branches::compute_observed` (an observer that may stop it), with
/// speculative retries, and through `compute`, with any grid, mode, options and solver.
pub(crate) fn backbone_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let system = reference_system(d, c)?;
    let s = settings(d);
    let period = 3.9 * d.real("period factor", 0.5..=2.0);
    let grid = PeriodGrid {
        start: d.real("grid start", period..=period),
        end: d.real("grid end", period * 0.8..=period),
        steps: d.size("steps", 2..=8),
    };
    let mode = d.size("mode", 1..=2);
    let subharmonic = d.size("subharmonic", 1..=2);
    let sequential = sequential_options(d);
    let options = BackboneOptions {
        grid,
        mode,
        subharmonic,
        predictor: sequential.predictor,
        max_consecutive_failures: sequential.max_consecutive_failures,
        retry_depth: sequential.retry_depth,
        selection: sequential.selection,
        trivial_energy: d.real("trivial_energy", 0.0..=1e-3),
    };
    let mut request = Request {
        settings: s,
        method: Method::PeriodGrid(options),
        solver: request_solver(d, c)?,
        ..Request::new(mode).subharmonic(subharmonic)
    };
    let mut points = Vec::new();
    let stop = stop_policy(d, true);
    let (mut seen, mut stopped) = (0, false);
    let collect = |p: &BackbonePoint| {
        points.push(p.clone());
        seen += 1;
        stopped = stops_at(stop, seen, p);
        if stopped {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    };
    let observed = match d.pick("backbone", &["with", "speculative", "plain"]) {
        "with" => true,
        "speculative" => {
            request.speculation = Some(Speculation {
                after_evaluations: d.size("after_evaluations", 0..=20),
            });
            true
        }
        _ => false,
    };
    let run = if observed {
        compute_observed(&system, &request, collect)
    } else {
        compute(&system, &request)
    };
    let run = typed(c, "backbone", run)?;
    // A run stopped by the observer says so (the plain form's observer never stops it).
    c.mode_branches("backbone", &run, stopped);
    // Lifted to any settings (fewer harmonics, zero, more), it keeps its end reason.
    if d.flag("lift", 0.3) {
        let lifted = Request {
            settings: settings(d),
            ..request.clone()
        };
        let lifted = typed(c, "lift", lift(&run, &lifted))?;
        c.mode_branches("lift", &lifted, stopped);
    }
    // The observer saw the points the run returns.
    if observed && points != run.points {
        c.no_end.push(format!(
            "backbone: the observer saw {} points, the run returned {}",
            points.len(),
            run.points.len()
        ));
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

/// `branches::compute_observed` by `Method::Arclength` (or `Method::Switch`) with any options,
/// escape and observer.
pub(crate) fn arclength_backbone_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
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
        switch: d.flag("switch", 0.3).then(|| SwitchAt {
            branch_point: d.size("switch branch point", 0..=3),
            side: d.choice("switch side", &[1.0, -1.0], &[0.0, f64::NAN, 2.0]),
        }),
    };
    let method = match options.switch {
        Some(at) => Method::Switch(options, at),
        None => Method::Arclength(options),
    };
    let request = Request {
        settings: s,
        method,
        solver: request_solver(d, c)?,
        ..Request::new(options.mode).subharmonic(options.subharmonic)
    };
    // The observer sees rejected steps too, so an unbounded run (a shrink factor close to 1
    // with no rejection budget) is stopped by the watcher's step cap.
    let mut observer = BackboneWatcher {
        watcher: Watcher::new(stop_policy(d, arclength_bounded(&arclength))),
        points: Vec::new(),
    };
    let run = typed(
        c,
        "arclength_backbone",
        compute_observed(&system, &request, &mut observer),
    )?;
    let BackboneWatcher { watcher, points } = observer;
    let stopped = watcher.stopped;
    if watcher.seen >= STEP_CAP {
        c.no_end
            .push(format!("arclength backbone: no end after {STEP_CAP} steps"));
    }
    c.mode_branches("arclength backbone", &run, stopped);
    if points != run.points {
        c.no_end.push(format!(
            "arclength backbone: the observer saw {} points, the run returned {}",
            points.len(),
            run.points.len()
        ));
    }
    Ok(())
}

/// `branches::compute_observed` with a random request: any method (`Auto` and the options
/// derived from the system among them, or options drawn at random), mode, order, solver,
/// speculation and time-domain check, on one of the paper's systems or the three-bar chain
/// (whose floating bar makes `Auto` enter its branch at a shorter period). Every run is
/// stopped by its observer after a few steps, so that the system-derived grids stay cheap.
pub(crate) fn request_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let system = if d.flag("three-bar chain", 0.2) {
        let gap = d.real("chain gap", 1e-4..=0.1);
        let spring = d.real("chain spring", 0.05..=5.0);
        typed(c, "contact_chain", contact_chain(3, gap, spring))?
    } else {
        reference_system(d, c)?
    };
    let s = settings(d);
    let mode = d.size("mode", 1..=2);
    let subharmonic = d.size("subharmonic", 1..=3);
    let derived = d.flag("options from the system", 0.7);
    let name = d.pick(
        "method",
        &[
            "auto",
            "period-grid",
            "arclength",
            "switch",
            "energy",
            "genuine-subharmonic",
        ],
    );
    let grid = |d: &mut Draw, c: &mut Checks| -> Result<BackboneOptions, String> {
        if derived {
            typed(
                c,
                "BackboneOptions::for_mode",
                BackboneOptions::for_mode(&system, mode, subharmonic),
            )
        } else {
            let period = 3.9 * d.real("period factor", 0.5..=2.0);
            let grid = PeriodGrid {
                start: d.real("grid start", period..=period),
                end: d.real("grid end", period * 0.8..=period),
                steps: d.size("steps", 2..=8),
            };
            Ok(BackboneOptions::on_grid(grid, mode, subharmonic))
        }
    };
    let arclength = |d: &mut Draw, c: &mut Checks| -> Result<ArclengthBackboneOptions, String> {
        let mut options = if derived {
            typed(
                c,
                "ArclengthBackboneOptions::for_mode",
                ArclengthBackboneOptions::for_mode(&system, mode, subharmonic),
            )?
        } else {
            let range = (d.real("omega lo", 1.0..=1.6), d.real("omega hi", 1.6..=2.5));
            let start = d.real("start_period", 3.0..=4.5);
            ArclengthBackboneOptions::seeded_at(start, range, (mode, subharmonic))
        };
        options.escape = d.flag("escape", 0.5).then(|| stall_escape(d));
        Ok(options)
    };
    let method = match name {
        "auto" => Method::Auto(d.flag("auto grid", 0.5).then(|| grid(d, c)).transpose()?),
        "period-grid" => Method::PeriodGrid(grid(d, c)?),
        "genuine-subharmonic" => Method::GenuineSubharmonic(grid(d, c)?),
        "arclength" => Method::Arclength(arclength(d, c)?),
        "switch" => Method::Switch(
            arclength(d, c)?,
            SwitchAt {
                branch_point: d.size("switch branch point", 0..=3),
                side: d.choice("switch side", &[1.0, -1.0], &[0.0, f64::NAN, 2.0]),
            },
        ),
        _ => {
            let mut options = typed(
                c,
                "EnergyBackboneOptions::for_mode",
                EnergyBackboneOptions::for_mode(&system, mode, subharmonic),
            )?;
            if !derived {
                options.levels = EnergyGrid {
                    start: d.real("level start", 0.5..=2.0),
                    end: d.real("level end", 1.0..=50.0),
                    steps: d.size("levels", 2..=8),
                };
            }
            Method::Energy(options)
        }
    };
    let mut request = Request::new(mode).subharmonic(subharmonic).method(method);
    request.settings = s;
    request.solver = request_solver(d, c)?;
    if d.flag("speculation", 0.2) {
        request.speculation = Some(Speculation {
            after_evaluations: d.size("after_evaluations", 0..=20),
        });
    }
    if d.flag("time-domain check", 0.2) {
        request = request.checked(TimeDomainCheck::for_system(&system));
    }
    // The observer sees rejected steps too; it always stops the run (after a few steps).
    let mut observer = BackboneWatcher {
        watcher: Watcher::new(stop_policy(d, false)),
        points: Vec::new(),
    };
    // A request that names another mode than its method's options is refused, naming both.
    let disagrees = d.flag("request names another mode", 0.1) && name != "auto";
    if disagrees {
        request.mode = 3 - mode;
    }
    let outcome = compute_observed(&system, &request, &mut observer);
    if disagrees {
        c.expect(
            matches!(
                &outcome,
                Err(Error::Settings(SettingsError::MethodDisagrees {
                    request_mode,
                    method_mode,
                    ..
                })) if *request_mode == 3 - mode && *method_mode == mode
            ),
            || {
                format!(
                    "compute ({name}): mode {} against options of mode {mode}: {outcome:?}",
                    3 - mode
                )
            },
        );
    }
    let run = typed(c, "compute", outcome)?;
    let BackboneWatcher { watcher, points } = observer;
    c.mode_branches(&format!("compute ({name})"), &run, watcher.stopped);
    c.expect(points == run.points, || {
        format!(
            "compute ({name}): the observer saw {} points, the run returned {}",
            points.len(),
            run.points.len()
        )
    });
    // `Auto` says what it chose; any other method runs as asked.
    c.expect((name == "auto") == run.auto.is_some(), || {
        format!(
            "compute ({name}): ran {} with choice {:?}",
            run.method.name(),
            run.auto
        )
    });
    if name != "auto" {
        c.expect(run.method.name() == name, || {
            format!("compute ({name}): ran {}", run.method.name())
        });
    }
    for p in run.converged() {
        if let Some(report) = p.time_domain {
            c.finite("compute displacement defect", [&report.displacement_defect]);
        }
        if let Some(character) = &p.character {
            let shares = character
                .energy_by_bar
                .iter()
                .chain(&character.energy_by_harmonic);
            c.finite("compute energy shares", shares);
        }
    }
    Ok(())
}

/// Values a constructor accepts at its extremes: a bar length or a gap from the least
/// normal `f64` to `f64::MAX` (the independent run's `4.75e299` among them).
const EXTREME_ACCEPTED: [f64; 8] = [
    f64::MIN_POSITIVE,
    1e-300,
    1e-160,
    1e10,
    1e100,
    1e200,
    4.75e299,
    f64::MAX,
];

/// The clamped bar of length `length` (wave speed and stiffness 1) facing its obstacle at
/// `gap`.
fn clamped_of_length(length: f64, gap: f64) -> Result<BarSystem, ModelError> {
    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::new(length, 1.0, 1.0)?);
    b.dirichlet(bar.left())?.signorini(bar.right(), gap)?;
    b.build()
}

/// A parameter value: in `valid`, or with probability `self.edge / 2` one of
/// [`EXTREME_ACCEPTED`].
fn parameter_value(d: &mut Draw, name: &str, valid: std::ops::RangeInclusive<f64>) -> f64 {
    if d.flag(&format!("{name} extreme"), d.edge / 2.0) {
        d.pick(name, &EXTREME_ACCEPTED)
    } else {
        d.real(name, valid)
    }
}

/// `branches::parameter_branch` in the gap or the bar length of the clamped bar, over values or
/// by arclength, up to the extremes of what `Bar::new` and the conditions accept.
pub(crate) fn parameter_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let gap = d.real("gap", 1e-4..=0.1);
    let by_length = d.flag("bar length", 0.5);
    // The family and its start value: the gap at `gap`, or the unit length.
    let family = move |v: f64| {
        if by_length {
            clamped_of_length(v, gap)
        } else {
            clamped_bar_with_obstacle(v)
        }
    };
    let start = if by_length { 1.0 } else { gap };
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
        let mut values = vec![d.real("first value", start..=start)];
        values.extend(
            (1..count).map(|i| parameter_value(d, &format!("value{i}"), start..=2.0 * start)),
        );
        let options = SequentialOptions {
            max_consecutive_failures: d.size("max_consecutive_failures", 0..=5),
            retry_depth: d.size("retry_depth", 0..=2),
            ..Default::default()
        };
        ParameterSteps::Values(values, options)
    } else {
        let mut o = arclength_options(d);
        o.parameter_range = (
            d.real("range lo", start * 0.5..=start),
            parameter_value(d, "range hi", start..=start * 3.0),
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
        stopped = stops_at(stop, seen, p);
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
        parameter_branch(family, s, (x, omega), start, steps, solver, observer),
    )?;
    c.branch("parameter branch", &branch, stopped);
    // Converged points are finite, energies included: a point whose energy or `E / E_g` is
    // not finite (a system without grazing energy, a motion whose energy overflows) is
    // `NonFiniteEnergy`, not converged. Failed points hold the solver's last iterate.
    for (_, p) in &points {
        if p.converged() || p.status == PointStatus::NonFiniteEnergy {
            c.backbone_point("parameter point", p);
        }
    }
    Ok(())
}

/// Whether a backbone observer with policy `stop` stops at point `p`, the `seen`-th it is
/// handed (every point counts, converged or not).
fn stops_at(stop: Stop, seen: usize, p: &BackbonePoint) -> bool {
    match stop {
        Stop::FirstPoint => true,
        Stop::FirstRejection => !p.converged(),
        Stop::After(n) => seen >= n,
        Stop::Never => false,
    }
}
