//! A backbone point continued in a system parameter with `branches::parameter_branch`: the gap of
//! the clamped bar, where the truncated problem is positively homogeneous
//! (`x(s g0) = s x(g0)`, so `E / g0^2` and `E / E_g` stay constant along the branch).

use nonsmooth_modes::branches::{
    compute, parameter_branch, BackboneOptions, BackbonePoint, Method, ParameterSteps, PeriodGrid,
    Request,
};
use nonsmooth_modes::continuation::{ArclengthOptions, EndReason, SequentialOptions};
use nonsmooth_modes::reference::clamped_bar_with_obstacle;
use nonsmooth_modes::solve::{SemismoothNewton, Solver};
use nonsmooth_modes::system::HarmonicBalanceSettings;
use nonsmooth_modes::Error;
use std::ops::ControlFlow;

/// The points of the clamped bar's first mode on `grid`, with the full semismooth Newton.
fn grid_points(settings: HarmonicBalanceSettings, grid: PeriodGrid) -> Vec<BackbonePoint> {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let request = Request {
        settings,
        method: Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)),
        solver: Some(Solver::default()),
        ..Request::new(1)
    };
    compute(&system, &request).unwrap().points
}

/// A converged point of the clamped bar's first mode near `T = 3.8`.
fn start(settings: HarmonicBalanceSettings) -> BackbonePoint {
    let grid = PeriodGrid {
        start: 3.95,
        end: 3.8,
        steps: 31,
    };
    let points = grid_points(settings, grid);
    points.into_iter().rev().find(|p| p.converged()).unwrap()
}

#[test]
fn gap_branches_keep_the_normalised_energy() {
    let settings = HarmonicBalanceSettings::default();
    let from = start(settings);
    let values: Vec<f64> = (0..9).map(|i| 1e-3 * (1.0 + 0.25 * i as f64)).collect();
    for steps in [
        ParameterSteps::Values(values.clone(), SequentialOptions::default()),
        ParameterSteps::Arclength(ArclengthOptions {
            parameter_range: (5e-4, 3e-3),
            ..Default::default()
        }),
    ] {
        let arclength = matches!(steps, ParameterSteps::Arclength(_));
        let mut seen = Vec::new();
        let branch = parameter_branch(
            clamped_bar_with_obstacle,
            settings,
            (from.x.clone(), from.omega),
            1e-3,
            steps,
            SemismoothNewton::default(),
            |gap, p| {
                seen.push((gap, p.clone()));
                ControlFlow::Continue(())
            },
        )
        .unwrap();
        if arclength {
            assert!(matches!(branch.end, EndReason::ParameterOutOfRange { .. }));
        } else {
            assert_eq!(branch.end, EndReason::Completed);
            assert_eq!(seen.len(), values.len());
        }
        assert!(seen.len() > 5);
        assert_eq!(
            seen.len(),
            branch.points.len() + branch.rejections * usize::from(!arclength)
        );
        for (gap, p) in &seen {
            assert!(p.converged());
            assert_eq!(p.omega, from.omega);
            assert!(
                (p.energy_normalized / from.energy_normalized - 1.0).abs() < 1e-8,
                "gap {gap}: {} vs {}",
                p.energy_normalized,
                from.energy_normalized
            );
            assert!((p.energy / (gap * gap) / (from.energy / 1e-6) - 1.0).abs() < 1e-8);
        }
        assert!(seen.iter().any(|(gap, _)| *gap > 2.5e-3));
    }
}

#[test]
fn bad_starts_are_typed_errors() {
    let settings = HarmonicBalanceSettings {
        harmonics: 8,
        ..Default::default()
    };
    let from = start(settings);
    let run = |value: f64, steps| {
        parameter_branch(
            clamped_bar_with_obstacle,
            settings,
            (from.x.clone(), from.omega),
            value,
            steps,
            SemismoothNewton::default(),
            |_, _| ControlFlow::Continue(()),
        )
    };
    // A gap the family rejects, values that do not start at the start's, a short start.
    assert!(matches!(
        run(
            -1.0,
            ParameterSteps::Values(vec![-1.0, 1.0], SequentialOptions::default())
        ),
        Err(Error::Model(_))
    ));
    assert!(matches!(
        run(
            1e-3,
            ParameterSteps::Values(vec![2e-3, 3e-3], SequentialOptions::default())
        ),
        Err(Error::Continuation(_))
    ));
    let short = parameter_branch(
        clamped_bar_with_obstacle,
        settings,
        (from.x[1..].to_vec(), from.omega),
        1e-3,
        ParameterSteps::Arclength(ArclengthOptions::default()),
        SemismoothNewton::default(),
        |_, _| ControlFlow::Continue(()),
    );
    assert!(matches!(short, Err(Error::Continuation(_))));
}

/// Steps too coarse for the branch slide to the state of rest (at `T = 3.95`, gap from `1e-3`
/// to `1e-2` in 5 values): those points reach the observer as collapsed to rest, never as
/// converged points of the branch, and every converged point is above the trivial-energy floor.
#[test]
fn a_gap_branch_that_slides_to_rest_reports_it() {
    use nonsmooth_modes::branches::PointStatus;
    let settings = HarmonicBalanceSettings::default();
    let grid = PeriodGrid {
        start: 3.96,
        end: 3.95,
        steps: 2,
    };
    let from = grid_points(settings, grid)
        .into_iter()
        .rev()
        .find(|p| p.converged())
        .unwrap();
    let values: Vec<f64> = (0..5).map(|i| 1e-3 + 2.25e-3 * i as f64).collect();
    let mut seen = Vec::new();
    parameter_branch(
        clamped_bar_with_obstacle,
        settings,
        (from.x.clone(), from.omega),
        1e-3,
        ParameterSteps::Values(values, SequentialOptions::default()),
        SemismoothNewton::default(),
        |_, p| {
            seen.push(p.clone());
            ControlFlow::Continue(())
        },
    )
    .unwrap();
    assert_eq!(seen.len(), 5);
    let collapsed = seen
        .iter()
        .filter(|p| p.status == PointStatus::CollapsedToRest)
        .count();
    assert!(
        collapsed >= 1,
        "{:?}",
        seen.iter().map(|p| p.energy_normalized).collect::<Vec<_>>()
    );
    for p in &seen {
        assert_eq!(p.converged(), p.status == PointStatus::Converged);
        if p.converged() {
            assert!(p.energy_normalized > 1e-6, "{}", p.energy_normalized);
        }
    }
}
