//! Forced, damped responses (`forced`): the Jacobians against finite differences, the
//! linear response against its closed form, the undamped limit against the backbone, and
//! typed errors.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::continuation::ContinuationProblem;
use nonsmooth_modes::forced::{
    forced_response, Damping, Excitation, ForcedSystem, Forcing, ResponseMethod, ResponseRequest,
};
use nonsmooth_modes::linalg::DenseMatrix;
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact,
};
use nonsmooth_modes::solve::Problem;
use nonsmooth_modes::system::{AssemblyBuilder, BarSystem, HarmonicBalanceSettings};
use nonsmooth_modes::{Error, ForcingError};
use num_complex::Complex64;

fn settings(m: usize) -> HarmonicBalanceSettings {
    HarmonicBalanceSettings {
        harmonics: m,
        ..Default::default()
    }
}

fn clamped_base(gap: f64, eta: f64, amplitude: f64) -> (BarSystem, Forcing) {
    let system = clamped_bar_with_obstacle(gap).unwrap();
    let base = system.bar_id(0).unwrap().left();
    let forcing = Forcing {
        damping: Damping::Uniform(eta),
        excitations: vec![Excitation::base_motion(base, amplitude)],
    };
    (system, forcing)
}

/// A deterministic state with every coefficient set.
fn state(n: usize, size: f64) -> Vec<f64> {
    (0..n)
        .map(|i| size * ((i as f64 * 0.77).sin() + 0.3 * (i as f64 * 1.9).cos()))
        .collect()
}

#[test]
fn the_jacobian_and_the_frequency_derivative_match_finite_differences() {
    let (system, forcing) = clamped_base(1e-3, 0.05, 1e-4);
    let mut problem = ForcedSystem::new(&system, settings(6), &forcing).unwrap();
    let omega = 1.7;
    problem.set_parameter(omega);
    let n = problem.dimension();
    // A state that touches on part of the period: the law switches inside the grid.
    let x = state(n, 4e-4);
    let mut jac = DenseMatrix::zeros(0, 0);
    problem.jacobian(&x, &mut jac);
    let (mut plus, mut minus) = (vec![0.0; n], vec![0.0; n]);
    let h = 1e-9;
    let mut worst: f64 = 0.0;
    for j in 0..n {
        let mut y = x.clone();
        y[j] += h;
        problem.residual(&y, &mut plus);
        y[j] -= 2.0 * h;
        problem.residual(&y, &mut minus);
        for i in 0..n {
            let fd = (plus[i] - minus[i]) / (2.0 * h);
            worst = worst.max((fd - jac[(i, j)]).abs() / (1.0 + jac[(i, j)].abs()));
        }
    }
    assert!(
        worst < 1e-5,
        "Jacobian: worst relative difference {worst:e}"
    );
    let mut df = vec![0.0; n];
    problem.parameter_derivative(&x, &mut df);
    let dh = 1e-6;
    problem.set_parameter(omega + dh);
    problem.residual(&x, &mut plus);
    problem.set_parameter(omega - dh);
    problem.residual(&x, &mut minus);
    let worst = (0..n)
        .map(|i| ((plus[i] - minus[i]) / (2.0 * dh) - df[i]).abs() / (1.0 + df[i].abs()))
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-6,
        "dF/dOmega: worst relative difference {worst:e}"
    );
}

/// The complex amplitude of the displacement at `x = l` of bar 0 at harmonic 1.
fn tip_amplitude(problem: &ForcedSystem, x: &[f64]) -> Complex64 {
    let tip = problem.system().bar_id(0).unwrap().right();
    problem.end_displacement(x, tip, 1)
}

#[test]
fn without_contact_the_response_is_the_closed_form_linear_damped_response() {
    // The clamped bar, base-excited, with a gap no motion reaches: the tip is free and
    // U(x) = U0 cos(k (l - x)) / cos(k l), k^2 = (Omega^2 - i eta Omega) / c^2.
    let (u0, eta, gap) = (1e-6, 0.02, 1.0);
    let (system, forcing) = clamped_base(gap, eta, u0);
    let mut problem = ForcedSystem::new(&system, settings(5), &forcing).unwrap();
    for omega in [0.4, 1.2, std::f64::consts::FRAC_PI_2, 2.9, 4.71238898] {
        problem.set_parameter(omega);
        let x = problem.open_response().unwrap();
        let mut f = vec![0.0; x.len()];
        problem.residual(&x, &mut f);
        let residual = f.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!(residual < 1e-15, "omega {omega}: residual {residual:e}");
        let k = Complex64::new(omega * omega, -eta * omega).sqrt();
        let exact = u0 / k.cos();
        let got = tip_amplitude(&problem, &x);
        assert!(
            (got - exact).norm() <= 1e-10 * exact.norm(),
            "omega {omega}: {got} against {exact}"
        );
        let other: f64 = (2..=5)
            .map(|n| {
                let tip = system.bar_id(0).unwrap().right();
                problem.end_displacement(&x, tip, n).norm()
            })
            .sum();
        assert!(other < 1e-20, "omega {omega}: higher harmonics {other:e}");
    }
}

#[test]
fn a_force_at_a_free_end_gives_the_closed_form_response() {
    // Bar free at x = 0 under F cos(Omega t), obstacle far beyond x = l: the tip is free and
    // U(x) = alpha cos(k (l - x)) with EA U'(0) = -F, i.e. alpha = -F / (EA k sin(k l)).
    let (force, eta, ea, l) = (2e-6, 0.03, 1.7, 1.3);
    let mut b = AssemblyBuilder::new();
    let bar = b.add_bar(Bar::new(l, 0.8, ea).unwrap());
    b.neumann(bar.left()).unwrap();
    b.signorini(bar.right(), 10.0).unwrap();
    let system = b.build().unwrap();
    let forcing = Forcing {
        damping: Damping::PerBar(vec![eta]),
        excitations: vec![Excitation::force(bar.left(), force)],
    };
    let mut problem = ForcedSystem::new(&system, settings(4), &forcing).unwrap();
    for omega in [0.3, 1.1, 2.5] {
        problem.set_parameter(omega);
        let x = problem.open_response().unwrap();
        let k = Complex64::new(omega * omega, -eta * omega).sqrt() / 0.8;
        let exact = -force / (ea * k * (k * l).sin());
        let got = tip_amplitude(&problem, &x);
        assert!(
            (got - exact).norm() <= 1e-10 * exact.norm(),
            "omega {omega}: {got} against {exact}"
        );
        // Solved with the contact law, the open response is the solution: the gap is
        // never closed and the force stays zero.
        let mut f = vec![0.0; x.len()];
        problem.residual(&x, &mut f);
        assert!(f.iter().all(|v| v.abs() < 1e-15));
    }
}

#[test]
fn a_base_motion_through_a_spring_gives_the_closed_form_response() {
    // Robin bar: EA p(0) + k_s (u(0) - U0) = 0 with a free tip. U = alpha cos(k (l - x)),
    // alpha (k_s cos(kl) - EA k sin(kl)) = k_s U0 (EA = 1, l = 1, c = 1).
    let (k_s, u0, eta) = (0.5, 1e-6, 0.01);
    let system = robin_bar_with_obstacle(k_s, 5.0).unwrap();
    let forcing = Forcing {
        damping: Damping::Uniform(eta),
        excitations: vec![Excitation::base_motion(
            system.bar_id(0).unwrap().left(),
            u0,
        )],
    };
    let mut problem = ForcedSystem::new(&system, settings(4), &forcing).unwrap();
    for omega in [0.3, 0.653, 1.9] {
        problem.set_parameter(omega);
        let x = problem.open_response().unwrap();
        let k = Complex64::new(omega * omega, -eta * omega).sqrt();
        let exact = k_s * u0 / (k_s * k.cos() - k * k.sin());
        let got = tip_amplitude(&problem, &x);
        assert!(
            (got - exact).norm() <= 1e-10 * exact.norm(),
            "omega {omega}: {got} against {exact}"
        );
    }
}

#[test]
fn bad_forcing_is_a_typed_error() {
    let (system, good) = clamped_base(1e-3, 0.01, 1e-6);
    let bar = system.bar_id(0).unwrap();
    let with = |damping: Damping, excitations: Vec<Excitation>| {
        ForcedSystem::new(
            &system,
            settings(4),
            &Forcing {
                damping,
                excitations,
            },
        )
        .map(|_| ())
    };
    let excitation = good.excitations.clone();
    let cases: Vec<(Result<(), Error>, &str)> = vec![
        (
            with(Damping::Uniform(-1.0), excitation.clone()),
            "negative damping",
        ),
        (
            with(Damping::Uniform(f64::NAN), excitation.clone()),
            "NaN damping",
        ),
        (
            with(Damping::PerBar(vec![0.1, 0.2]), excitation.clone()),
            "two values, one bar",
        ),
        (with(Damping::Uniform(0.1), vec![]), "no excitation"),
        (
            with(
                Damping::Uniform(0.1),
                vec![Excitation::base_motion(bar.left(), f64::INFINITY)],
            ),
            "infinite amplitude",
        ),
        (
            with(
                Damping::Uniform(0.1),
                vec![Excitation::force(bar.left(), 1.0)],
            ),
            "force at a clamped end",
        ),
        (
            with(
                Damping::Uniform(0.1),
                vec![Excitation::base_motion(bar.right(), 1.0)],
            ),
            "base motion at the contact end",
        ),
    ];
    for (result, what) in cases {
        assert!(
            matches!(result, Err(Error::Forcing(_))),
            "{what}: {result:?}"
        );
    }
    let e = with(
        Damping::Uniform(0.1),
        vec![Excitation::force(bar.left(), 1.0)],
    )
    .unwrap_err();
    assert!(
        matches!(e, Error::Forcing(ForcingError::NothingToExcite { .. })),
        "{e}"
    );
    let zero_harmonics = ForcedSystem::new(&system, settings(0), &good);
    assert!(matches!(zero_harmonics, Err(Error::Settings(_))));
    for band in [-0.1, f64::NAN, 5.0] {
        let bad_band = HarmonicBalanceSettings {
            resonance_band: band,
            ..settings(4)
        };
        let result = ForcedSystem::new(&system, bad_band, &good);
        assert!(matches!(result, Err(Error::Settings(_))), "band {band}");
    }
    let bad_range = ResponseRequest {
        settings: settings(4),
        forcing: good,
        omega_range: (1.0, 0.5),
        steps: 10,
        method: ResponseMethod::Sequential,
        solver: Default::default(),
    };
    assert!(matches!(
        forced_response(&system, &bad_range),
        Err(Error::Settings(_))
    ));
}

/// Without damping and with a zero excitation, a backbone point (cosine basis, padded with
/// zero sines) solves the forced system, and its period-averaged energy is the backbone's
/// energy: the forced problem contains the autonomous one.
#[test]
fn undamped_and_unforced_the_backbone_points_solve_the_forced_system_with_their_energy() {
    use nonsmooth_modes::branches::{
        compute, to_full_basis, BackboneOptions, Method, PeriodGrid, Request,
    };
    use nonsmooth_modes::fourier::CosineBasis;
    use nonsmooth_modes::modal::energy_at;
    let m = 12;
    for system in [
        clamped_bar_with_obstacle(1e-3).unwrap(),
        robin_bar_with_obstacle(0.5, 1e-3).unwrap(),
    ] {
        let mut options = BackboneOptions::for_mode(&system, 1, 1).unwrap();
        let g = options.grid;
        options.grid = PeriodGrid {
            start: g.start,
            end: g.start + 0.3 * (g.end - g.start),
            steps: 7,
        };
        let request = Request::for_method(Method::PeriodGrid(options)).settings(settings(m));
        let run = compute(&system, &request).unwrap();
        let forcing = Forcing {
            damping: Damping::Uniform(0.0),
            excitations: vec![Excitation::base_motion(
                system.bar_id(0).unwrap().left(),
                0.0,
            )],
        };
        let mut problem = ForcedSystem::new(&system, settings(m), &forcing).unwrap();
        let mut checked = 0;
        for p in run.converged() {
            problem.set_parameter(p.omega);
            let x = to_full_basis(&p.x, m).unwrap();
            let mut f = vec![0.0; x.len()];
            problem.residual(&x, &mut f);
            let residual = f.iter().map(|v| v * v).sum::<f64>().sqrt();
            assert!(residual < 1e-11, "T {}: residual {residual:e}", p.period);
            // The truncated motion's energy drifts over the period by the work of its
            // complementarity residual: its mean over the period is what both must agree on.
            let basis = CosineBasis::new(m, 30).unwrap();
            let instants = 256;
            let mean = (0..instants)
                .map(|k| {
                    let theta = 2.0 * std::f64::consts::PI * k as f64 / instants as f64;
                    energy_at(&system, &basis, &p.x, p.omega, theta)
                })
                .sum::<f64>()
                / instants as f64;
            let energy = problem.average_energy(&x);
            assert!(
                (energy - mean).abs() < 1e-10 * mean,
                "T {}: averaged {energy:e}, mean of the backbone's {mean:e}",
                p.period,
            );
            checked += 1;
        }
        assert!(checked >= 4, "{checked} points checked");
    }
}

/// The clamped bar's first mode, base-excited and swept up in frequency with the harmonic
/// selection: the resonance peak lies on the backbone of the same discretisation (energy
/// within 5 % of the backbone's at the peak frequency), on two grids, at two forcing levels,
/// on a grid much finer than the linear peak's width, and as damping and forcing go to zero
/// together, well past the band of frequencies where
/// the selection drops most harmonics (`docs/validation.md`, "Forced response").
/// The harmonic-balance settings of the forced sweeps: 20 harmonics with the default band.
fn with_band() -> HarmonicBalanceSettings {
    HarmonicBalanceSettings {
        harmonics: 20,
        resonance_band: nonsmooth_modes::system::RESONANCE_BAND,
        ..Default::default()
    }
}

/// `E/E_g` on the first backbone of `system` under `settings`, interpolated in frequency
/// (`None` outside the backbone's range).
fn backbone_energy(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
) -> impl Fn(f64) -> Option<f64> {
    use nonsmooth_modes::branches::{compute, Request};
    let backbone = compute(system, &Request::new(1).settings(settings)).unwrap();
    let skeleton: Vec<(f64, f64)> = (backbone.converged())
        .map(|p| (p.omega, p.energy_normalized))
        .collect();
    move |omega: f64| {
        let w = (skeleton.windows(2)).find(|w| (w[0].0 - omega) * (w[1].0 - omega) <= 0.0)?;
        let t = (omega - w[0].0) / (w[1].0 - w[0].0);
        Some(w[0].1 + t * (w[1].1 - w[0].1))
    }
}

#[test]
fn the_resonance_peak_lies_on_the_backbone() {
    let with_band = with_band();
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let on_backbone = backbone_energy(&system, with_band);
    let at = |omega| on_backbone(omega).expect("the peak within the backbone's range");
    // At a fixed ratio U / eta the peak stays where input and dissipated power balance: as
    // both go to zero (2e-3 -> 1e-3 -> 5e-4 for eta at U / eta = 2e-3) it stays on the backbone.
    let cases = [
        (1e-3, 1e-6, 451),
        (1e-3, 1e-6, 901),
        (2e-3, 4e-6, 451),
        (1e-3, 2e-6, 901),
        (5e-4, 1e-6, 901),
        // A grid of steps four times shorter than the width `eta` of a linear peak: counted
        // in steps, its failures left the branch at the band's edge (`Omega = 1.5785`).
        (2e-3, 2e-6, 901),
    ];
    for (eta, u0, steps) in cases {
        let (_, forcing) = clamped_base(1e-3, eta, u0);
        let request = ResponseRequest {
            settings: with_band,
            forcing,
            omega_range: (1.55, 2.0),
            steps,
            method: ResponseMethod::Sequential,
            solver: Default::default(),
        };
        let response = forced_response(&system, &request).unwrap();
        let peak = response.peak().unwrap();
        eprintln!(
            "eta {eta}, U {u0}, {steps} steps: peak E/E_g {:.4} at {:.4}, backbone {:.4}",
            peak.energy_normalized,
            peak.omega,
            at(peak.omega)
        );
        let on_backbone = at(peak.omega);
        let ratio = peak.energy_normalized / on_backbone;
        assert!(
            peak.omega > 1.75 && (ratio - 1.0).abs() < 0.05,
            "eta {eta}: peak E/E_g {} at {}, backbone {on_backbone}",
            peak.energy_normalized,
            peak.omega
        );
        // Past the peak the sweep drops to the low branch and ends the range there, once its
        // steps have failed over `MAX_CONSECUTIVE_FAILURES` widths `eta` (a peak closer to the
        // end of the range leaves no room to drop).
        let span = nonsmooth_modes::branches::MAX_CONSECUTIVE_FAILURES as f64 * eta;
        let last = response.points.last().unwrap();
        assert!(last.omega == 2.0);
        if 2.0 - peak.omega > 1.1 * span {
            assert!(last.converged && last.amplitude < 0.1, "{eta}: {last:?}");
        }
    }
}

/// The arclength curve of the clamped bar passes the frequency where the harmonic selection
/// switches every harmonic back on above the linear resonance (the equations jump there),
/// and the kinks of the sampled laws where its corrector stalled (at `Omega = 1.637`): past
/// the edge, its points in contact lie on the backbone of the same discretisation (energy
/// within 5 %) up to `Omega = 1.68` at least, and every point was measured with the selection
/// it was solved with.
#[test]
fn an_arclength_curve_passes_the_band_edge_onto_the_backbone() {
    let settings = with_band();
    let system = clamped_bar_with_obstacle(1e-3).unwrap();
    let on_backbone = backbone_energy(&system, settings);
    let (_, forcing) = clamped_base(1e-3, 1e-3, 1e-6);
    let request = ResponseRequest {
        settings,
        forcing,
        omega_range: (1.55, 2.0),
        steps: 200,
        method: ResponseMethod::Arclength,
        solver: Default::default(),
    };
    let response = forced_response(&system, &request).unwrap();
    // The band's upper edge about the first natural frequency pi / 2.
    let edge = std::f64::consts::FRAC_PI_2 * (1.0 + settings.resonance_band / 20.0);
    let past: Vec<_> = (response.converged())
        .filter(|p| p.omega > edge && p.amplitude > 1.0)
        .filter_map(|p| Some((p, on_backbone(p.omega)?)))
        .collect();
    assert!(
        past.len() >= 10,
        "{} points in contact past the edge {edge}; end {:?}",
        past.len(),
        response.end
    );
    let reached = past.iter().map(|(p, _)| p.omega).fold(0.0, f64::max);
    assert!(reached > 1.68, "reached {reached}; end {:?}", response.end);
    for (p, backbone) in past {
        let ratio = p.energy_normalized / backbone;
        assert!(
            (ratio - 1.0).abs() < 0.05,
            "E/E_g {} at {}, backbone {backbone}",
            p.energy_normalized,
            p.omega
        );
    }
    // Each point lists the harmonics it was solved without, once each, ascending.
    for p in &response.points {
        assert!(p.dropped_harmonics.windows(2).all(|w| w[0] < w[1]));
    }
}

/// The harmonics the selection holds at zero are listed once each: a full basis drops a
/// harmonic's cosine and sine together.
#[test]
fn dropped_harmonics_are_listed_once() {
    let (system, forcing) = clamped_base(1e-3, 1e-3, 1e-6);
    let mut problem = ForcedSystem::new(&system, with_band(), &forcing).unwrap();
    // At the first natural frequency every harmonic of the clamped bar sits on one.
    problem.set_parameter(std::f64::consts::FRAC_PI_2);
    let dropped = problem.dropped_harmonics();
    assert!(!dropped.is_empty());
    assert!(dropped.windows(2).all(|w| w[0] < w[1]), "{dropped:?}");
}

/// A force so large that `|F|^2` overflows: the dogleg's trust-region ratio was NaN, its
/// radius stopped changing and the same trial point was evaluated for ever (the reproducer of
/// the reliability issue, as drawn). It now ends with a typed error or a result, at once.
#[test]
fn a_force_whose_residual_overflows_when_squared_ends_the_dogleg() {
    use nonsmooth_modes::solve::{Dogleg, Solver};
    let system = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
    let end = system.bar_id(0).unwrap().left();
    let request = ResponseRequest {
        settings: HarmonicBalanceSettings {
            harmonics: 6,
            samples_per_harmonic: 3,
            ..Default::default()
        },
        forcing: Forcing {
            damping: Damping::PerBar(vec![0.121]),
            excitations: vec![Excitation::force(end, -3.3e153)],
        },
        omega_range: (0.6158, 0.7939),
        steps: 9,
        method: ResponseMethod::Sequential,
        solver: Solver::Dogleg(Dogleg::default()),
    };
    // Both methods: the reproducer's method was not recorded, and both call the dogleg. The
    // call runs on a thread of its own, so that a loop that never ends fails the test
    // instead of hanging it.
    for method in [ResponseMethod::Sequential, ResponseMethod::Arclength] {
        let request = ResponseRequest {
            method,
            ..request.clone()
        };
        let system = system.clone();
        let (send, receive) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let outcome = forced_response(&system, &request).map(|response| {
                response
                    .points
                    .iter()
                    .all(|p| !p.converged || p.energy.is_finite())
            });
            let _ = send.send(outcome);
        });
        // The loop never ended; Newton refuses the same call in milliseconds.
        match receive.recv_timeout(std::time::Duration::from_secs(60)) {
            Ok(Ok(finite)) => assert!(finite, "{method:?}: a converged point with NaN energy"),
            Ok(Err(e)) => assert!(!e.to_string().is_empty()),
            Err(e) => panic!("{method:?}: no answer within 60 s ({e})"),
        }
    }
}

/// The reliability reproducers of the forced system's public calls: before a frequency is
/// set, the open response is a typed error (it indexed rows not yet built); a gap history of
/// a law the system does not have, or of a state of another size, is a typed error; the
/// contact defect of a basis whose four-times-finer grid is over the memory budget is
/// measured on the basis' own grid instead of panicking.
#[test]
fn the_forced_systems_calls_refuse_what_they_cannot_use() {
    let (system, forcing) = clamped_base(1e-3, 0.02, 1e-6);
    let mut problem = ForcedSystem::new(&system, settings(3), &forcing).unwrap();
    let x = open_response_once_a_frequency_is_set(&mut problem);
    assert!(problem
        .gap_history(&x, 0)
        .unwrap()
        .iter()
        .all(|g| g.is_finite()));
    for index in [1, usize::MAX] {
        match problem.gap_history(&x, index) {
            Err(nonsmooth_modes::SettingsError::IndexOutOfRange {
                index: i, count: 1, ..
            }) => assert_eq!(i, index),
            other => panic!("{index}: {other:?}"),
        }
    }
    match problem.gap_history(&x[1..], 0) {
        Err(nonsmooth_modes::SettingsError::Length { got, expected, .. }) => {
            assert_eq!((got + 1, expected), (x.len(), x.len()))
        }
        other => panic!("{other:?}"),
    }
    // One harmonic, 10^7 samples per harmonic: within the budget, its finer grid is not.
    let huge = HarmonicBalanceSettings {
        harmonics: 1,
        samples_per_harmonic: 10_000_000,
        ..Default::default()
    };
    let mut big = ForcedSystem::new(&system, huge, &forcing).expect("within the budget");
    big.set_parameter(1.2);
    let x = big.open_response().unwrap();
    let defect = big.contact_defect(&x);
    assert!(defect.is_finite() && defect >= 0.0, "{defect}");
}

/// The reliability reproducer of an open response asked for before any frequency: the
/// two-bar system of a second bar `(0.95, 1, 1)` at gap `1e-3`, 3 harmonics, indexed the
/// rows of a frequency not yet set. It is a typed error naming the forcing frequency.
#[test]
fn an_open_response_before_a_frequency_is_a_typed_error() {
    let system = two_bars_in_contact(Bar::new(0.95, 1.0, 1.0).unwrap(), 1e-3).unwrap();
    let forcing = Forcing {
        damping: Damping::Uniform(0.02),
        excitations: vec![Excitation::base_motion(
            system.bar_id(0).unwrap().left(),
            1e-6,
        )],
    };
    let mut problem = ForcedSystem::new(&system, settings(3), &forcing).unwrap();
    let x = open_response_once_a_frequency_is_set(&mut problem);
    assert!(x.iter().all(|v| v.is_finite()), "{x:?}");
}

/// The reliability reproducers of an open response that was NaN in `Ok`: a frequency of
/// infinity or +-1e300 (the rows' sines carry no digit there), amplitudes of +-`f64::MAX` and
/// a damping of 1.7e112 (the solve overflows) are typed errors quoting the value.
#[test]
fn an_open_response_beyond_the_range_of_f64_is_a_typed_error() {
    use nonsmooth_modes::SettingsError;
    let (system, forcing) = clamped_base(1e-3, 0.02, 1e-6);
    let mut problem = ForcedSystem::new(&system, settings(3), &forcing).unwrap();
    for omega in [f64::INFINITY, f64::NEG_INFINITY, -1e300, 0.0, -1.2] {
        problem.set_parameter(omega);
        match problem.open_response() {
            Err(Error::Settings(SettingsError::NotPositive { value, .. })) => {
                assert_eq!(value, omega)
            }
            other => panic!("{omega}: {other:?}"),
        }
    }
    problem.set_parameter(1e300);
    match problem.open_response() {
        Err(Error::Settings(SettingsError::FrequencyTooLarge { omega, max, .. })) => {
            assert!(omega == 1e300 && max < 1e300 && max > 1e12, "{max:e}")
        }
        other => panic!("{other:?}"),
    }
    problem.set_parameter(1e-310);
    assert!(matches!(
        problem.open_response(),
        Err(Error::Settings(SettingsError::FrequencyTooSmall { .. }))
    ));
    let mut refused = Vec::new();
    let mut non_finite = |forcing: &Forcing| {
        let mut problem = ForcedSystem::new(&system, settings(3), forcing).unwrap();
        problem.set_parameter(1.2);
        match problem.open_response() {
            Err(Error::Settings(SettingsError::NonFiniteResult { what, omega })) => {
                assert!(what.contains("open-contact") && omega == 1.2, "{what}");
                refused.push(forcing.clone());
            }
            Ok(x) => assert!(x.iter().all(|v| v.is_finite()), "{x:?}"),
            Err(e) => panic!("{e}"),
        }
    };
    let base = system.bar_id(0).unwrap().left();
    for amplitude in [f64::MAX, -f64::MAX] {
        non_finite(&Forcing {
            damping: Damping::Uniform(0.02),
            excitations: vec![Excitation::base_motion(base, amplitude)],
        });
    }
    non_finite(&Forcing {
        damping: Damping::Uniform(1.7e112),
        excitations: vec![Excitation::base_motion(base, 1e-6)],
    });
    let robin = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
    let end = robin.bar_id(0).unwrap().left();
    for amplitude in [f64::MAX, -f64::MAX] {
        let forcing = Forcing {
            damping: Damping::PerBar(vec![0.121]),
            excitations: vec![Excitation::force(end, amplitude)],
        };
        let mut problem = ForcedSystem::new(&robin, settings(6), &forcing).unwrap();
        problem.set_parameter(0.7);
        match problem.open_response() {
            Err(Error::Settings(SettingsError::NonFiniteResult { .. })) => refused.push(forcing),
            Ok(x) => assert!(x.iter().all(|v| v.is_finite()), "{x:?}"),
            Err(e) => panic!("{e}"),
        }
    }
    // Every reproducer's NaN response is refused.
    assert_eq!(refused.len(), 5, "{refused:?}");
}

/// The reliability reproducer of an arclength response that never ended: `steps` of 2^40 or
/// `usize::MAX` are refused before the run with `TooLarge`, as the sequential grid refuses
/// them, instead of sizing a run of `4 steps` points.
#[test]
fn an_arclength_response_of_too_many_steps_is_refused() {
    use nonsmooth_modes::ContinuationError;
    let (system, forcing) = clamped_base(1e-3, 0.02, 1e-6);
    for method in [ResponseMethod::Arclength, ResponseMethod::Sequential] {
        for steps in [1usize << 40, usize::MAX] {
            let request = ResponseRequest {
                settings: settings(3),
                forcing: forcing.clone(),
                omega_range: (1.2, 1.8),
                steps,
                method,
                solver: Default::default(),
            };
            let started = std::time::Instant::now();
            match forced_response(&system, &request) {
                Err(Error::Continuation(ContinuationError::TooLarge(e))) => {
                    assert!(e.requested_bytes >= 8.0 * steps as f64, "{e}")
                }
                other => panic!("{method:?}, {steps}: {:?}", other.map(|r| r.points.len())),
            }
            assert!(started.elapsed().as_secs() < 5);
        }
    }
}

/// The stress suite's finding (case 17297 of the default seed): the open response to a base
/// motion of `-f64::MAX` with a subnormal damping is finite, but its gap history overflows;
/// it is a typed error instead of NaN in `Ok`.
#[test]
fn a_gap_history_that_overflows_is_a_typed_error() {
    use nonsmooth_modes::SettingsError;
    let system = clamped_bar_with_obstacle(0.03274889209035036).unwrap();
    let base = system.bar_id(0).unwrap().left();
    let forcing = Forcing {
        damping: Damping::Uniform(5e-324),
        excitations: vec![Excitation::base_motion(base, -f64::MAX)],
    };
    let s = HarmonicBalanceSettings {
        harmonics: 2,
        samples_per_harmonic: 37,
        complementarity: 0.12870716386037875,
        ..Default::default()
    };
    let mut problem = ForcedSystem::new(&system, s, &forcing).unwrap();
    problem.set_parameter(2.8886608796619937);
    let x = problem.open_response().unwrap();
    assert!(x.iter().all(|v| v.is_finite()));
    match problem.gap_history(&x, 0) {
        Err(SettingsError::NonFiniteResult { what, .. }) => assert_eq!(what, "gap history"),
        other => panic!("{other:?}"),
    }
}

/// Asks `problem` for its open response before any frequency (a typed error naming the
/// forcing frequency, NaN), then at `Omega = 1.2`, which it returns.
fn open_response_once_a_frequency_is_set(problem: &mut ForcedSystem) -> Vec<f64> {
    match problem.open_response() {
        Err(Error::Settings(nonsmooth_modes::SettingsError::NotFinite { what, value })) => {
            assert!(
                what.contains("forcing frequency") && value.is_nan(),
                "{what}"
            )
        }
        other => panic!("{other:?}"),
    }
    problem.set_parameter(1.2);
    problem.open_response().unwrap()
}
