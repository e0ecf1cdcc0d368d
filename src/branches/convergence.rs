//! The same request run for several numbers of harmonics `m`.

use crate::branches::compute::compute;
use crate::branches::request::Request;
use crate::branches::result::ModeBranches;
use crate::error::{Error, SettingsError};
use crate::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};

/// The run of `request` on `system` once for each number of harmonics in `harmonics`, in
/// that order: the convergence of a branch, or of one of its points, in `m`.
///
/// Each entry is what [`compute`] returns for `request` with
/// [`settings.harmonics`](crate::system::HarmonicBalanceSettings::harmonics) set to that
/// `m` (everything else as asked: mode, order, method, check, stability), so it is read as
/// any run is. The point of interest is usually the last converged one of a period grid
/// that ends on it (`run.converged().last()`), and
/// [`diagnose`](crate::modal::diagnose) on
/// [`ModeBranches::problem`] gives its residual and penetration at a finer sampling.
///
/// # Errors
/// [`SettingsError::Length`] for an empty `harmonics`, and the set-up error of the first
/// `m` the system cannot be discretised with (checked for every `m` before any run, so that
/// no run is computed and then dropped); then the first error of [`compute`].
pub fn convergence_study(
    system: &BarSystem,
    request: &Request,
    harmonics: &[usize],
) -> Result<Vec<ModeBranches>, Error> {
    if harmonics.is_empty() {
        return Err(SettingsError::Length {
            what: "numbers of harmonics of a convergence study",
            got: 0,
            expected: 1,
        }
        .into());
    }
    for &m in harmonics {
        let settings = HarmonicBalanceSettings {
            harmonics: m,
            ..request.settings
        };
        NonsmoothSystem::new(system, settings)?;
    }
    harmonics
        .iter()
        .map(|&m| compute(system, &request.clone().harmonics(m)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::branches::{BackboneOptions, Method, PeriodGrid};
    use crate::fourier::Basis;
    use crate::reference::clamped_bar_with_obstacle;

    fn request() -> Request {
        let grid = PeriodGrid {
            start: 3.9,
            end: 3.8,
            steps: 3,
        };
        Request::for_method(Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)))
    }

    /// One run per `m`, in order, each what `compute` gives for that `m`.
    #[test]
    fn each_entry_is_the_request_at_its_harmonics() {
        let system = clamped_bar_with_obstacle(1e-3).unwrap();
        let study = convergence_study(&system, &request(), &[6, 10]).unwrap();
        assert_eq!(study.len(), 2);
        for (run, m) in study.iter().zip([6, 10]) {
            assert_eq!(run.problem().basis().harmonics(), m);
            let alone = compute(&system, &request().harmonics(m)).unwrap();
            assert_eq!(run.points, alone.points);
            assert!(run.converged().count() >= 2, "m = {m}: {:?}", run.end);
        }
    }

    /// An empty list, or one `m` the system cannot be set up with, is refused before any
    /// run, quoting what was given.
    #[test]
    fn bad_lists_are_refused_before_any_run() {
        let system = clamped_bar_with_obstacle(1e-3).unwrap();
        let empty = convergence_study(&system, &request(), &[]).unwrap_err();
        assert!(empty.to_string().contains("convergence study"), "{empty}");
        let zero = convergence_study(&system, &request(), &[10, 0]).unwrap_err();
        let alone = NonsmoothSystem::new(
            &system,
            HarmonicBalanceSettings {
                harmonics: 0,
                ..request().settings
            },
        )
        .unwrap_err();
        assert_eq!(zero.to_string(), alone.to_string());
    }
}
