//! Forced sweeps: up and down (the hysteresis of a curve that bends over), and through the
//! resonance of an assembly with a floating bar.

use nonsmooth_modes::forced::{
    forced_response, Damping, Excitation, ForcedResponse, Forcing, ResponseMethod, ResponseRequest,
};
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, contact_chain};
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings, RESONANCE_BAND};

/// The response of `system` with its first bar's left end moved by `1e-6 cos(Omega t)`,
/// `eta = 1e-3`, `m = 20` with the harmonic selection, over `omega_range` in `steps`.
fn response(
    system: &BarSystem,
    omega_range: (f64, f64),
    steps: usize,
    method: ResponseMethod,
) -> ForcedResponse {
    let base = system.bar_id(0).unwrap().left();
    let request = ResponseRequest {
        settings: HarmonicBalanceSettings {
            harmonics: 20,
            resonance_band: RESONANCE_BAND,
            ..Default::default()
        },
        forcing: Forcing {
            damping: Damping::Uniform(1e-3),
            excitations: vec![Excitation::base_motion(base, 1e-6)],
        },
        omega_range,
        steps,
        method,
        solver: Default::default(),
    };
    forced_response(system, &request).unwrap()
}

fn sweep(method: ResponseMethod) -> ForcedResponse {
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    response(&system, (1.55, 2.0), 451, method)
}

/// The sweep up climbs the backbone and jumps down at its peak; the sweep down stays on the
/// low branch over the same frequencies. Where both are on the low branch they are the same
/// motion; between the peak and the linear resonance the two differ by the jump.
#[test]
fn a_sweep_down_stays_below_the_peak_that_a_sweep_up_climbs() {
    let up = sweep(ResponseMethod::Sequential);
    let down = sweep(ResponseMethod::SweepDown);
    // The sweep down starts at the high end and descends.
    let omegas: Vec<f64> = down.points.iter().map(|p| p.omega).collect();
    assert_eq!(omegas.first().copied(), Some(2.0));
    assert!(omegas.windows(2).all(|w| w[1] < w[0]));
    // The sweep up leaves its branch at its peak, once.
    let peak = up.peak().unwrap();
    assert_eq!(up.jumps, vec![peak.omega], "jumps {:?}", up.jumps);
    assert!(
        peak.energy_normalized > 2.0,
        "peak {}",
        peak.energy_normalized
    );
    let at = |r: &ForcedResponse, omega: f64| {
        (r.converged())
            .find(|p| (p.omega - omega).abs() < 1e-12)
            .map(|p| p.energy_normalized)
    };
    let mut compared = (0, 0);
    for p in up.converged() {
        let Some(below) = at(&down, p.omega) else {
            continue;
        };
        if p.omega > peak.omega {
            // Both on the low branch: the same motion.
            assert!(
                (p.energy_normalized - below).abs() <= 1e-6 * below.max(1e-3),
                "at {}: up {} down {below}",
                p.omega,
                p.energy_normalized
            );
            compared.0 += 1;
        } else if p.omega > 1.65 {
            // The sweep up on the backbone, the sweep down below the obstacle.
            assert!(
                p.energy_normalized > 10.0 * below,
                "at {}: up {} down {below}",
                p.omega,
                p.energy_normalized
            );
            compared.1 += 1;
        }
    }
    assert!(compared.0 >= 20 && compared.1 >= 20, "{compared:?}");
}

/// The chain whose middle bar is held by its contacts only converges through its first
/// bar's resonance, and the open floating bar stays where it rests.
#[test]
fn the_floating_chain_converges_through_its_first_resonance() {
    let gap = 1e-3;
    let chain = contact_chain(3, gap, 0.5).unwrap();
    // Around the first bar's clamped–free resonance `pi / 2`.
    let response = response(&chain, (1.5, 1.8), 601, ResponseMethod::Sequential);
    let points = response.points.len();
    let converged: Vec<_> = response.converged().collect();
    assert!(
        10 * converged.len() >= 9 * points,
        "{} of {points} converged",
        converged.len()
    );
    // The sweep reaches the obstacle and leaves it: it is not converged at rest alone.
    let touching = converged.iter().filter(|p| p.amplitude >= 1.0).count();
    assert!(touching >= 2, "{touching} points touch");
    // Where no contact closes, the floating bar rests at its mean position at rest:
    // coefficient 0 (the mean) of bar 2 (0-based 1) is `(A, B)` at 2 and 3.
    for p in converged.iter().filter(|p| p.amplitude < 0.5) {
        assert!(
            p.x[2].abs() < 1e-6 * gap && p.x[3].abs() < 1e-6 * gap,
            "mean of the floating bar {:e}, {:e} at Omega = {}",
            p.x[2],
            p.x[3],
            p.omega
        );
    }
}
