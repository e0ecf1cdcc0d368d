//! Genuine subharmonics: the subspace of the multiples of `K` is invariant (the Jacobian at a
//! point of it is block diagonal), and a point of the `K`-fold repeated branch can be left
//! along the complement block's most singular direction.

use nonsmooth_modes::branches::{
    compute, linear_period, symmetry_breaking_direction, BackboneOptions, Method, PeriodGrid,
    PointStatus, Request, GENUINE_SHARE,
};
use nonsmooth_modes::continuation::ContinuationProblem;
use nonsmooth_modes::fourier::Basis;
use nonsmooth_modes::linalg::DenseMatrix;
use nonsmooth_modes::modal::{branch_seed, subharmonic_share};
use nonsmooth_modes::reference::robin_bar_with_obstacle;
use nonsmooth_modes::solve::{Problem, Solver};
use nonsmooth_modes::system::{HarmonicBalanceSettings, NonsmoothSystem};
use std::f64::consts::PI;
use std::ops::ControlFlow;

const K: usize = 3;

fn settings(harmonics: usize) -> HarmonicBalanceSettings {
    HarmonicBalanceSettings {
        harmonics,
        ..Default::default()
    }
}

/// At a point of the subspace of the multiples of `K` (a penetrating seed of NSM 2 sub 3 of
/// the Robin bar, so that the law is active at some samples), the Jacobian has no entry
/// between the multiples of `K` and the other harmonics, in either direction.
#[test]
fn the_multiples_of_k_are_an_invariant_subspace() {
    let system = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
    let mut problem = NonsmoothSystem::new(&system, settings(12)).unwrap();
    let omega = 2.0 * PI / (0.98 * linear_period(&system, 2, K).unwrap());
    let seed: Vec<f64> = branch_seed(&mut problem, 2, K, omega)
        .unwrap()
        .iter()
        .map(|v| 1.3 * v)
        .collect();
    problem.set_parameter(omega);
    let n = problem.dimension();
    let mut f = vec![0.0; n];
    problem.residual(&seed, &mut f);
    let mut jac = DenseMatrix::zeros(n, n);
    problem.jacobian(&seed, &mut jac);
    let per = system.unknowns_per_harmonic();
    let laws = system.contact_count();
    let linear = per - laws;
    let len = problem.basis().len();
    let harmonic_of_row = |r: usize| {
        if r < len * linear {
            r / linear
        } else {
            (r - len * linear) % len
        }
    };
    let (mut coupling, mut size) = (0.0f64, 0.0f64);
    for r in 0..n {
        for c in 0..n {
            let (hr, hc) = (harmonic_of_row(r) % K == 0, (c / per) % K == 0);
            size = size.max(jac[(r, c)].abs());
            if hr != hc {
                coupling = coupling.max(jac[(r, c)].abs());
            }
        }
    }
    assert!(size > 0.0);
    assert!(
        coupling <= 1e-12 * size,
        "coupling {coupling:e} of {size:e}"
    );
    // The direction leaves the subspace: zero on its multiples of K, nonzero off them.
    let (direction, measure) = symmetry_breaking_direction(&mut problem, &seed, omega, K).unwrap();
    assert!(measure.is_finite() && measure >= 0.0);
    for (j, d) in direction.iter().enumerate() {
        if (j / per) % K == 0 {
            assert_eq!(*d, 0.0);
        }
    }
    assert!(direction.iter().any(|d| d.abs() == 1.0));
    assert!(symmetry_breaking_direction(&mut problem, &seed, omega, 1).is_none());
}

/// NSM 2 sub 3 of the Robin bar at `m = 30`: the run leaves the repeated branch, and every
/// converged point after the switch has at least `GENUINE_SHARE` of its energy off the
/// multiples of 3, recomputed here from its unknowns.
#[test]
fn nsm2_sub3_of_the_robin_bar_leaves_the_repeated_branch() {
    let system = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
    let grid = PeriodGrid {
        steps: 30,
        ..PeriodGrid::for_mode(&system, 2, K).unwrap()
    };
    let options = BackboneOptions::on_grid(grid, 2, K);
    let problem = NonsmoothSystem::new(&system, settings(30)).unwrap();
    let request = Request {
        settings: settings(30),
        method: Method::GenuineSubharmonic(options),
        solver: Some(Solver::default()),
        ..Request::new(2).subharmonic(K)
    };
    let points = compute(&system, &request).unwrap().points;
    let share = |p: &nonsmooth_modes::branches::BackbonePoint| {
        subharmonic_share(&system, problem.basis(), &p.x, p.omega, K).unwrap()
    };
    let genuine: Vec<_> = points
        .iter()
        .filter(|p| p.status == PointStatus::Converged && share(p) >= GENUINE_SHARE)
        .collect();
    assert!(genuine.len() >= 5, "{} genuine points", genuine.len());
    let first = points
        .iter()
        .position(|p| share(p) >= GENUINE_SHARE)
        .unwrap();
    for p in &points[first..] {
        if p.converged() {
            assert!(share(p) >= GENUINE_SHARE, "step {}: {}", p.step, share(p));
        }
    }
    // Before the switch, the branch is the repeated one.
    for p in points[..first].iter().filter(|p| p.converged()) {
        assert!(share(p) < 1e-10, "step {}: {}", p.step, share(p));
    }
}

/// The arclength backbone of NSM 2 sub 3 reports branch points on the repeated branch, and
/// switching at the first one leaves the subspace of the multiples of `K`: the points before
/// the switch are the repeated branch (share below 1e-9), some after it are genuinely
/// subharmonic (share above `GENUINE_SHARE`), and none sits at rest. A branch point the run
/// never reaches leaves the run as it is without a switch; a bad request is refused.
#[test]
fn switching_at_a_branch_point_of_the_repeated_branch_leaves_the_subspace() {
    use nonsmooth_modes::branches::{ArclengthBackboneOptions, SwitchAt};
    use nonsmooth_modes::continuation::{EndReason, Event};
    use nonsmooth_modes::{ContinuationError, Error};
    let system = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
    let run = |switch: Option<SwitchAt>| {
        let options = ArclengthBackboneOptions::for_mode(&system, 2, K).unwrap();
        let method = match switch {
            Some(at) => Method::Switch(options, at),
            None => Method::Arclength(options),
        };
        let request = Request {
            settings: settings(40),
            method,
            solver: Some(Solver::default()),
            ..Request::new(2).subharmonic(K)
        };
        let mut points = Vec::new();
        let observer = |p: &nonsmooth_modes::branches::BackbonePoint| {
            points.push(p.clone());
            ControlFlow::Continue(())
        };
        let result = nonsmooth_modes::branches::compute_observed(&system, &request, observer);
        result.map(|run| (points, run))
    };
    let problem = NonsmoothSystem::new(&system, settings(40)).unwrap();
    let basis = problem.basis().clone();
    let share = |p: &nonsmooth_modes::branches::BackbonePoint| {
        subharmonic_share(&system, &basis, &p.x, p.omega, K).unwrap()
    };
    let (points, branch) = run(Some(SwitchAt {
        branch_point: 1,
        side: 1.0,
    }))
    .unwrap();
    assert_eq!(points, branch.points);
    let at = points
        .iter()
        .position(|p| {
            p.events
                .iter()
                .any(|e| matches!(e, Event::BranchPoint { .. }))
        })
        .expect("a branch point");
    assert!(points[..=at].iter().all(|p| share(p) < 1e-9));
    let genuine = points[at + 1..]
        .iter()
        .filter(|p| share(p) > GENUINE_SHARE)
        .count();
    assert!(genuine >= 10, "{genuine} genuinely subharmonic points");
    assert_eq!(points[at + 1].step, points[at].step + 1);
    assert!(points.iter().all(|p| p.energy_normalized > 1.0));

    let (plain, _) = run(None).unwrap();
    let (unreached, unreached_branch) = run(Some(SwitchAt {
        branch_point: 1000,
        side: -1.0,
    }))
    .unwrap();
    assert!(!matches!(
        unreached_branch.end,
        EndReason::SwitchFailed { .. }
    ));
    assert_eq!(plain.len(), unreached.len());
    assert!(plain.iter().zip(&unreached).all(|(a, b)| a.x == b.x));
    assert!(matches!(
        run(Some(SwitchAt {
            branch_point: 0,
            side: 1.0
        })),
        Err(Error::Continuation(ContinuationError::InvalidOption { .. }))
    ));
}
