//! Criterion benchmarks of the default request of the `backbone` example, the clamped bar's
//! 181-step backbone by `Method::Auto` (both equation sets, labels, the judge's sample), as a
//! whole and by parts, at `m = 20, 40, 80`:
//!
//! - `whole`: `branches::compute` of the example's request, with the second equation set on
//!   a second thread (`speculation`, as the example runs it on two cores) and serial;
//! - `sequential`: the paper's algorithm alone (`Method::PeriodGrid`, the example's
//!   `--method sequential`), labels included, on one thread; `sequential_two_threads` as
//!   the example runs it on two cores (speculative retries, and the points annotated on the
//!   calling thread while the driver steps on another);
//! - `selected`: `Method::Auto` under harmonic selection alone (the second equation set);
//! - `labels`: the character and label of each converged point of the kept run, with the
//!   open-contact natural frequencies the labels name;
//! - `judge`: the time-domain march of the judge's 8 points of the kept run;
//! - `selection_scan`: the open- and closed-contact natural frequencies the selection reads.
//!
//! A system keeps its natural-frequency scans (`system::spectra`), so every iteration builds
//! the system anew, as a process running the request once does.
//!
//! ```text
//! cargo bench --bench default_request                 # everything
//! cargo bench --bench default_request -- whole/       # the request as a whole
//! cargo bench --bench default_request -- "labels|judge"
//! ```

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, BenchmarkId, Criterion};
use nonsmooth_modes::bar::shortest_travel_time;
use nonsmooth_modes::branches::{
    compute, BackboneOptions, BackbonePoint, Method, ModeBranches, PeriodGrid, Request,
    JUDGE_CELLS_PER_TRAVEL, JUDGE_SAMPLES,
};
use nonsmooth_modes::continuation::Speculation;
use nonsmooth_modes::modal::{character, label, natural_frequencies, ContactState};
use nonsmooth_modes::reference::clamped_bar_with_obstacle;
use nonsmooth_modes::system::{BarSystem, RESONANCE_BAND};
use nonsmooth_modes::verify::{periodicity_check, PeriodicityOptions};
use std::hint::black_box;
use std::time::Duration;

const GAP: f64 = 1e-3;
const HARMONICS: [usize; 3] = [20, 40, 80];

/// The example's grid: 181 periods from 3.95 down to 3.05, the other options the system's.
fn grid(system: &BarSystem) -> BackboneOptions {
    let grid = PeriodGrid {
        start: 3.95,
        end: 3.05,
        steps: 181,
    };
    BackboneOptions {
        grid,
        ..BackboneOptions::for_mode(system, 1, 1).expect("the clamped bar's grid")
    }
}

/// The example's request at `m` harmonics by `method`, with or without a second thread.
fn request(m: usize, method: Method, threads: bool) -> Request {
    Request {
        speculation: threads.then(Speculation::default),
        ..Request::new(1).harmonics(m).method(method)
    }
}

fn run(system: &BarSystem, request: &Request) -> ModeBranches {
    compute(system, request).expect("a backbone")
}

/// The clamped bar, built anew (with no scans kept).
fn fresh() -> BarSystem {
    clamped_bar_with_obstacle(GAP).expect("the clamped bar")
}

fn group<'a>(c: &'a mut Criterion, name: &str) -> BenchmarkGroup<'a, WallTime> {
    let mut group = c.benchmark_group(name);
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    group
}

fn bench_whole(c: &mut Criterion) {
    let system = clamped_bar_with_obstacle(GAP).expect("the clamped bar");
    let auto = Method::Auto(Some(grid(&system)));
    let mut group = group(c, "whole");
    for m in HARMONICS {
        for (name, threads) in [("two_threads", true), ("serial", false)] {
            let request = request(m, auto, threads);
            group.bench_with_input(BenchmarkId::new(name, m), &request, |b, r| {
                b.iter(|| run(&fresh(), black_box(r)))
            });
        }
    }
    group.finish();
}

fn bench_runs(c: &mut Criterion) {
    let system = clamped_bar_with_obstacle(GAP).expect("the clamped bar");
    let options = grid(&system);
    let mut group = group(c, "runs");
    for m in HARMONICS {
        for (name, threads) in [("sequential", false), ("sequential_two_threads", true)] {
            let sequential = request(m, Method::PeriodGrid(options), threads);
            group.bench_with_input(BenchmarkId::new(name, m), &sequential, |b, r| {
                b.iter(|| run(&fresh(), black_box(r)))
            });
        }
        let selected =
            request(m, Method::Auto(Some(options)), false).resonance_band(RESONANCE_BAND);
        group.bench_with_input(BenchmarkId::new("selected", m), &selected, |b, r| {
            b.iter(|| run(&fresh(), black_box(r)))
        });
    }
    group.finish();
}

/// The kept run's converged points.
fn kept(system: &BarSystem, m: usize) -> (ModeBranches, Vec<BackbonePoint>) {
    let result = run(system, &request(m, Method::Auto(Some(grid(system))), false));
    let points = result.converged().cloned().collect();
    (result, points)
}

fn bench_parts(c: &mut Criterion) {
    let system = clamped_bar_with_obstacle(GAP).expect("the clamped bar");
    let mut group = group(c, "parts");
    for m in HARMONICS {
        let (result, points) = kept(&system, m);
        let highest = points.iter().map(|p| p.omega).fold(0.0, f64::max);
        group.bench_function(BenchmarkId::new("labels", m), |b| {
            b.iter(|| {
                let mut problem = result.problem().clone();
                // The labels' scan: open-contact modes a little beyond the points' fundamentals.
                let open = natural_frequencies(&fresh(), ContactState::Open, 2.0 * highest)
                    .expect("a scan");
                let natural: Vec<f64> = open.iter().map(|mode| mode.omega).collect();
                for p in &points {
                    let described = character(&mut problem, &p.x, p.omega, &natural);
                    if let Ok(described) = described {
                        black_box(label(&described, 1, p.omega, &natural, None).ok());
                    }
                }
            })
        });
        let travel = shortest_travel_time(system.bars());
        let options = PeriodicityOptions {
            dt: travel / JUDGE_CELLS_PER_TRAVEL,
            adjust_grid: true,
            ..PeriodicityOptions::default()
        };
        let (n, s) = (points.len(), points.len().min(JUDGE_SAMPLES));
        let sample: Vec<&BackbonePoint> =
            (0..s).map(|k| &points[(2 * k + 1) * n / (2 * s)]).collect();
        let basis = result.problem().basis();
        group.bench_function(BenchmarkId::new("judge", m), |b| {
            b.iter(|| {
                for p in &sample {
                    black_box(periodicity_check(&system, basis, &p.x, p.omega, &options).ok());
                }
            })
        });
        // The selection's bound at the grid's first frequency (`2 (m + 1) Omega (1 + c/m)`).
        let omega = 2.0 * std::f64::consts::PI / 3.95;
        let bound = 2.0 * (m as f64 + 1.0) * omega * (1.0 + RESONANCE_BAND / m as f64);
        group.bench_function(BenchmarkId::new("selection_scan", m), |b| {
            b.iter(|| {
                let system = fresh();
                for state in [ContactState::Open, ContactState::Closed] {
                    black_box(natural_frequencies(&system, state, bound).ok());
                }
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_whole, bench_runs, bench_parts);
criterion_main!(benches);
