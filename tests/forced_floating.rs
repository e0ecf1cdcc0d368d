//! Forced responses of an assembly with a floating bar: the three-bar chain whose middle bar
//! is held by its contacts only.

use nonsmooth_modes::forced::{
    forced_response, Damping, Excitation, Forcing, ResponseMethod, ResponseRequest,
};
use nonsmooth_modes::reference::contact_chain;
use nonsmooth_modes::system::{HarmonicBalanceSettings, RESONANCE_BAND};

#[test]
fn the_floating_chain_converges_through_its_first_resonance() {
    let gap = 1e-3;
    let chain = contact_chain(3, gap, 0.5).unwrap();
    let base = chain.bar_id(0).unwrap().left();
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
        // Around the first bar's clamped–free resonance `pi / 2`.
        omega_range: (1.5, 1.8),
        steps: 601,
        method: ResponseMethod::Sequential,
        solver: Default::default(),
    };
    let response = forced_response(&chain, &request).unwrap();
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
