//! The system of the command line: a `--system` shorthand or an `--assembly` file, its
//! default period grid and the system at another value of a continued parameter.

use crate::args::{Args, Parameter};
use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::PeriodGrid;
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact,
};
use nonsmooth_modes::system::BarSystem;
use nonsmooth_modes::ModelError;

#[derive(Debug, Clone)]
pub enum SystemKind {
    Clamped,
    Robin,
    TwoBar,
    /// Read from `--assembly`.
    File(BarSystem),
}

/// Default period range: just below the linear period of the chosen mode down to a strongly
/// nonlinear period; the shorthands' fixed grids for their first mode, else the rule of the
/// header (`K T_i 79/80 -> K T_i 61/80`, `T_i` rounded to 6 significant digits).
pub fn default_periods(a: &Args) -> Result<(f64, f64), Box<dyn std::error::Error>> {
    if a.mode != 1 || a.subharmonic != 1 {
        let system = build_system(a, Parameter::Omega, f64::NAN)?;
        let grid = PeriodGrid::for_mode(&system, a.mode, a.subharmonic)?;
        return Ok((grid.start, grid.end));
    }
    Ok(match &a.system {
        SystemKind::Clamped => (3.95, 3.05),
        // Robin k = 0.5: omega_1 = 0.653271, T_1 = 9.618
        SystemKind::Robin => (9.5, 6.0),
        // bar 1 clamped-free: T_1 = 4
        SystemKind::TwoBar => (3.95, 3.05),
        SystemKind::File(system) => {
            let grid = PeriodGrid::for_mode(system, a.mode, a.subharmonic)?;
            (grid.start, grid.end)
        }
    })
}

/// The gap of the clamped bar with obstacle if `system` is that system (the same bars and the
/// same conditions, compared by their names, which carry their ends and values): its exact
/// first mode is then known.
pub fn clamped_gap(system: &BarSystem) -> Option<f64> {
    let gap = system.laws().next()?.gap().offset;
    let reference = clamped_bar_with_obstacle(gap).ok()?;
    let names = |s: &BarSystem| s.conditions().map(|c| c.name()).collect::<Vec<_>>();
    (system.bars() == reference.bars() && names(system) == names(&reference)).then_some(gap)
}

/// The system of the file at `path`.
#[cfg(feature = "serde")]
pub fn load_assembly(path: &str) -> Result<BarSystem, lexopt::Error> {
    nonsmooth_modes::io::assembly::Assembly::from_path(path)
        .map(|assembly| assembly.into_system())
        .map_err(|e| format!("--assembly {path}: {e}").into())
}

/// Without the `serde` feature (on by default, off with `--no-default-features`) there is no
/// file parser: the flag is refused with the command that has one.
#[cfg(not(feature = "serde"))]
pub fn load_assembly(path: &str) -> Result<BarSystem, lexopt::Error> {
    Err(format!(
        "--assembly needs the default feature `serde`, which this build leaves out: \
         cargo run --release --example backbone -- --assembly {path}"
    )
    .into())
}

/// The system of the command line with `parameter` set to `value` (the other flags fixed).
pub fn build_system(a: &Args, parameter: Parameter, value: f64) -> Result<BarSystem, ModelError> {
    let mut a = a.clone();
    match parameter {
        Parameter::Omega | Parameter::Energy => {}
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

pub fn parameter_value(a: &Args, parameter: Parameter) -> f64 {
    match parameter {
        Parameter::Omega | Parameter::Energy => f64::NAN,
        Parameter::Gap => a.gap,
        Parameter::RobinStiffness => a.robin_stiffness,
        Parameter::StiffnessRatio => a.stiffness_ratio,
    }
}
