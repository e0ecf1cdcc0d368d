//! Criterion benchmark of an exact branch against the grid size: the clamped bar's branch
//! (gap `1e-3`) over five periods `3.60 -> 3.52` (whole numbers of steps at every size), from
//! a harmonic-balance run computed once, at 50, 100 and 200 cells per travel time. One
//! iteration is the whole branch (its seed and four continued points); a point costs about
//! a fifth of it.
//!
//! ```text
//! cargo bench --all-features --bench exact
//! ```

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nonsmooth_modes::branches::{compute, BackboneOptions, Method, PeriodGrid, Request};
use nonsmooth_modes::exact::{exact_branch_from, ExactOptions};
use nonsmooth_modes::reference::clamped_bar_with_obstacle;
use nonsmooth_modes::stability::StabilityOptions;
use std::hint::black_box;
use std::time::Duration;

fn exact(c: &mut Criterion) {
    let mut group = c.benchmark_group("exact_branch_clamped_5_points");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    let system = clamped_bar_with_obstacle(1e-3).expect("system");
    let grid = PeriodGrid {
        start: 3.60,
        end: 3.52,
        steps: 5,
    };
    let options = BackboneOptions {
        grid,
        ..BackboneOptions::for_mode(&system, 1, 1).expect("options")
    };
    let run = compute(
        &system,
        &Request::new(1).method(Method::PeriodGrid(options)),
    )
    .expect("harmonic balance");
    for cells in [50usize, 100, 200] {
        let exact = ExactOptions {
            stability: StabilityOptions {
                cells_per_travel: cells as f64,
                ..StabilityOptions::default()
            },
            ..ExactOptions::default()
        };
        group.bench_with_input(BenchmarkId::from_parameter(cells), &cells, |b, _| {
            b.iter(|| exact_branch_from(black_box(&run), &grid, &exact).expect("exact branch"))
        });
    }
    group.finish();
}

criterion_group!(benches, exact);
criterion_main!(benches);
