//! Sweeps: many backbones (modes, subharmonics, parameter values, harmonic counts) computed in
//! one call, in parallel with the `parallel` feature.
//!
//! Each [`SweepJob`] is one call of [`branches::backbone`](fn@crate::branches::backbone): a system,
//! harmonic-balance settings, backbone options and a solver. The jobs are independent, so
//! [`backbones`] runs them on rayon's thread pool when the crate is built with
//! `--features parallel`, and one after the other otherwise. Every job is computed by the same
//! sequential code either way (faer runs single-threaded, FFT plans and scratch buffers are
//! per basis and per thread), so the results are identical bit for bit, in the order of the
//! jobs.
//!
//! ```
//! use nonsmooth_modes::modal::{BackboneOptions, PeriodGrid};
//! use nonsmooth_modes::reference::clamped_bar_with_obstacle;
//! use nonsmooth_modes::sweep::{backbones, Solver, SweepJob};
//! use nonsmooth_modes::system::HarmonicBalanceSettings;
//!
//! let system = clamped_bar_with_obstacle(1e-3)?;
//! let options = BackboneOptions {
//!     grid: PeriodGrid { start: 3.9, end: 3.8, steps: 3 },
//!     ..Default::default()
//! };
//! // the same backbone at m = 8 and m = 16
//! let jobs: Vec<SweepJob> = [8, 16]
//!     .into_iter()
//!     .map(|m| SweepJob {
//!         system: system.clone(),
//!         settings: HarmonicBalanceSettings { harmonics: m, ..Default::default() },
//!         options,
//!         solver: Solver::default(),
//!     })
//!     .collect();
//! let results = backbones(&jobs);
//! assert_eq!(results.len(), 2);
//! assert!(results.iter().all(|r| r.as_ref().is_ok_and(|points| points.len() == 3)));
//! # Ok::<(), nonsmooth_modes::Error>(())
//! ```

use crate::branches::{backbone, Backbone, BackboneOptions};
use crate::error::{Error, SolveError};
use crate::solve::{Dogleg, NonlinearSolver, Problem, SemismoothNewton, SolveInfo, SolveMonitor};
use crate::system::{BarSystem, HarmonicBalanceSettings};

/// A solver chosen per job (so that one sweep can mix solvers).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Solver {
    /// [`SemismoothNewton`] (the default).
    Newton(SemismoothNewton),
    /// Powell's [`Dogleg`].
    Dogleg(Dogleg),
}

impl Default for Solver {
    fn default() -> Self {
        Self::Newton(SemismoothNewton::default())
    }
}

impl NonlinearSolver for Solver {
    fn solve_monitored(
        &self,
        problem: &mut dyn Problem,
        x: &mut [f64],
        monitor: &mut dyn SolveMonitor,
    ) -> Result<SolveInfo, SolveError> {
        match self {
            Self::Newton(s) => s.solve_monitored(problem, x, monitor),
            Self::Dogleg(s) => s.solve_monitored(problem, x, monitor),
        }
    }

    fn tolerance(&self, problem: &mut dyn Problem) -> f64 {
        match self {
            Self::Newton(s) => s.tolerance(problem),
            Self::Dogleg(s) => s.tolerance(problem),
        }
    }
}

/// One backbone of a sweep: the arguments of [`branches::backbone`](fn@crate::branches::backbone).
#[derive(Debug, Clone)]
pub struct SweepJob<S = Solver> {
    /// The bar system.
    pub system: BarSystem,
    /// Harmonic-balance settings (harmonics, samples, complementarity parameter).
    pub settings: HarmonicBalanceSettings,
    /// Period grid, mode, subharmonic, predictor, failure budget.
    pub options: BackboneOptions,
    /// The nonlinear solver (cloned for the run).
    pub solver: S,
}

impl<S: NonlinearSolver + Clone> SweepJob<S> {
    /// Computes this job's backbone (what [`backbones`] does for each job).
    ///
    /// # Errors
    /// See [`branches::backbone`](fn@crate::branches::backbone).
    pub fn run(&self) -> Result<Backbone, Error> {
        backbone(
            &self.system,
            self.settings,
            &self.options,
            self.solver.clone(),
        )
    }
}

/// Computes every job's backbone, in the order of `jobs`: in parallel on rayon's global
/// thread pool with the `parallel` feature, sequentially without it. Results do not depend on
/// the number of threads.
pub fn backbones<S>(jobs: &[SweepJob<S>]) -> Vec<Result<Backbone, Error>>
where
    S: NonlinearSolver + Clone + Send + Sync,
{
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        jobs.par_iter().map(SweepJob::run).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        jobs.iter().map(SweepJob::run).collect()
    }
}

/// [`backbones`] one job after the other on the calling thread, whatever the features (the
/// reference the parallel sweep is checked against).
pub fn backbones_serial<S>(jobs: &[SweepJob<S>]) -> Vec<Result<Backbone, Error>>
where
    S: NonlinearSolver + Clone,
{
    jobs.iter().map(SweepJob::run).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::branches::PeriodGrid;
    use crate::reference::{clamped_bar_with_obstacle, robin_bar_with_obstacle};
    use crate::solve::DoglegOptions;

    fn jobs() -> Vec<SweepJob> {
        let clamped = clamped_bar_with_obstacle(1e-3).unwrap();
        let robin = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
        let grid = PeriodGrid {
            start: 3.95,
            end: 3.75,
            steps: 21,
        };
        let mut jobs = Vec::new();
        for m in [10, 20, 31] {
            jobs.push(SweepJob {
                system: clamped.clone(),
                settings: HarmonicBalanceSettings {
                    harmonics: m,
                    ..Default::default()
                },
                options: BackboneOptions {
                    grid,
                    ..Default::default()
                },
                solver: Solver::default(),
            });
        }
        jobs.push(SweepJob {
            system: clamped.clone(),
            settings: HarmonicBalanceSettings::default(),
            options: BackboneOptions {
                grid,
                ..Default::default()
            },
            solver: Solver::Dogleg(Dogleg::new(DoglegOptions::default()).unwrap()),
        });
        jobs.push(SweepJob {
            system: robin,
            settings: HarmonicBalanceSettings {
                harmonics: 12,
                ..Default::default()
            },
            options: BackboneOptions {
                grid: PeriodGrid {
                    start: 9.5,
                    end: 8.5,
                    steps: 11,
                },
                ..Default::default()
            },
            solver: Solver::default(),
        });
        // an invalid job: its error comes back in its slot
        jobs.push(SweepJob {
            system: clamped,
            settings: HarmonicBalanceSettings {
                harmonics: 0,
                ..Default::default()
            },
            options: BackboneOptions::default(),
            solver: Solver::default(),
        });
        jobs
    }

    #[test]
    fn sweep_equals_serial_runs_bit_for_bit() {
        let jobs = jobs();
        let swept = backbones(&jobs);
        let serial = backbones_serial(&jobs);
        assert_eq!(swept.len(), jobs.len());
        for (k, (a, b)) in swept.iter().zip(&serial).enumerate() {
            match (a, b) {
                (Ok(a), Ok(b)) => {
                    assert_eq!(a.len(), b.len(), "job {k}");
                    for (p, q) in a.iter().zip(b) {
                        assert_eq!(p.converged, q.converged, "job {k} step {}", p.step);
                        assert_eq!(p.energy.to_bits(), q.energy.to_bits(), "job {k}");
                        assert_eq!(p.residual_norm.to_bits(), q.residual_norm.to_bits());
                        assert!(p
                            .x
                            .iter()
                            .zip(&q.x)
                            .all(|(u, v)| u.to_bits() == v.to_bits()));
                        assert_eq!(p, q);
                    }
                }
                (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
                _ => panic!("job {k}: sweep and serial run disagree on success"),
            }
        }
        assert!(swept[..5].iter().all(Result::is_ok));
        assert!(swept[5].is_err());
        // the jobs did real work: most steps of the clamped backbones converge
        let converged = swept[1]
            .as_ref()
            .unwrap()
            .iter()
            .filter(|p| p.converged)
            .count();
        assert!(converged >= 15, "{converged} of 21 converged");
    }

    #[test]
    fn solver_choice_forwards() {
        let job = &jobs()[3];
        let direct = backbone(
            &job.system,
            job.settings,
            &job.options,
            Dogleg::new(DoglegOptions::default()).unwrap(),
        )
        .unwrap();
        assert_eq!(job.run().unwrap(), direct);
    }
}
