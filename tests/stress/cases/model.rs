//! Models: assemblies of bars with built-in and downstream conditions, and harmonic-balance
//! settings.

use super::{random_bar, reference_system, settings, MAX_HARMONICS};
use crate::checks::{moderate_motion, typed, CaseResult, Checks};
use crate::draw::Draw;
use nonsmooth_modes::bar::{Bar, BarId, EndRef};
use nonsmooth_modes::bc::{BoundaryCondition, LinearRows, Quantity, Term};
use nonsmooth_modes::branches::{compute, BackboneOptions, Method, PeriodGrid, Request};
use nonsmooth_modes::modal::{
    branch_seed, energy, grazing_energy, natural_frequencies, ContactState,
};
use nonsmooth_modes::solve::{NewtonOptions, SemismoothNewton, Solver};
use nonsmooth_modes::system::{
    AssemblyBuilder, BarSystem, HarmonicBalanceSettings, NonsmoothSystem,
};
use std::f64::consts::PI;

/// A downstream linear condition `k u + EA p = 0` (a spring of any stiffness, NaN and
/// infinities included) whose row may name another end than its own (`stranger`) or whose
/// stiffness closure may read one: the builder must refuse an end outside the assembly.
#[derive(Debug, Clone, Copy)]
struct Downstream {
    end: EndRef,
    spring: f64,
    stranger: Option<EndRef>,
    reads_stranger: bool,
}

impl BoundaryCondition for Downstream {
    fn name(&self) -> String {
        format!("downstream spring {} at {}", self.spring, self.end)
    }
    fn ends(&self) -> Vec<EndRef> {
        vec![self.end]
    }
    fn linear_rows(&self, _: f64, stiffness: &dyn Fn(EndRef) -> f64, rows: &mut LinearRows) {
        let read = if self.reads_stranger {
            self.stranger.unwrap_or(self.end)
        } else {
            self.end
        };
        let ea = stiffness(read);
        let mut terms = vec![
            Term::new(self.end, Quantity::Displacement, self.spring),
            Term::new(self.end, Quantity::OutwardStrain, ea),
        ];
        if let Some(other) = self.stranger {
            terms.push(Term::new(other, Quantity::Displacement, 1.0));
        }
        rows.push(&terms);
    }
    fn stored_energy(&self, value: &dyn Fn(EndRef, Quantity) -> f64) -> f64 {
        0.5 * self.spring * value(self.end, Quantity::Displacement).powi(2)
    }
}

/// An id of a bar that no assembly of this case has: the fifth bar of another builder.
pub(crate) fn foreign_bar() -> BarId {
    let mut other = AssemblyBuilder::new();
    for _ in 0..4 {
        let _ = other.add_bar(Bar::unit());
    }
    other.add_bar(Bar::unit())
}

/// Bars and conditions of every kind on every end (none, two, foreign ends, downstream
/// conditions with any spring), built; a system with contact is then discretised, its linear
/// modes and grazing energy computed and a short backbone run.
pub(crate) fn assembly(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let mut b = AssemblyBuilder::new();
    let bars = d.size("bars", 1..=3).min(4);
    let mut ends = Vec::new();
    for _ in 0..bars {
        let bar = match random_bar(d) {
            Ok(bar) => bar,
            Err(e) => {
                c.error("Bar::new", &e);
                Bar::unit()
            }
        };
        let id = b.add_bar(bar);
        ends.extend([id.left(), id.right()]);
    }
    let foreign = foreign_bar().right();
    for &end in &ends {
        let other = if d.flag("foreign other end", 0.1) || ends.len() < 2 {
            foreign
        } else {
            ends[d.rng.below(ends.len() as u64) as usize]
        };
        let conditions = d.size("conditions", 1..=1).min(2);
        for _ in 0..conditions {
            let kind = d.pick(
                "condition",
                &[
                    "dirichlet",
                    "neumann",
                    "robin",
                    "signorini",
                    "signorini",
                    "contact",
                    "downstream",
                    "foreign",
                ],
            );
            let result = match kind {
                "dirichlet" => b.dirichlet(end).map(|_| ()),
                "neumann" => b.neumann(end).map(|_| ()),
                "robin" => b.robin(end, d.real("robin", 0.05..=20.0)).map(|_| ()),
                "signorini" => b.signorini(end, d.real("gap", 1e-5..=1.0)).map(|_| ()),
                "contact" => b.contact(end, other, d.real("gap", 1e-5..=1.0)).map(|_| ()),
                "downstream" => {
                    let stranger = d.flag("stranger", 0.15).then_some(other);
                    let reads_stranger = stranger.is_some() && d.flag("reads stranger", 0.5);
                    b.add_condition(Downstream {
                        end,
                        spring: d.real("spring", -5.0..=5.0),
                        stranger,
                        reads_stranger,
                    })
                    .map(|_| ())
                }
                _ => b.dirichlet(foreign).map(|_| ()),
            };
            if let Err(e) = result {
                c.error("condition", &e);
            }
        }
    }
    let system = typed(c, "build", b.build())?;
    #[cfg(feature = "serde")]
    file_round_trip(c, &system);
    if let Ok(modes) = natural_frequencies(&system, ContactState::Open, d.real("upper", 1.0..=12.0))
    {
        for m in &modes {
            c.finite("natural frequency", [&m.omega]);
            m.shapes.iter().for_each(|s| c.finite("mode shape", s));
        }
    }
    if system.contact_count() == 0 {
        return Ok(());
    }
    let s = HarmonicBalanceSettings {
        harmonics: d.size("harmonics", 1..=4).min(MAX_HARMONICS),
        samples_per_harmonic: 8,
        ..Default::default()
    };
    let mut problem = typed(c, "NonsmoothSystem::new", NonsmoothSystem::new(&system, s))?;
    let (e_g, mode) = typed(c, "grazing_energy", grazing_energy(&system))?;
    c.finite("grazing energy", [&e_g, &mode.omega]);
    let period = 2.0 * PI / mode.omega;
    if let Ok(seed) = branch_seed(&mut problem, 1, 1, mode.omega * 1.02) {
        c.finite("seed", &seed);
        if moderate_motion(&system, &seed, mode.omega) {
            let e = energy(&system, problem.basis(), &seed, mode.omega);
            c.finite("seed energy", [&e]);
        }
    }
    let grid = PeriodGrid {
        start: period * 0.99,
        end: period * 0.9,
        steps: 3,
    };
    let fast = SemismoothNewton::new(NewtonOptions::fail_fast()).expect("valid");
    let request = Request {
        settings: s,
        method: Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)),
        solver: Some(Solver::Newton(fast)),
        ..Request::new(1)
    };
    let run = typed(c, "backbone", compute(&system, &request))?;
    run.points
        .iter()
        .for_each(|p| c.backbone_point("backbone", p));
    Ok(())
}

/// A system written as an assembly file, JSON and TOML, and read back is the same system bit
/// for bit: its bars' numbers and its conditions (whose names carry their values). A system
/// with a downstream condition cannot be written (`Unrepresentable`).
#[cfg(feature = "serde")]
fn file_round_trip(c: &mut Checks, system: &BarSystem) {
    use nonsmooth_modes::io::assembly::{Assembly, AssemblyFile, FileFormat};
    let Ok(file) = AssemblyFile::from_system(system) else {
        return;
    };
    let bits = |s: &BarSystem| -> Vec<u64> {
        s.bars()
            .iter()
            .flat_map(|b| [b.length(), b.wave_speed(), b.stiffness()])
            .map(f64::to_bits)
            .collect()
    };
    let names = |s: &BarSystem| -> Vec<String> { s.conditions().map(|c| c.name()).collect() };
    for format in [FileFormat::Json, FileFormat::Toml] {
        let text = match format {
            FileFormat::Json => file.to_json(),
            FileFormat::Toml => file.to_toml(),
        };
        let text = match text {
            Ok(text) => text,
            Err(e) => {
                c.wrong
                    .push(format!("{format}: a valid system not written: {e}"));
                continue;
            }
        };
        match Assembly::parse(&text, format) {
            Ok(back) => c.expect(
                bits(back.system()) == bits(system) && names(back.system()) == names(system),
                || format!("{format}: read back with other numbers:\n{text}"),
            ),
            Err(e) => c.wrong.push(format!(
                "{format}: the file written does not read back: {e}"
            )),
        }
    }
}

/// Harmonic-balance settings of every size and value, a frequency of any value: the problem,
/// its seed and the seed's energy.
pub(crate) fn settings_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    let system = reference_system(d, c)?;
    let s = settings(d);
    let mut problem = typed(c, "NonsmoothSystem::new", NonsmoothSystem::new(&system, s))?;
    if d.flag("set kink blend", 0.3) {
        let blend = d.real("kink blend", 0.0..=0.5);
        let _ = typed(c, "set_kink_blend", problem.set_kink_blend(blend));
    }
    let omega = d.real("omega", 0.3..=10.0);
    let mode = d.size("mode", 1..=3);
    let sub = d.size("subharmonic", 1..=3);
    let seed = typed(
        c,
        "branch_seed",
        branch_seed(&mut problem, mode, sub, omega),
    )?;
    c.finite("seed", &seed);
    if moderate_motion(&system, &seed, omega) {
        c.finite(
            "seed energy",
            [&energy(&system, problem.basis(), &seed, omega)],
        );
    }
    Ok(())
}
