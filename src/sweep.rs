//! Sweeps: many branches (modes, subharmonics, parameter values, harmonic counts) computed in
//! one call, in parallel with the `parallel` feature.
//!
//! Each [`SweepJob`] is one call of [`branches::compute`](crate::branches::compute): a system
//! and a request. The jobs are independent, so [`backbones`] runs them on rayon's thread pool
//! when the crate is built with `--features parallel`, and one after the other otherwise.
//! Every job is computed by the same sequential code either way (faer runs single-threaded,
//! FFT plans and scratch buffers are per basis and per thread), so the results are identical
//! bit for bit, in the order of the jobs.
//!
//! ```
//! use nonsmooth_modes::branches::{BackboneOptions, Method, PeriodGrid, Request};
//! use nonsmooth_modes::reference::clamped_bar_with_obstacle;
//! use nonsmooth_modes::sweep::{backbones, SweepJob};
//!
//! let system = clamped_bar_with_obstacle(1e-3)?;
//! let grid = PeriodGrid { start: 3.9, end: 3.8, steps: 3 };
//! let method = Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1));
//! // the same backbone at m = 8 and m = 16
//! let jobs: Vec<SweepJob> = [8, 16]
//!     .into_iter()
//!     .map(|m| SweepJob {
//!         system: system.clone(),
//!         request: Request::new(1).harmonics(m).method(method),
//!     })
//!     .collect();
//! let results = backbones(&jobs);
//! assert_eq!(results.len(), 2);
//! assert!(results.iter().all(|r| r.as_ref().is_ok_and(|run| run.points.len() == 3)));
//! # Ok::<(), nonsmooth_modes::Error>(())
//! ```

use crate::branches::{compute, ModeBranches, Request};
use crate::error::Error;
pub use crate::solve::Solver;
use crate::system::BarSystem;

/// One branch of a sweep: the arguments of [`compute`].
#[derive(Debug, Clone)]
pub struct SweepJob {
    /// The bar system.
    pub system: BarSystem,
    /// What to compute.
    pub request: Request,
}

impl SweepJob {
    /// Computes this job's branch (what [`backbones`] does for each job).
    ///
    /// # Errors
    /// See [`compute`].
    pub fn run(&self) -> Result<ModeBranches, Error> {
        compute(&self.system, &self.request)
    }
}

/// Computes every job's branch, in the order of `jobs`: in parallel on rayon's global
/// thread pool with the `parallel` feature, sequentially without it. Results do not depend on
/// the number of threads.
pub fn backbones(jobs: &[SweepJob]) -> Vec<Result<ModeBranches, Error>> {
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
pub fn backbones_serial(jobs: &[SweepJob]) -> Vec<Result<ModeBranches, Error>> {
    jobs.iter().map(SweepJob::run).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::branches::{BackboneOptions, Method, PeriodGrid};
    use crate::reference::{clamped_bar_with_obstacle, robin_bar_with_obstacle};
    use crate::solve::{Dogleg, DoglegOptions};

    fn grid(start: f64, end: f64, steps: usize) -> Method {
        let grid = PeriodGrid { start, end, steps };
        Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1))
    }

    fn jobs() -> Vec<SweepJob> {
        let clamped = clamped_bar_with_obstacle(1e-3).unwrap();
        let robin = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
        let on_grid = grid(3.95, 3.75, 21);
        let job = |system: &BarSystem, m: usize, method: Method| SweepJob {
            system: system.clone(),
            request: Request::new(1).harmonics(m).method(method),
        };
        let mut jobs: Vec<SweepJob> = [10, 20, 31]
            .into_iter()
            .map(|m| job(&clamped, m, on_grid))
            .collect();
        let mut dogleg = job(&clamped, 20, on_grid);
        dogleg.request.solver = Some(Solver::Dogleg(
            Dogleg::new(DoglegOptions::default()).unwrap(),
        ));
        jobs.push(dogleg);
        jobs.push(job(&robin, 12, grid(9.5, 8.5, 11)));
        // an invalid job: its error comes back in its slot
        jobs.push(job(&clamped, 0, on_grid));
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
                    assert_eq!(a.points.len(), b.points.len(), "job {k}");
                    for (p, q) in a.points.iter().zip(&b.points) {
                        assert_eq!(p.converged(), q.converged(), "job {k} step {}", p.step);
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
        let converged = swept[1].as_ref().unwrap().converged().count();
        assert!(converged >= 15, "{converged} of 21 converged");
    }

    /// A request without a solver runs the method's ([`Request::solver_for`]): the same
    /// points, bit for bit, as the request naming that solver.
    #[test]
    fn solver_choice_forwards() {
        let job = &jobs()[1];
        let mut named = job.clone();
        named.request.solver = Some(job.request.solver_for(&job.request.method).unwrap());
        let (implicit, explicit) = (job.run().unwrap(), named.run().unwrap());
        assert!(implicit.converged().count() >= 15);
        assert_eq!(implicit.points, explicit.points);
    }
}
