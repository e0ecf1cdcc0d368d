//! A hand-written continuation loop, as a downstream crate would write it.
//!
//! Sequential continuation in the period of the clamped bar's first nonsmooth mode, driven
//! step by step with `Sequential::step`; at the first rejected step (a fold or a resonance the
//! natural parameter cannot pass) the loop switches to pseudo-arclength from the last
//! converged point, and it stops as soon as the energy exceeds a threshold. Both drivers
//! return the same `Step`, so one loop (`follow`) serves both.
//!
//! Then a loop in a system parameter: a Robin bar's mode at a fixed frequency, continued in
//! the spring's stiffness (`ParameterFamily`). As the spring stiffens the linear frequency
//! passes the loop's and the mode leaves it: the equations are then solved by the state of
//! rest only, which the driver refuses by default (a rejected step, reported), so the loop
//! stays on its branch or says where it left it. Each accepted point is also measured against
//! the secant of the two before it in `E / E_g` (`branches::JUMP_RATIO`), and a jump is
//! reported.
//!
//! ```text
//! cargo run --release --example custom_loop -- [E_OVER_EG_THRESHOLD (default 20)]
//! ```

use nonsmooth_modes::branches::{compute, Request, JUMP_RATIO};
use nonsmooth_modes::continuation::{
    Arclength, ArclengthOptions, PeriodParametrised, Point, RejectReason, Sequential,
    SequentialOptions, Step,
};
use nonsmooth_modes::modal::{branch_seed, energy, grazing_energy};
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, robin_bar_with_obstacle, ClampedFirstMode,
};
use nonsmooth_modes::solve::SemismoothNewton;
use nonsmooth_modes::system::{HarmonicBalanceSettings, NonsmoothSystem, ParameterFamily};
use std::f64::consts::PI;

/// How a phase of the loop ended.
enum Phase {
    /// The energy threshold was crossed.
    Threshold,
    /// A step was rejected after the last accepted point `Some(p)`.
    Rejected(Option<Point>),
    /// The driver ended by itself.
    Ended,
}

/// The loop itself, the same for both drivers: step until the threshold, a rejection (when
/// `stop_on_rejection`) or the end.
fn follow(
    label: &str,
    mut step: impl FnMut() -> Step,
    normalized: impl Fn(&Point) -> f64,
    threshold: f64,
    stop_on_rejection: bool,
) -> Phase {
    let (mut last, mut rejected) = (None, 0);
    loop {
        match step() {
            Step::Accepted(p) => {
                let (e, exact) = (normalized(&p), ClampedFirstMode::new(1e-3, p.parameter));
                let events: Vec<&str> = p.events.iter().map(|e| e.label()).collect();
                let exact = exact.energy_normalized();
                println!(
                    "{label}  T {:.4}  E/Eg {e:9.4}  exact {exact:9.4}  {events:?}",
                    p.parameter
                );
                if e > threshold {
                    return Phase::Threshold;
                }
                last = Some(p);
            }
            Step::Rejected(r) if stop_on_rejection => {
                println!("{label}  T {:.4}  rejected: {:?}", r.parameter, r.reason);
                return Phase::Rejected(last);
            }
            Step::Rejected(_) => rejected += 1,
            Step::Finished(end) => {
                println!("{label} ended: {end:?} ({rejected} rejected steps)");
                return Phase::Ended;
            }
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let threshold: f64 = match std::env::args().nth(1) {
        Some(text) => text.parse()?,
        None => 20.0,
    };
    let gap = 1e-3;
    let system = clamped_bar_with_obstacle(gap)?;
    let settings = HarmonicBalanceSettings::default();
    let mut problem = NonsmoothSystem::new(&system, settings)?;
    let basis = problem.basis().clone();
    let (e_g, _) = grazing_energy(&system)?;
    let normalized = |p: &Point| energy(&system, &basis, &p.x, 2.0 * PI / p.parameter) / e_g;

    // Phase 1: sequential in the period, one call of `step()` at a time; it hands over at
    // the first rejected step.
    let start = branch_seed(&mut problem, 1, 1, 2.0 * PI / 3.95)?;
    let periods: Vec<f64> = (0..=180).map(|i| 3.95 - 0.005 * i as f64).collect();
    let mut sequential = Sequential::new(
        PeriodParametrised::new(problem),
        SemismoothNewton::default(),
        start,
        periods,
        SequentialOptions::default(),
    )?;
    let from = match follow(
        "sequential",
        || sequential.step(),
        normalized,
        threshold,
        true,
    ) {
        Phase::Rejected(Some(p)) => p,
        Phase::Rejected(None) => return Err("no converged point to switch from".into()),
        Phase::Threshold | Phase::Ended => return Ok(()),
    };

    // Phase 2: pseudo-arclength from the last converged point, towards shorter periods, with
    // the same loop.
    println!("switching to arclength");
    let problem = PeriodParametrised::new(NonsmoothSystem::new(&system, settings)?);
    let options = ArclengthOptions {
        direction: -1.0,
        parameter_range: (3.0, 4.0),
        ..Default::default()
    };
    let mut arclength = Arclength::restart(problem, SemismoothNewton::default(), &from, options)?;
    let phase = follow(
        "arclength",
        || arclength.step(),
        normalized,
        threshold,
        false,
    );
    if let Phase::Threshold = phase {
        println!("energy threshold {threshold} reached");
    }
    stiffness_loop(gap)
}

/// Phase 3: the Robin bar's first mode at the frequency of its sixth backbone point at
/// `k = 3`, continued in the spring stiffness `k` from 3 to 13.
fn stiffness_loop(gap: f64) -> Result<(), Box<dyn std::error::Error>> {
    let request = Request::new(1).harmonics(10);
    let run = compute(&robin_bar_with_obstacle(3.0, gap)?, &request)?;
    let from = run.converged().nth(5).ok_or("no backbone point at k = 3")?;
    let settings = HarmonicBalanceSettings {
        resonance_band: run.problem().resonance_band(),
        ..request.settings
    };
    let family = |k: f64| robin_bar_with_obstacle(k, gap);
    let problem = ParameterFamily::at(family, settings, from.omega, 3.0)?;
    let values: Vec<f64> = (0..=40).map(|i| 3.0 + 0.25 * i as f64).collect();
    let mut driver = Sequential::new(
        problem,
        SemismoothNewton::default(),
        from.x.clone(),
        values,
        SequentialOptions::default(),
    )?;
    println!("stiffness loop at Omega = {:.4}", from.omega);
    // The last two accepted `(k, E / E_g)`, for the secant that measures the next.
    let mut last: Vec<(f64, f64)> = Vec::new();
    loop {
        match driver.step() {
            Step::Accepted(p) => {
                let system = robin_bar_with_obstacle(p.parameter, gap)?;
                let basis = NonsmoothSystem::new(&system, settings)?.basis().clone();
                let e = energy(&system, &basis, &p.x, from.omega) / grazing_energy(&system)?.0;
                let jump = match last.as_slice() {
                    [.., (ka, ea), (kb, eb)] => {
                        let predicted = eb + (p.parameter - kb) / (kb - ka) * (eb - ea);
                        let ratio = ((e - predicted) / (predicted - eb)).abs();
                        (ratio > JUMP_RATIO).then_some(ratio)
                    }
                    _ => None,
                };
                match jump {
                    Some(ratio) => println!(
                        "stiffness  k {:.2}  E/Eg {e:9.4}  jump: {ratio:.1} predicted steps off",
                        p.parameter
                    ),
                    None => println!("stiffness  k {:.2}  E/Eg {e:9.4}", p.parameter),
                }
                last.push((p.parameter, e));
            }
            // Without an acceptance test of its own, the loop's points are refused only at
            // rest.
            Step::Rejected(r) => match r.reason {
                RejectReason::NotAccepted => {
                    println!("stiffness  k {:.2}  refused: at rest", r.parameter)
                }
                other => println!("stiffness  k {:.2}  rejected: {other:?}", r.parameter),
            },
            Step::Finished(end) => {
                println!("stiffness loop ended: {end:?}");
                return Ok(());
            }
        }
    }
}
