//! The kinds of cases, and the inputs several of them share: the paper's reference systems
//! and harmonic-balance settings.

mod backbones;
mod drivers;
mod exact;
mod forced;
mod full_basis;
mod model;
mod post;
mod solvers;
mod surfaces;

use crate::checks::{typed, CaseResult, Checks};
use crate::draw::Draw;
use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::modal::grazing_energy;
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, robin_bar_with_obstacle, two_bars_in_contact,
};
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};
use std::f64::consts::PI;

/// Most harmonics of a valid case.
pub(crate) const MAX_HARMONICS: usize = 8;

/// A kind of case: the part of the public API it stresses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Kind {
    Assembly,
    Settings,
    Solver,
    Backbone,
    Sequential,
    Arclength,
    ArclengthBackbone,
    ParameterBranch,
    PostProcessing,
    Request,
    FullBasis,
    Forced,
    FullBasisHelpers,
    ForcedCalls,
    Stability,
    Exact,
}

/// Every kind, drawn uniformly by each case.
pub(crate) const KINDS: [Kind; 16] = [
    Kind::Assembly,
    Kind::Settings,
    Kind::Solver,
    Kind::Backbone,
    Kind::Sequential,
    Kind::Arclength,
    Kind::ArclengthBackbone,
    Kind::ParameterBranch,
    Kind::PostProcessing,
    Kind::Request,
    Kind::FullBasis,
    Kind::Forced,
    Kind::FullBasisHelpers,
    Kind::ForcedCalls,
    Kind::Stability,
    Kind::Exact,
];

impl Kind {
    pub(crate) fn run(self, d: &mut Draw, c: &mut Checks) -> CaseResult {
        match self {
            Kind::Assembly => model::assembly(d, c),
            Kind::Settings => model::settings_case(d, c),
            Kind::Solver => solvers::solver_case(d, c),
            Kind::Backbone => backbones::backbone_case(d, c),
            Kind::Sequential => drivers::sequential_case(d, c),
            Kind::Arclength => drivers::arclength_case(d, c),
            Kind::ArclengthBackbone => backbones::arclength_backbone_case(d, c),
            Kind::ParameterBranch => backbones::parameter_case(d, c),
            Kind::PostProcessing => post::post_processing(d, c),
            Kind::Request => backbones::request_case(d, c),
            Kind::FullBasis => full_basis::full_basis_case(d, c),
            Kind::Forced => forced::forced_case(d, c),
            Kind::FullBasisHelpers => surfaces::full_basis_helpers_case(d, c),
            Kind::ForcedCalls => surfaces::forced_calls_case(d, c),
            Kind::Stability => surfaces::stability_case(d, c),
            Kind::Exact => exact::exact_case(d, c),
        }
    }
}

/// One of the paper's systems, with a random gap (and spring, or second bar).
pub(crate) fn reference_system(d: &mut Draw, c: &mut Checks) -> Result<BarSystem, String> {
    let gap = d.real("gap", 1e-6..=1.0);
    let system = match d.pick("system", &["clamped", "robin", "two bars"]) {
        "clamped" => clamped_bar_with_obstacle(gap),
        "robin" => robin_bar_with_obstacle(d.real("spring", 0.05..=20.0), gap),
        _ => {
            let second = typed(c, "Bar::new", random_bar(d))?;
            two_bars_in_contact(second, gap)
        }
    };
    typed(c, "reference system", system)
}

pub(crate) fn random_bar(d: &mut Draw) -> Result<Bar, nonsmooth_modes::ModelError> {
    Bar::new(
        d.real("length", 0.2..=5.0),
        d.real("wave speed", 0.2..=5.0),
        d.real("stiffness", 0.1..=10.0),
    )
}

pub(crate) fn settings(d: &mut Draw) -> HarmonicBalanceSettings {
    HarmonicBalanceSettings {
        harmonics: d.size("harmonics", 1..=MAX_HARMONICS),
        samples_per_harmonic: d.size("samples_per_harmonic", 3..=40),
        complementarity: d.real("complementarity", 0.1..=100.0),
        kink_blend: if d.flag("blend", 0.2) {
            d.real("kink_blend", 0.0..=0.1)
        } else {
            0.0
        },
        resonance_band: if d.flag("selection", 0.3) {
            d.real("resonance_band", 0.0..=0.5)
        } else {
            0.0
        },
    }
}

/// A valid reference system with valid small settings, for the kinds that stress something
/// else: the problem, its system and the first linear period (`2 pi / omega_1`).
pub(crate) fn valid_problem(
    d: &mut Draw,
    c: &mut Checks,
) -> Result<(NonsmoothSystem, f64), String> {
    let saved = d.edge;
    d.edge = 0.0;
    let system = reference_system(d, c);
    let s = settings(d);
    d.edge = saved;
    let system = system?;
    let problem = typed(c, "NonsmoothSystem::new", NonsmoothSystem::new(&system, s))?;
    let (_, mode) = typed(c, "grazing_energy", grazing_energy(&system))?;
    Ok((problem, 2.0 * PI / mode.omega))
}
