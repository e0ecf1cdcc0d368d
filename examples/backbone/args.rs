//! The command line: its flags and their defaults, the parser with its validation, the
//! example's limits and the usage text.

use crate::systems::{load_assembly, SystemKind};
use nonsmooth_modes::branches::{SwitchAt, MAX_CONSECUTIVE_FAILURES};
use nonsmooth_modes::continuation::{ArclengthOptions, Selection};
use nonsmooth_modes::system::HarmonicBalanceSettings;

pub const USAGE: &str = "usage: backbone [--system ds|rs|two-bar] [--gap G] [--robin-stiffness K]
  [--length2 L --speed2 C --stiffness-ratio R] | [--assembly FILE.toml|FILE.json]
  [--harmonics M] [--samples-per-harmonic NH] [--resonance-band C]
  [--complementarity AC] [--mode I] [--subharmonic K] [--repeated] [--period-start T0] [--period-end T1] [--steps S]
  [--solver newton|dogleg] [--newton fail-fast|full] [--retry-depth K] [--max-failures F]
  [--selection first|lowest-energy] [--serial] [--out FILE]
  [--method sequential|arclength]
  [--ds DS] [--ds-min A] [--ds-max B] [--max-steps N] [--omega-range LO:HI] [--switch-at N[:SIDE]]
  [--parameter omega|energy|gap|robin-stiffness|stiffness-ratio] [--parameter-range LO:HI]
  [--energy-range LO:HI] [--progress] [--verify] [--stability] [--hill] [--basis cosine|full]
  [--exact] [--cells-per-travel N]";

/// Largest `--steps` and `--max-steps`.
pub const MAX_POINTS: usize = 1_000_000;
/// Largest `--harmonics` (one solve costs about the cube of it).
pub const MAX_HARMONICS: usize = 1_000;
/// Largest `--samples-per-harmonic`.
pub const MAX_SAMPLES_PER_HARMONIC: usize = 10_000;

/// The flags that set a value of a `--system` shorthand, refused with `--assembly`.
const SHORTHAND_VALUES: [&str; 5] = [
    "gap",
    "robin-stiffness",
    "length2",
    "speed2",
    "stiffness-ratio",
];

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Parameter {
    Omega,
    /// The energy level `E / E_g`, the frequency an unknown.
    Energy,
    Gap,
    RobinStiffness,
    StiffnessRatio,
}

#[derive(Debug, Clone)]
pub struct Args {
    pub system: SystemKind,
    pub gap: f64,
    pub robin_stiffness: f64,
    pub length2: f64,
    pub speed2: f64,
    pub stiffness_ratio: f64,
    pub settings: HarmonicBalanceSettings,
    pub mode: usize,
    pub subharmonic: usize,
    /// With `--subharmonic K > 1`: keep the `K`-fold repeated branch, do not switch off it.
    pub repeated: bool,
    /// `--basis full`: the branch continued in the constant + cosine + sine basis.
    pub full_basis: bool,
    pub period_start: Option<f64>,
    pub period_end: Option<f64>,
    pub steps: usize,
    pub dogleg: bool,
    /// `Some(true)`: fail-fast budget, `Some(false)`: full, `None`: per method.
    pub fail_fast: Option<bool>,
    /// `None`: the run's own default (`BackboneOptions::for_mode` for a period backbone of a
    /// file, 1 otherwise).
    pub retry_depth: Option<usize>,
    /// Consecutive failed steps before a sequential run ends as stalled.
    pub max_failures: usize,
    pub selection: Selection,
    /// No speculative retry on a second thread.
    pub serial: bool,
    pub out: Option<String>,
    /// `--method`: `Some(true)` arclength, `Some(false)` sequential, `None` chosen from the
    /// system (`runs::arclength_by_default`).
    pub arclength: Option<bool>,
    pub driver: ArclengthOptions,
    pub omega_range: Option<(f64, f64)>,
    /// `--switch-at N[:SIDE]` of arclength runs.
    pub switch: Option<SwitchAt>,
    pub parameter: Parameter,
    pub parameter_range: Option<(f64, f64)>,
    /// Levels `E / E_g` of `--parameter energy`.
    pub energy_range: Option<(f64, f64)>,
    pub progress: bool,
    pub verify: bool,
    /// `--stability`: the Floquet multipliers of every converged point.
    pub stability: bool,
    /// `--hill`: the Hill exponents of every converged point.
    pub hill: bool,
    /// `--exact`: the exact branch of the one-period map, seeded by the harmonic-balance run.
    pub exact: bool,
    /// `--cells-per-travel`: the exact map's grid (a minimum; `None`: the default of
    /// `StabilityOptions`).
    pub cells_per_travel: Option<f64>,
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

/// `N` or `N:SIDE` of `--switch-at`: the `N`-th branch point (from 1), side `+1` (default) or
/// `-1`.
fn switch_at(text: &str) -> Result<SwitchAt, lexopt::Error> {
    let (n, side) = text.split_once(':').unwrap_or((text, "1"));
    let branch_point: usize = n.parse().map_err(|e| format!("`{n}`: {e}"))?;
    let side: f64 = side.parse().map_err(|e| format!("`{side}`: {e}"))?;
    if branch_point == 0 || !(side == 1.0 || side == -1.0) {
        return Err(format!("expected N:SIDE with N >= 1 and SIDE 1 or -1, got `{text}`").into());
    }
    Ok(SwitchAt { branch_point, side })
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
pub fn parse() -> Result<Option<Args>, lexopt::Error> {
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
        repeated: false,
        period_start: None,
        period_end: None,
        steps: 181,
        dogleg: false,
        fail_fast: None,
        retry_depth: None,
        max_failures: MAX_CONSECUTIVE_FAILURES,
        selection: Selection::FirstConverged,
        serial: false,
        out: None,
        arclength: None,
        driver: ArclengthOptions::default(),
        omega_range: None,
        switch: None,
        parameter: Parameter::Omega,
        parameter_range: None,
        energy_range: None,
        progress: false,
        verify: false,
        stability: false,
        hill: false,
        full_basis: false,
        exact: false,
        cells_per_travel: None,
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
            Long("resonance-band") => a.settings.resonance_band = parser.value()?.parse()?,
            Long("mode") => a.mode = parser.value()?.parse()?,
            Long("subharmonic") => a.subharmonic = parser.value()?.parse()?,
            Long("repeated") => a.repeated = true,
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
            Long("retry-depth") => a.retry_depth = Some(parser.value()?.parse()?),
            Long("max-failures") => a.max_failures = parser.value()?.parse()?,
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
                    "sequential" => Some(false),
                    "arclength" => Some(true),
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
            Long("switch-at") => a.switch = Some(switch_at(&parser.value()?.string()?)?),
            Long("parameter") => {
                a.parameter = match parser.value()?.string()?.as_str() {
                    "omega" => Parameter::Omega,
                    "energy" => Parameter::Energy,
                    "gap" => Parameter::Gap,
                    "robin-stiffness" => Parameter::RobinStiffness,
                    "stiffness-ratio" => Parameter::StiffnessRatio,
                    other => return Err(format!("unknown parameter `{other}`").into()),
                }
            }
            Long("parameter-range") => a.parameter_range = Some(range(&parser.value()?.string()?)?),
            Long("energy-range") => a.energy_range = Some(range(&parser.value()?.string()?)?),
            Long("progress") => a.progress = true,
            Long("verify") => a.verify = true,
            Long("stability") => a.stability = true,
            Long("hill") => a.hill = true,
            Long("exact") => a.exact = true,
            Long("cells-per-travel") => a.cells_per_travel = Some(parser.value()?.parse()?),
            Long("basis") => {
                a.full_basis = match parser.value()?.string()?.as_str() {
                    "cosine" => false,
                    "full" => true,
                    other => return Err(format!("unknown basis `{other}`").into()),
                }
            }
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
        if !matches!(a.parameter, Parameter::Omega | Parameter::Energy) {
            return Err("--parameter other than omega or energy needs a --system shorthand".into());
        }
        a.system = SystemKind::File(load_assembly(&path)?);
    }
    if a.switch.is_some() && a.arclength != Some(true) {
        return Err("--switch-at needs --method arclength".into());
    }
    if a.full_basis
        && (a.parameter != Parameter::Omega || a.arclength == Some(true) || a.subharmonic != 1)
    {
        return Err(
            "--basis full runs sequentially in the period (--parameter omega, no --method \
             arclength) for --subharmonic 1"
                .into(),
        );
    }
    if a.exact && (a.parameter != Parameter::Omega || a.full_basis || a.hill) {
        return Err(
            "--exact continues in the period (--parameter omega) in the cosine basis, without --hill"
                .into(),
        );
    }
    match a.cells_per_travel {
        Some(_) if !a.exact => {
            return Err("--cells-per-travel sets the grid of --exact, which is not given".into())
        }
        Some(cells) if !(cells.is_finite() && (1.0..=1000.0).contains(&cells)) => {
            return Err(format!("--cells-per-travel must lie in [1, 1000], got {cells}").into())
        }
        _ => {}
    }
    if a.parameter == Parameter::Energy && a.arclength == Some(true) {
        return Err("--parameter energy is sequential: it takes no --method arclength".into());
    }
    Ok(Some(a))
}
