//! Backbone of a nonsmooth mode by sequential continuation in the period, written as CSV.
//!
//! ```text
//! cargo run --release --example backbone -- [--system ds|rs|two-bar] [--gap 1e-3]
//!     [--robin-stiffness 0.5] [--length2 0.95 --speed2 1 --stiffness-ratio 1]
//!     [--harmonics 20 --samples-per-harmonic 30 --penalty 4] [--mode 1]
//!     [--period-start T0 --period-end T1 --steps S] [--solver newton|dogleg] [--out FILE]
//! ```
//!
//! Columns: `step,period,omega,energy,energy_normalized,exact_energy_normalized,converged,
//! residual_norm,iterations` (`exact_energy_normalized` is the exact first mode of the clamped
//! bar, formulation §9, for `--system ds --mode 1` and empty otherwise).

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::modal::backbone::backbone_with;
use nonsmooth_modes::modal::{BackboneOptions, BackbonePoint, PeriodGrid};
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact, ClampedFirstMode,
};
use nonsmooth_modes::solve::{Dogleg, NonlinearSolver, SemismoothNewton};
use nonsmooth_modes::system::{BarSystem, HarmonicBalance};
use std::io::Write;
use std::ops::ControlFlow;
use std::process::ExitCode;

const USAGE: &str = "usage: backbone [--system ds|rs|two-bar] [--gap G] [--robin-stiffness K]
  [--length2 L --speed2 C --stiffness-ratio R] [--harmonics M] [--samples-per-harmonic NH]
  [--penalty AC] [--mode I] [--period-start T0] [--period-end T1] [--steps S]
  [--solver newton|dogleg] [--out FILE]";

#[derive(Debug, Clone, Copy, PartialEq)]
enum SystemKind {
    Clamped,
    Robin,
    TwoBar,
}

#[derive(Debug)]
struct Args {
    system: SystemKind,
    gap: f64,
    robin_stiffness: f64,
    length2: f64,
    speed2: f64,
    stiffness_ratio: f64,
    settings: HarmonicBalance,
    mode: usize,
    period_start: Option<f64>,
    period_end: Option<f64>,
    steps: usize,
    dogleg: bool,
    out: Option<String>,
}

/// Default period range per system: just below the linear period of the chosen mode
/// down to a strongly nonlinear period.
fn default_periods(system: SystemKind) -> (f64, f64) {
    match system {
        SystemKind::Clamped => (3.95, 3.05),
        // Robin k = 0.5: omega_1 = 0.653271, T_1 = 9.618
        SystemKind::Robin => (9.5, 6.0),
        // bar 1 clamped-free: T_1 = 4
        SystemKind::TwoBar => (3.95, 3.05),
    }
}

fn parse() -> Result<Args, lexopt::Error> {
    use lexopt::prelude::*;
    let mut a = Args {
        system: SystemKind::Clamped,
        gap: 1e-3,
        robin_stiffness: 0.5,
        length2: 0.95,
        speed2: 1.0,
        stiffness_ratio: 1.0,
        settings: HarmonicBalance::default(),
        mode: 1,
        period_start: None,
        period_end: None,
        steps: 181,
        dogleg: false,
        out: None,
    };
    let mut parser = lexopt::Parser::from_env();
    while let Some(arg) = parser.next()? {
        match arg {
            Long("system") => {
                a.system = match parser.value()?.string()?.as_str() {
                    "ds" => SystemKind::Clamped,
                    "rs" => SystemKind::Robin,
                    "two-bar" => SystemKind::TwoBar,
                    other => return Err(format!("unknown system `{other}`").into()),
                }
            }
            Long("gap") => a.gap = parser.value()?.parse()?,
            Long("robin-stiffness") => a.robin_stiffness = parser.value()?.parse()?,
            Long("length2") => a.length2 = parser.value()?.parse()?,
            Long("speed2") => a.speed2 = parser.value()?.parse()?,
            Long("stiffness-ratio") => a.stiffness_ratio = parser.value()?.parse()?,
            Long("harmonics") => a.settings.harmonics = parser.value()?.parse()?,
            Long("samples-per-harmonic") => {
                a.settings.samples_per_harmonic = parser.value()?.parse()?
            }
            Long("penalty") => a.settings.penalty = parser.value()?.parse()?,
            Long("mode") => a.mode = parser.value()?.parse()?,
            Long("period-start") => a.period_start = Some(parser.value()?.parse()?),
            Long("period-end") => a.period_end = Some(parser.value()?.parse()?),
            Long("steps") => a.steps = parser.value()?.parse()?,
            Long("solver") => {
                a.dogleg = match parser.value()?.string()?.as_str() {
                    "newton" => false,
                    "dogleg" => true,
                    other => return Err(format!("unknown solver `{other}`").into()),
                }
            }
            Long("out") => a.out = Some(parser.value()?.string()?),
            Short('h') | Long("help") => return Err("help requested".into()),
            _ => return Err(arg.unexpected()),
        }
    }
    Ok(a)
}

fn build_system(a: &Args) -> Result<BarSystem, nonsmooth_modes::Error> {
    Ok(match a.system {
        SystemKind::Clamped => clamped_bar_with_obstacle(a.gap)?,
        SystemKind::Robin => robin_bar_with_obstacle(a.robin_stiffness, a.gap)?,
        SystemKind::TwoBar => {
            let second = Bar::new(a.length2, a.speed2, a.stiffness_ratio)?;
            two_bars_in_contact(second, a.gap)?
        }
    })
}

fn csv_row(p: &BackbonePoint, exact: Option<f64>) -> String {
    format!(
        "{},{:.10},{:.10},{:.10e},{:.10e},{},{},{:.3e},{}",
        p.step,
        p.period,
        p.omega,
        p.energy,
        p.energy_normalized,
        exact.map(|e| format!("{e:.10e}")).unwrap_or_default(),
        p.converged,
        p.residual_norm,
        p.iterations
    )
}

fn run(a: &Args, out: &mut dyn Write) -> Result<(usize, usize), Box<dyn std::error::Error>> {
    let system = build_system(a)?;
    let (t0, t1) = default_periods(a.system);
    let options = BackboneOptions {
        grid: PeriodGrid {
            start: a.period_start.unwrap_or(t0),
            end: a.period_end.unwrap_or(t1),
            steps: a.steps,
        },
        mode: a.mode,
        ..Default::default()
    };
    let exact = a.system == SystemKind::Clamped && a.mode == 1;
    writeln!(
        out,
        "step,period,omega,energy,energy_normalized,exact_energy_normalized,converged,residual_norm,iterations"
    )?;
    let (mut total, mut converged) = (0, 0);
    let mut io_error = None;
    let mut observer = |p: &BackbonePoint| {
        total += 1;
        converged += usize::from(p.converged);
        let e = exact.then(|| ClampedFirstMode::new(a.gap, p.period).energy_normalized());
        match writeln!(out, "{}", csv_row(p, e)) {
            Ok(()) => ControlFlow::Continue(()),
            Err(err) => {
                io_error = Some(err);
                ControlFlow::Break(())
            }
        }
    };
    let solver: Box<dyn NonlinearSolver> = if a.dogleg {
        Box::new(Dogleg::default())
    } else {
        Box::new(SemismoothNewton::default())
    };
    backbone_with(&system, a.settings, &options, DynSolver(solver), &mut observer)?;
    if let Some(e) = io_error {
        return Err(e.into());
    }
    Ok((total, converged))
}

/// Lets a boxed solver stand where a generic one is expected.
struct DynSolver(Box<dyn NonlinearSolver>);

impl NonlinearSolver for DynSolver {
    fn solve(
        &self,
        problem: &mut dyn nonsmooth_modes::solve::Problem,
        x: &mut [f64],
    ) -> Result<nonsmooth_modes::solve::SolveInfo, nonsmooth_modes::SolveError> {
        self.0.solve(problem, x)
    }
    fn tolerance(&self, problem: &dyn nonsmooth_modes::solve::Problem) -> f64 {
        self.0.tolerance(problem)
    }
}

fn main() -> ExitCode {
    let args = match parse() {
        Ok(a) => a,
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
