//! What an independent stress run of `main` still found (issue 26), each kept as a regression
//! test:
//! 1. indices and counts at `usize::MAX` (an overflowing `bar + 1` in the bar check of
//!    `Solution::displacement_grid`, and the same kind of arithmetic elsewhere): typed errors
//!    naming the index asked for, or the documented panic of a low-level function, never a
//!    wrapped index that lands on another row, column or unknown;
//! 2. histories just under the memory budget: their vectors hold exactly what the budget
//!    counted, and an allocation the process cannot make is a typed error, not an abort;
//! 4. a dogleg asked for a tolerance below the rounding floor with an unbounded iteration
//!    budget: it stops when its residual stops falling;
//! 5. a `parameter_branch` over bar lengths up to `4.75e299`: a point whose energy is not
//!    finite is not converged.
//!
//! (Finding 6, assemblies written as JSON and read back bit for bit, is tested in
//! `tests/assembly_file.rs`; the stress suite `tests/stress/` draws all of these kinds.)

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{parameter_branch, BackbonePoint, ParameterSteps, PointStatus};
use nonsmooth_modes::continuation::{ContinuationProblem, SequentialOptions};
use nonsmooth_modes::fourier::{Basis, MEMORY_BUDGET_BYTES};
use nonsmooth_modes::linalg::DenseMatrix;
use nonsmooth_modes::modal::{branch_seed, diagnose, law_history};
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, ClampedFirstMode};
use nonsmooth_modes::solve::{
    Dogleg, DoglegOptions, NewtonOptions, NonlinearSolver, SemismoothNewton,
};
use nonsmooth_modes::system::{
    AssemblyBuilder, BarSystem, HarmonicBalanceSettings, Layout, NonsmoothSystem,
};
use nonsmooth_modes::{ModelError, SettingsError, Solution, SolveError};
use std::f64::consts::PI;
use std::ops::ControlFlow;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::mpsc;
use std::time::Duration;

const GAP: f64 = 1e-3;
const HARMONICS: usize = 4;
const OMEGA: f64 = 1.7;

fn settings() -> HarmonicBalanceSettings {
    HarmonicBalanceSettings {
        harmonics: HARMONICS,
        ..Default::default()
    }
}

fn clamped() -> BarSystem {
    clamped_bar_with_obstacle(GAP).unwrap()
}

/// A motion of the clamped bar (the exact mode, truncated).
fn motion() -> Vec<f64> {
    ClampedFirstMode::new(GAP, 3.6).unknowns(HARMONICS)
}

/// Samples of a law or end history within the budget: four doubles each.
fn max_history_samples() -> usize {
    (MEMORY_BUDGET_BYTES / 32) as usize
}

/// The message of the panic of `f`, which must panic.
fn panic_message(what: &str, f: impl FnOnce()) -> String {
    let payload = catch_unwind(AssertUnwindSafe(f)).expect_err(what);
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_default()
}

// --- 1. Indices and counts at `usize::MAX` ---

/// Bar and law indices up to `usize::MAX` are typed errors that carry the index asked for
/// (a wrapped `bar + 1` said 0) and the count; `Solution::displacement_grid(usize::MAX, ..)`
/// was the independent run's panic (`attempt to add with overflow`, 144 and 66 cases).
#[test]
fn indices_at_usize_max_are_typed_errors_naming_them() {
    let system = clamped();
    let problem = NonsmoothSystem::new(&system, settings()).unwrap();
    let x = motion();
    let solution = Solution::new(&problem, &x, OMEGA).unwrap();
    let out_of_range = |result: Result<(), SettingsError>, index: usize, what: &str| match result {
        Err(SettingsError::IndexOutOfRange {
            what: named,
            index: i,
            count,
        }) => {
            assert_eq!((i, count), (index, 1), "{what}");
            assert!(named.contains(what), "{named}");
        }
        other => panic!("{what} {index}: {other:?}"),
    };
    for index in [1, 2, 1 << 63, usize::MAX - 1, usize::MAX] {
        out_of_range(
            solution.displacement_grid(index, 2, 2).map(|_| ()),
            index,
            "bar",
        );
        out_of_range(solution.law_history(index, 4).map(|_| ()), index, "law");
        out_of_range(
            law_history(&problem, &x, OMEGA, index, 4).map(|_| ()),
            index,
            "law",
        );
    }
    // An end of the fifth bar of another assembly.
    let mut other = AssemblyBuilder::new();
    for _ in 0..4 {
        other.add_bar(Bar::unit());
    }
    let foreign = other.add_bar(Bar::unit()).right();
    out_of_range(solution.end_history(foreign, 4).map(|_| ()), 4, "bar");
    let message = solution
        .displacement_grid(usize::MAX, 2, 2)
        .unwrap_err()
        .to_string();
    assert!(message.contains(&usize::MAX.to_string()), "{message}");
}

/// Counts at `usize::MAX`, and products of counts that overflow `usize`, are over the budget.
#[test]
fn counts_at_usize_max_are_over_the_budget() {
    let system = clamped();
    let problem = NonsmoothSystem::new(&system, settings()).unwrap();
    let x = motion();
    let solution = Solution::new(&problem, &x, OMEGA).unwrap();
    let end = system.bar_id(0).unwrap().right();
    let too_large = |result: Result<(), SettingsError>, what: &str| {
        assert!(
            matches!(result, Err(SettingsError::TooLarge(_))),
            "{what}: {result:?}"
        );
    };
    for (p, i) in [
        (usize::MAX, usize::MAX),
        (usize::MAX, 0),
        (0, usize::MAX),
        (usize::MAX, 1),
        (1 << 32, 1 << 32),
    ] {
        too_large(
            solution.displacement_grid(0, p, i).map(|_| ()),
            &format!("grid {p} x {i}"),
        );
    }
    for n in [usize::MAX - 1, usize::MAX] {
        too_large(solution.end_history(end, n).map(|_| ()), "end history");
        too_large(solution.law_history(0, n).map(|_| ()), "law history");
        too_large(solution.diagnose(n).map(|_| ()), "diagnose");
    }
    let empty = solution.displacement_grid(0, 0, 0).unwrap();
    assert!(empty.position.is_empty() && empty.displacement.is_empty());
}

/// The low-level accessors panic, with a message, on an index out of range, where wrapping
/// arithmetic used to land on another row, column or unknown in release builds (row
/// `2^63` of a one-bar system started at `2^63 * 2 = 0`, the first row).
#[test]
fn low_level_indices_out_of_range_panic_instead_of_wrapping() {
    let system = clamped();
    let mut problem = NonsmoothSystem::new(&system, settings()).unwrap();
    let rows = problem.rows_at(OMEGA)[1].clone();
    assert_eq!(rows.unknowns(), 2);
    for l in [1, 1 << 63, usize::MAX] {
        let message = panic_message("gap_row", || {
            rows.gap_row(l);
        });
        assert!(message.contains("in range"), "{message}");
        panic_message("force_row", || {
            rows.force_row(l);
        });
    }
    panic_message("linear_row", || {
        rows.linear_row(1 << 63);
    });
    let layout = Layout::of(&system);
    assert_eq!(layout.index(1, 0, 1), 3);
    for (i, bar, which) in [(0, 1, 0), (0, 0, 2), (1 << 63, 0, 0), (usize::MAX, 0, 0)] {
        let message = panic_message("Layout::index", || {
            layout.index(i, bar, which);
        });
        assert!(message.contains("Layout::index"), "{message}");
    }
    let message = panic_message("DenseMatrix::zeros", || {
        DenseMatrix::zeros(usize::MAX, 2);
    });
    assert!(message.contains("overflows"), "{message}");
    let m = DenseMatrix::zeros(2, 3);
    panic_message("row out of range", || {
        let _ = m[(2, 0)];
    });
    panic_message("column out of range", || {
        m.column(3);
    });
    let message = panic_message("ClampedFirstMode::unknowns", || {
        ClampedFirstMode::new(GAP, 3.6).unknowns(usize::MAX);
    });
    assert!(message.contains("overflows"), "{message}");
}

/// Errors of assembly files count their items from 1 (the fields are public, so an index
/// may be `usize::MAX`): the count does not overflow.
#[cfg(feature = "serde")]
#[test]
fn assembly_file_errors_count_from_one_without_overflow() {
    use nonsmooth_modes::io::assembly::AssemblyFileError;
    let next = "18446744073709551616";
    let errors = [
        AssemblyFileError::DuplicateBarName {
            name: "a".into(),
            first: usize::MAX,
            second: usize::MAX,
        },
        AssemblyFileError::Bar {
            index: usize::MAX,
            name: "a".into(),
            source: ModelError::NoBars,
        },
        AssemblyFileError::End {
            end: "a.end".into(),
            conditions: vec![usize::MAX, usize::MAX],
            source: ModelError::NoBars,
        },
    ];
    for e in errors {
        assert!(e.to_string().contains(next), "{e}");
    }
}

// --- 2. Histories near the memory budget ---

/// The vectors of the histories hold exactly the values the budget counted (pushing into
/// empty vectors rounded their capacity up to a power of two, past the count: the
/// independent run's aborts of `diagnose` just under the budget).
#[test]
fn histories_allocate_exactly_what_the_budget_counts() {
    let system = clamped();
    let problem = NonsmoothSystem::new(&system, settings()).unwrap();
    let x = motion();
    let solution = Solution::new(&problem, &x, OMEGA).unwrap();
    let n = 1000;
    let h = solution.law_history(0, n).unwrap();
    for v in [&h.time, &h.gap, &h.force, &h.residual] {
        assert_eq!((v.len(), v.capacity()), (n, n));
    }
    let end = system.bar_id(0).unwrap().right();
    let h = solution.end_history(end, n).unwrap();
    for v in [&h.time, &h.displacement, &h.strain, &h.contact_force] {
        assert_eq!((v.len(), v.capacity()), (n, n));
    }
    let g = solution.displacement_grid(0, 7, 13).unwrap();
    assert_eq!((g.position.len(), g.position.capacity()), (7, 7));
    assert_eq!((g.time.len(), g.time.capacity()), (13, 13));
    assert_eq!((g.displacement.len(), g.displacement.capacity()), (91, 91));
}

/// One sample past the budget is a typed error with the bytes of what was asked.
#[test]
fn one_sample_past_the_budget_is_over_it() {
    let system = clamped();
    let problem = NonsmoothSystem::new(&system, settings()).unwrap();
    let x = motion();
    let solution = Solution::new(&problem, &x, OMEGA).unwrap();
    let over = max_history_samples() + 1;
    match solution.law_history(0, over) {
        Err(SettingsError::TooLarge(e)) => {
            assert_eq!(e.requested_bytes, over as f64 * 32.0);
            assert_eq!(e.budget_bytes, MEMORY_BUDGET_BYTES);
        }
        other => panic!("{:?}", other.map(|h| h.time.len())),
    }
    let end = system.bar_id(0).unwrap().right();
    assert!(matches!(
        solution.end_history(end, over),
        Err(SettingsError::TooLarge(_))
    ));
    let samples = problem.basis().samples();
    let refinement = max_history_samples() / samples + 1;
    assert!(matches!(
        diagnose(&problem, &x, OMEGA, refinement),
        Err(SettingsError::TooLarge(_))
    ));
    // `(p + 1)(i + 1) - 1` values: at the budget, then one position more.
    let (p, i) = ((1 << 14) - 1, (1 << 15) - 1);
    assert!(matches!(
        solution.displacement_grid(0, p + 1, i),
        Err(SettingsError::TooLarge(_))
    ));
}

/// Set in the environment of the child process of
/// [`histories_just_under_the_budget_are_typed_errors_when_memory_is_short`].
const CHILD: &str = "NONSMOOTH_MODES_MEMORY_CHILD";

/// Histories just under the budget, in a process limited to 1 GiB of address space
/// (`ulimit -v`): the allocator refuses them, and each request is
/// `SettingsError::AllocationFailed`, not an abort (the child would die of `SIGABRT`).
#[cfg(target_os = "linux")]
#[test]
fn histories_just_under_the_budget_are_typed_errors_when_memory_is_short() {
    let exe = std::env::current_exe().unwrap();
    let output = std::process::Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 1048576 && exec \"$0\" \"$@\"")
        .arg(exe)
        .args([
            "--exact",
            "near_budget_requests_in_a_small_process",
            "--ignored",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(CHILD, "1")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "child {:?}\nstdout: {stdout}\nstderr: {stderr}",
        output.status
    );
    assert!(stdout.contains("1 passed"), "{stdout}");
}

/// The child of
/// [`histories_just_under_the_budget_are_typed_errors_when_memory_is_short`] (does nothing
/// outside it).
#[test]
#[ignore = "run under a memory limit by histories_just_under_the_budget_are_typed_errors_when_memory_is_short"]
fn near_budget_requests_in_a_small_process() {
    if std::env::var_os(CHILD).is_none() {
        return;
    }
    let system = clamped();
    let problem = NonsmoothSystem::new(&system, settings()).unwrap();
    let x = motion();
    let solution = Solution::new(&problem, &x, OMEGA).unwrap();
    let refused = |result: Result<(), SettingsError>, what: &str| match result {
        Err(SettingsError::AllocationFailed { bytes, .. }) => {
            assert!(
                bytes > 5e8 && bytes <= MEMORY_BUDGET_BYTES as f64,
                "{what}: {bytes:e}"
            );
        }
        // An allocator that grants it all the same is no failure either.
        Ok(()) => println!("{what}: allocated"),
        Err(e) => panic!("{what}: {e:?}"),
    };
    let max = max_history_samples();
    let refinement = max / problem.basis().samples();
    refused(
        diagnose(&problem, &x, OMEGA, refinement).map(|_| ()),
        "diagnose",
    );
    refused(solution.law_history(0, max).map(|_| ()), "law history");
    let end = system.bar_id(0).unwrap().right();
    refused(solution.end_history(end, max).map(|_| ()), "end history");
    let (p, i) = ((1 << 14) - 1, (1 << 15) - 1);
    refused(
        solution.displacement_grid(0, p, i).map(|_| ()),
        "displacement grid",
    );
}

// --- 4. A dogleg below the rounding floor ---

/// Runs `f` on a thread and fails if it has not answered within a minute (a regression
/// fails instead of hanging the suite).
fn within_a_minute<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    let (send, receive) = mpsc::channel();
    std::thread::spawn(move || send.send(f()));
    receive
        .recv_timeout(Duration::from_secs(60))
        .expect("no answer within a minute")
}

/// A start that creeps towards the state of rest: the residual falls by about 0.03 % per
/// dogleg iteration (the clamped bar, 8 harmonics, 0.3 times the seed at `1.05 omega_1`).
fn creeping_start() -> (NonsmoothSystem, Vec<f64>) {
    let settings = HarmonicBalanceSettings {
        harmonics: 8,
        ..Default::default()
    };
    let mut problem = NonsmoothSystem::new(&clamped(), settings).unwrap();
    let omega = 2.0 * PI / 3.6 * 1.05;
    let x: Vec<f64> = branch_seed(&mut problem, 1, 1, omega)
        .unwrap()
        .iter()
        .map(|v| 0.3 * v)
        .collect();
    problem.set_parameter(omega);
    (problem, x)
}

/// A tolerance below what `f64` can reach (`2.2e-309`, subnormal) with
/// `max_iterations = usize::MAX`: the dogleg stops when its residual stops falling
/// (`SolveError::Stagnated` with its window), where it used to take tiny accepted steps for
/// ever; Newton with the same options stops too.
#[test]
fn a_dogleg_asked_for_a_tolerance_below_the_rounding_floor_stops() {
    let result = within_a_minute(|| {
        let (mut problem, mut x) = creeping_start();
        let dogleg = Dogleg::new(DoglegOptions {
            tolerance: 2.2e-309,
            max_iterations: usize::MAX,
            ..Default::default()
        })
        .unwrap();
        let result = dogleg.solve(&mut problem, &mut x);
        (result, x.iter().all(|v| v.is_finite()))
    });
    match result {
        (
            Err(SolveError::Stagnated {
                iteration,
                residual_norm,
                earlier_residual_norm,
                window,
            }),
            true,
        ) => {
            assert_eq!(window, Dogleg::STALL_WINDOW);
            assert!(iteration >= window && iteration < 1000, "{iteration}");
            assert!(residual_norm > Dogleg::STALL_RATIO * earlier_residual_norm);
        }
        other => panic!("{other:?}"),
    }
    for tolerance in [5e-324, 2.2e-309, 1e-300, f64::EPSILON / 4.0] {
        let (newton, dogleg) = within_a_minute(move || {
            let (mut problem, start) = creeping_start();
            let newton = SemismoothNewton::new(NewtonOptions {
                tolerance,
                max_iterations: usize::MAX,
                ..Default::default()
            })
            .unwrap();
            let dogleg = Dogleg::new(DoglegOptions {
                tolerance,
                max_iterations: usize::MAX,
                min_radius: 5e-324,
                ..Default::default()
            })
            .unwrap();
            let mut x = start.clone();
            let newton = newton.solve(&mut problem, &mut x).map(|i| i.residual_norm);
            let mut x = start;
            let dogleg = dogleg.solve(&mut problem, &mut x).map(|i| i.residual_norm);
            (newton, dogleg)
        });
        for r in [newton, dogleg] {
            match r {
                Ok(norm) => assert!(norm.is_finite()),
                Err(e) => assert!(!e.to_string().is_empty()),
            }
        }
    }
}

/// The stagnation test leaves converging solves alone: the default dogleg from the exact
/// mode converges, as before.
#[test]
fn a_converging_dogleg_is_not_stopped() {
    let mut problem = NonsmoothSystem::new(&clamped(), settings()).unwrap();
    let omega = 2.0 * PI / 3.6;
    problem.set_parameter(omega);
    let mut x: Vec<f64> = motion().iter().map(|v| v * 1.05).collect();
    let info = Dogleg::default().solve(&mut problem, &mut x).unwrap();
    assert!(info.residual_norm <= Dogleg::default().tolerance(&mut problem));
}

// --- 5. Points whose energy is not finite ---

/// The clamped bar of length `l` (wave speed and stiffness 1) facing its obstacle at `GAP`.
fn clamped_of_length(l: f64) -> Result<BarSystem, ModelError> {
    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::new(l, 1.0, 1.0)?);
    b.dirichlet(bar.left())?.signorini(bar.right(), GAP)?;
    b.build()
}

/// The points a `parameter_branch` over `values` of `family` hands its observer.
fn branch_points(
    family: fn(f64) -> Result<BarSystem, ModelError>,
    values: Vec<f64>,
    start: Vec<f64>,
) -> Vec<(f64, BackbonePoint)> {
    let settings = HarmonicBalanceSettings {
        harmonics: HARMONICS,
        samples_per_harmonic: 10,
        ..Default::default()
    };
    let first = values[0];
    let steps = ParameterSteps::Values(values, SequentialOptions::default());
    let mut points = Vec::new();
    parameter_branch(
        family,
        settings,
        (start, 2.0 * PI / 3.6),
        first,
        steps,
        SemismoothNewton::default(),
        |value, p| {
            points.push((value, p.clone()));
            ControlFlow::Continue(())
        },
    )
    .unwrap();
    points
}

/// A converged point has a finite energy and `E / E_g`, else it is `NonFiniteEnergy`:
/// bar lengths up to `4.75e299` (the independent run's case: converged with energy NaN) and
/// gaps whose grazing energy underflows (formerly documented as converged with
/// `energy_normalized = NaN`).
#[test]
fn points_without_a_finite_energy_are_not_converged() {
    let lengths = branch_points(
        clamped_of_length,
        vec![1.0, 1e10, 1e100, 1e200, 4.75e299, f64::MAX],
        motion(),
    );
    // From `1e-150` down to `1e-160` in steps of `10^-0.5`.
    let values = (0..=20)
        .map(|i| 1e-150 * 10f64.powf(-0.5 * i as f64))
        .collect();
    let start = ClampedFirstMode::new(1e-150, 3.6).unknowns(HARMONICS);
    let gaps = branch_points(clamped_bar_with_obstacle, values, start);
    for (value, p) in lengths.iter().chain(&gaps) {
        assert_eq!(
            p.converged(),
            p.status == PointStatus::Converged,
            "{value:e}"
        );
        let finite = p.energy.is_finite() && p.energy_normalized.is_finite();
        if p.converged() {
            assert!(finite, "{value:e}: {p:?}");
        }
        if p.status == PointStatus::NonFiniteEnergy {
            assert!(!finite, "{value:e}: {p:?}");
            assert!(p.residual_norm.is_finite() && p.x.iter().all(|v| v.is_finite()));
        }
    }
    let status = |points: &[(f64, BackbonePoint)], value: f64| {
        let (_, p) = points.iter().find(|(v, _)| *v == value).unwrap();
        p.status.clone()
    };
    assert_eq!(status(&lengths, 1.0), PointStatus::Converged);
    assert_eq!(status(&lengths, 4.75e299), PointStatus::NonFiniteEnergy);
    // Gaps whose grazing energy underflows (below about `1e-154`): E / E_g is NaN.
    assert!(
        gaps.iter()
            .any(|(v, p)| *v < 1e-155 && p.status == PointStatus::NonFiniteEnergy),
        "{:?}",
        gaps.iter()
            .map(|(v, p)| (v, p.status.label()))
            .collect::<Vec<_>>()
    );
    assert_eq!(PointStatus::NonFiniteEnergy.label(), "non-finite-energy");
}
