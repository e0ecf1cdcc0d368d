//! The structured solve (linear rows condensed) equals the dense solve of `J dx = -F`, for one
//! right-hand side and for several at once.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::EnergyLevel;
use nonsmooth_modes::continuation::ContinuationProblem;
use nonsmooth_modes::linalg::DenseMatrix;
use nonsmooth_modes::modal::{branch_seed, grazing_energy};
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact,
};
use nonsmooth_modes::solve::{Problem, Structured};
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};
use std::f64::consts::PI;

/// Gaussian elimination with partial pivoting: the dense reference.
fn dense_solve(j: &DenseMatrix, f: &[f64]) -> Vec<f64> {
    let n = f.len();
    let mut a: Vec<Vec<f64>> = (0..n)
        .map(|r| (0..n).map(|c| j[(r, c)]).collect())
        .collect();
    let mut b: Vec<f64> = f.iter().map(|v| -v).collect();
    for k in 0..n {
        let p = (k..n)
            .max_by(|&x, &y| a[x][k].abs().total_cmp(&a[y][k].abs()))
            .unwrap();
        a.swap(k, p);
        b.swap(k, p);
        let (pivot_rows, rest) = a.split_at_mut(k + 1);
        let pivot = &pivot_rows[k];
        for (offset, row) in rest.iter_mut().enumerate() {
            let m = row[k] / pivot[k];
            for (v, p) in row[k..].iter_mut().zip(&pivot[k..]) {
                *v -= m * p;
            }
            b[k + 1 + offset] -= m * b[k];
        }
    }
    let mut x = vec![0.0; n];
    for k in (0..n).rev() {
        let s: f64 = (k + 1..n).map(|c| a[k][c] * x[c]).sum();
        x[k] = (b[k] - s) / a[k][k];
    }
    x
}

fn check(system: &BarSystem, harmonics: usize, period: f64) {
    let settings = HarmonicBalanceSettings {
        harmonics,
        ..Default::default()
    };
    let mut problem = NonsmoothSystem::new(system, settings).unwrap();
    let omega = 2.0 * PI / period;
    let seed = branch_seed(&mut problem, 1, 1, omega).unwrap();
    // A point that uses both branches of the law: the seed scaled up, plus a perturbation.
    let x: Vec<f64> = seed
        .iter()
        .enumerate()
        .map(|(i, s)| 1.7 * s + 2e-5 * (((i * 7) % 11) as f64 - 5.0))
        .collect();
    let n = problem.dimension();
    problem.set_parameter(omega);
    let mut f = vec![0.0; n];
    problem.residual(&x, &mut f);
    let mut jac = DenseMatrix::zeros(n, n);
    problem.jacobian(&x, &mut jac);
    // Two right-hand sides in one call: -F and a second vector that is not a residual.
    let other: Vec<f64> = (0..n).map(|i| ((i * 5) % 7) as f64 * 1e-4 - 3e-4).collect();
    let mut got: Vec<f64> = f.iter().map(|v| -v).chain(other.iter().cloned()).collect();
    problem
        .solve_jacobian(&x, &mut got, 2)
        .expect("a structured step")
        .expect("regular");
    let minus_other: Vec<f64> = other.iter().map(|v| -v).collect();
    for (want, got) in [dense_solve(&jac, &f), dense_solve(&jac, &minus_other)]
        .iter()
        .zip(got.chunks_exact(n))
    {
        let scale = want.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let err = want
            .iter()
            .zip(got)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            err <= 1e-9 * scale,
            "m {harmonics}, T {period}: {err:e} vs {scale:e}"
        );
    }
}

#[test]
fn structured_step_matches_the_dense_solve() {
    let clamped = clamped_bar_with_obstacle(1e-3).unwrap();
    let robin = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
    let two = two_bars_in_contact(Bar::new(0.95, 1.0, 1.0).unwrap(), 1e-3).unwrap();
    for m in [3, 8, 17] {
        check(&clamped, m, 3.63);
        check(&robin, m, 9.1);
        check(&two, m, 3.71);
    }
}

/// `residual_along` (observables synthesised once per direction, affine in `t`) equals the
/// residual at `x + t dx`, for cached and fresh directions, and after a change of frequency.
#[test]
fn line_search_residual_equals_the_residual_at_the_trial_point() {
    let systems = [
        clamped_bar_with_obstacle(1e-3).unwrap(),
        robin_bar_with_obstacle(0.5, 1e-3).unwrap(),
        two_bars_in_contact(Bar::new(0.95, 1.0, 1.0).unwrap(), 1e-3).unwrap(),
    ];
    for system in &systems {
        let settings = HarmonicBalanceSettings {
            harmonics: 12,
            ..Default::default()
        };
        let mut problem = NonsmoothSystem::new(system, settings).unwrap();
        let n = problem.dimension();
        for (period, scale) in [(3.6, 1.7), (3.3, 0.4)] {
            let omega = 2.0 * PI / period;
            let seed = branch_seed(&mut problem, 1, 1, omega).unwrap();
            let x: Vec<f64> = seed.iter().map(|s| scale * s).collect();
            let mut f = vec![0.0; n];
            problem.set_parameter(omega);
            problem.residual(&x, &mut f);
            for shift in [0usize, 3] {
                let dx: Vec<f64> = seed
                    .iter()
                    .enumerate()
                    .map(|(i, s)| -0.6 * s + 3e-5 * ((((i + shift) * 7) % 11) as f64 - 5.0))
                    .collect();
                // The same direction at a second frequency: nothing cached may leak across.
                for (t, omega) in [1.0, 0.5, 0.125, 1e-3, 0.5].into_iter().zip([
                    omega,
                    omega,
                    omega,
                    omega,
                    1.01 * omega,
                ]) {
                    let (mut trial, mut along) = (vec![0.0; n], vec![0.0; n]);
                    problem.set_parameter(omega);
                    assert!(problem.residual_along(&x, &dx, t, &mut trial, &mut along));
                    let point: Vec<f64> = x.iter().zip(&dx).map(|(a, d)| a + t * d).collect();
                    assert_eq!(trial, point);
                    let mut direct = vec![0.0; n];
                    problem.residual(&point, &mut direct);
                    let scale = direct.iter().fold(1e-3_f64, |m, v| m.max(v.abs()));
                    for (k, (a, b)) in along.iter().zip(&direct).enumerate() {
                        assert!(
                            (a - b).abs() <= 1e-12 * scale,
                            "T = {period}, t = {t}, entry {k}: {a:e} vs {b:e}"
                        );
                    }
                }
            }
        }
    }
}

/// The bordering solve of an energy-level problem (the harmonic-balance step bordered by
/// `dF/dOmega` and the energy row) equals the dense solve of its Jacobian.
#[test]
fn bordered_energy_level_step_matches_the_dense_solve() {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let settings = HarmonicBalanceSettings {
        harmonics: 6,
        ..Default::default()
    };
    let mut inner = NonsmoothSystem::new(&system, settings).unwrap();
    let omega = 1.02 * PI / 2.0;
    let seed = branch_seed(&mut inner, 1, 1, omega).unwrap();
    let (e_g, _) = grazing_energy(&system).unwrap();
    let mut problem = EnergyLevel::new(inner, e_g).unwrap();
    problem.set_parameter(2.0);
    let mut y: Vec<f64> = seed.iter().map(|s| 1.4 * s).collect();
    y.push(omega);
    let n = problem.dimension();
    let mut f = vec![0.0; n];
    problem.residual(&y, &mut f);
    let mut jac = DenseMatrix::zeros(n, n);
    problem.jacobian(&y, &mut jac);
    let want = dense_solve(&jac, &f);
    let mut got = f.clone();
    problem.residual(&y, &mut f);
    let solved = problem.structure().unwrap().solve_jacobian(&y, &mut got, 1);
    assert!(matches!(solved, Some(Ok(()))), "{solved:?}");
    let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (g, w) in got.iter().zip(&want) {
        assert!((g + w).abs() <= 1e-8 * scale, "{g} vs {}", -w);
    }
}
