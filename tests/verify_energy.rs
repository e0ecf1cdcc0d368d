//! Property tests of the integrator: random admissible initial states of random assemblies keep
//! their energy to rounding over ten periods, never penetrate and never pull on a contact.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::system::{AssemblyBuilder, BarSystem};
use nonsmooth_modes::verify::{
    march, BarCells, Condition, Grid, MarchOptions, Model, SpringUpdate, State,
};
use nonsmooth_modes::ModelError;
use proptest::prelude::*;
use std::f64::consts::PI;

const DT: f64 = 0.05;

/// A small deterministic generator for the cell values (xorshift64*).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let v = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d);
        (v >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// Random assembly `kind` with bars of `cells[b]` cells and speeds `speeds[b]`; all gaps 1
/// for now (set from the initial state later).
fn assembly(kind: usize, cells: &[usize], speeds: &[f64], stiffness: &[f64], spring: f64) -> Model {
    let system = system(kind, cells, speeds, stiffness, spring).unwrap();
    Model::from_system(&system).unwrap()
}

/// The bar system of [`assembly`].
fn system(
    kind: usize,
    cells: &[usize],
    speeds: &[f64],
    stiffness: &[f64],
    spring: f64,
) -> Result<BarSystem, ModelError> {
    let mut b = AssemblyBuilder::new();
    let bar =
        |i: usize| Bar::new(cells[i] as f64 * speeds[i] * DT, speeds[i], stiffness[i]).unwrap();
    match kind {
        0 => {
            let one = b.add_bar(bar(0));
            b.dirichlet(one.left())?.signorini(one.right(), 1.0)?;
        }
        1 => {
            let one = b.add_bar(bar(0));
            b.signorini(one.left(), 1.0)?.signorini(one.right(), 1.0)?;
        }
        2 => {
            let (one, two) = (b.add_bar(bar(0)), b.add_bar(bar(1)));
            b.dirichlet(one.left())?.dirichlet(two.left())?.contact(
                one.right(),
                two.right(),
                1.0,
            )?;
        }
        3 => {
            let (one, two) = (b.add_bar(bar(0)), b.add_bar(bar(1)));
            b.dirichlet(one.left())?
                .contact(one.right(), two.left(), 1.0)?
                .signorini(two.right(), 1.0)?;
        }
        _ => {
            let one = b.add_bar(bar(0));
            b.robin(one.left(), spring)?.signorini(one.right(), 1.0)?;
        }
    }
    b.build()
}

/// Random cells (a smooth part and a rough part), clamped ends at zero displacement.
fn random_cells(model: &Model, grid: &Grid, rng: &mut Rng, roughness: f64) -> Vec<BarCells> {
    (0..model.bars().len())
        .map(|b| {
            let n = grid.cells(b);
            let clamped_left = model.conditions().iter().any(|c| {
                matches!(c, Condition::Clamped { end } if end.bar.index() == b && end.end.normal() < 0.0)
            });
            let (a1, a2, a3) = (rng.next(), rng.next(), rng.next());
            let smooth = |i: usize, p: f64| {
                let x = (i as f64 + 0.5) / n as f64;
                a1 * (PI * x + p).cos() + a2 * (3.0 * PI * x + p).sin() + a3 * x
            };
            BarCells {
                left_displacement: if clamped_left { 0.0 } else { 0.1 * rng.next() },
                strain: (0..n).map(|i| smooth(i, 0.3) + roughness * rng.next()).collect(),
                velocity: (0..n).map(|i| smooth(i, 1.1) + roughness * rng.next()).collect(),
            }
        })
        .collect()
}

/// Sets every gap so that the initial state touches (`margin = 0`) or clears its obstacles.
fn with_admissible_gaps(model: Model, grid: &Grid, cells: &[BarCells], margins: &[f64]) -> Model {
    let ends: Vec<[f64; 2]> = cells
        .iter()
        .enumerate()
        .map(|(b, c)| {
            let dx = model.bars()[b].wave_speed() * grid.dt();
            [
                c.left_displacement,
                c.left_displacement + dx * c.strain.iter().sum::<f64>(),
            ]
        })
        .collect();
    let outward = |e: nonsmooth_modes::bar::EndRef| {
        e.end.normal() * ends[e.bar.index()][usize::from(e.end.normal() > 0.0)]
    };
    let gaps: Vec<Option<f64>> = model
        .conditions()
        .iter()
        .map(|c| match *c {
            Condition::Obstacle { end, .. } => Some(outward(end)),
            Condition::Contact { first, second, .. } => Some(outward(first) + outward(second)),
            _ => None,
        })
        .collect();
    let mut model = model;
    for (i, (gap, margin)) in gaps.iter().zip(margins).enumerate() {
        if let Some(gap) = gap {
            model = model.with_gap(i, gap + margin).unwrap();
        }
    }
    model
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]

    #[test]
    fn energy_is_conserved_and_contacts_are_admissible(
        kind in 0usize..5,
        cells in prop::collection::vec(6usize..24, 2),
        speeds in prop::collection::vec(prop::sample::select(vec![0.5, 1.0, 2.0]), 2),
        stiffness in prop::collection::vec(0.3f64..3.0, 2),
        spring in 0.1f64..3.0,
        seed in 1u64..u64::MAX,
        roughness in prop::sample::select(vec![0.0, 0.3, 1.0]),
        margins in prop::collection::vec(prop::sample::select(vec![0.0, 0.0, 0.01, 0.2]), 3),
    ) {
        let model = assembly(kind, &cells, &speeds, &stiffness, spring);
        let grid = Grid::new(&model, DT).unwrap();
        let mut rng = Rng(seed);
        let data = random_cells(&model, &grid, &mut rng, roughness);
        let model = with_admissible_gaps(model, &grid, &data, &margins);
        let grid = Grid::new(&model, DT).unwrap();
        let initial = State::from_cells(&model, &grid, &data).unwrap();
        prop_assert!(initial.penetration() < 1e-14);
        // Ten periods of the slowest bar's clamped-free mode.
        let slowest = model.bars().iter().map(|b| b.length() / b.wave_speed()).fold(0.0, f64::max);
        let options = MarchOptions { spring: SpringUpdate::Midpoint, snapshot_every: 0 };
        let t = march(&initial, 40.0 * slowest, &options).unwrap();
        let scale = 1.0 + model.conditions().iter().map(|c| match c {
            Condition::Obstacle { gap, .. } | Condition::Contact { gap, .. } => gap.abs(),
            _ => 0.0,
        }).sum::<f64>();
        prop_assert!(t.energy_drift < 1e-10, "kind {} drift {:e}", kind, t.energy_drift);
        prop_assert!(t.max_penetration < 1e-13 * scale, "penetration {:e}", t.max_penetration);
        prop_assert!(t.min_contact_force >= 0.0);
        for c in &t.contacts {
            prop_assert!(c.force.iter().all(|f| *f >= 0.0));
            prop_assert!(c.gap.iter().all(|g| *g > -1e-13 * scale));
        }
    }
}

/// Energy of a Robin bar under the exact spring update: the projection error vanishes like
/// `dt^2`; the midpoint update conserves energy to rounding.
#[test]
fn spring_energy_error_is_second_order() {
    let mut drifts = Vec::new();
    for n in [25usize, 50, 100, 200] {
        let mut b = AssemblyBuilder::new();
        let one = b.add_bar(Bar::unit());
        b.robin(one.left(), 0.5)
            .unwrap()
            .signorini(one.right(), 0.03)
            .unwrap();
        let model = Model::from_system(&b.build().unwrap()).unwrap();
        let grid = Grid::new(&model, 1.0 / n as f64).unwrap();
        let initial = State::from_fields(&model, &grid, |_, x| {
            (0.01 + 0.02 * (1.3 * x).sin(), 0.01 * x)
        })
        .unwrap();
        let exact = march(&initial, 100.0, &MarchOptions::default()).unwrap();
        let midpoint = march(
            &initial,
            100.0,
            &MarchOptions {
                spring: SpringUpdate::Midpoint,
                snapshot_every: 0,
            },
        )
        .unwrap();
        assert!(midpoint.energy_drift < 1e-12, "{:e}", midpoint.energy_drift);
        assert!(exact.max_penetration < 1e-15);
        assert!(
            exact.contacts[0].force.iter().any(|f| *f > 0.0),
            "no impact"
        );
        drifts.push(exact.energy_drift);
    }
    eprintln!("energy drift of the exact spring update, dt = 1/25 .. 1/200: {drifts:?}");
    for w in drifts.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!(order > 1.7 && order < 2.3, "order {order}: {drifts:?}");
    }
    assert!(drifts[0] < 1e-2, "{drifts:?}");
}
