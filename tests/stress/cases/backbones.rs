//! Backbones over a period grid and by arclength, and branches in a parameter of the system.

use super::drivers::{
    arclength_bounded, arclength_options, sequential_options, stall_escape, stop_policy, Stop,
    Watcher, STEP_CAP,
};
use super::solvers::solver;
use super::{reference_system, settings, MAX_HARMONICS};
use crate::checks::{typed, CaseResult, Checks};
use crate::draw::Draw;
use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{
    arclength_backbone_observed, backbone, backbone_speculative_with, backbone_with,
    parameter_branch, ArclengthBackboneOptions, BackboneObserver, BackboneOptions, BackbonePoint,
    ParameterSteps, PeriodGrid, PointStatus, SwitchAt,
};
use nonsmooth_modes::continuation::{EndReason, Rejection, SequentialOptions, Speculation};
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, ClampedFirstMode};
use nonsmooth_modes::system::{AssemblyBuilder, BarSystem, HarmonicBalanceSettings};
use nonsmooth_modes::ModelError;
use std::f64::consts::PI;
use std::ops::ControlFlow;

/// `branches::backbone`, `backbone_with` (an observer that may stop it) and
/// `backbone_speculative_with`, with any grid, mode, options and solver.
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
    let solver = solver(d, c)?;
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

/// `branches::arclength_backbone_observed` with any options, escape and observer.
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
        if p.converged || p.status == PointStatus::NonFiniteEnergy {
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
        Stop::FirstRejection => !p.converged,
        Stop::After(n) => seen >= n,
        Stop::Never => false,
    }
}
