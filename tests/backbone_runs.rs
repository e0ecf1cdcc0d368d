//! A backbone run keeps everything it computed: a run that stalls returns its points, each
//! with its status, and the reason it ended.

use nonsmooth_modes::continuation::EndReason;
use nonsmooth_modes::modal::{backbone, BackboneOptions, PeriodGrid, PointStatus};
use nonsmooth_modes::reference::clamped_bar_with_obstacle;
use nonsmooth_modes::solve::SemismoothNewton;
use nonsmooth_modes::system::HarmonicBalanceSettings;
use nonsmooth_modes::{ContinuationError, Error, SettingsError};

/// A grid on which no branch can be entered is refused with what the start search tried,
/// not run as points at rest: the clamped bar on periods near `T = 9`, more than twice its
/// linear period, where no nonsmooth mode of the first family exists and no harmonic of the
/// truncated system resonates.
#[test]
fn a_grid_without_a_branch_is_refused_with_what_was_tried() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let options = BackboneOptions {
        grid: PeriodGrid {
            start: 9.1,
            end: 8.9,
            steps: 30,
        },
        ..Default::default()
    };
    let settings = HarmonicBalanceSettings {
        harmonics: 10,
        ..Default::default()
    };
    match backbone(&system, settings, &options, SemismoothNewton::default()) {
        Err(Error::Settings(SettingsError::StartNotFound {
            omega,
            up_to,
            attempts,
            at_rest,
            failed,
        })) => {
            assert!((omega - 2.0 * std::f64::consts::PI / 9.1).abs() < 1e-12);
            assert!(up_to > omega);
            assert!(attempts > 1);
            assert_eq!(at_rest + failed, attempts);
        }
        other => panic!("{other:?}"),
    }
}

/// A run that stalls returns every point it computed, each with its status, and ends with
/// `Stalled` after `max_consecutive_failures` failures: the clamped bar's first family on a
/// grid that runs past `T = 3`, where its energy `8 / (pi^2 (T - 3)^2)` blows up and the
/// family ends.
#[test]
fn a_stalled_run_keeps_its_points_and_says_why() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let options = BackboneOptions {
        grid: PeriodGrid {
            start: 3.5,
            end: 2.5,
            steps: 41,
        },
        max_consecutive_failures: 6,
        ..Default::default()
    };
    let settings = HarmonicBalanceSettings {
        harmonics: 10,
        ..Default::default()
    };
    let run = backbone(&system, settings, &options, SemismoothNewton::default()).unwrap();
    match (&run.end, run.error()) {
        (EndReason::Stalled { failures, .. }, Some(ContinuationError::Stalled { .. })) => {
            assert_eq!(*failures, 6);
        }
        other => panic!("{other:?}"),
    }
    assert!(run.converged().count() >= 5);
    assert!(run.points.len() < 41);
    for p in &run {
        assert_eq!(p.converged, p.status == PointStatus::Converged);
        assert!(p.x.iter().all(|v| v.is_finite()));
    }
    // The last points are the failures that stalled it.
    assert!(run.points.iter().rev().take(6).all(|p| !p.converged));
    assert!(run.grazing_energy > 0.0);
}

/// A run that completes says so; its statuses agree with `converged`, and the failed steps
/// of the clamped bar at m = 20 are solver failures carrying the solver's error.
#[test]
fn a_completed_run_reports_each_step_status() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let run = backbone(
        &system,
        HarmonicBalanceSettings::default(),
        &BackboneOptions::default(),
        SemismoothNewton::default(),
    )
    .unwrap();
    assert_eq!(run.end, EndReason::Completed);
    assert_eq!(run.error(), None);
    assert_eq!(run.len(), 181);
    for p in &run {
        assert_eq!(p.converged, p.status == PointStatus::Converged);
        if let PointStatus::SolverFailed(e) = &p.status {
            assert!(!e.to_string().is_empty());
        }
    }
    assert!(run.converged().count() >= 170);
}
