//! The surfaces added after the core (issue 47): the full-basis helpers on states of any
//! length and harmonics, the forced system's calls at any frequency, damping and amplitude,
//! and the Floquet multipliers of a harmonic-balance state at any scale and frequency.

use super::{reference_system, settings, valid_problem, MAX_HARMONICS};
use crate::checks::{typed, CaseResult, Checks};
use crate::draw::Draw;
use nonsmooth_modes::branches::{
    asymmetry, shift_origin, symmetry_instant, to_full_basis, with_harmonics,
};
use nonsmooth_modes::continuation::ContinuationProblem;
use nonsmooth_modes::forced::{Damping, Excitation, ForcedSystem, Forcing};
use nonsmooth_modes::fourier::frequency_of_period;
use nonsmooth_modes::modal::branch_seed;
use nonsmooth_modes::stability::{floquet, StabilityOptions};

/// A state of `blocks` coefficients per unknown for `harmonics`, or of a length that need
/// not fit it. The state is the caller's own memory: its length stays small.
fn state(d: &mut Draw, harmonics: usize, blocks: impl Fn(usize) -> usize) -> Vec<f64> {
    let per = d.size("unknowns per coefficient", 1..=3).min(3);
    let len = if harmonics <= MAX_HARMONICS && d.flag("length fits", 0.8) {
        per * blocks(harmonics)
    } else {
        d.size("length", 0..=40).min(40)
    };
    (0..len)
        .map(|_| d.real("coefficient", -1e-3..=1e-3))
        .collect()
}

/// The full-basis helpers (`to_full_basis`, `with_harmonics`, `symmetry_instant`,
/// `asymmetry`, `shift_origin`) with any harmonics (`0`, `2^40`, `usize::MAX`...), a state
/// of any length and values, any target and phase: each returns a typed error or finite
/// values of the length its layout implies, and a sine share in `[0, 1]`.
pub(crate) fn full_basis_helpers_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let harmonics = d.size("harmonics", 1..=MAX_HARMONICS);
    let cosine = state(d, harmonics, |m| m + 1);
    match to_full_basis(&cosine, harmonics) {
        Ok(y) => {
            c.finite("to_full_basis", &y);
            let per = cosine.len() / (harmonics + 1);
            c.expect(y.len() == per * (2 * harmonics + 1), || {
                format!("to_full_basis: {} values from {}", y.len(), cosine.len())
            });
        }
        Err(e) => {
            c.error("to_full_basis", &e);
        }
    }
    let x = state(d, harmonics, |m| 2 * m + 1);
    let to = d.size("to", 1..=2 * MAX_HARMONICS);
    match with_harmonics(&x, harmonics, to) {
        Ok(y) => {
            c.finite("with_harmonics", &y);
            let per = x.len() / (2 * harmonics + 1);
            c.expect(to >= harmonics && y.len() == per * (2 * to + 1), || {
                format!(
                    "with_harmonics to {to}: {} values from {}",
                    y.len(),
                    x.len()
                )
            });
        }
        Err(e) => {
            c.error("with_harmonics", &e);
        }
    }
    let shares = [
        symmetry_instant(&x, harmonics).map(|(t, s)| [t, s]),
        asymmetry(&x, harmonics).map(|s| [0.0, s]),
    ];
    for share in shares {
        match share {
            Ok([t, s]) => {
                c.finite("symmetry instant", [&t, &s]);
                c.expect((0.0..=1.0).contains(&s), || format!("sine share {s}"));
            }
            Err(e) => {
                c.error("symmetry instant", &e);
            }
        }
    }
    let theta = d.real("theta0", -10.0..=10.0);
    let shifted = typed(c, "shift_origin", shift_origin(&x, harmonics, theta))?;
    c.finite("shift_origin", &shifted);
    c.expect(shifted.len() == x.len(), || {
        format!("shift_origin: {} values from {}", shifted.len(), x.len())
    });
    Ok(())
}

/// The forced system's own calls with any damping, amplitude and frequency (`0`, negative,
/// `1e300`, `f64::MAX`, infinities, NaN): the open response is a typed error or finite, and
/// so is the gap history of any law index.
pub(crate) fn forced_calls_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let system = reference_system(d, c)?;
    let s = settings(d);
    let end = system.bar_id(0).ok_or("a system without bars")?.left();
    let amplitude = d.real("amplitude", 1e-9..=1e-3);
    // A force at a clamped end acts on nothing (a typed error): mostly a base motion.
    let excitation = if d.flag("force", 0.2) {
        Excitation::force(end, amplitude)
    } else {
        Excitation::base_motion(end, amplitude)
    };
    let forcing = Forcing {
        damping: Damping::Uniform(d.real("damping", 0.0..=0.5)),
        excitations: vec![excitation],
    };
    let mut problem = typed(
        c,
        "ForcedSystem::new",
        ForcedSystem::new(&system, s, &forcing),
    )?;
    problem.set_parameter(d.real("omega", 0.1..=5.0));
    let x = typed(c, "open_response", problem.open_response())?;
    c.finite("open response", &x);
    // Law 0 exists; the edges (1, `2^40`, `usize::MAX`) are beyond the single law.
    let law = d.size("law", 0..=0);
    let gaps = typed(c, "gap_history", problem.gap_history(&x, law))?;
    c.finite("gap history", &gaps);
    Ok(())
}

/// The Floquet multipliers of a grazing seed at any scale (`0`, `1e-300`, `1e300`, NaN...)
/// and period: a typed error, or a report whose numbers are all finite.
pub(crate) fn stability_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let (mut problem, period) = valid_problem(d, c)?;
    let omega = frequency_of_period(period * d.real("period factor", 0.6..=0.95));
    let seed = typed(c, "branch_seed", branch_seed(&mut problem, 1, 1, omega))?;
    let scale = d.real("scale", 0.5..=2.0);
    let x: Vec<f64> = seed.iter().map(|v| v * scale).collect();
    let options = StabilityOptions {
        cells_per_travel: d.real("cells per travel", 8.0..=16.0),
        corrections: d.size("corrections", 0..=2).min(2),
        ..StabilityOptions::default()
    };
    let system = problem.system().clone();
    let f = typed(
        c,
        "floquet",
        floquet(&system, problem.basis(), &x, omega, &options),
    )?;
    c.finite(
        "floquet",
        [
            &f.max_modulus,
            &f.initial_defect,
            &f.periodicity_defect,
            &f.correction,
            &f.displacement_correction,
            &f.energy_correction,
            &f.trivial_distance,
            &f.dt,
            &f.period,
        ],
    );
    c.finite(
        "floquet multipliers",
        f.multipliers.iter().flat_map(|m| [&m.re, &m.im]),
    );
    Ok(())
}
