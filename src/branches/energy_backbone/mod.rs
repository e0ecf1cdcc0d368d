//! Backbones parametrised by energy: the nonsmooth mode continued in `E / E_g` with the
//! frequency as an unknown ([`EnergyLevel`]), from the grazing point of a linear mode.

pub(crate) mod judge;

use judge::{Judge, Walk};
pub use judge::{CALM_STEPS, ESCAPE_PERIODS, MARGINAL_SHARE, SLOPE_COLLAPSE, SLOPE_MEMORY};

use crate::branches::level::EnergyLevel;
use crate::branches::point::{BackbonePoint, PointStatus, Timescale};
use crate::continuation::{
    augmented, geomspace, Direction, EndReason, Ends, Predictor, Range, Sequential,
    SequentialOptions, Step,
};
use crate::error::{BadRange, Error};
use crate::modal::drift::check_held;
use crate::modal::energy::energy;
use crate::modal::linear::{grazing_energy, grazing_energy_of, open_mode};
use crate::solve::NonlinearSolver;
use crate::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};
use std::ops::ControlFlow;

/// `steps` energy levels `E / E_g` from `start` to `end` (both included) in geometric
/// progression, rising: the run starts at the mode's grazing point and climbs the levels
/// above it ([`EnergyGrid::validate`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct EnergyGrid {
    /// First level (positive).
    pub start: f64,
    /// Last level (positive).
    pub end: f64,
    /// Number of levels (at least 2).
    pub steps: usize,
}

impl EnergyGrid {
    /// Checks the levels as given, before anything is computed.
    ///
    /// # Errors
    /// [`BadRange`] quoting the grid: a level that is not finite or not positive, fewer than
    /// 2 steps, equal ends (every step the same level) or a grid that falls: the run climbs
    /// from the grazing point through the levels above the one it has reached, so a falling
    /// grid would jump to its first level and walk down against the run.
    pub fn validate(&self) -> Result<(), BadRange> {
        Range::grid("energy grid", self.start, self.end, self.steps)
            .check(Ends::Positive, Direction::Rising)
    }

    /// The first mode's grid: `E / E_g` from 1, its grazing point, to 300, in 181 levels.
    /// For the clamped bar this spans the paper's periods, `T = 3.90` to `3.02`.
    const FIRST_MODE: Self = Self {
        start: 1.0,
        end: 300.0,
        steps: 181,
    };

    /// The grid of NSM `mode` of `system`: from the grazing energy of linear mode `mode`
    /// (where its nonsmooth mode leaves the linear family) to 300 times it, in 181 levels;
    /// `1` to `300` in 181 levels for `mode = 1`.
    ///
    /// # Errors
    /// A failed mode search or grazing energy ([`grazing_energy_of`]).
    pub fn for_mode(system: &BarSystem, mode: usize) -> Result<Self, Error> {
        let default = Self::FIRST_MODE;
        if mode == 1 {
            return Ok(default);
        }
        let (e_g, _) = grazing_energy(system)?;
        let start = grazing_energy_of(system, &open_mode(system, mode)?)? / e_g;
        Ok(Self {
            start,
            end: start * default.end / default.start,
            ..default
        })
    }
}

/// Options of an energy backbone ([`Method::Energy`](crate::branches::Method::Energy)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyBackboneOptions {
    /// Levels to visit ([`EnergyGrid::for_mode`] derives them from the system).
    pub levels: EnergyGrid,
    /// Linear mode the branch starts from (1-based, among the modes of nonzero frequency;
    /// default 1).
    pub mode: usize,
    /// Period multiple `k` of the seed (NSM `mode` sub `k`; default 1).
    pub subharmonic: usize,
    /// Predictor of the sequential driver (default secant: the frequency changes smoothly
    /// with the energy along a branch).
    pub predictor: Predictor,
    /// Consecutive failures before the run stops (default 40).
    pub max_consecutive_failures: usize,
    /// Retry a failed step from up to this many earlier converged points (default 1).
    pub retry_depth: usize,
}

impl EnergyBackboneOptions {
    /// The options of NSM `mode` sub `subharmonic` of `system`: the levels
    /// [`EnergyGrid::for_mode`], a secant predictor, 40 consecutive failures, one retry.
    ///
    /// # Errors
    /// See [`EnergyGrid::for_mode`].
    pub fn for_mode(system: &BarSystem, mode: usize, subharmonic: usize) -> Result<Self, Error> {
        Ok(Self {
            levels: EnergyGrid::for_mode(system, mode)?,
            mode,
            subharmonic,
            predictor: Predictor::Secant,
            max_consecutive_failures: 40,
            retry_depth: 1,
        })
    }
}

/// Computes a backbone by sequential continuation in the energy level `E / E_g`, the
/// frequency being an unknown ([`EnergyLevel`]), and hands each point, converged or not, to
/// `observer` (which may stop the run). Returns `E_g` and why the run ended.
///
/// # The run
/// - **Start.** A nonsmooth mode at a fixed frequency just above linear mode `mode`'s,
///   solved from its grazing seed (placed on harmonic `subharmonic`; see
///   [`START_RATIOS`](crate::branches::START_RATIOS), then the nearer
///   [`CLOSE_START_RATIOS`](crate::branches::CLOSE_START_RATIOS) where a branch hardens so
///   little that it has left the seed's reach at the first). Its level is the branch's first;
///   the grid's levels above it follow.
/// - **Levels.** Each level is solved in `(x, Omega)` from the predictor. The state of
///   rest is no solution at any level, so no point collapses to it.
/// - **Acceptance.** A converged point joins the branch if its frequency is positive (and
///   below the problem's
///   [`max_frequency`](crate::system::Discretization::max_frequency)), it touches (a motion
///   without contact is a linear one), harmonic `subharmonic` carries the most of its
///   time-averaged energy, no other harmonic takes more than [`MARGINAL_SHARE`] of the energy
///   added since the last accepted point, and its period keeps falling at a rate comparable
///   to the last steps' ([`SLOPE_COLLAPSE`], [`SLOPE_MEMORY`]). Refused points are reported
///   as [`PointStatus::Rejected`].
/// - **Internal resonances.** Where harmonic `n` of the truncated system resonates with a
///   linear mode (`n Omega = omega_j`), the branch has a spike: in the period its energy
///   rises without bound on both sides of `T_r = 2 pi n / omega_j`, so in the energy it
///   climbs one flank for ever and never reaches the other side; the last two tests refuse
///   the flank. When [`ESCAPE_AFTER`] levels in a row are refused or fail, the run walks
///   the spike in the period, as a period grid does, from the last accepted point (at most
///   [`ESCAPE_PERIODS`] steps of `1/800` of its period, each a reported point), until
///   [`CALM_STEPS`] steps in a row grow steadily, and continues in the energy from there.
///   Branches are assumed to harden (the period falls as the energy grows), as they do with
///   gaps that close.
///
/// `docs/assemblies.md` compares it with the period grid on systems with exact solutions.
///
/// # Errors
/// Invalid settings or options, an assembly with a bar that can drift away
/// ([`SettingsError::Unconfined`](crate::SettingsError::Unconfined)), or no start
/// ([`SettingsError::NoStart`](crate::SettingsError::NoStart)): nothing was
/// computed.
pub(crate) fn energy_backbone_with<S: NonlinearSolver>(
    system: &BarSystem,
    settings: HarmonicBalanceSettings,
    options: &EnergyBackboneOptions,
    solver: S,
    mut observer: impl FnMut(BackbonePoint) -> ControlFlow<()>,
) -> Result<(f64, EndReason), Error> {
    let grid = options.levels;
    grid.validate()?;
    let problem = NonsmoothSystem::new(system, settings)?;
    // A bar that can drift away has no periodic motion that touches it: refused as by the
    // period and arclength backbones.
    check_held(system)?;
    let levels = geomspace(grid.start, grid.end, grid.steps)?;
    let (e_g, first) = grazing_energy(system)?;
    let linear = if options.mode == 1 {
        first
    } else {
        open_mode(system, options.mode)?
    };
    let mut judge = Judge::new(problem.clone(), e_g, options.subharmonic);
    let (mut x, mut omega) = judge.start(&solver, &linear)?;
    let seq_options = SequentialOptions {
        predictor: options.predictor,
        max_consecutive_failures: options.max_consecutive_failures,
        retry_depth: options.retry_depth,
        ..SequentialOptions::default()
    };
    let mut offset = 0;
    loop {
        let level = judge.level(&x, omega);
        let values: Vec<f64> = std::iter::once(level)
            .chain(levels.iter().copied().filter(|&l| l > level))
            .collect();
        let start = augmented::join(x.clone(), omega);
        // The segment's first point is its start, a solution already judged.
        judge.forget_reference();
        let mut driver = Sequential::new(
            EnergyLevel::new(problem.clone(), e_g)?,
            &solver,
            start,
            values,
            seq_options,
        )?
        // The judge decides what counts as rest.
        .with_rest_accepted()
        .with_acceptance(|y, _| {
            augmented::split(y).is_some_and(|(x, omega)| judge.accepts(x, omega))
        });
        let mut segment = Segment::default();
        let branch = driver.run(&mut |step: &Step| {
            let Some(p) = step.point() else {
                return ControlFlow::Continue(());
            };
            let Some((x, omega)) = augmented::split(&p.x) else {
                return ControlFlow::Continue(());
            };
            let e = energy(system, problem.basis(), x, omega);
            let status = PointStatus::refused_as(p, PointStatus::Rejected);
            let time = Timescale::of_frequency(omega);
            let mut point = BackbonePoint::from_parts(p, (x, time), e, e_g, status);
            point.step += offset;
            segment.see(&point);
            if observer(point).is_break() {
                segment.stopped = true;
                return ControlFlow::Break(());
            }
            segment.flow()
        });
        // The driver's acceptance test borrows the judge: give it back before the walk.
        drop(driver);
        offset += segment.points;
        let (true, false, Some(last)) = (segment.escaping, segment.stopped, segment.last_accepted)
        else {
            return Ok((e_g, branch.end));
        };
        judge.set_reference(&last.0, last.1);
        let walked = judge.walk(&solver, (&last.0, last.1), grid.end, |mut point| {
            point.step += offset;
            offset += 1;
            observer(point)
        });
        match walked {
            Walk::Resume(x_new, omega_new) => (x, omega) = (x_new, omega_new),
            Walk::Stopped => return Ok((e_g, EndReason::StoppedByObserver)),
            Walk::Beyond => return Ok((e_g, EndReason::Completed)),
            Walk::Lost => {
                let parameter = judge.level(&last.0, last.1);
                let failures = ESCAPE_PERIODS;
                return Ok((
                    e_g,
                    EndReason::Stalled {
                        failures,
                        parameter,
                    },
                ));
            }
        }
    }
}

/// Consecutive refused or failed levels after which an energy backbone jumps past an
/// internal resonance.
pub const ESCAPE_AFTER: usize = 2;

/// What one segment of an energy backbone (a run of the driver between two escapes) saw.
#[derive(Default)]
struct Segment {
    /// Points handed to the observer.
    points: usize,
    /// Refused or failed levels in a row.
    misses: usize,
    /// The last accepted point's `(x, Omega)`.
    last_accepted: Option<(Vec<f64>, f64)>,
    /// The segment stopped to jump a resonance.
    escaping: bool,
    /// The observer stopped the run.
    stopped: bool,
}

impl Segment {
    fn see(&mut self, point: &BackbonePoint) {
        self.points += 1;
        if point.converged() {
            self.misses = 0;
            self.last_accepted = Some((point.x.clone(), point.omega));
        } else {
            self.misses += 1;
        }
    }

    /// Stops the segment to escape after [`ESCAPE_AFTER`] misses in a row.
    fn flow(&mut self) -> ControlFlow<()> {
        if self.misses >= ESCAPE_AFTER && self.last_accepted.is_some() {
            self.escaping = true;
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}
