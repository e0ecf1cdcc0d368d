//! Rest is never a result. The state of rest solves the harmonic-balance equations of every
//! unforced system, so a loop in a system parameter that leaves the range where its mode
//! exists slides to it; the continuation drivers refuse it by default
//! (`Structured::at_rest`), custom loops included, and `with_rest_accepted` opts out.

use nonsmooth_modes::branches::{compute, Request};
use nonsmooth_modes::continuation::{Sequential, SequentialOptions, Step};
use nonsmooth_modes::modal::{energy, grazing_energy};
use nonsmooth_modes::reference::robin_bar_with_obstacle;
use nonsmooth_modes::solve::SemismoothNewton;
use nonsmooth_modes::system::{HarmonicBalanceSettings, NonsmoothSystem, ParameterFamily};

const GAP: f64 = 1e-3;

/// `E / E_g` of the Robin bar of spring stiffness `k` in the motion `x` at `omega`.
fn normalized(k: f64, settings: HarmonicBalanceSettings, x: &[f64], omega: f64) -> f64 {
    let system = robin_bar_with_obstacle(k, GAP).expect("a system");
    let basis = NonsmoothSystem::new(&system, settings)
        .expect("a problem")
        .basis()
        .clone();
    let (e_g, _) = grazing_energy(&system).expect("a grazing energy");
    energy(&system, &basis, x, omega) / e_g
}

/// The accepted points `(k, E / E_g)` of a sequential loop in the spring stiffness from 3 to
/// 13, at the frequency of a point of the first mode's backbone at `k = 3` just above the
/// linear frequency (the mode leaves that frequency as the spring stiffens).
fn stiffness_loop(accept_rest: bool) -> Vec<(f64, f64)> {
    let system = robin_bar_with_obstacle(3.0, GAP).expect("a system");
    let run = compute(&system, &Request::new(1).harmonics(10)).expect("a run");
    let settings = HarmonicBalanceSettings {
        resonance_band: run.problem().resonance_band(),
        ..Request::new(1).harmonics(10).settings
    };
    let from = run.converged().nth(5).expect("a converged point");
    let family = |k: f64| robin_bar_with_obstacle(k, GAP);
    let problem = ParameterFamily::at(family, settings, from.omega, 3.0).expect("a family");
    let values: Vec<f64> = (0..=40).map(|i| 3.0 + 0.25 * i as f64).collect();
    let driver = Sequential::new(
        problem,
        SemismoothNewton::default(),
        from.x.clone(),
        values,
        SequentialOptions::default(),
    )
    .expect("a driver");
    let mut driver = if accept_rest {
        driver.with_rest_accepted()
    } else {
        driver
    };
    let mut accepted = Vec::new();
    loop {
        match driver.step() {
            Step::Accepted(p) => {
                let e = normalized(p.parameter, settings, &p.x, from.omega);
                accepted.push((p.parameter, e));
            }
            Step::Rejected(_) => {}
            Step::Finished(_) => return accepted,
        }
    }
}

#[test]
fn a_stiffness_loop_never_returns_rest() {
    let refused = stiffness_loop(false);
    assert!(!refused.is_empty(), "the loop starts on the branch");
    for (k, e) in &refused {
        assert!(*e > 1e-6, "k = {k}: E/E_g = {e} accepted");
    }
    // Without the default, the same loop slides to rest: the test above can fail.
    let accepted = stiffness_loop(true);
    assert!(
        accepted.iter().any(|(_, e)| *e <= 1e-6),
        "the loop never reached rest: {accepted:?}"
    );
}
