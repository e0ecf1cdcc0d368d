//! The analytic generalised Jacobian and `dF/dOmega` of the harmonic-balance system against
//! central finite differences, away from kinks, for the paper's three systems.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::continuation::{ContinuationProblem, PeriodParametrised};
use nonsmooth_modes::linalg::DenseMatrix;
use nonsmooth_modes::modal::branch_seed;
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact,
};
use nonsmooth_modes::solve::Problem;
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};
use proptest::prelude::*;
use std::f64::consts::PI;
use std::sync::OnceLock;

const GAP: f64 = 1e-3;

/// The paper's three systems with a period range of their first nonsmooth mode.
fn system(which: usize) -> (BarSystem, f64, f64) {
    match which {
        0 => (clamped_bar_with_obstacle(GAP).unwrap(), 3.05, 3.95),
        1 => (robin_bar_with_obstacle(0.5, GAP).unwrap(), 6.0, 9.5),
        _ => (
            two_bars_in_contact(Bar::new(0.95, 1.0, 1.0).unwrap(), GAP).unwrap(),
            3.05,
            3.95,
        ),
    }
}

/// Which branch of `r = -min(lambda, a_c g)` every time sample of every law takes.
fn active_set(problem: &mut NonsmoothSystem, x: &[f64], omega: f64) -> Vec<bool> {
    let a_c = problem.complementarity();
    let laws = problem.system().contact_count();
    let mut set = Vec::new();
    for l in 0..laws {
        let g = problem.gap_history(x, omega, l);
        let f = problem.force_history(x, omega, l);
        set.extend(g.iter().zip(&f).map(|(g, f)| *f < a_c * g));
    }
    set
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// The branch seed of each system and basis size, at the middle of its period range (the
/// mode search is the slow part; the seed's shape does not depend on the period).
fn seed(which: usize, harmonics: usize) -> Vec<f64> {
    static SEEDS: OnceLock<Vec<Vec<f64>>> = OnceLock::new();
    let seeds = SEEDS.get_or_init(|| {
        (0..6)
            .map(|k| {
                let (sys, t0, t1) = system(k / 2);
                let m = if k % 2 == 0 { 3 } else { 8 };
                let settings = HarmonicBalanceSettings {
                    harmonics: m,
                    // The exact generalised Jacobian is what is checked here.
                    kink_blend: 0.0,
                    ..Default::default()
                };
                let mut problem = NonsmoothSystem::new(&sys, settings).unwrap();
                branch_seed(&mut problem, 1, 1, 4.0 * PI / (t0 + t1)).unwrap()
            })
            .collect()
    });
    seeds[2 * which + usize::from(harmonics == 8)].clone()
}

/// A point of the system's unknown space: the linear-mode seed, scaled so that the contact
/// closes and penetrates, plus a random perturbation of size `~0.3 g0` on every unknown.
fn point(which: usize, harmonics: usize, scale: f64, perturbation: &[f64]) -> Vec<f64> {
    seed(which, harmonics)
        .iter()
        .zip(perturbation)
        .map(|(s, p)| scale * s + 0.3 * GAP * p)
        .collect()
}

struct Checked {
    columns: usize,
    total: usize,
}

/// Checks every column of the Jacobian at `(x, omega)` whose active set does not change
/// between `x - h e_j` and `x + h e_j` for one of the steps `h = 1e-6 g0, 1e-7 g0, 1e-8 g0`
/// (the largest such); returns how many were checked. The law is piecewise linear, so a
/// smaller step costs only rounding, and a column stays unchecked only when a sample lies
/// within `1e-8 g0` of a kink.
fn check_jacobian(
    problem: &mut NonsmoothSystem,
    x: &[f64],
    omega: f64,
) -> Result<Checked, TestCaseError> {
    let n = x.len();
    let mut jac = DenseMatrix::zeros(n, n);
    problem.set_parameter(omega);
    problem.jacobian(x, &mut jac);
    let reference = active_set(problem, x, omega);
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    let mut checked = 0;
    for j in 0..n {
        let shifted = |h: f64| {
            let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
            xp[j] += h;
            xm[j] -= h;
            (xp, xm)
        };
        let stable = [1e-6, 1e-7, 1e-8].into_iter().map(|s| s * GAP).find(|&h| {
            let (xp, xm) = shifted(h);
            active_set(problem, &xp, omega) == reference
                && active_set(problem, &xm, omega) == reference
        });
        let Some(h) = stable else {
            continue;
        };
        let (xp, xm) = shifted(h);
        problem.set_parameter(omega);
        problem.residual(&xp, &mut fp);
        problem.set_parameter(omega);
        problem.residual(&xm, &mut fm);
        let fd: Vec<f64> = fp
            .iter()
            .zip(&fm)
            .map(|(p, m)| (p - m) / (2.0 * h))
            .collect();
        let col = jac.column(j);
        let scale = inf_norm(col).max(inf_norm(&fd)).max(1e-12);
        for (i, (a, d)) in col.iter().zip(&fd).enumerate() {
            prop_assert!(
                (a - d).abs() <= 1e-6 * scale,
                "J[{i}][{j}] analytic {a:e}, finite difference {d:e} (column scale {scale:e})"
            );
        }
        checked += 1;
    }
    Ok(Checked {
        columns: checked,
        total: n,
    })
}

/// Checks `dF/dOmega` against a central difference in `Omega`; `false` if the active set
/// changes within the step (nothing checked).
fn check_omega_derivative(
    problem: &mut NonsmoothSystem,
    x: &[f64],
    omega: f64,
) -> Result<bool, TestCaseError> {
    let n = x.len();
    let h = 1e-6 * omega;
    let reference = active_set(problem, x, omega);
    if active_set(problem, x, omega + h) != reference
        || active_set(problem, x, omega - h) != reference
    {
        return Ok(false);
    }
    let mut df = vec![0.0; n];
    problem.set_parameter(omega);
    problem.parameter_derivative(x, &mut df);
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    problem.set_parameter(omega + h);
    problem.residual(x, &mut fp);
    problem.set_parameter(omega - h);
    problem.residual(x, &mut fm);
    let fd: Vec<f64> = fp
        .iter()
        .zip(&fm)
        .map(|(p, m)| (p - m) / (2.0 * h))
        .collect();
    let scale = inf_norm(&df).max(inf_norm(&fd)).max(1e-15);
    for (i, (a, d)) in df.iter().zip(&fd).enumerate() {
        prop_assert!(
            (a - d).abs() <= 1e-6 * scale,
            "dF/dOmega[{i}] analytic {a:e}, finite difference {d:e} (scale {scale:e})"
        );
    }
    Ok(true)
}

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 32,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn jacobian_and_omega_derivative_match_finite_differences(
        which in 0..3_usize,
        harmonics in prop_oneof![Just(3_usize), Just(8)],
        period_fraction in 0.0..=1.0_f64,
        scale in 1.2..=2.5_f64,
        perturbation in proptest::collection::vec(-1.0..=1.0_f64, 36),
    ) {
        let (sys, t0, t1) = system(which);
        let settings = HarmonicBalanceSettings { harmonics, kink_blend: 0.0, ..Default::default() };
        let mut problem = NonsmoothSystem::new(&sys, settings).unwrap();
        let period = t0 + period_fraction * (t1 - t0);
        let omega = 2.0 * PI / period;
        let x = point(which, harmonics, scale, &perturbation);
        prop_assert_eq!(x.len(), (harmonics + 1) * 2 * sys.bars().len());
        let set = active_set(&mut problem, &x, omega);
        // Both branches of the law are visited: the point is in contact part of the period.
        prop_assume!(set.iter().any(|&s| s) && set.iter().any(|&s| !s));

        let checked = check_jacobian(&mut problem, &x, omega)?;
        prop_assert!(
            10 * checked.columns >= 9 * checked.total,
            "system {which}, m = {harmonics}, T = {period}: only {} of {} columns away from kinks",
            checked.columns, checked.total
        );
        // The active set is locally constant in Omega for almost every point; when it is not,
        // the case checks nothing for dF/dOmega, but the Jacobian was checked above.
        check_omega_derivative(&mut problem, &x, omega)?;
    }

    #[test]
    fn period_parametrisation_applies_the_chain_rule(
        which in 0..3_usize,
        period_fraction in 0.0..=1.0_f64,
        perturbation in proptest::collection::vec(-1.0..=1.0_f64, 36),
    ) {
        let (sys, t0, t1) = system(which);
        let settings = HarmonicBalanceSettings { harmonics: 8, kink_blend: 0.0, ..Default::default() };
        let mut problem = NonsmoothSystem::new(&sys, settings).unwrap();
        let period = t0 + period_fraction * (t1 - t0);
        let omega = 2.0 * PI / period;
        let x = point(which, 8, 1.5, &perturbation);
        let n = x.len();

        let (mut f_omega, mut df_omega) = (vec![0.0; n], vec![0.0; n]);
        problem.set_parameter(omega);
        problem.residual(&x, &mut f_omega);
        problem.set_parameter(omega);
        problem.parameter_derivative(&x, &mut df_omega);
        let mut j_omega = DenseMatrix::zeros(n, n);
        problem.set_parameter(omega);
        problem.jacobian(&x, &mut j_omega);

        let h = 1e-6 * period;
        let in_set = active_set(&mut problem, &x, omega);
        let stable = active_set(&mut problem, &x, 2.0 * PI / (period + h)) == in_set
            && active_set(&mut problem, &x, 2.0 * PI / (period - h)) == in_set;

        let mut by_period = PeriodParametrised::new(&mut problem);
        prop_assert_eq!(by_period.dimension(), n);
        let (mut f, mut df) = (vec![0.0; n], vec![0.0; n]);
        by_period.set_parameter(period);
        by_period.residual(&x, &mut f);
        prop_assert_eq!(&f, &f_omega);
        let mut jac = DenseMatrix::zeros(n, n);
        by_period.set_parameter(period);
        by_period.jacobian(&x, &mut jac);
        prop_assert_eq!(&jac, &j_omega);
        by_period.set_parameter(period);
        by_period.parameter_derivative(&x, &mut df);
        let chain = -2.0 * PI / (period * period);
        let scale = inf_norm(&df_omega).max(1e-15);
        for (a, b) in df.iter().zip(&df_omega) {
            prop_assert!((a - chain * b).abs() <= 1e-13 * scale * chain.abs());
        }
        if stable {
            let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
            by_period.set_parameter(period + h);
            by_period.residual(&x, &mut fp);
            by_period.set_parameter(period - h);
            by_period.residual(&x, &mut fm);
            let scale = inf_norm(&df).max(1e-15);
            for (i, (a, (p, m))) in df.iter().zip(fp.iter().zip(&fm)).enumerate() {
                let d = (p - m) / (2.0 * h);
                prop_assert!(
                    (a - d).abs() <= 1e-6 * scale,
                    "dF/dT[{i}] analytic {a:e}, finite difference {d:e}"
                );
            }
        }
    }
}

/// Points near a converged solution (where the truncated motion really grazes and closes):
/// a short backbone of each system, each converged point perturbed by 1% of `g0`.
#[test]
fn jacobian_matches_finite_differences_near_converged_points() {
    use nonsmooth_modes::branches::{compute, BackboneOptions, Method, PeriodGrid, Request};
    use nonsmooth_modes::solve::Solver;
    let mut checked = 0;
    let mut total = 0;
    let mut omega_checked = 0;
    let mut points = 0;
    for which in 0..3 {
        let (sys, t0, t1) = system(which);
        for harmonics in [3, 8] {
            let settings = HarmonicBalanceSettings {
                harmonics,
                // The exact generalised Jacobian is what is checked here.
                kink_blend: 0.0,
                ..Default::default()
            };
            let grid = PeriodGrid {
                start: t1 - 0.05 * (t1 - t0),
                end: t0 + 0.6 * (t1 - t0),
                steps: 5,
            };
            let request = Request {
                settings,
                method: Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)),
                solver: Some(Solver::default()),
                ..Request::new(1)
            };
            let branch = compute(&sys, &request).unwrap().points;
            let mut problem = NonsmoothSystem::new(&sys, settings).unwrap();
            for (k, p) in branch.iter().filter(|p| p.converged()).enumerate() {
                let x: Vec<f64> =
                    p.x.iter()
                        .enumerate()
                        .map(|(i, v)| v + 1e-2 * GAP * (((i * 7 + k * 3) % 11) as f64 / 5.0 - 1.0))
                        .collect();
                let c = check_jacobian(&mut problem, &x, p.omega).unwrap();
                checked += c.columns;
                total += c.total;
                omega_checked +=
                    usize::from(check_omega_derivative(&mut problem, &x, p.omega).unwrap());
                points += 1;
            }
        }
    }
    println!("{points} points, {checked} of {total} columns, dF/dOmega at {omega_checked} points");
    assert!(points >= 20, "only {points} converged points");
    assert!(
        10 * checked >= 9 * total,
        "{checked} of {total} columns checked"
    );
    assert!(
        2 * omega_checked >= points,
        "dF/dOmega checked at {omega_checked} of {points} points"
    );
}
