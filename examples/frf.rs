//! Frequency-response curve of a forced, damped bar system with exact unilateral contact,
//! written as CSV: a thin front end of `forced::forced_response`.
//!
//! ```text
//! cargo run --release --example frf -- [--system ds|rs|two-bar] [--gap 1e-3]
//!     [--robin-stiffness 0.5] [--length2 0.95 --speed2 1 --stiffness-ratio 1]
//!     [--assembly FILE] [--harmonics 20 --samples-per-harmonic 30 --complementarity 4]
//!     [--resonance-band 0.1]
//!     --forcing end:END:AMPLITUDE|base:END:AMPLITUDE [--forcing ...]
//!     [--damping ETA] [--omega-range LO:HI] [--steps S] [--method sequential|down|arclength]
//!     [--solver newton|dogleg] [--out FILE]
//! ```
//!
//! The system flags are those of the `backbone` example (`--system` shorthands, whose bars
//! are named `1` and `2`, or `--assembly FILE`). `END` names an end as assembly files do:
//! `NAME.start` (`x = 0`) or `NAME.end` (`x = l`). `end:END:F` applies the force
//! `F cos(Omega t)` along `+x` at a free or sprung end; `base:END:U` moves the ground a
//! clamped or sprung end is tied to by `U cos(Omega t)` (`forced::Excitation`). `--damping`
//! is the viscous damping `eta` of `u_tt + eta u_t = c^2 u_xx` in every bar (default 1e-3).
//! The default range is `0.95 omega_1 .. 1.3 omega_1` of the system's first linear mode
//! (open contacts). `--steps` defaults to `2 (HI - LO) / ETA`, at least 200 (at most
//! 100 000): steps of half the width of a linear resonance peak, which a sweep in coarser
//! steps jumps over before it reaches the obstacle.
//!
//! `--method sequential` (the default) sweeps the frequency up as an experiment does: it
//! follows the branch it is on, and where that branch ends (past a resonance peak) it drops
//! to the open-contact response and goes on; `--method down` sweeps down from the high end
//! the same way. Each sweep prints the frequencies where it left its branch (`jump at omega
//! = ...`). `--method arclength` follows one curve through
//! its folds: the harmonic selection is held while a step is corrected and moved between
//! points, where the point is solved again with the new selection, switching the harmonics it
//! adds on one at a time; a point that cannot be moved there, or a step that collapses at a
//! kink of the laws, moves on by a quarter of a grid step up to three grid steps before the
//! run ends (stalled), as it does where it comes back to a point it passed. `--resonance-band C` holds at zero every harmonic `n >= 2` within `C / m` of a
//! natural frequency (`HarmonicBalanceSettings::resonance_band`); its default here is
//! `system::RESONANCE_BAND` = 0.1, not 0 as in `backbone`: the clamped bar's natural
//! frequencies are odd multiples of the first, so near `omega_1` every odd harmonic sits on
//! one, and without the band the response climbs that internal resonance instead of the
//! backbone (`docs/validation.md`, "Forced response"). Where the band switches a harmonic on
//! or off the equations jump: a sweep steps over it, an arclength run moves the point across.
//!
//! Columns: `omega,amplitude,energy,energy_normalized,converged,status,contact_defect,
//! dropped_harmonics,residual_norm,iterations,fold`: `amplitude` is the largest closure of the first unilateral
//! end's gap over the period divided by its gap, `energy` the bars' mechanical energy
//! averaged over the period, `contact_defect` how far the truncated motion is from the
//! contact law between the samples (`forced::ForcedSystem::contact_defect`) and
//! `dropped_harmonics` the harmonics the band held at zero there (separated by `;`), and
//! `fold` whether the curve turns back in frequency there (arclength; the folds are also
//! listed on stderr with their frequency, amplitude and `E/E_g`). Every point
//! computed is written; a run that ends early, or whose start does not converge, says why on
//! stderr and exits with code 1. Usage errors, including a system, forcing or frequency range
//! the library refuses (`--omega-range 2:1` is reversed: the sweep climbs from `LO`), exit
//! with code 2.

use lexopt::prelude::*;
use nonsmooth_modes::bar::{Bar, EndRef};
use nonsmooth_modes::branches::PointStatus;
use nonsmooth_modes::continuation::EndReason;
use nonsmooth_modes::forced::{
    forced_response, Damping, Excitation, Forcing, ResponseMethod, ResponseRequest,
};
use nonsmooth_modes::modal::open_mode;
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact,
};
use nonsmooth_modes::solve::Solver;
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings, RESONANCE_BAND};
use nonsmooth_modes::Error;
use std::io::Write;
use std::process::ExitCode;

const USAGE: &str = "usage: frf [--system ds|rs|two-bar] [--gap G] [--robin-stiffness K]
  [--length2 L --speed2 C --stiffness-ratio R] | [--assembly FILE.toml|FILE.json]
  [--harmonics M] [--samples-per-harmonic NH] [--complementarity AC] [--resonance-band C]
  --forcing end:END:AMPLITUDE|base:END:AMPLITUDE [--forcing ...] [--damping ETA]
  [--omega-range LO:HI] [--steps S] [--method sequential|down|arclength] [--solver newton|dogleg] [--out FILE]";

/// Largest `--harmonics` (a dense solve costs the cube of the unknowns).
const MAX_HARMONICS: usize = 200;
/// Largest `--samples-per-harmonic`.
const MAX_SAMPLES_PER_HARMONIC: usize = 10_000;
/// Largest `--steps`.
const MAX_STEPS: usize = 100_000;

struct Args {
    system: BarSystem,
    /// Bar names: the file's, or `1`, `2` for the shorthands.
    names: Vec<String>,
    settings: HarmonicBalanceSettings,
    forcing: Vec<String>,
    damping: f64,
    omega_range: Option<(f64, f64)>,
    /// `None`: derived from the damping and the range.
    steps: Option<usize>,
    method: ResponseMethod,
    solver: Solver,
    out: Option<String>,
}

fn range(text: &str) -> Result<(f64, f64), lexopt::Error> {
    let (a, b) = text
        .split_once(':')
        .ok_or_else(|| format!("expected LO:HI, got `{text}`"))?;
    let parse = |v: &str| v.parse::<f64>().map_err(|e| format!("`{v}`: {e}"));
    Ok((parse(a)?, parse(b)?))
}

fn at_most(flag: &str, value: std::ffi::OsString, max: usize) -> Result<usize, lexopt::Error> {
    let n: usize = value.parse()?;
    if n > max {
        return Err(format!("--{flag} {n} is over the example's limit of {max}").into());
    }
    Ok(n)
}

/// The end `NAME.start|NAME.end`.
fn end(text: &str, names: &[String], system: &BarSystem) -> Result<EndRef, String> {
    let (name, side) = text
        .rsplit_once('.')
        .ok_or_else(|| format!("expected NAME.start or NAME.end, got `{text}`"))?;
    let index = names
        .iter()
        .position(|n| n == name)
        .ok_or_else(|| format!("no bar named `{name}` (bars: {})", names.join(", ")))?;
    let id = system.bar_id(index).ok_or("a bar of the system")?;
    match side {
        "start" => Ok(id.left()),
        "end" => Ok(id.right()),
        _ => Err(format!("expected NAME.start or NAME.end, got `{text}`")),
    }
}

/// `end:END:F` or `base:END:U`.
fn excitation(text: &str, names: &[String], system: &BarSystem) -> Result<Excitation, String> {
    let mut parts = text.splitn(3, ':');
    let (kind, at, amplitude) = match (parts.next(), parts.next(), parts.next()) {
        (Some(k), Some(e), Some(a)) => (k, e, a),
        _ => {
            return Err(format!(
                "expected end:END:AMPLITUDE or base:END:AMPLITUDE, got `{text}`"
            ))
        }
    };
    let at = end(at, names, system)?;
    let amplitude: f64 = amplitude
        .parse()
        .map_err(|e| format!("`{amplitude}`: {e}"))?;
    match kind {
        "end" => Ok(Excitation::force(at, amplitude)),
        "base" => Ok(Excitation::base_motion(at, amplitude)),
        other => Err(format!("unknown excitation `{other}` (end or base)")),
    }
}

fn parse() -> Result<Option<Args>, lexopt::Error> {
    let mut parser = lexopt::Parser::from_env();
    let (mut shorthand, mut assembly) = (None, None);
    let (mut gap, mut robin, mut length2, mut speed2, mut ratio) = (1e-3, 0.5, 0.95, 1.0, 1.0);
    let mut settings = HarmonicBalanceSettings {
        resonance_band: RESONANCE_BAND,
        ..Default::default()
    };
    let (mut forcing, mut damping, mut omega_range) = (Vec::new(), 1e-3, None);
    let (mut steps, mut method, mut out) = (None, ResponseMethod::Sequential, None);
    let mut solver = Solver::default();
    let mut values_given = Vec::new();
    while let Some(arg) = parser.next()? {
        match arg {
            Long("system") => shorthand = Some(parser.value()?.string()?),
            Long("assembly") => assembly = Some(parser.value()?.string()?),
            Long(flag @ ("gap" | "robin-stiffness" | "length2" | "speed2" | "stiffness-ratio")) => {
                let flag = flag.to_string();
                let v: f64 = parser.value()?.parse()?;
                match flag.as_str() {
                    "gap" => gap = v,
                    "robin-stiffness" => robin = v,
                    "length2" => length2 = v,
                    "speed2" => speed2 = v,
                    _ => ratio = v,
                }
                values_given.push(flag);
            }
            Long("harmonics") => {
                settings.harmonics = at_most("harmonics", parser.value()?, MAX_HARMONICS)?
            }
            Long("samples-per-harmonic") => {
                settings.samples_per_harmonic = at_most(
                    "samples-per-harmonic",
                    parser.value()?,
                    MAX_SAMPLES_PER_HARMONIC,
                )?
            }
            Long("complementarity") => settings.complementarity = parser.value()?.parse()?,
            Long("resonance-band") => settings.resonance_band = parser.value()?.parse()?,
            Long("forcing") => forcing.push(parser.value()?.string()?),
            Long("damping") => damping = parser.value()?.parse()?,
            Long("omega-range") => omega_range = Some(range(&parser.value()?.string()?)?),
            Long("steps") => steps = Some(at_most("steps", parser.value()?, MAX_STEPS)?),
            Long("method") => {
                method = match parser.value()?.string()?.as_str() {
                    "sequential" => ResponseMethod::Sequential,
                    "down" => ResponseMethod::SweepDown,
                    "arclength" => ResponseMethod::Arclength,
                    other => return Err(format!("unknown method `{other}`").into()),
                }
            }
            Long("solver") => {
                solver = match parser.value()?.string()?.as_str() {
                    "newton" => Solver::default(),
                    "dogleg" => Solver::Dogleg(Default::default()),
                    other => return Err(format!("unknown solver `{other}`").into()),
                }
            }
            Long("out") => out = Some(parser.value()?.string()?),
            Short('h') | Long("help") => return Ok(None),
            _ => return Err(arg.unexpected()),
        }
    }
    let (system, names) = match (shorthand.as_deref(), assembly) {
        (Some(_), Some(_)) => return Err("--assembly and --system exclude each other".into()),
        (_, Some(path)) => {
            if let Some(flag) = values_given.first() {
                return Err(format!(
                    "--{flag} sets a value of a --system shorthand; with --assembly the values are in the file"
                )
                .into());
            }
            load_assembly(&path)?
        }
        (kind, None) => {
            let system = match kind.unwrap_or("ds") {
                "ds" => clamped_bar_with_obstacle(gap),
                "rs" => robin_bar_with_obstacle(robin, gap),
                "two-bar" => {
                    Bar::new(length2, speed2, ratio).and_then(|bar| two_bars_in_contact(bar, gap))
                }
                other => return Err(format!("unknown system `{other}`").into()),
            }
            .map_err(|e| e.to_string())?;
            let names = (1..=system.bars().len()).map(|i| i.to_string()).collect();
            (system, names)
        }
    };
    if forcing.is_empty() {
        return Err("--forcing is required (end:END:AMPLITUDE or base:END:AMPLITUDE)".into());
    }
    Ok(Some(Args {
        system,
        names,
        settings,
        forcing,
        damping,
        omega_range,
        steps,
        method,
        solver,
        out,
    }))
}

#[cfg(feature = "serde")]
fn load_assembly(path: &str) -> Result<(BarSystem, Vec<String>), lexopt::Error> {
    let assembly = nonsmooth_modes::io::assembly::Assembly::from_path(path)
        .map_err(|e| format!("--assembly {path}: {e}"))?;
    let names = assembly.names().to_vec();
    Ok((assembly.into_system(), names))
}

#[cfg(not(feature = "serde"))]
fn load_assembly(path: &str) -> Result<(BarSystem, Vec<String>), lexopt::Error> {
    Err(format!(
        "--assembly needs the default feature `serde`: cargo run --release --example frf -- --assembly {path}"
    )
    .into())
}

/// Steps of half the width `eta` of a linear resonance peak over the range, at least 200 and
/// at most [`MAX_STEPS`]: a sweep in coarser steps jumps over the peak before it reaches the
/// obstacle.
fn default_steps((lo, hi): (f64, f64), eta: f64) -> usize {
    let steps = 2.0 * (hi - lo) / eta;
    if steps.is_finite() {
        (steps.ceil() as usize).clamp(200, MAX_STEPS)
    } else {
        200
    }
}

fn status_name(s: &PointStatus) -> &'static str {
    match s {
        PointStatus::Converged => "converged",
        PointStatus::SolverFailed(_) => "solver-failed",
        PointStatus::NonFiniteEnergy => "non-finite-energy",
        _ => "rejected",
    }
}

fn run(a: Args) -> Result<ExitCode, Box<dyn std::error::Error>> {
    let excitations = (a.forcing.iter())
        .map(|f| excitation(f, &a.names, &a.system))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| format!("--forcing: {e}"))?;
    let omega_range = match a.omega_range {
        Some(r) => r,
        None => {
            let omega_1 = open_mode(&a.system, 1)?.omega;
            (0.95 * omega_1, 1.3 * omega_1)
        }
    };
    let request = ResponseRequest {
        settings: a.settings,
        forcing: Forcing {
            damping: Damping::Uniform(a.damping),
            excitations,
        },
        omega_range,
        steps: a
            .steps
            .unwrap_or_else(|| default_steps(omega_range, a.damping)),
        method: a.method,
        solver: a.solver,
    };
    let response = match forced_response(&a.system, &request) {
        Ok(r) => r,
        // A range refused as given is a usage error (exit 2, with the usage).
        Err(e) if e.bad_range().is_some() => return Err(format!("{e}\n{USAGE}").into()),
        // A solver that fails at the start is a failed run (exit 1), not a usage error.
        Err(e @ (Error::Solve(_) | Error::Continuation(_))) => {
            eprintln!("frf: {e}");
            return Ok(ExitCode::FAILURE);
        }
        Err(e) => return Err(e.into()),
    };
    let mut w: Box<dyn Write> = match &a.out {
        Some(path) => Box::new(std::io::BufWriter::new(std::fs::File::create(path)?)),
        None => Box::new(std::io::BufWriter::new(std::io::stdout().lock())),
    };
    writeln!(
        w,
        "omega,amplitude,energy,energy_normalized,converged,status,contact_defect,dropped_harmonics,residual_norm,iterations,fold"
    )?;
    for p in &response.points {
        writeln!(
            w,
            "{},{},{},{},{},{},{},{},{},{},{}",
            p.omega,
            p.amplitude,
            p.energy,
            p.energy_normalized,
            p.converged,
            status_name(&p.status),
            p.contact_defect,
            p.dropped_harmonics
                .iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(";"),
            p.residual_norm,
            p.iterations,
            p.fold
        )?;
    }
    w.flush()?;
    let converged = response.converged().count();
    eprintln!(
        "{converged} of {} points converged; end: {:?}; rejected steps: {}",
        response.points.len(),
        response.end,
        response.rejected_steps
    );
    for omega in &response.jumps {
        eprintln!("jump at omega = {omega}");
    }
    for f in response.folds() {
        eprintln!(
            "fold at omega = {} (amplitude {}, E/E_g {})",
            f.omega, f.amplitude, f.energy_normalized
        );
    }
    Ok(match response.end {
        EndReason::Completed | EndReason::ParameterOutOfRange { .. } | EndReason::MaxSteps => {
            ExitCode::SUCCESS
        }
        _ => ExitCode::FAILURE,
    })
}

fn main() -> ExitCode {
    let args = match parse() {
        Ok(Some(a)) => a,
        Ok(None) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            eprintln!("frf: {e}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    match run(args) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("frf: {e}");
            ExitCode::from(2)
        }
    }
}
