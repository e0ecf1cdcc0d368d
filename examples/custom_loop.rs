//! A hand-written continuation loop, as a downstream crate would write it.
//!
//! Sequential continuation in the period of the clamped bar's first nonsmooth mode, driven
//! step by step with `Sequential::step`; at the first failed step (a fold or a resonance the
//! natural parameter cannot pass) the loop switches to pseudo-arclength from the last
//! converged point, and it stops as soon as the energy exceeds a threshold.
//!
//! ```text
//! cargo run --release --example custom_loop -- [E_OVER_EG_THRESHOLD (default 20)]
//! ```

use nonsmooth_modes::continuation::{
    Arclength, ArclengthOptions, ArclengthOutcome, PeriodParametrised, Point, Sequential,
    SequentialOptions, StallEscape, StepOutcome,
};
use nonsmooth_modes::modal::{branch_seed, energy, grazing_energy};
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, ClampedFirstMode};
use nonsmooth_modes::solve::SemismoothNewton;
use nonsmooth_modes::system::{HarmonicBalance, NonsmoothSystem};
use std::f64::consts::PI;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let threshold: f64 = match std::env::args().nth(1) {
        Some(text) => text.parse()?,
        None => 20.0,
    };
    let gap = 1e-3;
    let system = clamped_bar_with_obstacle(gap)?;
    let settings = HarmonicBalance::default();
    let mut problem = NonsmoothSystem::new(&system, settings)?;
    let basis = problem.basis().clone();
    let (e_g, _) = grazing_energy(&system)?;
    let normalized = |p: &Point| energy(&system, &basis, &p.x, 2.0 * PI / p.lambda) / e_g;

    // Phase 1: sequential in the period, one call of `step()` at a time.
    let start = branch_seed(&mut problem, 1, 1, 2.0 * PI / 3.95)?;
    let periods: Vec<f64> = (0..=180).map(|i| 3.95 - 0.005 * i as f64).collect();
    let mut sequential = Sequential::new(
        PeriodParametrised::new(problem),
        SemismoothNewton::default(),
        start,
        periods,
        SequentialOptions::default(),
    )?;
    let mut last: Option<Point> = None;
    loop {
        match sequential.step() {
            StepOutcome::Converged(p) => {
                let e = normalized(&p);
                println!(
                    "sequential  T {:.4}  E/Eg {:9.4}  exact {:9.4}",
                    p.lambda,
                    e,
                    ClampedFirstMode::new(gap, p.lambda).energy_normalized()
                );
                if e > threshold {
                    println!("energy threshold {threshold} reached");
                    return Ok(());
                }
                last = Some(p);
            }
            StepOutcome::Failed(p) => {
                println!(
                    "sequential  T {:.4}  failed: {:?}: switching to arclength",
                    p.lambda, p.error
                );
                break;
            }
            StepOutcome::Finished => {
                println!("sequential run finished without failure");
                return Ok(());
            }
            StepOutcome::Stalled(e) => return Err(e.into()),
        }
    }

    // Phase 2: pseudo-arclength from the last converged point, towards shorter periods.
    let Some(from) = last else {
        return Err("no converged point to switch from".into());
    };
    let problem = PeriodParametrised::new(NonsmoothSystem::new(&system, settings)?);
    let options = ArclengthOptions {
        direction: -1.0,
        parameter_range: (3.0, 4.0),
        escape: Some(StallEscape::default()),
        ..Default::default()
    };
    let (mut arclength, _) =
        Arclength::restart(problem, SemismoothNewton::default(), &from, options)?;
    let mut rejected = 0;
    loop {
        match arclength.step() {
            ArclengthOutcome::Accepted(p) => {
                let e = normalized(&p);
                let events: Vec<&str> = p.events.iter().map(|e| e.label()).collect();
                println!(
                    "arclength   T {:.4}  E/Eg {:9.4}  ds {:.3e} {}",
                    p.lambda,
                    e,
                    p.step_size,
                    events.join(",")
                );
                if e > threshold {
                    println!("energy threshold {threshold} reached ({rejected} rejected steps)");
                    return Ok(());
                }
            }
            ArclengthOutcome::Rejected(_) => rejected += 1,
            ArclengthOutcome::Finished(end) => {
                println!("arclength ended: {end:?}");
                return Ok(());
            }
        }
    }
}
