//! What a user asks of [`compute`](crate::branches::compute): which nonsmooth mode, with how
//! many harmonics, by which method, with which solver, and whether every point is checked in
//! the time domain.

use crate::bar::shortest_travel_time;
use crate::branches::backbone::{ArclengthBackboneOptions, BackboneOptions};
use crate::branches::energy_backbone::EnergyBackboneOptions;
use crate::branches::switch::SwitchAt;
use crate::continuation::Speculation;
use crate::error::{BadRange, SolveError};
use crate::exact::options::ExactOptions;
use crate::solve::{NewtonOptions, SemismoothNewton, Solver};
use crate::stability::{HillOptions, StabilityOptions};
use crate::system::{BarSystem, HarmonicBalanceSettings};
use crate::verify::PeriodicityOptions;

/// How a branch is followed. Each variant but [`Method::Auto`] carries its options, built
/// from the system by their `for_mode` constructors (no option set carries another
/// system's numbers); the request's [`Request::mode`] and [`Request::subharmonic`] replace
/// the options' own.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Method {
    /// Let the system decide, from the period grid given (`None`: the system's own,
    /// [`BackboneOptions::for_mode`]), as [`compute`](crate::branches::compute) documents: a
    /// genuine subharmonic for an order `K >= 2`, otherwise the period grid where the branch
    /// can be entered at the grid's first period, and pseudo-arclength over the grid's range
    /// (walking the branch back to its first period) where it can be entered only at a higher
    /// frequency; for a request that keeps every harmonic, both on the paper's equations and
    /// under harmonic selection, the run whose skeleton covers more of the grid returned. The
    /// result records the choices ([`AutoChoice`], [`SelectionJudgement`]).
    Auto(Option<BackboneOptions>),
    /// Sequential continuation over a grid of periods ([`BackboneOptions::for_mode`]).
    PeriodGrid(BackboneOptions),
    /// Pseudo-arclength continuation in `Omega` with the stall escape
    /// ([`ArclengthBackboneOptions::for_mode`]).
    Arclength(ArclengthBackboneOptions),
    /// Pseudo-arclength that leaves its branch at a branch point for the branch crossing
    /// there.
    Switch(ArclengthBackboneOptions, SwitchAt),
    /// Sequential continuation in the energy level `E / E_g`, the frequency an unknown
    /// ([`EnergyBackboneOptions::for_mode`]).
    Energy(EnergyBackboneOptions),
    /// A genuinely subharmonic branch (NSM `i` sub `K`, `K >= 2`), left from the `K`-fold
    /// repeated branch over a period grid ([`BackboneOptions::for_mode`] with the order).
    GenuineSubharmonic(BackboneOptions),
}

impl Method {
    /// The mode and order the method's options name (`None` for [`Method::Auto`] without a
    /// grid).
    pub fn mode_and_order(&self) -> Option<(usize, usize)> {
        match self {
            Self::Auto(grid) => grid.map(|o| (o.mode, o.subharmonic)),
            Self::PeriodGrid(o) | Self::GenuineSubharmonic(o) => Some((o.mode, o.subharmonic)),
            Self::Arclength(o) | Self::Switch(o, _) => Some((o.mode, o.subharmonic)),
            Self::Energy(o) => Some((o.mode, o.subharmonic)),
        }
    }

    /// Checks the grid the method carries (a period grid, energy levels), as given, before
    /// anything is computed: [`Method::Auto`] would otherwise meet a bad period only as the
    /// frequency it derives from it. Arclength ranges are checked with the driver's options.
    ///
    /// # Errors
    /// [`BadRange`] as [`PeriodGrid::validate`](crate::branches::PeriodGrid::validate) and
    /// [`EnergyGrid::validate`](crate::branches::EnergyGrid::validate).
    pub(crate) fn validate_grid(&self) -> Result<(), BadRange> {
        match self {
            Self::Auto(Some(o)) | Self::PeriodGrid(o) | Self::GenuineSubharmonic(o) => {
                o.grid.validate()
            }
            Self::Energy(o) => o.levels.validate(),
            Self::Auto(None) | Self::Arclength(_) | Self::Switch(..) => Ok(()),
        }
    }

    /// A short name for tables and messages: `auto`, `period-grid`, `arclength`, `switch`,
    /// `energy` or `genuine-subharmonic`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Auto(_) => "auto",
            Self::PeriodGrid(_) => "period-grid",
            Self::Arclength(_) => "arclength",
            Self::Switch(..) => "switch",
            Self::Energy(_) => "energy",
            Self::GenuineSubharmonic(_) => "genuine-subharmonic",
        }
    }
}

/// Why [`Method::Auto`] chose the method it ran.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub enum AutoChoice {
    /// The requested order is `K >= 2`: a genuine subharmonic.
    Subharmonic,
    /// The branch can be entered at the grid's first period: the period grid.
    EnteredAtGridStart,
    /// The period grid fell short (it stalled, or fewer than half its steps are good:
    /// converged and, where a check was asked, verified), and pseudo-arclength over its
    /// range gave more good points: its run is returned.
    GridFellShort {
        /// Good points of the grid.
        good: usize,
        /// Steps of the grid.
        steps: usize,
    },
    /// No start was found near the grid's first period: the period grid runs from the
    /// unsolved seed, and may enter its branch further on (a run that never does ends with
    /// [`SettingsError::StartNotFound`](crate::SettingsError::StartNotFound)).
    NoStartFound,
    /// The system has floating bars, and the run from the start reached through the tethered
    /// system (every law next to a floating bar tied by a spring, lowered to zero along the
    /// path) gave more good points than the run from the searched start: its run is
    /// returned. It is the period grid from that start, or pseudo-arclength from the same
    /// start where the grid falls short and arclength does better.
    Tethered {
        /// Good points of the tethered start's run.
        good: usize,
        /// Good points of the run from the searched start (0 where it found none).
        searched_good: usize,
    },
    /// The branch could be entered only at period `entered_at`, shorter than the grid's
    /// first: pseudo-arclength from the grid's first period, which walks the branch back.
    EnteredAtShorterPeriod {
        /// Period of the start found.
        entered_at: f64,
    },
    /// The runs at the request's harmonics fell short (fewer good points than half the
    /// grid's steps), and `Auto`'s run at `harmonics` (half the request's), each converged
    /// point lifted to the request's harmonics and solved there at its frequency, gave more
    /// good points: its run is returned. Its method is the coarse run's; its points keep
    /// the coarse run's steps and branches.
    Lifted {
        /// Harmonics of the coarse run.
        harmonics: usize,
        /// Good points of the lifted run.
        good: usize,
        /// Good points of the best run at the request's harmonics.
        direct_good: usize,
    },
}

/// How [`Method::Auto`](crate::branches::Method::Auto) chose between the paper's equations
/// and harmonic selection ([`ModeBranches::selection`](crate::branches::ModeBranches::selection)):
/// the grid periods each run covers with a good point of the mode's own branch (converged,
/// labelled [`Label::Skeleton`](crate::modal::Label::Skeleton), so neither an internal resonance nor unverified where a
/// check was asked; a period counts once, from the point nearest it within half a grid
/// step).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SelectionJudgement {
    /// The selection's band width `c` ([`HarmonicBalanceSettings::resonance_band`](crate::system::HarmonicBalanceSettings::resonance_band)).
    pub width: f64,
    /// Grid periods covered by the run under selection (0 where it found no point).
    pub covered_selected: usize,
    /// Grid periods covered by the run on the paper's equations (0 where it found no
    /// point).
    pub covered_full: usize,
    /// Steps of the period grid.
    pub steps: usize,
}

impl SelectionJudgement {
    /// Whether the run under selection was returned: it covers at least as many periods (a
    /// run that failed covers none). A tie keeps the selected equations, whose truncation
    /// converges in `m` (`docs/theory.md`, "Harmonic selection"): the paper's equations then
    /// cover as much only with points that continue their branch across a truncation
    /// resonance, 20 to 80 % off the exact family on a clamped bar.
    pub fn selected(&self) -> bool {
        self.covered_selected > 0 && self.covered_selected >= self.covered_full
    }
}

/// The time-domain check of every converged point ([`crate::verify::periodicity_check`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeDomainCheck {
    /// Options of the march; its time step is replaced by [`TimeDomainCheck::for_system`]'s
    /// where built by it.
    pub options: PeriodicityOptions,
    /// A point whose displacement defect after one period exceeds this is labelled
    /// [`Label::Unverified`](crate::modal::Label::Unverified).
    pub max_displacement_defect: f64,
    /// Most time steps one point's march may take: a point whose march would take more is
    /// not checked ([`CheckOutcome::OverBudget`](crate::branches::CheckOutcome::OverBudget):
    /// it keeps its label, and a run does not count it as good); a budget of time per point,
    /// the march itself refuses what would exceed its memory or work bound
    /// ([`CheckOutcome::NotRun`](crate::branches::CheckOutcome::NotRun)).
    pub max_steps: f64,
}

impl TimeDomainCheck {
    /// Largest displacement defect of a verified point by default: 5 % of the motion's
    /// displacement, the tolerance of the crate's acceptance figures.
    pub const MAX_DISPLACEMENT_DEFECT: f64 = 0.05;
    /// Cells per shortest travel time by default (the paper's clamped bar: `dt = 1/400`).
    pub const CELLS_PER_TRAVEL: f64 = 400.0;
    /// Most time steps of one point's march by default: a second or so.
    pub const MAX_STEPS: f64 = 1e6;

    /// The check of `system`: a time step of `1/400` of the shortest travel time `l_b / c_b`
    /// of its bars (so that the cell count per bar does not depend on the units), on a
    /// grid adjusted to commensurate cells where one is near, one period,
    /// [`Self::MAX_DISPLACEMENT_DEFECT`] and [`Self::MAX_STEPS`].
    pub fn for_system(system: &BarSystem) -> Self {
        let travel = shortest_travel_time(system.bars());
        Self {
            options: PeriodicityOptions {
                dt: travel / Self::CELLS_PER_TRAVEL,
                adjust_grid: true,
                ..PeriodicityOptions::default()
            },
            max_displacement_defect: Self::MAX_DISPLACEMENT_DEFECT,
            max_steps: Self::MAX_STEPS,
        }
    }
}

/// A request of [`compute`](crate::branches::compute): NSM `mode` sub `subharmonic` of a
/// system, with `settings`, by `method`.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    /// Linear mode the branch leaves (1-based, among the modes of nonzero frequency).
    pub mode: usize,
    /// Period multiple `K` (NSM `mode` sub `K`; 1 for the main branch).
    pub subharmonic: usize,
    /// Harmonics and contact-law settings.
    pub settings: HarmonicBalanceSettings,
    /// How the branch is followed.
    pub method: Method,
    /// The nonlinear solver; `None`: the method's own ([`Request::solver_for`]).
    pub solver: Option<Solver>,
    /// Period grids only: run the first retry of each failing step on a second thread
    /// ([`Speculation`]); the points are the same bit for bit.
    pub speculation: Option<Speculation>,
    /// Check every converged point in the time domain and label those that fail it
    /// (`None`: no check; points are labelled by their harmonic content alone). The outcome
    /// of each point's check is [`BackbonePoint::check`](crate::branches::BackbonePoint::check):
    /// a system with a condition that declares no time-domain form is not marched, and its
    /// points are [`CheckOutcome::Unchecked`](crate::branches::CheckOutcome::Unchecked).
    pub check: Option<TimeDomainCheck>,
    /// Compute the Floquet multipliers of every converged point
    /// ([`stability`](crate::stability); `None`: no stability).
    pub stability: Option<StabilityOptions>,
    /// Compute the Hill exponents of every converged point ([`hill`](fn@crate::stability::hill);
    /// `None`: none), as a cross-check of [`Request::stability`].
    pub hill: Option<HillOptions>,
    /// Continue the exact periodic orbits of the time-domain integrator's one-period map
    /// over the period grid, seeded by the harmonic-balance points, with a Floquet verdict at
    /// every point ([`exact`](crate::exact); `None`: none). The result is
    /// [`ModeBranches::exact`](crate::branches::ModeBranches::exact), beside the
    /// harmonic-balance points it was seeded from.
    pub exact: Option<ExactOptions>,
}

impl Request {
    /// The main branch of NSM `mode` with the default settings, [`Method::Auto`] on the
    /// system's grid, the
    /// method's solver, no speculation and no time-domain check.
    pub fn new(mode: usize) -> Self {
        Self {
            mode,
            subharmonic: 1,
            settings: HarmonicBalanceSettings::default(),
            method: Method::Auto(None),
            solver: None,
            speculation: None,
            check: None,
            stability: None,
            hill: None,
            exact: None,
        }
    }

    /// The request that runs `method` on the mode and order its options name (NSM 1 for
    /// [`Method::Auto`] without a grid), so that the two cannot disagree.
    pub fn for_method(method: Method) -> Self {
        let (mode, order) = method.mode_and_order().unwrap_or((1, 1));
        Self::new(mode).subharmonic(order).method(method)
    }

    /// The same request with `harmonics` harmonics.
    pub fn harmonics(mut self, harmonics: usize) -> Self {
        self.settings.harmonics = harmonics;
        self
    }

    /// The same request with harmonic selection of width `width`
    /// ([`HarmonicBalanceSettings::resonance_band`](crate::system::HarmonicBalanceSettings::resonance_band); `RESONANCE_BAND` is the measured
    /// choice, 0 keeps every harmonic).
    pub fn resonance_band(mut self, width: f64) -> Self {
        self.settings.resonance_band = width;
        self
    }

    /// The same request for NSM `mode` sub `order`.
    pub fn subharmonic(mut self, order: usize) -> Self {
        self.subharmonic = order;
        self
    }

    /// The same request by `method`.
    pub fn method(mut self, method: Method) -> Self {
        self.method = method;
        self
    }

    /// The same request with `settings` (harmonics, samples, contact law).
    pub fn settings(mut self, settings: HarmonicBalanceSettings) -> Self {
        self.settings = settings;
        self
    }

    /// The same request solved by `solver` instead of the method's own.
    pub fn solver(mut self, solver: Solver) -> Self {
        self.solver = Some(solver);
        self
    }

    /// The same request with every converged point checked by `check`.
    pub fn checked(mut self, check: TimeDomainCheck) -> Self {
        self.check = Some(check);
        self
    }

    /// The same request with the Floquet multipliers of every converged point, computed with
    /// `options` ([`StabilityOptions::default`] for the usual grid and tolerance).
    pub fn with_stability(mut self, options: StabilityOptions) -> Self {
        self.stability = Some(options);
        self
    }

    /// The same request with the exact branch of the mode over its period grid, computed
    /// with `options` ([`ExactOptions::default`] for the usual grid and tolerance).
    pub fn with_exact(mut self, options: ExactOptions) -> Self {
        self.exact = Some(options);
        self
    }

    /// The same request with the Hill exponents of every converged point, computed with
    /// `options` ([`HillOptions::default`] for the usual search).
    pub fn with_hill(mut self, options: HillOptions) -> Self {
        self.hill = Some(options);
        self
    }

    /// The solver of a run by `method`: [`Request::solver`] if given; otherwise
    /// semismooth Newton that gives up early on a period grid (each step starts from a
    /// converged neighbour, and a failing step is retried from another), and with its full
    /// budget for the other methods (their escapes and starts solve from far guesses).
    ///
    /// # Errors
    /// None in practice: the fail-fast options are valid ([`SolveError::InvalidOption`]
    /// otherwise).
    pub fn solver_for(&self, method: &Method) -> Result<Solver, SolveError> {
        Ok(match (self.solver, method) {
            (Some(solver), _) => solver,
            (None, Method::PeriodGrid(_) | Method::GenuineSubharmonic(_)) => {
                Solver::Newton(SemismoothNewton::new(NewtonOptions::fail_fast())?)
            }
            (None, _) => Solver::default(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::clamped_bar_with_obstacle;

    /// The builders set what they name and nothing else; without a solver the method's own
    /// runs (fail-fast Newton on a grid, full Newton otherwise).
    #[test]
    fn builders_set_their_fields() {
        let system = clamped_bar_with_obstacle(1e-3).unwrap();
        let settings = HarmonicBalanceSettings {
            harmonics: 7,
            ..HarmonicBalanceSettings::default()
        };
        let grid = Method::PeriodGrid(BackboneOptions::for_mode(&system, 1, 1).unwrap());
        let request = Request::new(2)
            .settings(settings)
            .subharmonic(3)
            .method(grid)
            .checked(TimeDomainCheck::for_system(&system));
        assert_eq!((request.mode, request.subharmonic), (2, 3));
        assert_eq!(request.settings, settings);
        assert_eq!(request.method, grid);
        assert_eq!(request.check.unwrap().options.dt, 1.0 / 400.0);
        let fail_fast = SemismoothNewton::new(NewtonOptions::fail_fast()).unwrap();
        assert_eq!(
            request.solver_for(&grid).unwrap(),
            Solver::Newton(fail_fast)
        );
        let arclength =
            Method::Arclength(ArclengthBackboneOptions::for_mode(&system, 1, 1).unwrap());
        assert_eq!(request.solver_for(&arclength).unwrap(), Solver::default());
        let from_options = Method::PeriodGrid(BackboneOptions::for_mode(&system, 2, 3).unwrap());
        let request_of = Request::for_method(from_options);
        assert_eq!((request_of.mode, request_of.subharmonic), (2, 3));
        assert_eq!(Request::for_method(Method::Auto(None)).mode, 1);
        let dogleg = Solver::Dogleg(crate::solve::Dogleg::default());
        assert_eq!(request.solver(dogleg).solver_for(&grid).unwrap(), dogleg);
    }
}
