//! Diagnostics of computed points: the Signorini residual norm `R^(m)` converges with `m`
//! (paper Fig. 5), and the reported penetration and energy drift shrink with it.

use nonsmooth_modes::continuation::ContinuationProblem;
use nonsmooth_modes::modal::diagnose;
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, ClampedFirstMode};
use nonsmooth_modes::solve::{NonlinearSolver, SemismoothNewton};
use nonsmooth_modes::system::{HarmonicBalanceSettings, NonsmoothSystem};
use std::f64::consts::PI;

const GAP: f64 = 1e-3;
/// A first-mode period away from the internal resonances (`T = 3.5` is one: harmonic 7 sits on
/// the clamped-clamped frequency `4 pi`).
const PERIOD: f64 = 3.55;

#[test]
fn signorini_residual_norm_decreases_with_m_at_about_the_first_order_rate() {
    let system = clamped_bar_with_obstacle(GAP).unwrap();
    let omega = 2.0 * PI / PERIOD;
    let exact = ClampedFirstMode::new(GAP, PERIOD).energy_normalized();
    let mut norms = Vec::new();
    for m in [10, 20, 40, 80] {
        let settings = HarmonicBalanceSettings {
            harmonics: m,
            ..Default::default()
        };
        let mut problem = NonsmoothSystem::new(&system, settings).unwrap();
        let mut x = ClampedFirstMode::new(GAP, PERIOD).unknowns(m);
        assert_eq!(x.len(), problem.dimension());
        problem.set_parameter(omega);
        SemismoothNewton::default()
            .solve(&mut problem, &mut x)
            .unwrap();
        let d = diagnose(&problem, &x, omega, 8).unwrap();
        let e = nonsmooth_modes::modal::energy(&system, problem.basis(), &x, omega)
            / nonsmooth_modes::reference::clamped_grazing_energy(GAP);
        // The solution found from the exact guess is the first-mode point, not a resonance.
        assert!(
            (e / exact - 1.0).abs() < 0.1,
            "m = {m}: E/E_g {e} vs exact {exact}"
        );
        assert!(d.residual_norm[0] > 0.0 && d.residual_norm[0].is_finite());
        norms.push((m as f64, d.residual_norm[0], d.max_penetration));
    }
    for w in norms.windows(2) {
        assert!(w[1].1 < w[0].1, "R^(m) must decrease: {norms:?}");
        assert!(w[1].2 < w[0].2, "penetration must decrease: {norms:?}");
    }
    // Least-squares slope of log R against log m: about -1 (the paper's O(1/m)).
    let n = norms.len() as f64;
    let (sx, sy) = norms
        .iter()
        .fold((0.0, 0.0), |(a, b), (m, r, _)| (a + m.ln(), b + r.ln()));
    let (mx, my) = (sx / n, sy / n);
    let (num, den) = norms.iter().fold((0.0, 0.0), |(a, b), (m, r, _)| {
        (a + (m.ln() - mx) * (r.ln() - my), b + (m.ln() - mx).powi(2))
    });
    let slope = num / den;
    assert!((-1.6..=-0.6).contains(&slope), "slope {slope}: {norms:?}");
}
