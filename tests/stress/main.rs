//! Stress suite of the public API: seeded random cases of every kind of input (bars and
//! assemblies with built-in and downstream conditions, harmonic-balance settings, solvers and
//! their options, the continuation drivers and backbones, post-processing of valid systems),
//! valid, at the edges and bad: `0`, negative, subnormal, `1e-300`, `1e300`, `f64::MAX`,
//! infinities and NaN; sizes `0`, `1`, small, `2^40` and `usize::MAX`, and one and twice past
//! the memory budget; tolerances below the rounding floor with `usize::MAX` iterations;
//! parameters at the extremes the constructors accept; assemblies written to JSON and TOML
//! and read back bit for bit; the surfaces added after the core (the full-basis helpers,
//! the forced system's calls, Floquet multipliers) with the same hostile values.
//!
//! Each case runs under `catch_unwind` on a worker thread and is classified: `Ok`, typed
//! error, panic (with its message), a non-finite number in an `Ok` result, a run without a
//! consistent end reason, a result that contradicts its input (an error naming another index
//! or size, memory held beyond what the budget counted, a file read back with other
//! numbers), or a hang (no answer within [`HANG_SECONDS`](harness::HANG_SECONDS)). The tests
//! fail on any but the first two, and print each failure with its case index and the inputs
//! drawn, so that `STRESS_SEED`/`STRESS_ONLY` reproduce it.
//!
//! Overflowing arithmetic wraps silently in a release build: run the suite with overflow
//! checks too (`CARGO_PROFILE_RELEASE_OVERFLOW_CHECKS=true`, in a target directory of its
//! own), where it panics.
//!
//! - `stress_public_api`: [`QUICK_CASES`] cases (a minute in release);
//! - `stress_public_api_long` (`#[ignore]`): `STRESS_CASES` cases, 20 000 by default:
//!   `cargo test --release --all-features --test stress -- --ignored --nocapture`.
//!
//! Valid cases are cheap on purpose (at most 8 harmonics, a few continuation steps, short
//! time-domain marches), so that the long run takes minutes on one core; budgets that could
//! legitimately run for hours (`max_steps = usize::MAX`, a shrink factor of `0.9999999` with
//! an unbounded number of rejections) are always drawn together with an observer that stops
//! the run, as a user asking for them would.

mod cases;
mod checks;
mod draw;
mod harness;

use harness::run_suite;

/// Cases of the quick test.
const QUICK_CASES: usize = 1500;
/// Cases of the long test unless `STRESS_CASES` says otherwise.
const LONG_CASES: usize = 20_000;
/// Base seed unless `STRESS_SEED` says otherwise.
const SEED: u64 = 0x5EED_2024_0BAD_CAFE;

fn env_number(name: &str) -> Option<u64> {
    let v = std::env::var(name).ok()?;
    let v = v.trim();
    match v.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16).ok(),
        None => v.parse().ok(),
    }
}

/// Runs `cases` cases (or only `STRESS_ONLY`) and fails on any failure.
fn stress(cases: usize) {
    let base = env_number("STRESS_SEED").unwrap_or(SEED);
    let failures = match env_number("STRESS_ONLY") {
        Some(only) => run_suite(base, std::iter::once(only as usize)),
        None => run_suite(base, 0..cases),
    };
    assert!(
        failures.is_empty(),
        "{} failing cases (panics, non-finite results, runs without end reason, hangs): see above",
        failures.len()
    );
}

#[test]
fn stress_public_api() {
    stress(QUICK_CASES);
}

#[test]
#[ignore = "long: 20 000 cases by default (STRESS_CASES), run in release"]
fn stress_public_api_long() {
    let cases = env_number("STRESS_CASES").map_or(LONG_CASES, |n| n as usize);
    stress(cases);
}
