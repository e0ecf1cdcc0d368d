//! Every bad input returns its typed error, carrying the numbers that explain it.

use nonsmooth_modes::bar::{Bar, EndRef};
use nonsmooth_modes::bc::{
    BoundaryCondition, Contact, LinearRows, Quantity, Robin, Signorini, Term,
};
use nonsmooth_modes::branches::{
    compute, lift, parameter_branch, ArclengthBackboneOptions, BackboneOptions,
    EnergyBackboneOptions, EnergyGrid, Method, ModeBranches, ParameterSteps, PeriodGrid, Request,
};
use nonsmooth_modes::continuation::{
    geomspace, linspace, ArclengthOptions, ContinuationProblem, Sequential, SequentialOptions,
};
use nonsmooth_modes::forced::{
    forced_response, Damping, Excitation, Forcing, ResponseMethod, ResponseRequest,
};
use nonsmooth_modes::linalg::DenseMatrix;
use nonsmooth_modes::modal::{branch_seed, grazing_energy, natural_frequencies, ContactState};
use nonsmooth_modes::reference::clamped_bar_with_obstacle;
use nonsmooth_modes::solve::{
    Dogleg, DoglegOptions, NewtonOptions, NonlinearSolver, Problem, SemismoothNewton, Solver,
};
use nonsmooth_modes::system::{
    AssemblyBuilder, BarSystem, HarmonicBalanceSettings, NonsmoothSystem,
};
use nonsmooth_modes::{
    BadRange, ContinuationError, Error, ModelError, RangeDefect, SettingsError, SolveError,
};
use std::f64::consts::PI;

const BAD: [f64; 6] = [0.0, -1.0, -0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY];

/// `value` as reported: the same number, or NaN for NaN.
fn same(reported: f64, given: f64) -> bool {
    reported == given && reported.is_sign_negative() == given.is_sign_negative()
        || (reported.is_nan() && given.is_nan())
}

fn assert_not_positive(result: Result<impl std::fmt::Debug, ModelError>, what: &str, value: f64) {
    match result {
        Err(ModelError::NotPositive { what: w, value: v }) => {
            assert_eq!(w, what);
            assert!(same(v, value), "{what}: reported {v}, given {value}");
        }
        other => panic!("{what} = {value}: expected NotPositive, got {other:?}"),
    }
}

fn clamped() -> BarSystem {
    clamped_bar_with_obstacle(1e-3).unwrap()
}

/// The paper's grid of the clamped bar (its derived grid, written out).
const PAPER_GRID: PeriodGrid = PeriodGrid {
    start: 3.95,
    end: 3.05,
    steps: 181,
};

/// The period grid `options` with the full semismooth Newton, as these checks always ran it.
fn grid_run(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    options: BackboneOptions,
) -> Result<ModeBranches, Error> {
    let method = Method::PeriodGrid(options);
    let request = Request::for_method(method)
        .settings(settings)
        .solver(Solver::default());
    compute(system, &request)
}

fn linear_only() -> BarSystem {
    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::unit());
    b.dirichlet(bar.left())
        .unwrap()
        .neumann(bar.right())
        .unwrap();
    b.build().unwrap()
}

#[test]
fn bad_bars() {
    for v in BAD {
        assert_not_positive(Bar::new(v, 1.0, 1.0), "bar length", v);
        assert_not_positive(Bar::new(1.0, v, 1.0), "bar wave speed", v);
        assert_not_positive(Bar::new(1.0, 1.0, v), "bar axial stiffness", v);
    }
    // The first bad value is reported.
    assert_not_positive(Bar::new(-2.0, f64::NAN, 0.0), "bar length", -2.0);
    assert!(Bar::new(f64::MIN_POSITIVE, f64::MAX, 1e-300).is_ok());
}

#[test]
fn bad_condition_parameters() {
    let mut b = AssemblyBuilder::new();
    let one = b.add_bar(Bar::unit());
    let two = b.add_bar(Bar::unit());
    for v in BAD {
        assert_not_positive(Signorini::new(one.right(), v), "Signorini gap", v);
        assert_not_positive(Contact::new(one.right(), two.right(), v), "contact gap", v);
        assert_not_positive(Robin::new(one.left(), v), "Robin spring stiffness", v);
        let mut b = AssemblyBuilder::new();
        let bar = b.add_bar(Bar::unit());
        assert_not_positive(b.signorini(bar.right(), v).map(|_| ()), "Signorini gap", v);
        assert_not_positive(
            b.robin(bar.left(), v).map(|_| ()),
            "Robin spring stiffness",
            v,
        );
        assert_not_positive(
            b.contact(bar.left(), bar.right(), v).map(|_| ()),
            "contact gap",
            v,
        );
    }
}

#[test]
fn assembly_errors_name_the_end_or_condition() {
    assert_eq!(
        AssemblyBuilder::new().build().unwrap_err(),
        ModelError::NoBars
    );

    // An end without a condition.
    let mut b = AssemblyBuilder::new();
    let one = b.add_bar(Bar::unit());
    let two = b.add_bar(Bar::unit());
    b.dirichlet(one.left())
        .unwrap()
        .dirichlet(one.right())
        .unwrap()
        .neumann(two.right())
        .unwrap();
    assert_eq!(
        b.build().unwrap_err(),
        ModelError::UnconstrainedEnd { end: two.left() }
    );
    let message = b.build().unwrap_err().to_string();
    assert_eq!(
        message,
        "left end (x = 0) of bar 1 (the 2nd added) has no boundary condition"
    );

    // An end with two conditions, named in order: each is valid on its own, so the builder
    // takes both and `build` rejects the pair.
    b.neumann(two.left())
        .unwrap()
        .signorini(two.left(), 0.1)
        .unwrap();
    match b.build().unwrap_err() {
        ModelError::OverconstrainedEnd { end, first, second } => {
            assert_eq!(end, two.left());
            assert!(first.starts_with("Neumann"), "{first}");
            assert!(second.starts_with("Signorini"), "{second}");
        }
        other => panic!("expected OverconstrainedEnd, got {other:?}"),
    }

    // A contact of an end with itself: rejected at the call, and not added.
    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::unit());
    b.dirichlet(bar.left()).unwrap();
    let repeated = b.contact(bar.right(), bar.right(), 0.1).unwrap_err();
    assert!(matches!(
        repeated,
        ModelError::RepeatedEnd { end, .. } if end == bar.right()
    ));
    assert!(
        repeated
            .to_string()
            .ends_with("lists the right end (x = l) of bar 0 (the 1st added) twice"),
        "{repeated}"
    );
    assert_eq!(
        b.build().unwrap_err(),
        ModelError::UnconstrainedEnd { end: bar.right() }
    );
}

#[test]
fn unknown_bar_from_another_builder() {
    let mut other = AssemblyBuilder::new();
    other.add_bar(Bar::unit());
    other.add_bar(Bar::unit());
    let foreign = other.add_bar(Bar::unit());
    assert_eq!(foreign.index(), 2);
    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::unit());
    b.dirichlet(bar.left())
        .unwrap()
        .neumann(bar.right())
        .unwrap();
    match b.dirichlet(foreign.left()).unwrap_err() {
        ModelError::UnknownBar {
            condition,
            bar,
            bars,
        } => {
            assert_eq!((bar, bars), (2, 1));
            assert!(condition.starts_with("Dirichlet"), "{condition}");
            let message = b.dirichlet(foreign.left()).unwrap_err().to_string();
            assert!(
                message.ends_with("refers to bar 2 (the 3rd added), but the assembly has 1 bar(s)"),
                "{message}"
            );
        }
        other => panic!("expected UnknownBar, got {other:?}"),
    }
    // The rejected condition was not added.
    assert!(b.build().is_ok());
}

/// A condition that gives `rows` linear rows on `ends.len()` ends.
#[derive(Debug)]
struct Miscounted {
    ends: Vec<EndRef>,
    rows: usize,
}

impl BoundaryCondition for Miscounted {
    fn name(&self) -> String {
        "miscounted".into()
    }
    fn ends(&self) -> Vec<EndRef> {
        self.ends.clone()
    }
    fn linear_rows(&self, _: f64, _: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
        for _ in 0..self.rows {
            rows.push(&[Term::new(self.ends[0], Quantity::Displacement, 1.0)]);
        }
    }
}

#[test]
fn wrong_equation_count() {
    for (ends, rows) in [(1, 0), (1, 2), (2, 1), (2, 3)] {
        let mut b = AssemblyBuilder::new();
        let bar = b.add_bar(Bar::unit());
        let all = [bar.left(), bar.right()];
        let result = b.add_condition(Miscounted {
            ends: all[..ends].to_vec(),
            rows,
        });
        assert_eq!(
            result.map(|_| ()).unwrap_err(),
            ModelError::EquationCount {
                condition: "miscounted".into(),
                ends,
                rows,
                laws: 0,
            }
        );
    }
}

#[test]
fn bad_harmonic_balance_settings() {
    let system = clamped();
    let err = |settings| NonsmoothSystem::new(&system, settings).unwrap_err();
    let zero = HarmonicBalanceSettings {
        harmonics: 0,
        ..Default::default()
    };
    assert_eq!(err(zero), Error::Settings(SettingsError::ZeroHarmonics));
    for n_h in [0, 1, 2] {
        let s = HarmonicBalanceSettings {
            samples_per_harmonic: n_h,
            ..Default::default()
        };
        assert_eq!(
            err(s),
            Error::Settings(SettingsError::TooFewSamples { got: n_h, min: 3 })
        );
    }
    assert!(NonsmoothSystem::new(
        &system,
        HarmonicBalanceSettings {
            samples_per_harmonic: 3,
            ..Default::default()
        }
    )
    .is_ok());
    for v in BAD {
        match err(HarmonicBalanceSettings {
            complementarity: v,
            ..Default::default()
        }) {
            Error::Settings(SettingsError::NotPositive { what, value }) => {
                assert_eq!(what, "complementarity parameter a_c");
                assert!(same(value, v));
            }
            other => panic!("a_c {v}: {other:?}"),
        }
    }
    // Errors reach backbone unchanged.
    assert_eq!(
        grid_run(&system, zero, BackboneOptions::on_grid(PAPER_GRID, 1, 1)).unwrap_err(),
        Error::Settings(SettingsError::ZeroHarmonics)
    );
}

#[test]
fn system_without_contact() {
    let system = linear_only();
    assert_eq!(system.contact_count(), 0);
    assert_eq!(
        NonsmoothSystem::new(&system, HarmonicBalanceSettings::default()).unwrap_err(),
        Error::Settings(SettingsError::NoContact)
    );
    assert_eq!(
        grazing_energy(&system).unwrap_err(),
        SettingsError::NoContact
    );
    assert_eq!(
        grid_run(
            &system,
            HarmonicBalanceSettings::default(),
            BackboneOptions::on_grid(PAPER_GRID, 1, 1),
        )
        .unwrap_err(),
        Error::Settings(SettingsError::NoContact)
    );
    // Linear modes of a linear system are fine.
    let modes = natural_frequencies(&system, ContactState::Open, 5.0).unwrap();
    assert_eq!(modes.len(), 2);
}

#[test]
fn bad_modes_and_subharmonics() {
    let system = clamped();
    let settings = HarmonicBalanceSettings {
        harmonics: 5,
        ..Default::default()
    };
    let run = |mode, subharmonic| {
        let options = BackboneOptions::on_grid(PAPER_GRID, mode, subharmonic);
        grid_run(&system, settings, options).unwrap_err()
    };
    assert_eq!(
        run(0, 1),
        Error::Settings(SettingsError::ZeroIndex {
            what: "mode number",
            value: 0
        })
    );
    assert_eq!(
        run(1, 0),
        Error::Settings(SettingsError::ZeroIndex {
            what: "subharmonic order",
            value: 0
        })
    );
    assert_eq!(
        run(1, 6),
        Error::Settings(SettingsError::HarmonicOutOfRange {
            subharmonic: 6,
            harmonics: 5
        })
    );
    let mut problem = NonsmoothSystem::new(&system, settings).unwrap();
    for v in BAD {
        match branch_seed(&mut problem, 1, 1, v).unwrap_err() {
            Error::Settings(SettingsError::NotPositive { what, value }) => {
                assert_eq!(what, "fundamental frequency");
                assert!(same(value, v));
            }
            other => panic!("omega {v}: {other:?}"),
        }
    }
    // A valid seed has no NaN and a subharmonic seed lives on its harmonic only.
    let seed = branch_seed(&mut problem, 1, 5, 2.0 * PI / 3.9).unwrap();
    assert!(seed.iter().all(|v| v.is_finite()));
    for (i, v) in seed.iter().enumerate() {
        assert_eq!(*v != 0.0, i / 2 == 5 && *v != 0.0, "entry {i}");
    }
    assert!(seed[problem.index(5, 0, 1)] != 0.0);
    for v in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        match natural_frequencies(&system, ContactState::Open, v).unwrap_err() {
            SettingsError::NotPositive { what, value } => {
                assert_eq!(what, "upper frequency");
                assert!(same(value, v));
            }
            other => panic!("{other:?}"),
        }
    }
}

/// The clamped system at `T = 3.6`.
fn frozen(problem: &mut NonsmoothSystem) -> &mut NonsmoothSystem {
    problem.set_parameter(2.0 * PI / 3.6);
    problem
}

#[test]
fn solver_input_errors() {
    let settings = HarmonicBalanceSettings {
        harmonics: 6,
        ..Default::default()
    };
    let mut problem = NonsmoothSystem::new(&clamped(), settings).unwrap();
    let n = problem.dimension();
    let solvers: [&dyn NonlinearSolver; 2] = [&SemismoothNewton::default(), &Dogleg::default()];
    for solver in solvers {
        let mut x = vec![0.0; n];
        x[3] = f64::NAN;
        assert_eq!(
            solver.solve(&mut frozen(&mut problem), &mut x).unwrap_err(),
            SolveError::NonFinite {
                what: "initial guess",
                iteration: 0
            }
        );
        x[3] = f64::INFINITY;
        assert!(matches!(
            solver.solve(&mut frozen(&mut problem), &mut x),
            Err(SolveError::NonFinite {
                what: "initial guess",
                ..
            })
        ));
        for len in [0, n - 1, n + 1] {
            let mut x = vec![0.0; len];
            assert_eq!(
                solver.solve(&mut frozen(&mut problem), &mut x).unwrap_err(),
                SolveError::Dimension {
                    got: len,
                    expected: n
                }
            );
        }
    }
}

#[test]
fn iteration_budget() {
    let settings = HarmonicBalanceSettings {
        harmonics: 6,
        ..Default::default()
    };
    let mut problem = NonsmoothSystem::new(&clamped(), settings).unwrap();
    let omega = 2.0 * PI / 3.6;
    // A poor start: the seed of the branch blown up five times, with every harmonic excited.
    let seed = branch_seed(&mut problem, 1, 1, omega).unwrap();
    let start: Vec<f64> = seed
        .iter()
        .enumerate()
        .map(|(i, s)| 5.0 * s + 1e-3 * ((i % 5) as f64 - 2.0))
        .collect();
    let tolerance = 1e-9 * 1e-3;
    let newton = SemismoothNewton::new(NewtonOptions {
        max_iterations: 1,
        ..Default::default()
    })
    .unwrap();
    let dogleg = Dogleg::new(DoglegOptions {
        max_iterations: 1,
        ..Default::default()
    })
    .unwrap();
    let solvers: [&dyn NonlinearSolver; 2] = [&newton, &dogleg];
    for solver in solvers {
        let mut x = start.clone();
        match solver.solve(&mut frozen(&mut problem), &mut x).unwrap_err() {
            SolveError::MaxIterations {
                iterations,
                residual_norm,
                tolerance: tol,
            } => {
                assert_eq!(iterations, 1);
                assert!((tol / tolerance - 1.0).abs() < 1e-12, "tolerance {tol:e}");
                assert!(residual_norm.is_finite() && residual_norm > tol);
            }
            other => panic!("expected MaxIterations, got {other:?}"),
        }
        // The last iterate is returned, finite.
        assert!(x.iter().all(|v| v.is_finite()));
        assert_ne!(x, start);
    }
    // With a generous budget (50 iterations, line search down to 1e-10) the same start
    // converges (to a finite solution).
    let mut x = start.clone();
    let generous = SemismoothNewton::new(NewtonOptions {
        max_iterations: 50,
        min_step: 1e-10,
        ..Default::default()
    })
    .unwrap();
    let info = generous.solve(&mut frozen(&mut problem), &mut x).unwrap();
    assert!(info.residual_norm <= tolerance && info.residual_norm.is_finite());
    assert!(x.iter().all(|v| v.is_finite()));
    // The same poor start with a stagnation (or plateau) window of five iterations: its
    // residual does not halve within five iterations, so the solve stops early with the two
    // norms that show it.
    let stall = NewtonOptions {
        stall_window: 5,
        ..Default::default()
    };
    let plateau = NewtonOptions {
        plateau_window: 5,
        plateau_ratio: 0.5,
        ..Default::default()
    };
    for options in [stall, plateau] {
        let mut x = start.clone();
        let fast = SemismoothNewton::new(options).unwrap();
        match fast.solve(&mut frozen(&mut problem), &mut x).unwrap_err() {
            SolveError::Stagnated {
                iteration,
                residual_norm,
                earlier_residual_norm,
                window,
            } => {
                assert_eq!(window, 5);
                assert!(iteration >= 5 && iteration < info.iterations);
                assert!(residual_norm > 0.5 * earlier_residual_norm);
                assert!(residual_norm.is_finite() && residual_norm > tolerance);
            }
            other => panic!("expected Stagnated, got {other:?}"),
        }
        assert!(x.iter().all(|v| v.is_finite()));
    }
    // The same start with half the residual evaluations the generous solve needed: it stops
    // in a line search once the budget is spent, with the count that shows it.
    let budget = info.residual_evaluations / 2;
    let mut x = start.clone();
    let budgeted = SemismoothNewton::new(NewtonOptions {
        max_evaluations: budget,
        ..Default::default()
    })
    .unwrap();
    match budgeted
        .solve(&mut frozen(&mut problem), &mut x)
        .unwrap_err()
    {
        SolveError::EvaluationBudget {
            iteration,
            evaluations,
            residual_norm,
        } => {
            assert_eq!(evaluations, budget);
            assert!(iteration < info.iterations);
            assert!(residual_norm.is_finite() && residual_norm > tolerance);
        }
        other => panic!("expected EvaluationBudget, got {other:?}"),
    }
    assert!(x.iter().all(|v| v.is_finite()));
}

#[test]
fn zero_evaluation_budget_is_refused() {
    let e = SemismoothNewton::new(NewtonOptions {
        max_evaluations: 0,
        ..Default::default()
    })
    .unwrap_err();
    assert!(
        matches!(
            e,
            SolveError::InvalidOption {
                what: "max_evaluations",
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn stall_and_plateau_ratios_above_one_are_refused() {
    let o = NewtonOptions::fail_fast();
    for (options, name) in [
        (
            NewtonOptions {
                stall_ratio: 1.5,
                ..o
            },
            "stall_ratio",
        ),
        (
            NewtonOptions {
                plateau_ratio: 1.5,
                ..o
            },
            "plateau_ratio",
        ),
    ] {
        let e = SemismoothNewton::new(options).unwrap_err();
        assert!(
            matches!(e, SolveError::InvalidOption { what, value } if value == 1.5 && what.starts_with(name)),
            "{e:?}"
        );
    }
}

/// `F(x) = x - 1` with a zero Jacobian.
struct ZeroJacobian;

impl Problem for ZeroJacobian {
    fn dimension(&self) -> usize {
        3
    }
    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        for (fi, xi) in f.iter_mut().zip(x) {
            *fi = xi - 1.0;
        }
    }
    fn jacobian(&mut self, _: &[f64], jac: &mut DenseMatrix) {
        jac.reset(3, 3);
    }
}

/// `F(x) = x` with a NaN in the Jacobian.
struct NanJacobian;

impl Problem for NanJacobian {
    fn dimension(&self) -> usize {
        2
    }
    fn residual(&mut self, x: &[f64], f: &mut [f64]) {
        f.copy_from_slice(x);
    }
    fn jacobian(&mut self, _: &[f64], jac: &mut DenseMatrix) {
        jac.reset(2, 2);
        jac[(0, 0)] = f64::NAN;
        jac[(1, 1)] = 1.0;
    }
}

#[test]
fn singular_jacobian() {
    let solvers: [&dyn NonlinearSolver; 2] = [&SemismoothNewton::default(), &Dogleg::default()];
    for solver in solvers {
        let mut x = vec![0.0; 3];
        match solver.solve(&mut ZeroJacobian, &mut x).unwrap_err() {
            SolveError::SingularJacobian {
                iteration,
                pivot,
                ratio,
            } => {
                assert_eq!(iteration, 0);
                assert!(pivot < 3);
                assert_eq!(ratio, 0.0);
            }
            other => panic!("expected SingularJacobian, got {other:?}"),
        }
    }
}

/// A NaN in the Jacobian is reported as such by both solvers (the residual is finite).
#[test]
fn non_finite_jacobian() {
    let solvers: [(&str, &dyn NonlinearSolver); 2] = [
        ("newton", &SemismoothNewton::default()),
        ("dogleg", &Dogleg::default()),
    ];
    for (name, solver) in solvers {
        let mut x = vec![1.0, 1.0];
        assert_eq!(
            solver.solve(&mut NanJacobian, &mut x).unwrap_err(),
            SolveError::NonFinite {
                what: "Jacobian",
                iteration: 0
            },
            "{name}"
        );
    }
}

#[test]
fn invalid_solver_options() {
    for v in BAD {
        let check = |r: Result<(), SolveError>, what: &str| match r {
            Err(SolveError::InvalidOption { what: w, value }) => {
                assert_eq!(w, what);
                assert!(same(value, v));
            }
            other => panic!("{what} = {v}: {other:?}"),
        };
        let o = NewtonOptions::default();
        check(
            SemismoothNewton::new(NewtonOptions { tolerance: v, ..o }).map(|_| ()),
            "tolerance",
        );
        check(
            SemismoothNewton::new(NewtonOptions { armijo: v, ..o }).map(|_| ()),
            "armijo",
        );
        check(
            SemismoothNewton::new(NewtonOptions { min_step: v, ..o }).map(|_| ()),
            "min_step",
        );
        check(
            SemismoothNewton::new(NewtonOptions {
                stall_ratio: v,
                ..o
            })
            .map(|_| ()),
            "stall_ratio",
        );
        check(
            SemismoothNewton::new(NewtonOptions {
                plateau_ratio: v,
                ..o
            })
            .map(|_| ()),
            "plateau_ratio",
        );
        let o = DoglegOptions::default();
        check(
            Dogleg::new(DoglegOptions { tolerance: v, ..o }).map(|_| ()),
            "tolerance",
        );
        check(
            Dogleg::new(DoglegOptions {
                initial_radius: v,
                ..o
            })
            .map(|_| ()),
            "initial_radius",
        );
        check(
            Dogleg::new(DoglegOptions { min_radius: v, ..o }).map(|_| ()),
            "min_radius",
        );
    }
    assert!(SemismoothNewton::new(NewtonOptions::default()).is_ok());
    assert!(Dogleg::new(DoglegOptions::default()).is_ok());
}

/// The options' own `validate` gives the error of the constructor, and a solver keeps the
/// options it was built with (the defaults for `Default`).
#[test]
fn solver_options_validate_and_read_back() {
    let newton = NewtonOptions {
        min_step: 1e-6,
        ..NewtonOptions::fail_fast()
    };
    assert_eq!(newton.validate(), Ok(()));
    assert_eq!(SemismoothNewton::new(newton).unwrap().options(), &newton);
    assert_eq!(
        SemismoothNewton::default().options(),
        &NewtonOptions::default()
    );
    let bad = NewtonOptions {
        max_evaluations: 0,
        ..newton
    };
    assert_eq!(
        bad.validate(),
        SemismoothNewton::new(bad).map(|_| ()),
        "max_evaluations"
    );
    assert!(bad.validate().is_err());

    let dogleg = DoglegOptions {
        initial_radius: 0.5,
        ..DoglegOptions::default()
    };
    assert_eq!(dogleg.validate(), Ok(()));
    assert_eq!(Dogleg::new(dogleg).unwrap().options(), &dogleg);
    assert_eq!(Dogleg::default().options(), &DoglegOptions::default());
    for min_radius in [0.0, f64::NAN] {
        let bad = DoglegOptions {
            min_radius,
            ..dogleg
        };
        match (bad.validate(), Dogleg::new(bad)) {
            (
                Err(SolveError::InvalidOption {
                    what: "min_radius",
                    value,
                }),
                Err(SolveError::InvalidOption {
                    what: "min_radius",
                    value: again,
                }),
            ) => assert!(same(value, min_radius) && same(again, min_radius)),
            other => panic!("min_radius = {min_radius}: {other:?}"),
        }
    }
}

type Driver = Sequential<'static, NonsmoothSystem, SemismoothNewton>;

/// `range` is the range `what` from `start` to `end` (`steps` values for a grid) refused for
/// `defect`, its numbers as given (a NaN end as NaN) and quoted in its message.
fn assert_range(
    range: &BadRange,
    what: &str,
    (start, end, steps): (f64, f64, Option<usize>),
    defect: RangeDefect,
) {
    assert_eq!(range.what, what);
    assert_eq!(range.defect, defect, "{range:?}");
    assert!(
        same(range.start, start) && same(range.end, end),
        "{range:?}"
    );
    assert_eq!(range.steps, steps);
    let message = range.to_string();
    let mut quoted = format!("the {what} from {start} to {end}");
    if let Some(steps) = steps {
        quoted += &format!(" in {steps} step");
    }
    assert!(message.contains(&quoted), "{message}");
}

/// `result` refuses `grid` as a period grid with `defect`, quoting it as given.
fn assert_bad_grid(result: Result<ModeBranches, Error>, grid: PeriodGrid, defect: RangeDefect) {
    match result {
        Err(e) => {
            let Error::Settings(SettingsError::Range(r)) = &e else {
                panic!("grid {grid:?}: expected a bad range, got {e:?}");
            };
            assert!(e.bad_range().is_some_and(|b| std::ptr::eq(b, r)));
            let ends = (grid.start, grid.end, Some(grid.steps));
            assert_range(r, "period grid", ends, defect);
        }
        Ok(run) => panic!("grid {grid:?} ran, {} points", run.points.len()),
    }
}

#[test]
fn bad_continuation_ranges() {
    let invalid = |r: Result<Vec<f64>, ContinuationError>,
                   what: &str,
                   given: (f64, f64, usize),
                   defect: RangeDefect| match r {
        Err(ContinuationError::Range(range)) => {
            assert_range(&range, what, (given.0, given.1, Some(given.2)), defect)
        }
        other => panic!("{what}: {other:?}"),
    };
    for steps in [0, 1] {
        let given = (3.9, 3.1, steps);
        invalid(
            linspace(3.9, 3.1, steps),
            "grid",
            given,
            RangeDefect::SinglePoint,
        );
        invalid(
            geomspace(3.9, 3.1, steps),
            "geometric grid",
            given,
            RangeDefect::SinglePoint,
        );
    }
    for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let not_finite = RangeDefect::NotFinite;
        invalid(linspace(v, 3.1, 10), "grid", (v, 3.1, 10), not_finite);
        invalid(linspace(3.9, v, 10), "grid", (3.9, v, 10), not_finite);
        invalid(
            geomspace(v, 3.1, 10),
            "geometric grid",
            (v, 3.1, 10),
            not_finite,
        );
    }
    for v in [0.0, -1.0] {
        let given = (v, 3.1, 10);
        invalid(
            geomspace(v, 3.1, 10),
            "geometric grid",
            given,
            RangeDefect::NotPositive,
        );
    }
    let values = linspace(3.9, 3.1, 5).unwrap();
    assert_eq!(values.len(), 5);
    assert!(values.iter().all(|v| v.is_finite()));

    let settings = HarmonicBalanceSettings {
        harmonics: 4,
        ..Default::default()
    };
    let problem = || NonsmoothSystem::new(&clamped(), settings).unwrap();
    let n = problem().dimension();
    let new = |start: Vec<f64>, values: Vec<f64>| {
        Driver::new(
            problem(),
            SemismoothNewton::default(),
            start,
            values,
            SequentialOptions::default(),
        )
        .map(|_| ())
    };
    assert_eq!(
        new(vec![0.0; n], vec![]).unwrap_err(),
        ContinuationError::InvalidOption {
            what: "number of parameter values",
            value: 0.0
        }
    );
    // Several values, all equal, would compute one point again and again.
    match new(vec![0.0; n], vec![1.6; 4]).unwrap_err() {
        ContinuationError::Range(range) => assert_range(
            &range,
            "parameter values",
            (1.6, 1.6, Some(4)),
            RangeDefect::Empty,
        ),
        other => panic!("{other:?}"),
    }
    match new(vec![0.0; n], vec![1.0, f64::NAN]).unwrap_err() {
        ContinuationError::InvalidOption { what, value } => {
            assert_eq!(what, "parameter value");
            assert!(value.is_nan());
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        new(vec![0.0; n + 2], vec![1.6]).unwrap_err(),
        ContinuationError::Dimension {
            got: n + 2,
            expected: n
        }
    );
    assert!(new(vec![0.0; n], vec![1.6]).is_ok());
}

#[test]
fn bad_period_grids() {
    let system = clamped();
    let settings = HarmonicBalanceSettings {
        harmonics: 4,
        ..Default::default()
    };
    let run = |grid: PeriodGrid, trivial_energy: f64| {
        let options = BackboneOptions {
            trivial_energy,
            ..BackboneOptions::on_grid(grid, 1, 1)
        };
        grid_run(&system, settings, options)
    };
    for v in BAD {
        for grid in [
            PeriodGrid {
                start: v,
                end: 3.5,
                steps: 5,
            },
            PeriodGrid {
                start: 3.9,
                end: v,
                steps: 5,
            },
        ] {
            let defect = if v.is_finite() {
                RangeDefect::NotPositive
            } else {
                RangeDefect::NotFinite
            };
            assert_bad_grid(run(grid, 1e-6), grid, defect);
        }
    }
    let single = PeriodGrid {
        start: 3.9,
        end: 3.5,
        steps: 1,
    };
    assert_bad_grid(run(single, 1e-6), single, RangeDefect::SinglePoint);
    for v in [-1.0, f64::NAN, f64::INFINITY] {
        match run(
            PeriodGrid {
                start: 3.9,
                end: 3.5,
                steps: 3,
            },
            v,
        )
        .unwrap_err()
        {
            Error::Continuation(ContinuationError::InvalidOption { what, value }) => {
                assert_eq!(what, "trivial_energy");
                assert!(same(value, v));
            }
            other => panic!("{other:?}"),
        }
    }
    // The arclength backbone checks the same floor.
    for v in [-1.0, f64::NAN, f64::INFINITY] {
        let options = ArclengthBackboneOptions {
            trivial_energy: v,
            ..ArclengthBackboneOptions::for_mode(&system, 1, 1).unwrap()
        };
        let request = Request {
            settings,
            method: Method::Arclength(options),
            solver: Some(Solver::default()),
            ..Request::new(1)
        };
        let result = compute(&system, &request);
        match result.unwrap_err() {
            Error::Continuation(ContinuationError::InvalidOption { what, value }) => {
                assert_eq!(what, "trivial_energy");
                assert!(same(value, v));
            }
            other => panic!("{other:?}"),
        }
    }
    // A good grid gives finite results everywhere, converged or not.
    let points = run(
        PeriodGrid {
            start: 3.9,
            end: 3.5,
            steps: 5,
        },
        1e-6,
    )
    .unwrap()
    .points;
    assert_eq!(points.len(), 5);
    for p in &points {
        assert!(p.period.is_finite() && p.omega.is_finite());
        assert!(p.energy.is_finite() && p.energy_normalized.is_finite());
        assert!(p.residual_norm.is_finite());
        assert!(p.x.iter().all(|v| v.is_finite()));
    }
}

/// A period grid whose ends are equal would compute its one point at every step: refused,
/// quoting the grid, by a named method and by `Method::Auto`, which also quotes a negative
/// period as typed (not the frequency it would derive). Either direction of a grid is fine.
#[test]
fn degenerate_period_grids_are_refused_as_given() {
    let system = clamped();
    let settings = HarmonicBalanceSettings {
        harmonics: 4,
        ..Default::default()
    };
    let empty = PeriodGrid {
        start: 3.5,
        end: 3.5,
        steps: 181,
    };
    let negative = PeriodGrid {
        start: -3.5,
        ..PAPER_GRID
    };
    for (grid, defect) in [
        (empty, RangeDefect::Empty),
        (negative, RangeDefect::NotPositive),
    ] {
        let options = BackboneOptions::on_grid(grid, 1, 1);
        for method in [
            Method::PeriodGrid(options),
            Method::Auto(Some(options)),
            Method::GenuineSubharmonic(BackboneOptions::on_grid(grid, 1, 2)),
        ] {
            let request = Request::for_method(method).settings(settings);
            let result = compute(&system, &request);
            if let Err(e) = &result {
                assert!(!e.to_string().contains("frequency"), "{e}");
            }
            assert_bad_grid(result, grid, defect);
        }
    }
    let message = empty.validate().unwrap_err().to_string();
    assert!(
        message.contains("from 3.5 to 3.5 in 181 steps is empty"),
        "{message}"
    );
    let rising = PeriodGrid {
        start: PAPER_GRID.end,
        end: PAPER_GRID.start,
        ..PAPER_GRID
    };
    assert!(rising.validate().is_ok() && PAPER_GRID.validate().is_ok());
}

/// Energy levels climb from the grazing point: equal ends and a falling grid are refused,
/// quoting the levels.
#[test]
fn degenerate_energy_grids_are_refused_as_given() {
    let system = clamped();
    for (start, end, defect) in [
        (2.0, 2.0, RangeDefect::Empty),
        (300.0, 1.0, RangeDefect::Reversed),
        (0.0, 2.0, RangeDefect::NotPositive),
    ] {
        let levels = EnergyGrid {
            start,
            end,
            steps: 5,
        };
        let options = EnergyBackboneOptions {
            levels,
            ..EnergyBackboneOptions::for_mode(&system, 1, 1).unwrap()
        };
        let request = Request::for_method(Method::Energy(options)).harmonics(4);
        match compute(&system, &request) {
            Err(Error::Settings(SettingsError::Range(r))) => {
                assert_range(&r, "energy grid", (start, end, Some(5)), defect);
            }
            other => panic!("{levels:?}: {:?}", other.map(|r| r.points.len())),
        }
    }
}

/// A forced response climbs its frequency range from its lower end: `2:1` is refused as
/// reversed, `1:1` as empty, and ends that are not positive and finite as such, each
/// quoting the range.
#[test]
fn degenerate_forcing_ranges_are_refused_as_given() {
    let system = clamped();
    let base = system.bar_id(0).unwrap().left();
    let request = |omega_range| ResponseRequest {
        settings: HarmonicBalanceSettings {
            harmonics: 4,
            ..Default::default()
        },
        forcing: Forcing {
            damping: Damping::Uniform(1e-3),
            excitations: vec![Excitation::base_motion(base, 1e-6)],
        },
        omega_range,
        steps: 10,
        method: ResponseMethod::Sequential,
        solver: Solver::default(),
    };
    for ((lo, hi), defect) in [
        ((2.0, 1.0), RangeDefect::Reversed),
        ((1.5, 1.5), RangeDefect::Empty),
        ((-1.0, 2.0), RangeDefect::NotPositive),
        ((f64::NAN, 2.0), RangeDefect::NotFinite),
    ] {
        match forced_response(&system, &request((lo, hi))) {
            Err(Error::Settings(SettingsError::Range(r))) => {
                assert_range(&r, "forcing frequency range", (lo, hi, None), defect);
            }
            other => panic!("{lo}:{hi}: {:?}", other.map(|r| r.points.len())),
        }
    }
    let message = forced_response(&system, &request((2.0, 1.0)))
        .unwrap_err()
        .to_string();
    assert!(message.contains("from 2 to 1 is reversed"), "{message}");
}

/// A continuation's parameter range that is empty or reversed, and natural-parameter values
/// that are all the same, are refused before the run starts, quoting them: the arclength
/// backbone's frequency range, the driver's options and the values of `parameter_branch`.
#[test]
fn degenerate_parameter_ranges_are_refused_as_given() {
    let system = clamped();
    for ((lo, hi), defect) in [
        ((2.0, 1.0), RangeDefect::Reversed),
        ((1.6, 1.6), RangeDefect::Empty),
    ] {
        let options = ArclengthBackboneOptions {
            omega_range: (lo, hi),
            ..ArclengthBackboneOptions::for_mode(&system, 1, 1).unwrap()
        };
        let request = Request::for_method(Method::Arclength(options)).harmonics(4);
        match compute(&system, &request) {
            Err(Error::Settings(SettingsError::Range(r))) => {
                assert_range(&r, "frequency range", (lo, hi, None), defect);
            }
            other => panic!("{lo}:{hi}: {:?}", other.map(|r| r.points.len())),
        }
        let driver = ArclengthOptions {
            parameter_range: (lo, hi),
            ..Default::default()
        };
        match driver.validate() {
            Err(ContinuationError::Range(r)) => {
                assert_range(&r, "parameter range", (lo, hi, None), defect);
            }
            other => panic!("{lo}:{hi}: {other:?}"),
        }
    }
    let settings = HarmonicBalanceSettings {
        harmonics: 4,
        ..Default::default()
    };
    let n = NonsmoothSystem::new(&system, settings).unwrap().dimension();
    let gap = 1e-3;
    let steps = ParameterSteps::Values(vec![gap; 4], SequentialOptions::default());
    let result = parameter_branch(
        clamped_bar_with_obstacle,
        settings,
        (vec![0.0; n], 2.0 * PI / 3.6),
        gap,
        steps,
        SemismoothNewton::default(),
        |_, _| std::ops::ControlFlow::Continue(()),
    );
    match result {
        Err(Error::Continuation(ContinuationError::Range(r))) => {
            let ends = (gap, gap, Some(4));
            assert_range(&r, "parameter values", ends, RangeDefect::Empty);
        }
        other => panic!("{:?}", other.map(|b| b.points.len())),
    }
}

/// Errors display their numbers.
#[test]
fn error_messages_carry_the_numbers() {
    let e = Error::from(SolveError::MaxIterations {
        iterations: 7,
        residual_norm: 2.5e-3,
        tolerance: 1e-12,
    });
    let s = e.to_string();
    assert!(
        s.contains('7') && s.contains("2.5e-3") && s.contains("1e-12"),
        "{s}"
    );
    let e = Error::from(ModelError::NotPositive {
        what: "bar length",
        value: -2.0,
    });
    assert!(e.to_string().contains("bar length") && e.to_string().contains("-2"));
}

#[test]
fn kink_blend_must_be_non_negative_and_finite() {
    let system = nonsmooth_modes::reference::clamped_bar_with_obstacle(1e-3).unwrap();
    for v in [-1e-4, f64::NAN, f64::INFINITY] {
        let settings = HarmonicBalanceSettings {
            kink_blend: v,
            ..Default::default()
        };
        match NonsmoothSystem::new(&system, settings) {
            Err(Error::Settings(SettingsError::NotPositive { what, value })) => {
                assert_eq!(what, "kink blend (non-negative)");
                assert!(value.is_nan() || value == v);
            }
            other => panic!("kink blend {v}: {other:?}"),
        }
    }
    let exact = HarmonicBalanceSettings {
        kink_blend: 0.0,
        ..Default::default()
    };
    assert!(NonsmoothSystem::new(&system, exact).is_ok());
}

/// A run is lifted to more harmonics, never fewer, and not to zero: the error names both
/// numbers.
#[test]
fn a_run_is_not_lifted_to_fewer_harmonics() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let grid = PeriodGrid {
        start: 3.9,
        end: 3.8,
        steps: 3,
    };
    let method = Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1));
    let run = compute(&system, &Request::for_method(method).harmonics(12)).unwrap();
    match lift(&run, &Request::for_method(method).harmonics(11)) {
        Err(Error::Settings(SettingsError::LiftToFewerHarmonics { from: 12, to: 11 })) => {}
        other => panic!("{other:?}"),
    }
    let zero = Request::for_method(method).harmonics(0);
    assert!(lift(&run, &zero).is_err());
    // The same harmonics solve each point again, where it already is.
    let same = lift(&run, &Request::for_method(method).harmonics(12)).unwrap();
    assert_eq!(same.converged().count(), run.converged().count());
}
