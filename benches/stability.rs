//! Criterion benchmark of one stability evaluation against the grid size: the Floquet
//! multipliers of the clamped bar's exact first nonsmooth mode (`T = 3.5`, gap `1e-3`, a
//! periodic orbit of the grid's map, so no correction runs) at 50, 100 and 200 cells per
//! travel time: `2 n` marches of one period and a dense eigenvalue problem of `n = 2 N`
//! rows. Then Hill's method (`stability::hill`) on the same motion's harmonic-balance
//! coefficients at 10, 20 and 40 harmonics: a search of 54 shifts, each a dense eigenvalue
//! problem of `2 (2 m + 1)` rows, and the refinements of its candidates.
//!
//! ```text
//! cargo bench --bench stability
//! ```

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nonsmooth_modes::fourier::frequency_of_period;
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, ClampedFirstMode};
use nonsmooth_modes::stability::{floquet_of_state, hill, HillOptions, StabilityOptions};
use nonsmooth_modes::system::HarmonicBalanceSettings;
use nonsmooth_modes::verify::clamped_first_mode;
use std::hint::black_box;
use std::time::Duration;

fn stability(c: &mut Criterion) {
    let mut group = c.benchmark_group("stability_exact_clamped");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    for cells in [50usize, 100, 200] {
        let period = 3.5;
        let state = clamped_first_mode(1e-3, period, 1.0 / cells as f64).expect("state");
        let options = StabilityOptions {
            cells_per_travel: cells as f64,
            ..StabilityOptions::default()
        };
        group.bench_with_input(BenchmarkId::from_parameter(cells), &cells, |b, _| {
            b.iter(|| floquet_of_state(black_box(&state), period, &options).expect("floquet"))
        });
    }
    group.finish();
}

fn hill_method(c: &mut Criterion) {
    let mut group = c.benchmark_group("hill_exact_clamped");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    let system = clamped_bar_with_obstacle(1e-3).expect("system");
    let (period, options) = (3.5, HillOptions::default());
    for harmonics in [10usize, 20, 40] {
        let settings = HarmonicBalanceSettings {
            harmonics,
            ..HarmonicBalanceSettings::default()
        };
        let x = ClampedFirstMode::new(1e-3, period).unknowns(harmonics);
        let omega = frequency_of_period(period);
        group.bench_with_input(
            BenchmarkId::from_parameter(harmonics),
            &harmonics,
            |b, _| {
                b.iter(|| hill(&system, settings, black_box(&x), omega, &options).expect("hill"))
            },
        );
    }
    group.finish();
}

criterion_group!(benches, stability, hill_method);
criterion_main!(benches);
