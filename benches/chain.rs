//! Criterion benchmarks of the Newton step on chains of `N` bars with `N - 1` contacts
//! (`reference::contact_chain`, gap `1e-3`, Robin `0.5`), at `m = 20`, `n_h = 30`, for
//! `N = 2, 4, 8, 16, 32`: how the cost of one step grows with the assembly.
//!
//! The state is the first open-contact mode's seed (`modal::branch_seed`) at 79/80 of its
//! linear period, scaled by 1.5 so that the contacts close over part of the period.
//!
//! - `chain_step`: one structured Newton step at a fixed frequency: the residual, then
//!   `Structured::solve_jacobian` (law samples, Gram matrices, factorisation, solve);
//! - `chain_continuation_step`: the first iteration of a continuation step: a new frequency
//!   (every harmonic's rows rebuilt), the residual and the structured step.
//!
//! ```text
//! cargo bench --bench chain
//! cargo bench --bench chain -- chain_step
//! ```

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, BenchmarkId, Criterion};
use nonsmooth_modes::branches::PeriodGrid;
use nonsmooth_modes::continuation::ContinuationProblem;
use nonsmooth_modes::fourier::Basis;
use nonsmooth_modes::modal::branch_seed;
use nonsmooth_modes::reference::contact_chain;
use nonsmooth_modes::solve::Problem;
use nonsmooth_modes::system::{HarmonicBalanceSettings, NonsmoothSystem};
use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Duration;

const BARS: [usize; 5] = [2, 4, 8, 16, 32];
const GAP: f64 = 1e-3;

/// The chain of `bars` bars at `m = 20`, its seeded state and its frequency.
fn seeded(bars: usize) -> (NonsmoothSystem, Vec<f64>, f64) {
    let system = contact_chain(bars, GAP, 0.5).expect("chain");
    let period = PeriodGrid::for_mode(&system, 1, 1).expect("mode").start;
    let omega = 2.0 * PI / period;
    let mut problem = NonsmoothSystem::new(&system, HarmonicBalanceSettings::default()).unwrap();
    let seed = branch_seed(&mut problem, 1, 1, omega).expect("seed");
    problem.set_parameter(omega);
    // The seed moves the first contact only. Neighbouring bars moving in opposition on the
    // first harmonic, `u_b = 3 g0 (-1)^b cos(k x) cos(Omega t)`, close every contact over
    // part of the period (an open contact leaves a floating bar free: a singular step).
    let mut x = seed;
    for bar in 0..bars {
        let sign = if bar % 2 == 0 { 1.0 } else { -1.0 };
        x[problem.index(1, bar, 0)] += 3.0 * GAP * sign;
    }
    let samples = problem.basis().samples();
    let active = problem.structure().unwrap().active_set(&x).unwrap();
    assert!(
        active.iter().all(|&a| a > 0 && a < samples),
        "every contact closes over part of the period: {active:?} of {samples}"
    );
    (problem, x, omega)
}

/// The Newton direction `J(x)^-1 F(x)` into `dx` (the sign does not matter for timing).
fn newton_step(problem: &mut NonsmoothSystem, x: &[f64], dx: &mut [f64]) {
    problem.residual(x, dx);
    let structured = problem.structure().expect("structured problem");
    let solved = structured
        .solve_jacobian(x, dx, 1)
        .expect("structured step");
    solved.expect("regular step");
}

/// A group of few, short samples: the largest chains take milliseconds per step.
fn group_settings<'a>(c: &'a mut Criterion, name: &str) -> BenchmarkGroup<'a, WallTime> {
    let mut group = c.benchmark_group(name);
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    group
}

fn chain_step(c: &mut Criterion) {
    let mut group = group_settings(c, "chain_step");
    for bars in BARS {
        // Set up on the routine's first call, so that a filtered-out size costs nothing.
        let mut state = None;
        group.bench_with_input(BenchmarkId::from_parameter(bars), &bars, |b, &bars| {
            let (problem, x, _) = state.get_or_insert_with(|| seeded(bars));
            let mut dx = vec![0.0; x.len()];
            b.iter(|| newton_step(problem, black_box(x), &mut dx));
        });
    }
    group.finish();
}

fn chain_continuation_step(c: &mut Criterion) {
    let mut group = group_settings(c, "chain_continuation_step");
    for bars in BARS {
        let (mut state, mut turn) = (None, 0);
        group.bench_with_input(BenchmarkId::from_parameter(bars), &bars, |b, &bars| {
            let (problem, x, omega) = state.get_or_insert_with(|| seeded(bars));
            let mut dx = vec![0.0; x.len()];
            // Two neighbouring frequencies taken in turn: each iteration moves.
            let omegas = [*omega, *omega * (1.0 + 1e-3)];
            b.iter(|| {
                turn ^= 1;
                problem.set_parameter(omegas[turn]);
                newton_step(problem, black_box(x), &mut dx);
            });
        });
    }
    group.finish();
}

criterion_group!(benches, chain_step, chain_continuation_step);
criterion_main!(benches);
