//! Criterion benchmarks of the harmonic-balance hot path on the clamped bar with an obstacle
//! (gap `1e-3`, `n_h = 30`): residual, generalised Jacobian, one continuation step's solve,
//! whole 181-step backbones at `m = 20, 40, 80` (serial and with speculative retries), a
//! sweep of backbones (parallel with `--features parallel`), and the closed-form energy of a
//! point.
//!
//! ```text
//! cargo bench --bench harmonic_balance                       # everything
//! cargo bench --bench harmonic_balance -- residual           # one group
//! cargo bench --features parallel --bench harmonic_balance -- sweep
//! ```

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nonsmooth_modes::branches::{
    compute, BackboneOptions, BackbonePoint, Method, ModeBranches, PeriodGrid, Request,
};
use nonsmooth_modes::continuation::{ContinuationProblem, Speculation};
use nonsmooth_modes::fourier::CosineBasis;
use nonsmooth_modes::linalg::DenseMatrix;
use nonsmooth_modes::modal::{energy, energy_at};
use nonsmooth_modes::reference::clamped_bar_with_obstacle;
use nonsmooth_modes::solve::Solver;
use nonsmooth_modes::solve::{NewtonOptions, NonlinearSolver, Problem, SemismoothNewton};
use nonsmooth_modes::sweep::{backbones, backbones_serial, SweepJob};
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};
use std::hint::black_box;
use std::time::Duration;

const GAP: f64 = 1e-3;

fn settings(m: usize) -> HarmonicBalanceSettings {
    HarmonicBalanceSettings {
        harmonics: m,
        ..Default::default()
    }
}

/// The backbone example's grid: 181 periods from 3.95 down to 3.05.
fn full_grid() -> BackboneOptions {
    let grid = PeriodGrid {
        start: 3.95,
        end: 3.05,
        steps: 181,
    };
    BackboneOptions::on_grid(grid, 1, 1)
}

/// The period-grid request of `options` at `m` harmonics with `solver`.
fn grid_request(m: usize, options: BackboneOptions, solver: Solver) -> Request {
    Request {
        settings: settings(m),
        method: Method::PeriodGrid(options),
        solver: Some(solver),
        ..Request::new(options.mode)
    }
}

/// The period-grid run of `options` on `system` at `m` harmonics with `solver`.
fn grid_run(
    system: &BarSystem,
    m: usize,
    options: BackboneOptions,
    solver: Solver,
) -> ModeBranches {
    compute(system, &grid_request(m, options, solver)).expect("a backbone")
}

/// The last two points of the backbone from `T = 3.95` to `3.9` at `m` harmonics (a state
/// near the branch for the residual and Jacobian benches; consecutive converged points for
/// the solve bench, at the `m` where there are two).
fn two_points(system: &BarSystem, m: usize) -> (BackbonePoint, BackbonePoint) {
    let grid = PeriodGrid {
        start: 3.95,
        end: 3.9,
        steps: 11,
    };
    let options = BackboneOptions::on_grid(grid, 1, 1);
    let points = grid_run(system, m, options, Solver::default());
    let converged: Vec<_> = points.converged().cloned().collect();
    let pick = if converged.len() >= 2 {
        &converged
    } else {
        &points.points
    };
    let n = pick.len();
    (pick[n - 2].clone(), pick[n - 1].clone())
}

fn residual_and_jacobian(c: &mut Criterion) {
    let system = clamped_bar_with_obstacle(GAP).unwrap();
    let mut residual = c.benchmark_group("residual");
    for m in [20, 80, 320] {
        let (_, p) = two_points(&system, m);
        let mut problem = NonsmoothSystem::new(&system, settings(m)).unwrap();
        let mut f = vec![0.0; problem.dimension()];
        problem.set_parameter(p.omega);
        residual.bench_with_input(BenchmarkId::from_parameter(m), &p, |b, p| {
            b.iter(|| problem.residual(black_box(&p.x), &mut f));
        });
    }
    residual.finish();
    let mut jacobian = c.benchmark_group("jacobian");
    for m in [20, 80, 320] {
        let (_, p) = two_points(&system, m);
        let mut problem = NonsmoothSystem::new(&system, settings(m)).unwrap();
        let mut jac = DenseMatrix::zeros(0, 0);
        problem.set_parameter(p.omega);
        jacobian.bench_with_input(BenchmarkId::from_parameter(m), &p, |b, p| {
            b.iter(|| problem.jacobian(black_box(&p.x), &mut jac));
        });
    }
    jacobian.finish();
}

/// One continuation step: solve at the next period from the previous solution.
fn one_solve(c: &mut Criterion) {
    let system = clamped_bar_with_obstacle(GAP).unwrap();
    let mut group = c.benchmark_group("solve");
    for m in [20, 80, 160] {
        let (from, to) = two_points(&system, m);
        let mut problem = NonsmoothSystem::new(&system, settings(m)).unwrap();
        let solver = SemismoothNewton::default();
        let mut x = from.x.clone();
        group.bench_with_input(
            BenchmarkId::from_parameter(m),
            &(from, to),
            |b, (from, to)| {
                b.iter(|| {
                    x.copy_from_slice(&from.x);
                    problem.set_parameter(to.omega);
                    solver.solve(&mut problem, black_box(&mut x)).unwrap()
                });
            },
        );
    }
    group.finish();
}

/// The `backbone` example's run (181 steps), without the CSV.
fn whole_backbone(c: &mut Criterion) {
    let system = clamped_bar_with_obstacle(GAP).unwrap();
    let options = full_grid();
    let mut group = c.benchmark_group("backbone_181");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5));
    // The `backbone` example's solver: the fail-fast budget of sequential runs.
    let solver = Solver::Newton(SemismoothNewton::new(NewtonOptions::fail_fast()).unwrap());
    for m in [20, 40, 80] {
        group.bench_with_input(BenchmarkId::new("serial", m), &m, |b, &m| {
            b.iter(|| grid_run(&system, m, options, solver));
        });
        // The same points with the first retry of failing steps on a worker thread.
        let speculative = Request {
            speculation: Some(Speculation::default()),
            ..grid_request(m, options, solver)
        };
        group.bench_with_input(BenchmarkId::new("speculative", m), &m, |b, _| {
            b.iter(|| compute(&system, &speculative).unwrap());
        });
    }
    group.finish();
}

/// Four 181-step backbones (m = 20 and 30, Newton and dogleg) as one sweep, against the same
/// jobs run one after the other.
fn sweep(c: &mut Criterion) {
    let system = clamped_bar_with_obstacle(GAP).unwrap();
    let options = full_grid();
    let mut jobs = Vec::new();
    for m in [20, 30] {
        for solver in [
            Solver::default(),
            Solver::Dogleg(nonsmooth_modes::solve::Dogleg::default()),
        ] {
            jobs.push(SweepJob {
                system: system.clone(),
                request: grid_request(m, options, solver),
            });
        }
    }
    let mut group = c.benchmark_group("sweep_4_backbones");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5));
    group.bench_function("backbones", |b| b.iter(|| backbones(black_box(&jobs))));
    group.bench_function("serial", |b| b.iter(|| backbones_serial(black_box(&jobs))));
    group.finish();
}

/// The closed-form energy of a point near the branch (computed once per continuation point):
/// at `theta = 0` (strain only, the common call) and at `theta = 0.3` (kinetic part too).
fn energy_of_point(c: &mut Criterion) {
    let system = clamped_bar_with_obstacle(GAP).unwrap();
    let mut group = c.benchmark_group("energy");
    for m in [40, 160] {
        let (_, p) = two_points(&system, m);
        let basis = CosineBasis::new(m, settings(m).samples_per_harmonic).unwrap();
        group.bench_with_input(BenchmarkId::new("theta_0", m), &p, |b, p| {
            b.iter(|| energy(&system, &basis, black_box(&p.x), p.omega));
        });
        group.bench_with_input(BenchmarkId::new("theta_0.3", m), &p, |b, p| {
            b.iter(|| energy_at(&system, &basis, black_box(&p.x), p.omega, 0.3));
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    residual_and_jacobian,
    one_solve,
    whole_backbone,
    sweep,
    energy_of_point
);
criterion_main!(benches);
