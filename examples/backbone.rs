//! Backbone of a nonsmooth mode by sequential continuation in the period, written as CSV.
//!
//! ```text
//! cargo run --release --example backbone -- [--system ds|rs|two-bar] [--gap 1e-3]
//!     [--robin-stiffness 0.5] [--length2 0.95 --speed2 1 --stiffness-ratio 1]
//!     [--assembly FILE]
//!     [--harmonics 20 --samples-per-harmonic 30 --complementarity 4] [--mode 1] [--subharmonic 1]
//!     [--period-start T0 --period-end T1 --steps S] [--solver newton|dogleg] [--out FILE]
//!     [--newton fail-fast|full] [--retry-depth K] [--selection first|lowest-energy] [--serial]
//!     [--method sequential|arclength] [--ds DS --ds-min A --ds-max B --max-steps N]
//!     [--omega-range LO:HI] [--parameter omega|gap|robin-stiffness|stiffness-ratio]
//!     [--parameter-range LO:HI] [--progress] [--verify]
//! ```
//!
//! The system: `--system ds|rs|two-bar` are shorthands for the paper's three systems
//! (`reference::clamped_bar_with_obstacle`, `robin_bar_with_obstacle`, `two_bars_in_contact`,
//! set by `--gap`, `--robin-stiffness`, `--length2`, `--speed2`, `--stiffness-ratio`; their
//! bars are named `1` and `2`). `--assembly FILE` reads any assembly from a TOML or JSON file
//! instead (`io::assembly`, which documents the schema; `examples/assemblies/` has the three
//! shorthands as files and a three-bar chain). It needs the `serde` feature
//! (`cargo run --release --features serde --example backbone -- --assembly FILE`; without it
//! the flag is refused with that command), excludes `--system` and the shorthands' value
//! flags (the values are in the file) and continues in the period only (`--parameter omega`).
//! A file that cannot be read or built is a usage error, explained on stderr.
//!
//! Default periods: the shorthands keep the grids they have always had (`ds` and `two-bar`
//! 3.95 -> 3.05, `rs` 9.5 -> 6.0, whatever the mode). For a file they come from the system's
//! own linear mode `i = --mode` (open contacts, `modal::open_mode`): with `T_i = 2 pi / omega_i`
//! rounded to 6 significant digits and `K = --subharmonic`, the periods go from
//! `K T_i 79/80` down to `K T_i 61/80` (181 steps by default), from just below the linear
//! period into the strongly nonlinear range. For the clamped bar `T_1 = 4`, which gives the
//! paper's grid 3.95 -> 3.05 exactly (`4 * 79 / 80` and `4 * 61 / 80` round to the doubles of
//! 3.95 and 3.05), so `--assembly examples/assemblies/clamped.toml` writes the same CSV as
//! `--system ds`, byte for byte. `--period-start` and `--period-end` override either default.
//!
//! Columns: `step,period,omega,energy,energy_normalized,exact_energy_normalized,converged,
//! residual_norm,iterations,step_size,event,parameter` (`exact_energy_normalized` is the exact
//! first mode of the clamped bar, formulation §9, when the system is the clamped bar —
//! `--system ds` or a file with the same bars and conditions — with `--mode 1 --subharmonic 1`,
//! and empty otherwise; `event` lists fold/jump/grazing events separated by `;`; `parameter` is the
//! continued parameter's value). `--verify` marches every point one period in time with the
//! exact integrator (`verify::periodicity_check`, `dt = 1/400`) and adds the columns
//! `periodicity_defect,displacement_defect,max_penetration`.
//!
//! `--method sequential` visits `--steps` equispaced periods. `--method arclength` follows
//! the branch in `Omega` inside `--omega-range` (default: the periods' range) with automatic
//! escape from internal-resonance stalls. `--parameter gap|robin-stiffness|stiffness-ratio`
//! continues in that parameter at the fixed period `--period-start` inside
//! `--parameter-range` (default: a decade either side), starting from the branch point at that
//! period (reached by a short sequential run from the system's default start).
//!
//! Newton's budget: `--newton fail-fast` (`NewtonOptions::fail_fast`, the default of sequential
//! runs: each step starts from a converged neighbour and a failed step is skipped) or
//! `--newton full` (`NewtonOptions::default`, the default of arclength runs, whose stall
//! escapes solve from far starts). A failed sequential step is retried from up to
//! `--retry-depth` earlier converged points (`SequentialOptions::retry_depth`, default 1; 0
//! switches the retry off). Where the machine has more than one core, the first retry runs on
//! a second thread beside the first attempt (`backbone_speculative_with`; the same points, bit
//! for bit); `--serial` keeps everything on one thread.
//!
//! `--selection lowest-energy` (`Selection::LowestMeasure` through
//! `BackboneOptions::selection`; period runs only) solves every step from the prediction and
//! from the `--retry-depth` earlier converged points and keeps the lowest-energy solution,
//! which near an internal resonance stays on the backbone rather than on a resonance spike of
//! the truncated system. It costs about `--retry-depth` extra solves per step and runs serially
//! (every start is solved anyway); `docs/performance.md` measures what it gains on the
//! clamped bar. `--selection first` (the default) keeps the first accepted solution.
//!
//! Limits: requests the library accepts (within its memory budget) but that would run for
//! hours or days are refused with exit code 2: `--steps` and `--max-steps` at most
//! [`MAX_POINTS`] (an arclength run whose steps are too small to move the parameter only ends
//! at `--max-steps`), `--harmonics` at most [`MAX_HARMONICS`], `--samples-per-harmonic` at
//! most [`MAX_SAMPLES_PER_HARMONIC`]. `--verify` skips, with a message, a point whose march
//! would take more than [`MAX_VERIFY_STEPS`] time steps (a period over 2500).
//!
//! Exit codes: 0 when the run completed (steps that did not converge are reported, not
//! errors); 1 when the run failed, including values the library rejects (`--steps 0`,
//! `--gap nan`, sizes over its memory budget, an unwritable `--out`); 2 on a usage error (an
//! unknown flag, a missing or unparsable value, a value over the example's limits, `--system`
//! with `--assembly`, an assembly file that cannot be read or built). Every
//! failure is explained on stderr. `--help` prints the usage on stdout and exits with 0.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::continuation::{
    linspace, ArclengthOptions, Event, Selection, SequentialOptions, Speculation,
};
use nonsmooth_modes::modal::{
    arclength_backbone, backbone, backbone_speculative_with, backbone_with, open_mode,
    parameter_branch, ArclengthBackboneOptions, BackboneOptions, BackbonePoint, ParameterSteps,
    PeriodGrid,
};
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact, ClampedFirstMode,
};
use nonsmooth_modes::solve::{Dogleg, NewtonOptions, SemismoothNewton};
// A plain enum of the crate's solvers: it can be cloned onto the thread of speculative retries.
use nonsmooth_modes::sweep::Solver;
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings};
use nonsmooth_modes::verify::{periodicity_check, PeriodicityOptions};
use nonsmooth_modes::ModelError;
use std::f64::consts::PI;
use std::io::Write;
use std::ops::ControlFlow;
use std::process::ExitCode;

const USAGE: &str = "usage: backbone [--system ds|rs|two-bar] [--gap G] [--robin-stiffness K]
  [--length2 L --speed2 C --stiffness-ratio R] | [--assembly FILE.toml|FILE.json]
  [--harmonics M] [--samples-per-harmonic NH]
  [--complementarity AC] [--mode I] [--subharmonic K] [--period-start T0] [--period-end T1] [--steps S]
  [--solver newton|dogleg] [--newton fail-fast|full] [--retry-depth K]
  [--selection first|lowest-energy] [--serial] [--out FILE]
  [--method sequential|arclength]
  [--ds DS] [--ds-min A] [--ds-max B] [--max-steps N] [--omega-range LO:HI]
  [--parameter omega|gap|robin-stiffness|stiffness-ratio] [--parameter-range LO:HI]
  [--progress] [--verify]";

/// Largest `--steps` and `--max-steps`.
const MAX_POINTS: usize = 1_000_000;
/// Largest `--harmonics` (one solve costs about the cube of it).
const MAX_HARMONICS: usize = 1_000;
/// Largest `--samples-per-harmonic`.
const MAX_SAMPLES_PER_HARMONIC: usize = 10_000;
/// Most time steps `--verify` marches for one point.
const MAX_VERIFY_STEPS: f64 = 1e6;

const HEADER: &str = "step,period,omega,energy,energy_normalized,exact_energy_normalized,converged,residual_norm,iterations,step_size,event,parameter";

#[derive(Debug, Clone)]
enum SystemKind {
    Clamped,
    Robin,
    TwoBar,
    /// Read from `--assembly`.
    File(BarSystem),
}

/// The flags that set a value of a `--system` shorthand, refused with `--assembly`.
const SHORTHAND_VALUES: [&str; 5] = [
    "gap",
    "robin-stiffness",
    "length2",
    "speed2",
    "stiffness-ratio",
];

#[derive(Debug, Clone, Copy, PartialEq)]
enum Parameter {
    Omega,
    Gap,
    RobinStiffness,
    StiffnessRatio,
}

#[derive(Debug, Clone)]
struct Args {
    system: SystemKind,
    gap: f64,
    robin_stiffness: f64,
    length2: f64,
    speed2: f64,
    stiffness_ratio: f64,
    settings: HarmonicBalanceSettings,
    mode: usize,
    subharmonic: usize,
    period_start: Option<f64>,
    period_end: Option<f64>,
    steps: usize,
    dogleg: bool,
    /// `Some(true)`: fail-fast budget, `Some(false)`: full, `None`: per method.
    fail_fast: Option<bool>,
    retry_depth: usize,
    selection: Selection,
    /// No speculative retry on a second thread.
    serial: bool,
    out: Option<String>,
    arclength: bool,
    driver: ArclengthOptions,
    omega_range: Option<(f64, f64)>,
    parameter: Parameter,
    parameter_range: Option<(f64, f64)>,
    progress: bool,
    verify: bool,
}

/// Default period range: just below the linear period of the chosen mode down to a strongly
/// nonlinear period; the shorthands' fixed grids, or for a file the rule of the header
/// (`K T_i 79/80 -> K T_i 61/80`, `T_i` rounded to 6 significant digits).
fn default_periods(a: &Args) -> Result<(f64, f64), Box<dyn std::error::Error>> {
    Ok(match &a.system {
        SystemKind::Clamped => (3.95, 3.05),
        // Robin k = 0.5: omega_1 = 0.653271, T_1 = 9.618
        SystemKind::Robin => (9.5, 6.0),
        // bar 1 clamped-free: T_1 = 4
        SystemKind::TwoBar => (3.95, 3.05),
        SystemKind::File(system) => {
            let omega = open_mode(system, a.mode)?.omega;
            // Rounded so that a linear period computed to 1e-13 lands on its decimal value
            // (4.000000000000001 -> 4) and the grid on round numbers.
            let period: f64 = format!("{:.5e}", 2.0 * PI / omega).parse()?;
            let period = a.subharmonic as f64 * period;
            (period * 79.0 / 80.0, period * 61.0 / 80.0)
        }
    })
}

/// The gap of the clamped bar with obstacle if `system` is that system (the same bars and the
/// same conditions, compared by their names, which carry their ends and values): its exact
/// first mode is then known.
fn clamped_gap(system: &BarSystem) -> Option<f64> {
    let gap = system.laws().next()?.gap().offset;
    let reference = clamped_bar_with_obstacle(gap).ok()?;
    let names = |s: &BarSystem| s.conditions().map(|c| c.name()).collect::<Vec<_>>();
    (system.bars() == reference.bars() && names(system) == names(&reference)).then_some(gap)
}

/// The system of the file at `path`.
#[cfg(feature = "serde")]
fn load_assembly(path: &str) -> Result<BarSystem, lexopt::Error> {
    nonsmooth_modes::io::assembly::Assembly::from_path(path)
        .map(|assembly| assembly.into_system())
        .map_err(|e| format!("--assembly {path}: {e}").into())
}

/// Without the `serde` feature there is no file parser: the flag is refused with the command
/// that has one.
#[cfg(not(feature = "serde"))]
fn load_assembly(path: &str) -> Result<BarSystem, lexopt::Error> {
    Err(format!(
        "--assembly needs the `serde` feature: cargo run --release --features serde \
         --example backbone -- --assembly {path}"
    )
    .into())
}

fn range(text: &str) -> Result<(f64, f64), lexopt::Error> {
    let (a, b) = text
        .split_once(':')
        .ok_or_else(|| format!("expected LO:HI, got `{text}`"))?;
    let parse = |v: &str| {
        v.parse::<f64>()
            .map_err(|e| lexopt::Error::from(format!("`{v}`: {e}")))
    };
    Ok((parse(a)?, parse(b)?))
}

/// The count `value` of `--flag`, at most `max`.
fn at_most(flag: &str, value: std::ffi::OsString, max: usize) -> Result<usize, lexopt::Error> {
    use lexopt::ValueExt;
    let n: usize = value.parse()?;
    if n > max {
        return Err(format!("--{flag} {n} is over the example's limit of {max}").into());
    }
    Ok(n)
}

/// The arguments of the command line, or `None` when the usage was asked for.
fn parse() -> Result<Option<Args>, lexopt::Error> {
    use lexopt::prelude::*;
    let mut a = Args {
        system: SystemKind::Clamped,
        gap: 1e-3,
        robin_stiffness: 0.5,
        length2: 0.95,
        speed2: 1.0,
        stiffness_ratio: 1.0,
        settings: HarmonicBalanceSettings::default(),
        mode: 1,
        subharmonic: 1,
        period_start: None,
        period_end: None,
        steps: 181,
        dogleg: false,
        fail_fast: None,
        retry_depth: 1,
        selection: Selection::FirstConverged,
        serial: false,
        out: None,
        arclength: false,
        driver: ArclengthOptions::default(),
        omega_range: None,
        parameter: Parameter::Omega,
        parameter_range: None,
        progress: false,
        verify: false,
    };
    let mut assembly = None;
    let mut system_given = false;
    let mut values_given = Vec::new();
    let mut parser = lexopt::Parser::from_env();
    while let Some(arg) = parser.next()? {
        if let Long(flag) = arg {
            if let Some(name) = SHORTHAND_VALUES.iter().find(|&&v| v == flag) {
                values_given.push(*name);
            }
        }
        match arg {
            Long("system") => {
                system_given = true;
                a.system = match parser.value()?.string()?.as_str() {
                    "ds" => SystemKind::Clamped,
                    "rs" => SystemKind::Robin,
                    "two-bar" => SystemKind::TwoBar,
                    other => return Err(format!("unknown system `{other}`").into()),
                }
            }
            Long("assembly") => assembly = Some(parser.value()?.string()?),
            Long("gap") => a.gap = parser.value()?.parse()?,
            Long("robin-stiffness") => a.robin_stiffness = parser.value()?.parse()?,
            Long("length2") => a.length2 = parser.value()?.parse()?,
            Long("speed2") => a.speed2 = parser.value()?.parse()?,
            Long("stiffness-ratio") => a.stiffness_ratio = parser.value()?.parse()?,
            Long("harmonics") => {
                a.settings.harmonics = at_most("harmonics", parser.value()?, MAX_HARMONICS)?
            }
            Long("samples-per-harmonic") => {
                a.settings.samples_per_harmonic = at_most(
                    "samples-per-harmonic",
                    parser.value()?,
                    MAX_SAMPLES_PER_HARMONIC,
                )?
            }
            Long("complementarity") => a.settings.complementarity = parser.value()?.parse()?,
            Long("mode") => a.mode = parser.value()?.parse()?,
            Long("subharmonic") => a.subharmonic = parser.value()?.parse()?,
            Long("period-start") => a.period_start = Some(parser.value()?.parse()?),
            Long("period-end") => a.period_end = Some(parser.value()?.parse()?),
            Long("steps") => a.steps = at_most("steps", parser.value()?, MAX_POINTS)?,
            Long("solver") => {
                a.dogleg = match parser.value()?.string()?.as_str() {
                    "newton" => false,
                    "dogleg" => true,
                    other => return Err(format!("unknown solver `{other}`").into()),
                }
            }
            Long("newton") => {
                a.fail_fast = match parser.value()?.string()?.as_str() {
                    "fail-fast" => Some(true),
                    "full" => Some(false),
                    other => return Err(format!("unknown Newton budget `{other}`").into()),
                }
            }
            Long("retry-depth") => a.retry_depth = parser.value()?.parse()?,
            Long("selection") => {
                a.selection = match parser.value()?.string()?.as_str() {
                    "first" => Selection::FirstConverged,
                    "lowest-energy" => Selection::LowestMeasure,
                    other => return Err(format!("unknown selection `{other}`").into()),
                }
            }
            Long("serial") => a.serial = true,
            Long("out") => a.out = Some(parser.value()?.string()?),
            Long("method") => {
                a.arclength = match parser.value()?.string()?.as_str() {
                    "sequential" => false,
                    "arclength" => true,
                    other => return Err(format!("unknown method `{other}`").into()),
                }
            }
            Long("ds") => a.driver.ds = parser.value()?.parse()?,
            Long("ds-min") => a.driver.ds_min = parser.value()?.parse()?,
            Long("ds-max") => a.driver.ds_max = parser.value()?.parse()?,
            Long("max-steps") => {
                a.driver.max_steps = at_most("max-steps", parser.value()?, MAX_POINTS)?
            }
            Long("omega-range") => a.omega_range = Some(range(&parser.value()?.string()?)?),
            Long("parameter") => {
                a.parameter = match parser.value()?.string()?.as_str() {
                    "omega" => Parameter::Omega,
                    "gap" => Parameter::Gap,
                    "robin-stiffness" => Parameter::RobinStiffness,
                    "stiffness-ratio" => Parameter::StiffnessRatio,
                    other => return Err(format!("unknown parameter `{other}`").into()),
                }
            }
            Long("parameter-range") => a.parameter_range = Some(range(&parser.value()?.string()?)?),
            Long("progress") => a.progress = true,
            Long("verify") => a.verify = true,
            Short('h') | Long("help") => return Ok(None),
            _ => return Err(arg.unexpected()),
        }
    }
    if let Some(path) = assembly {
        if system_given {
            return Err("--assembly and --system exclude each other".into());
        }
        if let Some(flag) = values_given.first() {
            return Err(format!(
                "--{flag} sets a value of a --system shorthand; with --assembly the values are in the file"
            )
            .into());
        }
        if a.parameter != Parameter::Omega {
            return Err("--parameter other than omega needs a --system shorthand".into());
        }
        a.system = SystemKind::File(load_assembly(&path)?);
    }
    Ok(Some(a))
}

/// The system of the command line with `parameter` set to `value` (the other flags fixed).
fn build_system(a: &Args, parameter: Parameter, value: f64) -> Result<BarSystem, ModelError> {
    let mut a = a.clone();
    match parameter {
        Parameter::Omega => {}
        Parameter::Gap => a.gap = value,
        Parameter::RobinStiffness => a.robin_stiffness = value,
        Parameter::StiffnessRatio => a.stiffness_ratio = value,
    }
    match a.system {
        SystemKind::Clamped => clamped_bar_with_obstacle(a.gap),
        SystemKind::Robin => robin_bar_with_obstacle(a.robin_stiffness, a.gap),
        SystemKind::TwoBar => {
            two_bars_in_contact(Bar::new(a.length2, a.speed2, a.stiffness_ratio)?, a.gap)
        }
        // A file's system has no parameter to vary (refused by `parse`).
        SystemKind::File(system) => Ok(system),
    }
}

fn parameter_value(a: &Args, parameter: Parameter) -> f64 {
    match parameter {
        Parameter::Omega => f64::NAN,
        Parameter::Gap => a.gap,
        Parameter::RobinStiffness => a.robin_stiffness,
        Parameter::StiffnessRatio => a.stiffness_ratio,
    }
}

fn events(events: &[Event]) -> String {
    events
        .iter()
        .map(Event::label)
        .collect::<Vec<_>>()
        .join(";")
}

/// Writes rows and counts them; remembers the first I/O error and stops the run on it.
struct Sink<'a> {
    out: &'a mut dyn Write,
    verify: Option<HarmonicBalanceSettings>,
    exact: Option<f64>,
    total: usize,
    converged: usize,
    error: Option<std::io::Error>,
    progress: bool,
}

impl Sink<'_> {
    /// `periodicity_defect,displacement_defect,max_penetration` of a point, or empty cells.
    fn verification(&self, system: &BarSystem, p: &BackbonePoint) -> String {
        let Some(settings) = self.verify else {
            return String::new();
        };
        let options = PeriodicityOptions {
            adjust_grid: true,
            ..Default::default()
        };
        let steps = 2.0 * PI / p.omega / options.dt;
        if steps > MAX_VERIFY_STEPS {
            eprintln!(
                "backbone: verification of step {} skipped: its march of {steps:.3e} time steps \
                 is over the example's limit of {MAX_VERIFY_STEPS:.0e}",
                p.step
            );
            return ",,,".to_string();
        }
        let report = settings
            .cosine_basis()
            .map_err(|e| e.to_string())
            .and_then(|basis| {
                periodicity_check(system, &basis, &p.x, p.omega, &options)
                    .map_err(|e| e.to_string())
            });
        match report {
            Ok(r) => format!(
                ",{:.6e},{:.6e},{:.6e}",
                r.defect, r.displacement_defect, r.max_penetration
            ),
            Err(e) => {
                eprintln!("backbone: verification of step {} failed: {e}", p.step);
                ",,,".to_string()
            }
        }
    }

    fn row(&mut self, system: &BarSystem, p: &BackbonePoint, parameter: f64) -> ControlFlow<()> {
        self.total += 1;
        self.converged += usize::from(p.converged);
        let exact = self
            .exact
            .map(|gap| ClampedFirstMode::new(gap, p.period).energy_normalized());
        if self.progress && self.total % 25 == 0 {
            eprintln!(
                "step {:5}  T {:.5}  E/Eg {:.5e}  ds {:.3e}",
                p.step, p.period, p.energy_normalized, p.step_size
            );
        }
        let verification = self.verification(system, p);
        let line = format!(
            "{},{:.10},{:.10},{:.10e},{:.10e},{},{},{:.3e},{},{:.6e},{},{}{}",
            p.step,
            p.period,
            p.omega,
            p.energy,
            p.energy_normalized,
            exact.map(|e| format!("{e:.10e}")).unwrap_or_default(),
            p.converged,
            p.residual_norm,
            p.iterations,
            p.step_size,
            events(&p.events),
            if parameter.is_nan() {
                String::new()
            } else {
                format!("{parameter:.10e}")
            },
            verification,
        );
        match writeln!(self.out, "{line}") {
            Ok(()) => ControlFlow::Continue(()),
            Err(e) => {
                self.error = Some(e);
                ControlFlow::Break(())
            }
        }
    }
}

fn run(a: &Args, out: &mut dyn Write) -> Result<(usize, usize), Box<dyn std::error::Error>> {
    let system = build_system(a, Parameter::Omega, f64::NAN)?;
    let (t0, t1) = match (a.period_start, a.period_end) {
        (Some(t0), Some(t1)) => (t0, t1),
        _ => default_periods(a)?,
    };
    let (t0, t1) = (a.period_start.unwrap_or(t0), a.period_end.unwrap_or(t1));
    let extra = if a.verify {
        ",periodicity_defect,displacement_defect,max_penetration"
    } else {
        ""
    };
    writeln!(out, "{HEADER}{extra}")?;
    let mut sink = Sink {
        out,
        verify: a.verify.then_some(a.settings),
        exact: (a.mode == 1 && a.subharmonic == 1 && a.parameter != Parameter::Gap)
            .then(|| clamped_gap(&system))
            .flatten(),
        total: 0,
        converged: 0,
        error: None,
        progress: a.progress,
    };
    let solver = if a.dogleg {
        Solver::Dogleg(Dogleg::default())
    } else if a.fail_fast.unwrap_or(!a.arclength) {
        // Sequential steps start from a converged neighbour: give up early.
        Solver::Newton(SemismoothNewton::new(NewtonOptions::fail_fast())?)
    } else {
        // Arclength's stall escapes solve from far starts: the full budget.
        Solver::Newton(SemismoothNewton::default())
    };
    if a.parameter != Parameter::Omega {
        run_parameter(a, t0, solver, &mut sink)?;
    } else if a.arclength {
        let (lo, hi) = (2.0 * PI / t0, 2.0 * PI / t1);
        let options = ArclengthBackboneOptions {
            start_period: t0,
            omega_range: a.omega_range.unwrap_or((lo.min(hi) * 0.999, lo.max(hi))),
            mode: a.mode,
            subharmonic: a.subharmonic,
            arclength: ArclengthOptions {
                direction: if t1 < t0 { 1.0 } else { -1.0 },
                ..a.driver
            },
            ..Default::default()
        };
        let (_, branch) = arclength_backbone(&system, a.settings, &options, solver, |p| {
            sink.row(&system, p, f64::NAN)
        })?;
        eprintln!(
            "backbone: arclength ended: {:?}; {} rejected steps",
            branch.end, branch.rejections
        );
    } else {
        let options = BackboneOptions {
            grid: PeriodGrid {
                start: t0,
                end: t1,
                steps: a.steps,
            },
            mode: a.mode,
            subharmonic: a.subharmonic,
            retry_depth: a.retry_depth,
            selection: a.selection,
            ..Default::default()
        };
        let see = |p: &BackbonePoint| sink.row(&system, p, f64::NAN);
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        if a.serial || cores < 2 {
            backbone_with(&system, a.settings, &options, solver, see)?;
        } else {
            let speculation = Speculation::default();
            backbone_speculative_with(&system, a.settings, &options, speculation, solver, see)?;
        }
    }
    if let Some(e) = sink.error {
        return Err(e.into());
    }
    Ok((sink.total, sink.converged))
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
    let steps = if a.arclength {
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
            retry_depth: a.retry_depth,
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
            Ok(system) => sink.row(&system, point, v),
            Err(_) => ControlFlow::Continue(()),
        },
    )?;
    eprintln!(
        "backbone: {} ended: {:?}; {} rejected steps",
        if a.arclength {
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

fn main() -> ExitCode {
    let args = match parse() {
        Ok(Some(a)) => a,
        Ok(None) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            eprintln!("backbone: {e}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let result = match &args.out {
        Some(path) => match std::fs::File::create(path) {
            Ok(f) => run(&args, &mut std::io::BufWriter::new(f)),
            Err(e) => Err(e.into()),
        },
        None => run(&args, &mut std::io::stdout().lock()),
    };
    match result {
        Ok((total, converged)) => {
            eprintln!("backbone: {converged} of {total} steps converged");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("backbone: error: {e}");
            ExitCode::FAILURE
        }
    }
}
