//! The same point of a backbone recomputed for several numbers of harmonics `m`.

use crate::branches::backbone::{backbone, BackboneOptions, PeriodGrid};
use crate::branches::point::BackbonePoint;
use crate::error::Error;
use crate::modal::diagnostics::{diagnose, PointDiagnostics};
use crate::solve::NonlinearSolver;
use crate::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};

/// One entry of a convergence study.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ConvergenceEntry {
    /// Number of harmonics.
    pub harmonics: usize,
    /// The last converged point of the run at this `m` (None if none converged).
    pub point: Option<BackbonePoint>,
    /// Its diagnostics.
    pub diagnostics: Option<PointDiagnostics>,
}

/// The same point recomputed for each `m` in `harmonics`: a sequential backbone over `grid`
/// (whose last period is the point of interest) for each `m`, keeping the last converged point
/// and its diagnostics (refinement 8).
///
/// # Errors
/// Invalid settings or options (the first `m` that fails to set up).
pub fn convergence_study<S: NonlinearSolver + Clone>(
    system: &BarSystem,
    base: HarmonicBalanceSettings,
    grid: PeriodGrid,
    harmonics: &[usize],
    solver: S,
) -> Result<Vec<ConvergenceEntry>, Error> {
    let mut out = Vec::new();
    for &m in harmonics {
        let settings = HarmonicBalanceSettings {
            harmonics: m,
            ..base
        };
        let options = BackboneOptions::on_grid(grid, 1, 1);
        let points = backbone(system, settings, &options, solver.clone())?;
        let point = points.into_iter().rev().find(|p| p.converged);
        let diagnostics = match &point {
            Some(p) => {
                let problem = NonsmoothSystem::new(system, settings)?;
                Some(diagnose(&problem, &p.x, p.omega, 8)?)
            }
            None => None,
        };
        out.push(ConvergenceEntry {
            harmonics: m,
            point,
            diagnostics,
        });
    }
    Ok(out)
}
