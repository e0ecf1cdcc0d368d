//! A backbone run keeps everything it computed: a run that stalls returns its points, each
//! with its status, and the reason it ended.

use nonsmooth_modes::continuation::EndReason;
use nonsmooth_modes::modal::{backbone, BackboneOptions, PeriodGrid, PointStatus};
use nonsmooth_modes::reference::clamped_bar_with_obstacle;
use nonsmooth_modes::solve::SemismoothNewton;
use nonsmooth_modes::system::HarmonicBalanceSettings;
use nonsmooth_modes::ContinuationError;

/// A run that stalls returns every point it computed with a status that is not `Converged`,
/// and ends with `Stalled` after `max_consecutive_failures` failures: the clamped bar on
/// periods near `T = 9`, more than twice its linear period, where no nonsmooth mode of the
/// first family exists and no harmonic of the truncated system resonates, so every step
/// collapses to rest.
#[test]
fn a_stalled_run_keeps_its_points_and_says_why() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let options = BackboneOptions {
        grid: PeriodGrid {
            start: 9.1,
            end: 8.9,
            steps: 30,
        },
        max_consecutive_failures: 12,
        ..Default::default()
    };
    let settings = HarmonicBalanceSettings {
        harmonics: 10,
        ..Default::default()
    };
    let run = backbone(&system, settings, &options, SemismoothNewton::default()).unwrap();
    match (&run.end, run.error()) {
        (EndReason::Stalled { failures, .. }, Some(ContinuationError::Stalled { .. })) => {
            assert_eq!(*failures, 12);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(run.points.len(), 12);
    assert_eq!(run.converged().count(), 0);
    for p in &run {
        assert!(!p.converged);
        assert_ne!(p.status, PointStatus::Converged);
        assert!(p.x.iter().all(|v| v.is_finite()));
    }
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
