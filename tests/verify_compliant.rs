//! The integrator's compliant obstacle (`verify::Condition::CompliantObstacle`, a spring of
//! stiffness `k` whose free end is at gap `g0`) against exact solutions: contact onset and
//! release at their exact instants, energy to second order (exact update) or to rounding
//! (midpoint update), and the rigid obstacle as the limit `k -> infinity`.

use nonsmooth_modes::bar::{Bar, BarId};
use nonsmooth_modes::system::AssemblyBuilder;
use nonsmooth_modes::verify::{
    clamped_first_mode, march, BarCells, Condition, Grid, MarchOptions, Model, SpringUpdate, State,
    Trajectory,
};

const DT: f64 = 1.0 / 400.0;
const GAP: f64 = 1e-3;

/// The id of the first bar of an assembly (a model's bar 0).
fn first_bar() -> BarId {
    AssemblyBuilder::new().add_bar(Bar::unit())
}

/// A unit bar (`EA = c = 1`, impedance 1), free at `x = 0`, against a compliant obstacle of
/// stiffness `k` at `x = 1`.
fn free_bar_against_spring(k: f64) -> Model {
    bar_against_spring(
        Condition::Free {
            end: first_bar().left(),
        },
        k,
    )
}

/// A unit bar held at `x = 0` by `left`, against a compliant obstacle of stiffness `k` at
/// `x = 1`.
fn bar_against_spring(left: Condition, k: f64) -> Model {
    Model::new(
        vec![Bar::unit()],
        vec![
            left,
            Condition::CompliantObstacle {
                end: first_bar().right(),
                gap: GAP,
                stiffness: k,
            },
        ],
    )
    .unwrap()
}

/// The bar moving rigidly at velocity `v`, its right end at `u(1) = u1`, marched `1.9`: until
/// `t = 2` the wave reaching `x = 1` is the initial one, `w = v`, so that the end obeys
/// `p' = v` while the gap is open and `p' = v - k p` while the spring is compressed by
/// `p = u(1) - g0 > 0` (impedance 1).
fn rigid_motion(k: f64, u1: f64, v: f64, spring: SpringUpdate) -> Trajectory {
    let model = free_bar_against_spring(k);
    let grid = Grid::new(&model, DT).unwrap();
    let n = grid.cells(0);
    let cells = [BarCells {
        left_displacement: u1,
        strain: vec![0.0; n],
        velocity: vec![v; n],
    }];
    let initial = State::from_cells(&model, &grid, &cells).unwrap();
    let options = MarchOptions {
        spring,
        snapshot_every: 0,
    };
    march(&initial, 1.9, &options).unwrap()
}

/// Largest difference between the right end's displacement and `exact(t)` over a march.
fn worst(trajectory: &Trajectory, exact: impl Fn(f64) -> f64) -> f64 {
    let end = &trajectory.ends[1];
    (trajectory.times.iter().zip(&end.displacement))
        .map(|(t, u)| (u - exact(*t)).abs())
        .fold(0.0, f64::max)
}

/// Onset: the gap `d` closes at `t0 = d / v` (linear in time, inside a step), then
/// `p(t) = v/k (1 - e^(-k (t - t0)))`. Release: from `p0 > 0` moving away at `v`,
/// `p(t) = -v/k + (p0 + v/k) e^(-k t)` returns to zero at `ln(1 + k p0 / v) / k`, and the end
/// then leaves at `v`. The exact update follows both to rounding; the midpoint update to
/// `O((k dt)^2)`.
#[test]
fn onset_and_release_follow_the_exact_solution() {
    let (k, v) = (50.0, 0.01);
    // Onset 0.3 steps into step 120 (t0 = 0.30075).
    let d = v * (120.3 * DT);
    let t0 = d / v;
    let onset = |t: f64| {
        if t <= t0 {
            GAP - d + v * t
        } else {
            GAP + v / k * (1.0 - (-k * (t - t0)).exp())
        }
    };
    let p0 = 1e-3;
    let release_time = (k * p0 / v).ln_1p() / k;
    let release = |t: f64| {
        if t <= release_time {
            GAP - v / k + (p0 + v / k) * (-k * t).exp()
        } else {
            GAP - v * (t - release_time)
        }
    };
    let scale = v / k;
    let exact_onset = rigid_motion(k, GAP - d, v, SpringUpdate::Exact);
    let exact_release = rigid_motion(k, GAP + p0, -v, SpringUpdate::Exact);
    let e1 = worst(&exact_onset, onset);
    let e2 = worst(&exact_release, release);
    eprintln!("exact update: onset error {e1:e}, release error {e2:e} (scale {scale:e})");
    assert!(e1 < 1e-12 * scale && e2 < 1e-12 * p0, "{e1:e} {e2:e}");
    // The force is k p while compressed, never negative, and zero once released.
    let history = &exact_release.contacts[0];
    assert!(history.force.iter().all(|f| *f >= 0.0));
    assert!((history.force[0] / (k * p0) - 1.0).abs() < 0.1);
    assert_eq!(*history.force.last().unwrap(), 0.0);
    assert!(history.gap.last().unwrap() > &0.0);
    // Only the rigid conditions' penetration counts: the compression is the law.
    assert_eq!(exact_release.max_penetration, 0.0);

    let midpoint_onset = rigid_motion(k, GAP - d, v, SpringUpdate::Midpoint);
    let midpoint_release = rigid_motion(k, GAP + p0, -v, SpringUpdate::Midpoint);
    let m1 = worst(&midpoint_onset, onset);
    let m2 = worst(&midpoint_release, release);
    eprintln!("midpoint update: onset error {m1:e}, release error {m2:e}");
    let kdt2 = (k * DT) * (k * DT);
    assert!(m1 < kdt2 * scale && m2 < kdt2 * p0, "{m1:e} {m2:e}");
    for t in [&midpoint_onset, &midpoint_release] {
        assert!(t.energy_drift < 1e-13, "{:e}", t.energy_drift);
    }
}

/// A clamped bar against a compliant obstacle of stiffness 10, marched 100 time units through
/// many contacts: the exact update's projection loses energy at second order in `k dt / Z`,
/// the midpoint update conserves `E = elastic + k p^2 / 2` to rounding.
#[test]
fn compliant_energy_error_is_second_order() {
    let bar = first_bar();
    let mut drifts = Vec::new();
    for n in [50usize, 100, 200, 400] {
        let model = Model::new(
            vec![Bar::unit()],
            vec![
                Condition::Clamped { end: bar.left() },
                Condition::CompliantObstacle {
                    end: bar.right(),
                    gap: 0.01,
                    stiffness: 10.0,
                },
            ],
        )
        .unwrap();
        let grid = Grid::new(&model, 1.0 / n as f64).unwrap();
        let initial =
            State::from_fields(&model, &grid, |_, x| (0.02 * (1.3 * x).sin(), 0.01 * x)).unwrap();
        let exact = march(&initial, 100.0, &MarchOptions::default()).unwrap();
        let options = MarchOptions {
            spring: SpringUpdate::Midpoint,
            snapshot_every: 0,
        };
        let midpoint = march(&initial, 100.0, &options).unwrap();
        assert!(midpoint.energy_drift < 1e-12, "{:e}", midpoint.energy_drift);
        let contacts = &exact.contacts[0];
        let pressed = contacts.force.iter().filter(|f| **f > 0.0).count();
        assert!(pressed > 0 && pressed < contacts.force.len(), "{pressed}");
        assert!(contacts.force.iter().all(|f| *f >= 0.0));
        assert!(contacts.gap.iter().any(|g| *g < -1e-4), "no compression");
        drifts.push(exact.energy_drift);
    }
    eprintln!("energy drift of the exact update, dt = 1/50 .. 1/400: {drifts:?}");
    // Measured orders 1.66, 1.92, 1.94: second order once k dt / Z <= 0.1.
    for w in drifts.windows(2).skip(1) {
        let order = (w[0] / w[1]).log2();
        assert!(order > 1.8 && order < 2.3, "order {order}: {drifts:?}");
    }
    assert!(drifts[3] < 2e-3, "{drifts:?}");
}

/// The exact first nonsmooth mode of the clamped bar (rigid obstacle) marched one period
/// against compliant obstacles of growing stiffness: the end's displacement approaches the
/// rigid march's, at first order in `1/k` once `k` is large (the spring's compression under
/// the mode's force `lambda` is `lambda / k`).
#[test]
fn stiff_compliant_obstacle_tends_to_the_rigid_one() {
    let period = 3.6;
    let rigid = clamped_first_mode(GAP, period, DT).unwrap();
    let reference = march(&rigid, period, &MarchOptions::default()).unwrap();
    let snapshot = rigid.snapshot();
    let cells: Vec<BarCells> = (snapshot.bars.iter())
        .map(|b| BarCells {
            left_displacement: b.displacement[0],
            strain: b.strain.clone(),
            velocity: b.velocity.clone(),
        })
        .collect();
    let bar = first_bar();
    let mut errors = Vec::new();
    for k in [1e2, 1e3, 1e4, 1e5, 1e6] {
        let model = bar_against_spring(Condition::Clamped { end: bar.left() }, k);
        let grid = Grid::new(&model, DT).unwrap();
        let initial = State::from_cells(&model, &grid, &cells).unwrap();
        let compliant = march(&initial, period, &MarchOptions::default()).unwrap();
        let (a, b) = (
            &compliant.ends[1].displacement,
            &reference.ends[1].displacement,
        );
        assert_eq!(a.len(), b.len());
        let error = a
            .iter()
            .zip(b)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max)
            / GAP;
        errors.push(error);
    }
    eprintln!("largest end displacement difference / g0, k = 1e2 .. 1e6: {errors:?}");
    for w in errors.windows(2) {
        assert!(w[1] < w[0], "{errors:?}");
    }
    let last = errors.len() - 1;
    let order = (errors[last - 1] / errors[last]).log10();
    assert!(order > 0.8, "order {order}: {errors:?}");
    assert!(errors[last] < 1e-3, "{errors:?}");
}
