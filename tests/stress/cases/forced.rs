//! Forced, damped responses (`forced::forced_response`) with any damping, excitation, range,
//! settings and method.

use super::{reference_system, settings};
use crate::checks::{typed, CaseResult, Checks};
use crate::draw::Draw;
use nonsmooth_modes::branches::PointStatus;
use nonsmooth_modes::forced::{
    forced_response, Damping, Excitation, Forcing, ResponseMethod, ResponseRequest,
};

/// A response curve of a reference system under a force or a base motion at one of its ends
/// (some of which cannot take it: a typed error); every number of a converged point is
/// finite, a point that is not converged says why, and the run has at most its steps' points.
pub(crate) fn forced_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let system = reference_system(d, c)?;
    let s = settings(d);
    let bars: Vec<_> = system.bar_ids().collect();
    let bar = bars[d.size("bar", 0..=bars.len() - 1).min(bars.len() - 1)];
    let end = if d.flag("right end", 0.3) {
        bar.right()
    } else {
        bar.left()
    };
    let amplitude = d.real("amplitude", 1e-9..=1e-3);
    let excitation = if d.flag("force", 0.4) {
        Excitation::force(end, amplitude)
    } else {
        Excitation::base_motion(end, amplitude)
    };
    let damping = if d.flag("per bar", 0.3) {
        Damping::PerBar(bars.iter().map(|_| d.real("damping", 0.0..=0.5)).collect())
    } else {
        Damping::Uniform(d.real("damping", 0.0..=0.5))
    };
    let lo = d.real("lowest frequency", 0.1..=4.0);
    let hi = lo * d.real("range ratio", 1.0..=1.5);
    // Any count, `2^40` and `usize::MAX` included: both methods refuse one over the memory
    // budget before they start (`0` and `1` are typed errors too).
    let steps = d.size("steps", 1..=8);
    let method = d.pick(
        "method",
        &[ResponseMethod::Sequential, ResponseMethod::Arclength],
    );
    let request = ResponseRequest {
        settings: s,
        forcing: Forcing {
            damping,
            excitations: vec![excitation],
        },
        omega_range: (lo, hi),
        steps,
        method,
        solver: Default::default(),
    };
    let run = typed(c, "forced response", forced_response(&system, &request))?;
    for p in &run.points {
        if p.converged {
            let numbers = [
                p.omega,
                p.amplitude,
                p.energy,
                p.energy_normalized,
                p.contact_defect,
                p.residual_norm,
            ];
            c.finite("forced point", &numbers);
            c.finite("forced point x", &p.x);
        } else {
            c.expect(p.status != PointStatus::Converged, || {
                format!("a point at {} neither converged nor failed", p.omega)
            });
        }
    }
    // The arclength takes at most four times its steps, plus its start.
    c.expect(
        run.points.len() <= steps.saturating_mul(4).saturating_add(1),
        || format!("{} points from {steps} steps", run.points.len()),
    );
    Ok(())
}
