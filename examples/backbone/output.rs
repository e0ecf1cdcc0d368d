//! The CSV output: the library's column table (`io::columns`) in the groups of the run, one
//! row per point; the `--verify` columns, the signature columns (contact intervals,
//! subharmonic share) and the label columns come after the point's, so that every other
//! column keeps its place.

use nonsmooth_modes::branches::{BackbonePoint, PointStatus};
use nonsmooth_modes::exact::ExactPoint;
use nonsmooth_modes::io::columns::{self, Digits, Group, Row};
use nonsmooth_modes::modal::{contact_intervals, subharmonic_share};
use nonsmooth_modes::reference::ClampedFirstMode;
use nonsmooth_modes::system::NonsmoothSystem;
use std::io::Write;
use std::ops::ControlFlow;

/// The groups of the table: the point's and the run's columns, then [`Group::Verify`] if
/// `verify`, [`Group::Subharmonic`] for a subharmonic order `K > 1`, [`Group::Stability`] if
/// `stability`, [`Group::Hill`] if `hill` and [`Group::ExactBranch`] if `exact_branch`.
pub fn groups(
    verify: bool,
    subharmonic: usize,
    stability: bool,
    hill: bool,
    exact_branch: bool,
) -> Vec<Group> {
    let asked = [
        (Group::Point, true),
        (Group::Run, true),
        (Group::Verify, verify),
        (Group::Subharmonic, subharmonic > 1),
        (Group::Stability, stability),
        (Group::Hill, hill),
        (Group::ExactBranch, exact_branch),
    ];
    asked
        .into_iter()
        .filter(|&(_, on)| on)
        .map(|(g, _)| g)
        .collect()
}

/// The header of the table of [`groups`].
pub fn header(
    verify: bool,
    subharmonic: usize,
    stability: bool,
    hill: bool,
    exact_branch: bool,
) -> String {
    columns::header(&groups(verify, subharmonic, stability, hill, exact_branch))
}

/// Says on stderr why a point was not checked in the time domain, where it says why.
pub fn say_check(p: &BackbonePoint) {
    if let Some((check, reason)) = p.check.as_ref().and_then(|c| Some((c, c.reason()?))) {
        eprintln!(
            "backbone: step {} not checked in the time domain ({check}): {reason}",
            p.step
        );
    }
}

/// Says on stderr why a point has no multipliers (if `stability`) or no Hill exponents (if
/// `hill`), where they could not be computed.
pub fn say_outcomes(p: &BackbonePoint, stability: bool, hill: bool) {
    if let (true, Some(Err(e))) = (stability, &p.stability) {
        eprintln!("backbone: no multipliers for step {}: {e}", p.step);
    }
    if let (true, Some(Err(e))) = (hill, &p.hill) {
        eprintln!("backbone: no Hill exponents for step {}: {e}", p.step);
    }
}

/// Writes rows and counts them; remembers the first I/O error and stops the run on it.
pub struct Sink<'a> {
    pub out: &'a mut dyn Write,
    /// `--verify`: march every point in time and write the verification columns.
    pub verify: bool,
    pub exact: Option<f64>,
    pub total: usize,
    pub converged: usize,
    pub error: Option<std::io::Error>,
    pub progress: bool,
    /// The subharmonic order `K` of the run: `subharmonic_share` is written for `K > 1`.
    pub subharmonic: usize,
    /// `--stability`: write `stable,max_multiplier,stability_reason`.
    pub stability: bool,
    /// `--hill`: write `hill_stable,hill_max_multiplier,hill_reason`.
    pub hill: bool,
    /// `--exact`: write `harmonic_balance_distance,seeded`.
    pub exact_branch: bool,
}

impl Sink<'_> {
    /// The contacts per period and, for `K > 1`, the subharmonic share of a point (`None`,
    /// with a message on stderr, where they cannot be computed, e.g. the unknowns of a failed
    /// step are not finite; no share for a point collapsed to rest).
    fn signature(
        &self,
        problem: &mut NonsmoothSystem,
        p: &BackbonePoint,
        counted: Option<usize>,
    ) -> (Option<usize>, Option<f64>) {
        fn said<T>(
            value: Result<T, nonsmooth_modes::SettingsError>,
            what: &str,
            step: usize,
        ) -> Option<T> {
            value
                .map_err(|e| eprintln!("backbone: {what} of step {step} not computed: {e}"))
                .ok()
        }
        // A converged point carries its contact count; the others are counted here.
        let contacts = match (counted, &p.character) {
            (Some(c), _) => Ok(c),
            (None, Some(c)) => Ok(c.contacts.iter().sum::<usize>()),
            (None, None) => {
                contact_intervals(problem, &p.x, p.omega).map(|c| c.iter().sum::<usize>())
            }
        };
        let contacts = said(contacts, "contacts_per_period", p.step);
        // The share of a motion at rest is that of rounding noise: no number to report.
        let share = (self.subharmonic > 1 && p.status != PointStatus::CollapsedToRest)
            .then(|| {
                let (system, basis) = (problem.system(), problem.basis());
                let share = subharmonic_share(system, basis, &p.x, p.omega, self.subharmonic);
                said(share, "subharmonic_share", p.step)
            })
            .flatten();
        (contacts, share)
    }

    /// Writes the row of `p`, a point of `problem` (whose system is the one at the point's
    /// parameter value `parameter`, NaN for period runs).
    pub fn row(
        &mut self,
        problem: &mut NonsmoothSystem,
        p: &BackbonePoint,
        parameter: f64,
    ) -> ControlFlow<()> {
        self.row_counted(problem, p, parameter, None, None)
    }

    /// Writes the row of a point of an exact branch, whose contacts were counted on its
    /// orbit (it has no harmonic-balance unknowns to count them on).
    pub fn exact_row(&mut self, problem: &mut NonsmoothSystem, e: &ExactPoint) -> ControlFlow<()> {
        let counted = Some(e.contacts.iter().sum());
        self.row_counted(problem, &e.point, f64::NAN, counted, Some(e))
    }

    /// [`Sink::row`], with the contacts per period `counted` where they are known, and the
    /// exact point `exact_point` the point is of, for an exact branch.
    fn row_counted(
        &mut self,
        problem: &mut NonsmoothSystem,
        p: &BackbonePoint,
        parameter: f64,
        counted: Option<usize>,
        exact_point: Option<&ExactPoint>,
    ) -> ControlFlow<()> {
        self.total += 1;
        self.converged += usize::from(p.converged());
        let exact = self
            .exact
            .map(|gap| ClampedFirstMode::new(gap, p.period).energy_normalized());
        if self.progress && self.total % 25 == 0 {
            eprintln!(
                "step {:5}  T {:.5}  E/Eg {:.5e}  ds {:.3e}",
                p.step, p.period, p.energy_normalized, p.step_size
            );
        }
        if self.verify {
            say_check(p);
        }
        let (contacts, subharmonic_share) = self.signature(problem, p, counted);
        say_outcomes(p, self.stability, self.hill);
        let row = Row {
            exact,
            parameter: (!parameter.is_nan()).then_some(parameter),
            contacts,
            subharmonic_share,
            harmonic_balance_distance: exact_point.and_then(|e| e.harmonic_balance_distance),
            seeded: exact_point.map(|e| e.seeded),
            ..Row::new(p, Digits::SHORT)
        };
        let (verify, stability, hill) = (self.verify, self.stability, self.hill);
        let groups = groups(verify, self.subharmonic, stability, hill, self.exact_branch);
        let mut line = String::new();
        columns::write_row(&groups, &row, &mut line);
        match writeln!(self.out, "{line}") {
            Ok(()) => ControlFlow::Continue(()),
            Err(e) => {
                self.error = Some(e);
                ControlFlow::Break(())
            }
        }
    }
}
