//! The time-domain check for any travel times (issue 22, item 3): bonded chains of two and three
//! bars whose travel times are not commensurate return after one period of their exact linear
//! mode with a defect that shrinks with the time step, conserve energy up to what the merges of
//! short pieces report, and harmonic-balance points of such an assembly can be checked; on a
//! commensurate grid the check gives the numbers it gave before.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{
    compute, compute_observed, BackboneOptions, BackbonePoint, Method, PeriodGrid, Request,
};
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, two_bars_in_contact};
use nonsmooth_modes::solve::{NewtonOptions, SemismoothNewton, Solver};
use nonsmooth_modes::system::{AssemblyBuilder, BarSystem, HarmonicBalanceSettings};
use nonsmooth_modes::verify::{
    march, periodicity_check, periodicity_of_state, Condition, Grid, Integrator, MarchOptions,
    Model, PeriodicityOptions, PeriodicityReport, State,
};
use std::f64::consts::{E, FRAC_1_SQRT_2, PI};
use std::ops::ControlFlow;

/// Static compression force of the chains.
const FORCE: f64 = 0.01;

/// A chain of bars clamped at both ends, each joined to the next by a contact that a static
/// compression `FORCE` keeps closed (a negative gap: the bars overlap), with its first linear
/// mode: `(model, omega, field)` where `field(bar, x) = (u, u_t)` at `t = 0` is the static
/// state plus the mode at a fifth of the amplitude that would open a contact.
struct Chain {
    model: Model,
    omega: f64,
    /// Static displacement `a_b + e_b x` of each bar: `(a_b, e_b)`.
    static_state: Vec<(f64, f64)>,
    /// Mode displacement of the junctions, `U_0 = U_B = 0` at the clamps.
    junctions: Vec<f64>,
    /// Scale of the mode in the initial state.
    amplitude: f64,
    bars: Vec<Bar>,
}

impl Chain {
    fn new(bars: &[Bar]) -> Self {
        assert!(bars.len() == 2 || bars.len() == 3);
        let omega = first_frequency(bars);
        let junctions = mode_junctions(bars, omega);
        let mut builder = AssemblyBuilder::new();
        let ids: Vec<_> = bars.iter().map(|b| builder.add_bar(*b)).collect();
        builder.dirichlet(ids[0].left()).unwrap();
        for pair in ids.windows(2) {
            builder
                .contact(pair[0].right(), pair[1].left(), 1.0)
                .unwrap();
        }
        builder.dirichlet(ids[ids.len() - 1].right()).unwrap();
        let system: BarSystem = builder.build().unwrap();
        let model = Model::from_system(&system).unwrap();
        // Uniform compression: strain -F/EA in every bar, the middle bars' left ends at 0.
        let last = bars.len() - 1;
        let static_state: Vec<(f64, f64)> = bars
            .iter()
            .enumerate()
            .map(|(b, bar)| {
                let e = -FORCE / bar.stiffness();
                (if b == last { -e * bar.length() } else { 0.0 }, e)
            })
            .collect();
        let mut chain = Self {
            model,
            omega,
            static_state,
            junctions,
            amplitude: 1.0,
            bars: bars.to_vec(),
        };
        // The dynamic force at a junction stays below a fifth of the static one.
        let largest = (0..last)
            .map(|b| (bars[b].stiffness() * chain.mode(b, bars[b].length()).1).abs())
            .fold(0.0, f64::max);
        chain.amplitude = 0.2 * FORCE / largest;
        chain
    }

    /// `(phi, phi_x)` of the mode in bar `b` at `x`.
    fn mode(&self, b: usize, x: f64) -> (f64, f64) {
        let bar = self.bars[b];
        let k = self.omega / bar.wave_speed();
        let (l, s) = (bar.length(), (k * bar.length()).sin());
        let (ua, ub) = (self.junctions[b], self.junctions[b + 1]);
        (
            (ua * (k * (l - x)).sin() + ub * (k * x).sin()) / s,
            k * (-ua * (k * (l - x)).cos() + ub * (k * x).cos()) / s,
        )
    }

    /// `(u, u_t)` at `t = 0`.
    fn field(&self, b: usize, x: f64) -> (f64, f64) {
        let (a, e) = self.static_state[b];
        (a + e * x + self.amplitude * self.mode(b, x).0, 0.0)
    }

    fn period(&self) -> f64 {
        2.0 * PI / self.omega
    }

    /// The initial state on the grid of step `dt`, every contact closed exactly.
    fn initial(&self, dt: f64) -> State {
        let grid = Grid::new(&self.model, dt).unwrap();
        let trial = State::from_fields(&self.model, &grid, |b, x| self.field(b, x)).unwrap();
        // Closed, pressed in by a rounding (an open gap of 1e-18 would be an impact).
        let mut model = self.model.clone();
        for (i, c) in self.model.conditions().iter().enumerate() {
            if let Condition::Contact { gap, .. } = *c {
                let closed = gap - trial.gap(i).unwrap();
                model = model.with_gap(i, closed - 1e-14 * closed.abs()).unwrap();
            }
        }
        let grid = Grid::new(&model, dt).unwrap();
        let state = State::from_fields(&model, &grid, |b, x| self.field(b, x)).unwrap();
        for i in 0..model.conditions().len() {
            if let Some(g) = state.gap(i) {
                assert!(g.abs() < 1e-15, "gap {g}");
            }
        }
        state
    }

    fn check(&self, dt: f64, periods: usize) -> PeriodicityReport {
        let options = PeriodicityOptions {
            dt,
            periods,
            ..Default::default()
        };
        periodicity_of_state(&self.initial(dt), self.period(), &options).unwrap()
    }

    /// The contacts stay closed and compressed over `periods` periods: every step's mean
    /// force above half the static one, every gap closed to rounding (of displacements of
    /// 0.01 over up to 5e4 steps). (The smallest force of
    /// the report can be 0: a gap that rounding leaves open by `1e-17` is an impact of zero
    /// duration.)
    fn stays_closed(&self, dt: f64, periods: usize) {
        let t = march(
            &self.initial(dt),
            periods as f64 * self.period(),
            &MarchOptions::default(),
        )
        .unwrap();
        for c in &t.contacts {
            assert!(c.force.iter().all(|f| *f > 0.5 * FORCE), "dt = {dt}");
            let open = c.gap.iter().fold(0.0f64, |m, g| m.max(g.abs()));
            assert!(open < 1e-13, "dt = {dt}: gap {open:e}");
        }
    }
}

/// `D(omega) = det K(omega)` times the sines that remove its poles, for the chain clamped at
/// both ends (dynamic stiffness `Z omega [cot, -csc; -csc, cot](omega tau)` per bar).
fn determinant(bars: &[Bar], omega: f64) -> f64 {
    let z = |b: usize| bars[b].stiffness() / bars[b].wave_speed();
    let sc = |b: usize| {
        let t = omega * bars[b].length() / bars[b].wave_speed();
        (t.sin(), t.cos())
    };
    let ((s0, c0), (s1, c1)) = (sc(0), sc(1));
    let first = z(0) * c0 * s1 + z(1) * c1 * s0;
    if bars.len() == 2 {
        return first;
    }
    let (s2, c2) = sc(2);
    first * (z(1) * c1 * s2 + z(2) * c2 * s1) - z(1) * z(1) * s0 * s2
}

/// The first root of [`determinant`] (positive near 0), by scanning and bisection.
fn first_frequency(bars: &[Bar]) -> f64 {
    let mut low = 1e-3;
    assert!(determinant(bars, low) > 0.0);
    let mut high = low;
    while determinant(bars, high) > 0.0 {
        low = high;
        high += 1e-3;
    }
    for _ in 0..200 {
        let mid = 0.5 * (low + high);
        if determinant(bars, mid) > 0.0 {
            low = mid;
        } else {
            high = mid;
        }
    }
    0.5 * (low + high)
}

/// Junction displacements `[0, U_1, .., 0]` of the mode at `omega`, largest 1.
fn mode_junctions(bars: &[Bar], omega: f64) -> Vec<f64> {
    let z = |b: usize| bars[b].stiffness() / bars[b].wave_speed();
    let t = |b: usize| omega * bars[b].length() / bars[b].wave_speed();
    let cot = |b: usize| t(b).cos() / t(b).sin();
    let mut u = if bars.len() == 2 {
        vec![0.0, 1.0, 0.0]
    } else {
        // K (U1, U2) = 0 with K11 = z0 cot0 + z1 cot1, K12 = -z1 csc1 (times omega).
        let k11 = z(0) * cot(0) + z(1) * cot(1);
        let k12 = -z(1) / t(1).sin();
        vec![0.0, -k12, k11, 0.0]
    };
    let largest = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    u.iter_mut().for_each(|v| *v /= largest);
    u
}

fn two_bars() -> Vec<Bar> {
    vec![
        Bar::new(1.0, 1.0, 1.0).unwrap(),
        Bar::new(FRAC_1_SQRT_2, 1.3, 1.7).unwrap(),
    ]
}

fn three_bars() -> Vec<Bar> {
    let mut bars = two_bars();
    bars.push(Bar::new(0.9, E / 2.0, 0.6).unwrap());
    bars
}

/// The defect of the exact mode over one period shrinks with the time step (first order: the
/// cells average the field), the energy is conserved up to what the merges remove, and the
/// contacts stay closed.
fn converges(bars: &[Bar]) -> Vec<PeriodicityReport> {
    let chain = Chain::new(bars);
    // The mode satisfies the balance at every junction.
    for b in 0..bars.len() - 1 {
        let left = bars[b].stiffness() * chain.mode(b, bars[b].length()).1;
        let right = bars[b + 1].stiffness() * chain.mode(b + 1, 0.0).1;
        assert!(
            (left - right).abs() < 1e-9 * left.abs().max(1.0),
            "{left} {right}"
        );
    }
    let reports: Vec<PeriodicityReport> = [1.0 / 25.0, 1.0 / 50.0, 1.0 / 100.0, 1.0 / 200.0]
        .iter()
        .map(|&dt| chain.check(dt, 1))
        .collect();
    for r in &reports {
        let grid = Grid::new(&chain.model, r.dt).unwrap();
        assert!(!grid.is_commensurate());
        assert!(r.energy_drift <= r.projected_energy + 1e-12, "{r:?}");
        assert!(r.max_penetration < 1e-15, "{r:?}");
        chain.stays_closed(r.dt, 1);
        assert!(r.projection_error < 0.1 * r.defect, "{r:?}");
    }
    // First order: about halved with the step.
    for w in reports.windows(2) {
        let ratio = w[0].defect / w[1].defect;
        assert!(ratio > 1.5, "halving dt: defect ratio {ratio}: {reports:?}");
    }
    assert!(reports[3].defect < reports[0].defect / 5.0, "{reports:?}");
    assert!(reports[3].defect < 0.02, "{:?}", reports[3]);
    assert!(reports[3].displacement_defect < 0.01, "{:?}", reports[3]);
    reports
}

#[test]
fn two_bars_with_incommensurate_travel_times_converge() {
    let reports = converges(&two_bars());
    eprintln!(
        "two bars, dt = 1/25 .. 1/200: defects {:?}",
        reports.iter().map(|r| r.defect).collect::<Vec<_>>()
    );
}

#[test]
fn three_bars_with_incommensurate_travel_times_converge() {
    let reports = converges(&three_bars());
    eprintln!(
        "three bars, dt = 1/25 .. 1/200: defects {:?}",
        reports.iter().map(|r| r.defect).collect::<Vec<_>>()
    );
}

/// Many periods: the waves reach their piece limit, the merges remove a little energy, and
/// exactly that: `E(t) + removed = E(0)` to rounding; the defect stays within the single
/// period's plus the reported estimate of the merges' error.
#[test]
fn long_marches_merge_and_account_for_what_they_remove() {
    let chain = Chain::new(&three_bars());
    let dt = 1.0 / 25.0;
    let one = chain.check(dt, 1);
    let many = chain.check(dt, 400);
    assert!(many.projected_energy > 0.0, "{many:?}");
    assert!(many.projected_energy < 0.02, "{many:?}");
    assert!(
        many.energy_drift <= many.projected_energy + 1e-12,
        "{many:?}"
    );
    chain.stays_closed(dt, 400);
    assert!(
        many.defect < 2.0 * one.defect + many.projection_error,
        "{one:?} {many:?}"
    );
    // The trajectory: E(T) + removed = E(0).
    let initial = chain.initial(dt);
    let t = march(&initial, 400.0 * chain.period(), &MarchOptions::default()).unwrap();
    let (e0, e1) = (t.energy[0], *t.energy.last().unwrap());
    assert!(
        (e1 + t.projected_energy - e0).abs() < 1e-12 * e0,
        "{e0} {e1} {}",
        t.projected_energy
    );
    // An integrator on its own keeps the default resolution: the pieces stay below the bound
    // at every step, and the steps report what they remove.
    let grid = initial.grid().clone();
    let bound: usize = (0..grid.bars()).map(|b| 2 * grid.max_pieces(b)).sum();
    let mut integrator = Integrator::new(initial.clone(), MarchOptions::default());
    let mut removed = 0.0;
    for _ in 0..20_000 {
        removed += integrator.step().projected_energy;
        assert!(integrator.state().pieces() <= bound);
    }
    let state = integrator.state();
    assert!((removed - state.projected_energy()).abs() < 1e-12 * e0);
    assert!((state.energy() + removed - e0).abs() < 1e-12 * e0);
    assert!(removed > 0.0);
}

/// A harmonic-balance point of the paper's two-bar system with a second bar of length
/// `1/sqrt(2)`: no step gives both bars an integer number of cells, and the point is checked
/// as well as its commensurate neighbour (length 0.95, Fig. 16).
#[test]
fn harmonic_balance_point_with_incommensurate_bars_is_checked() {
    let settings = HarmonicBalanceSettings {
        harmonics: 20,
        ..Default::default()
    };
    let basis = settings.cosine_basis().unwrap();
    for length in [FRAC_1_SQRT_2, 0.95] {
        let system = two_bars_in_contact(Bar::new(length, 1.0, 1.0).unwrap(), 1e-3).unwrap();
        let grid = PeriodGrid {
            start: 3.95,
            end: 3.85,
            steps: 3,
        };
        let request = Request {
            settings,
            method: Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)),
            solver: Some(Solver::default()),
            ..Request::new(1)
        };
        let points = compute(&system, &request).unwrap().points;
        let point = points.first().unwrap();
        assert!(point.converged());
        let mut reports = Vec::new();
        for dt in [1.0 / 200.0, 1.0 / 400.0] {
            let check = PeriodicityOptions {
                dt,
                ..Default::default()
            };
            let r = periodicity_check(&system, &basis, &point.x, point.omega, &check).unwrap();
            assert!(r.displacement_defect < 0.05, "l = {length}: {r:?}");
            assert!(r.defect < 0.25, "l = {length}: {r:?}");
            assert!(r.energy_drift <= r.projected_energy + 1e-12, "{r:?}");
            assert!(r.min_contact_force >= 0.0);
            assert!(r.max_penetration <= r.initial_penetration + 1e-12);
            reports.push(r);
        }
        // The defect is the harmonic-balance point's, not the grid's.
        let change = (reports[0].defect / reports[1].defect - 1.0).abs();
        assert!(change < 0.1, "l = {length}: {reports:?}");
    }
}

/// The first point of the `backbone` example's backbones of the clamped bar and of the
/// two-bar system with `--verify`, with the numbers the integrator gave before it handled
/// any travel times (`cargo run --release --example backbone -- --verify`, and with
/// `--system two-bar`, at the commit before; 7 digits as printed). Both grids are
/// commensurate; nothing is merged.
#[test]
fn commensurate_checks_give_the_numbers_they_gave_before() {
    let settings = HarmonicBalanceSettings::default();
    let basis = settings.cosine_basis().unwrap();
    let cases = [
        (
            clamped_bar_with_obstacle(1e-3).unwrap(),
            [1.177936e-1, 1.660649e-2, 1.698522e-5],
        ),
        (
            two_bars_in_contact(Bar::new(0.95, 1.0, 1.0).unwrap(), 1e-3).unwrap(),
            [1.304605e-1, 2.371669e-2, 2.362735e-5],
        ),
    ];
    for (system, before) in cases {
        let grid = PeriodGrid {
            start: 3.95,
            end: 3.05,
            steps: 181,
        };
        let solver = SemismoothNewton::new(NewtonOptions::fail_fast()).unwrap();
        let request = Request {
            settings,
            method: Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)),
            solver: Some(Solver::Newton(solver)),
            ..Request::new(1)
        };
        let mut first = None;
        compute_observed(&system, &request, |p: &BackbonePoint| {
            first = Some(p.clone());
            ControlFlow::Break(())
        })
        .unwrap();
        let p = first.unwrap();
        let check = PeriodicityOptions {
            adjust_grid: true,
            ..Default::default()
        };
        let r = periodicity_check(&system, &basis, &p.x, p.omega, &check).unwrap();
        let now = [r.defect, r.displacement_defect, r.max_penetration];
        for (a, b) in now.iter().zip(before) {
            assert!((a / b - 1.0).abs() < 1e-6, "{now:?} vs {before:?}");
        }
        assert!(
            r.projected_energy < 1e-25 && r.projection_error < 1e-10,
            "{r:?}"
        );
        assert!(r.energy_drift < 1e-12);
    }
}
