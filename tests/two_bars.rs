//! Two identical bars in contact against one bar and an obstacle at half the gap, and the
//! degenerate harmonics of formulation §5.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{
    compute, BackboneOptions, BackbonePoint, Method, ModeBranches, PeriodGrid, Request,
};
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, two_bars_in_contact};
use nonsmooth_modes::solve::Solver;
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};
use std::f64::consts::PI;

const GAP: f64 = 1e-3;

/// Relative distance of two vectors (`inf` norms).
fn distance(a: &[f64], b: &[f64]) -> f64 {
    let d = a
        .iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    let s = a.iter().chain(b).fold(0.0_f64, |m, x| m.max(x.abs()));
    d / s.max(f64::MIN_POSITIVE)
}

/// Unknowns of bar `bar` of a two-bar solution (`(A, B)` of each harmonic).
fn bar_unknowns(x: &[f64], bar: usize) -> Vec<f64> {
    x.chunks(4)
        .flat_map(|c| [c[2 * bar], c[2 * bar + 1]])
        .collect()
}

/// The period grid `options` of `system`, with the full semismooth Newton.
fn grid_run(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    options: BackboneOptions,
) -> ModeBranches {
    let method = Method::PeriodGrid(options);
    let request = Request::for_method(method)
        .settings(settings)
        .solver(Solver::default());
    compute(system, &request).unwrap()
}

/// Backbones of the two systems on the same grid: two unit bars (gap `g0`, complementarity parameter `a_c`)
/// and one clamped unit bar (gap `g0/2`, `2 a_c`).
fn pair(harmonics: usize, a_c: f64, grid: PeriodGrid) -> (Vec<BackbonePoint>, Vec<BackbonePoint>) {
    let options = BackboneOptions::on_grid(grid, 1, 1);
    let twins = two_bars_in_contact(Bar::unit(), GAP).unwrap();
    let settings = HarmonicBalanceSettings {
        harmonics,
        complementarity: a_c,
        ..Default::default()
    };
    let two = grid_run(&twins, settings, options);
    let single = clamped_bar_with_obstacle(0.5 * GAP).unwrap();
    let settings = HarmonicBalanceSettings {
        harmonics,
        complementarity: 2.0 * a_c,
        ..Default::default()
    };
    let one = grid_run(&single, settings, options);
    (two.points, one.points)
}

/// Both systems are the same problem: with `v_A = v_B = v` the two-bar gap `g0 - 2v` is twice
/// the single-bar gap `g0/2 - v`, so `-min(lambda, a_c (g0 - 2v)) = -min(lambda, 2 a_c (g0/2 - v))`.
/// Truncated solutions depend on `a_c`, so the comparison needs the doubled `a_c`.
#[test]
fn two_identical_bars_move_like_one_bar_against_half_the_gap() {
    for (harmonics, a_c) in [(10, 4.0), (20, 4.0), (12, 1.5)] {
        let grid = PeriodGrid {
            start: 3.95,
            end: 3.3,
            steps: 14,
        };
        let (two, one) = pair(harmonics, a_c, grid);
        assert_eq!(two.len(), one.len());
        let mut compared = 0;
        for (p2, p1) in two.iter().zip(&one) {
            assert_eq!(p2.period, p1.period);
            assert_eq!(
                p2.converged(),
                p1.converged(),
                "T {}: converged differently",
                p2.period
            );
            if !p1.converged() {
                continue;
            }
            let (a, b) = (bar_unknowns(&p2.x, 0), bar_unknowns(&p2.x, 1));
            assert!(
                distance(&a, &b) < 1e-9,
                "T {}: bars A and B differ by {:e}",
                p2.period,
                distance(&a, &b)
            );
            // The same equations up to scaling: the solutions agree to rounding (the two
            // systems' Newton steps are computed from differently sized reduced matrices).
            let d = distance(&a, &p1.x);
            assert!(
                d < 1e-9,
                "m {harmonics}, a_c {a_c}, T {}: two-bar vs single-bar unknowns differ by {d:e}",
                p2.period
            );
            // Twice the bars, twice the energy; E_g doubles too (the twin first mode is double
            // and the grazing motion of least energy moves both bars by g0/2).
            assert!((p2.energy / (2.0 * p1.energy) - 1.0).abs() < 1e-8);
            assert!((p2.energy_normalized / p1.energy_normalized - 1.0).abs() < 1e-8);
            compared += 1;
        }
        assert!(
            compared >= 10,
            "m {harmonics}: only {compared} converged periods compared"
        );
    }
}

/// Formulation §5: at `T = 3.2` harmonic 4 of two identical unit bars sits on their common
/// clamped-free frequency `5 pi / 2`; the linear rows lose rank (the bars can vibrate against
/// each other without touching), `HarmonicRows::regularise` pins the invisible direction, and
/// the backbone converges through `T = 3.2` to the single-bar solution.
#[test]
fn degenerate_harmonic_of_two_identical_bars() {
    let twins = two_bars_in_contact(Bar::unit(), GAP).unwrap();
    let settings = HarmonicBalanceSettings {
        harmonics: 10,
        ..Default::default()
    };
    let mut problem = NonsmoothSystem::new(&twins, settings).unwrap();
    let omega = 2.0 * PI / 3.2;
    assert!((4.0 * omega - 2.5 * PI).abs() < 1e-14);
    let rows = problem.rows_at(omega);
    let regularised: Vec<usize> = (0..rows.len())
        .filter(|&h| rows[h].is_regularised())
        .collect();
    // Harmonic 4 on 5 pi/2; harmonic 8 is on 5 pi, a clamped-clamped frequency, where the
    // closed-contact rows are singular but the linear rows (contact open) keep their rank.
    assert_eq!(regularised, vec![4], "regularised harmonics at T = 3.2");
    // Away from the degeneracy nothing is regularised.
    let rows = problem.rows_at(2.0 * PI / 3.23);
    assert!(rows.iter().all(|r| !r.is_regularised()));
    // A single bar never loses rank.
    let mut single =
        NonsmoothSystem::new(&clamped_bar_with_obstacle(0.5 * GAP).unwrap(), settings).unwrap();
    assert!(single.rows_at(omega).iter().all(|r| !r.is_regularised()));

    // 3.95 - 15 * 0.05 = 3.2: the grid hits the degenerate period.
    let grid = PeriodGrid {
        start: 3.95,
        end: 3.2,
        steps: 16,
    };
    let (two, one) = pair(10, 4.0, grid);
    let at = two.last().unwrap();
    assert!((at.period - 3.2).abs() < 1e-12, "last period {}", at.period);
    assert!(
        at.converged(),
        "two bars at T = 3.2: residual {:e}",
        at.residual_norm
    );
    let reference = one.last().unwrap();
    assert!(reference.converged());
    let (a, b) = (bar_unknowns(&at.x, 0), bar_unknowns(&at.x, 1));
    assert!(distance(&a, &b) < 1e-9);
    assert!(
        distance(&a, &reference.x) < 1e-9,
        "distance {:e}",
        distance(&a, &reference.x)
    );
}

/// Backbone of NSM1 of the two-bar system with bar 2 `second`, `m = 20`, `T = 3.9 -> 3.3`
/// (from 3.95, the grazing seed of configuration 2 slides to rest).
fn nsm1_of(second: Bar) -> Vec<BackbonePoint> {
    let system = two_bars_in_contact(second, GAP).unwrap();
    let grid = PeriodGrid {
        start: 3.9,
        end: 3.3,
        steps: 25,
    };
    let settings = HarmonicBalanceSettings::default();
    grid_run(&system, settings, BackboneOptions::on_grid(grid, 1, 1)).points
}

/// The paper's configuration 2 `(3.8, 4, 4)` read as `EA_2/EA_1 = alpha` gives bar 2 the
/// impedance `EA/c` and travel time `l/c` of configuration 1 `(0.95, 1, 1)`: the contact sees
/// the same bar, and the backbones coincide point for point (frequencies, normalised energies,
/// bar 1's unknowns). Read with the paper's definition `alpha = E1A1/(E2A2)`
/// (`paper_second_bar`, what the figures use), configuration 2 is another system.
#[test]
fn the_other_reading_of_configuration_2_is_configuration_1() {
    use nonsmooth_modes::reference::paper_second_bar;
    let one = nsm1_of(paper_second_bar(0.95, 1.0, 1.0).unwrap());
    let other_reading = nsm1_of(Bar::new(3.8, 4.0, 4.0).unwrap());
    let two = nsm1_of(paper_second_bar(3.8, 4.0, 4.0).unwrap());
    assert_eq!(one.len(), other_reading.len());
    let converged = one.iter().filter(|p| p.converged()).count();
    assert!(converged >= 20, "{converged} converged");
    for (a, b) in one.iter().zip(&other_reading) {
        assert_eq!(a.converged(), b.converged(), "T = {}", a.period);
        assert!((a.omega - b.omega).abs() <= 1e-12 * a.omega);
        let de = (a.energy_normalized - b.energy_normalized).abs();
        assert!(
            de <= 1e-8 * a.energy_normalized.max(1.0),
            "T = {}: {de:e}",
            a.period
        );
        if a.converged() {
            let d = distance(&bar_unknowns(&a.x, 0), &bar_unknowns(&b.x, 0));
            assert!(d < 1e-8, "T = {}: bar 1 differs by {d:e}", a.period);
        }
    }
    let differing = one
        .iter()
        .zip(&two)
        .filter(|(a, b)| a.converged() && b.converged())
        .filter(|(a, b)| (a.energy_normalized / b.energy_normalized - 1.0).abs() > 0.05)
        .count();
    assert!(
        differing >= 10,
        "{differing} points differ by more than 5 %"
    );
    assert!(paper_second_bar(3.8, 4.0, 0.0).is_err());
    assert!(paper_second_bar(3.8, 4.0, f64::NAN).is_err());
}
