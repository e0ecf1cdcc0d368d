//! Floating bars: the mean position a forced response cannot fix by itself.
//!
//! A bar held only by contacts has a rigid-body motion while they are open, and viscous
//! damping acts on velocities: with every contact of such a bar open over the period, its
//! mean position solves the equations at any value, and the Jacobian is singular there. The
//! mean (harmonic 0) of every law that a rigid-body motion of the open system moves is tied by
//! a spring across its gap, of stiffness [`MEAN_TETHER`] times the smaller `EA / l` of the
//! bars it touches: the law's force at harmonic 0 becomes `lambda - kappa c`, `c = g0 - g` the
//! closure of the gap (as the tether of the backbone's starts, here on the mean alone and
//! never released). The oscillating harmonics are untouched; an open floating bar rests at its
//! position at rest, and one in contact carries a mean force `kappa c` that the contacts do
//! not, a fraction [`MEAN_TETHER`] of the force that closes a gap.

use crate::bc::{Observable, Quantity, Term};
use crate::modal::{rigid_body_modes, ContactState};
use crate::system::rows::{dot, HarmonicRows};
use crate::system::BarSystem;

/// Stiffness of the tether of a floating bar's mean, relative to the bars' `EA / l`.
pub(crate) const MEAN_TETHER: f64 = 1e-8;

/// Gap rows below this fraction of the largest, applied to the rigid-body motions, are gaps
/// that no rigid-body motion moves.
const MOVED: f64 = 1e-9;

/// The observables `(gap, force)` of the laws of `system` at harmonic 0: `observables`, with
/// the force of every law a rigid-body motion of the open system moves tied by a spring of
/// stiffness `tether` times the smaller `EA / l` of its bars (module docs). Equal to
/// `observables` on a system without rigid-body motions.
pub(super) fn mean_observables(
    system: &BarSystem,
    observables: &[(Observable, Observable)],
    tether: f64,
) -> Vec<(Observable, Observable)> {
    let moved = moved_laws(system);
    (observables.iter().enumerate())
        .map(|(l, (gap, force))| {
            let mut force = force.clone();
            if moved.contains(&l) {
                let kappa = tether * softest_bar_stiffness(system, gap);
                // `- kappa c` with `c = -(displacement terms of the gap)`.
                let spring = (gap.terms.iter())
                    .filter(|t| is_displacement(t.quantity))
                    .map(|t| Term::new(t.end, t.quantity, kappa * t.coefficient));
                force.terms.extend(spring);
            }
            (gap.clone(), force)
        })
        .collect()
}

/// The laws (indices) whose gap some rigid-body motion of the open system changes.
pub(crate) fn moved_laws(system: &BarSystem) -> Vec<usize> {
    let Some(modes) = rigid_body_modes(system, ContactState::Open) else {
        return Vec::new();
    };
    let rows = HarmonicRows::new(system, 0.0);
    let moves: Vec<f64> = (0..system.contact_count())
        .map(|l| {
            let row = rows.gap_row(l);
            (modes.shapes.iter())
                .map(|s| dot(row, s).abs())
                .fold(0.0, f64::max)
        })
        .collect();
    let largest = moves.iter().copied().fold(0.0, f64::max);
    (0..moves.len())
        .filter(|&l| largest > 0.0 && moves[l] > MOVED * largest)
        .collect()
}

/// The smaller `EA / l` of the bars whose displacement the gap `gap` reads.
fn softest_bar_stiffness(system: &BarSystem, gap: &Observable) -> f64 {
    (gap.terms.iter())
        .map(|t| {
            let bar = system.bars()[t.end.bar.index()];
            bar.stiffness() / bar.length()
        })
        .fold(f64::INFINITY, f64::min)
}

fn is_displacement(q: Quantity) -> bool {
    matches!(q, Quantity::Displacement | Quantity::OutwardDisplacement)
}

#[cfg(test)]
mod tests {
    use super::{mean_observables, moved_laws, MEAN_TETHER};
    use crate::continuation::ContinuationProblem;
    use crate::forced::{
        forced_response, Damping, Excitation, Forcing, ResponseMethod, ResponseRequest,
    };
    use crate::reference::{clamped_bar_with_obstacle, contact_chain};
    use crate::solve::{NonlinearSolver, Solver};
    use crate::system::HarmonicBalanceSettings;

    #[test]
    fn the_laws_of_a_floating_bar_are_tethered_and_no_other() {
        let chain = contact_chain(3, 1e-3, 0.5).unwrap();
        assert_eq!(moved_laws(&chain), vec![0, 1]);
        let held = clamped_bar_with_obstacle(1e-3).unwrap();
        assert!(moved_laws(&held).is_empty());
        let observables: Vec<_> = held.laws().map(|l| (l.gap(), l.force())).collect();
        let mean = mean_observables(&held, &observables, MEAN_TETHER);
        assert_eq!(mean.len(), observables.len());
        for ((g, f), (mg, mf)) in observables.iter().zip(&mean) {
            assert_eq!(g.terms.len(), mg.terms.len());
            assert_eq!(f.terms.len(), mf.terms.len());
        }
    }

    #[test]
    fn a_hundred_times_softer_tether_leaves_a_motion_in_contact_where_it_was() {
        let chain = contact_chain(3, 1e-3, 0.5).unwrap();
        let base = chain.bar_id(0).unwrap().left();
        let request = ResponseRequest {
            settings: HarmonicBalanceSettings {
                harmonics: 8,
                ..Default::default()
            },
            forcing: Forcing {
                damping: Damping::Uniform(1e-3),
                excitations: vec![Excitation::base_motion(base, 1e-6)],
            },
            omega_range: (1.55, 1.5705),
            steps: 83,
            method: ResponseMethod::Sequential,
            solver: Solver::default(),
        };
        let response = forced_response(&chain, &request).unwrap();
        let touching = (response.converged())
            .filter(|p| p.amplitude > 1.0)
            .max_by(|a, b| a.omega.total_cmp(&b.omega))
            .expect("the chain reaches its obstacle");
        let mut softer = response.problem().clone();
        let observables = softer.observables().to_vec();
        softer.mean_observables = mean_observables(&chain, &observables, 1e-2 * MEAN_TETHER);
        softer.omega = f64::NAN;
        softer.set_parameter(touching.omega);
        let mut x = touching.x.clone();
        Solver::default().solve(&mut softer, &mut x).unwrap();
        let energy = softer.average_energy(&x);
        let relative = (energy / touching.energy - 1.0).abs();
        assert!(relative < 1e-4, "energy moved by {relative:e}");
    }
}
