//! The CSV output: its header, one row per point, the `--verify` columns, the signature
//! columns (contact intervals, subharmonic share) and the label columns, last so that every
//! other column keeps its place.

use nonsmooth_modes::branches::{BackbonePoint, PointStatus};
use nonsmooth_modes::continuation::Event;
use nonsmooth_modes::exact::ExactPoint;
use nonsmooth_modes::modal::{contact_intervals, subharmonic_share};
use nonsmooth_modes::reference::ClampedFirstMode;
use nonsmooth_modes::stability::Verdict;
use nonsmooth_modes::system::NonsmoothSystem;
use std::io::Write;
use std::ops::ControlFlow;

pub const HEADER: &str = "step,period,omega,energy,energy_normalized,exact_energy_normalized,converged,status,residual_norm,iterations,step_size,event,parameter";

/// The whole header: [`HEADER`], the `--verify` columns if `verify`, then
/// `contacts_per_period`, `subharmonic_share` for a subharmonic order `K > 1`, and
/// `label,branch,dominant_harmonic`, then [`STABILITY_COLUMNS`] if `stability` and
/// [`HILL_COLUMNS`] if `hill`.
pub fn header(verify: bool, subharmonic: usize, stability: bool, hill: bool) -> String {
    let mut header = HEADER.to_string();
    if verify {
        header.push_str(VERIFY_COLUMNS);
    }
    header.push_str(",contacts_per_period");
    if subharmonic > 1 {
        header.push_str(",subharmonic_share");
    }
    header.push_str(",label,branch,dominant_harmonic");
    if stability {
        header.push_str(STABILITY_COLUMNS);
    }
    if hill {
        header.push_str(HILL_COLUMNS);
    }
    header
}

/// The columns of `--verify`.
pub const VERIFY_COLUMNS: &str =
    ",periodicity_defect,displacement_defect,max_penetration,time_domain_check";

/// The columns of `--stability`.
pub const STABILITY_COLUMNS: &str = ",stable,max_multiplier,stability_reason";

/// The columns of `--hill`.
pub const HILL_COLUMNS: &str = ",hill_stable,hill_max_multiplier,hill_reason";

fn events(events: &[Event]) -> String {
    events
        .iter()
        .map(Event::label)
        .collect::<Vec<_>>()
        .join(";")
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
    /// `--hill`: write `hill_stable,hill_max_multiplier`.
    pub hill: bool,
}

impl Sink<'_> {
    /// `,contacts_per_period` and, for `K > 1`, `,subharmonic_share` of a point (empty cells
    /// where they cannot be computed, e.g. the unknowns of a failed step are not finite, and
    /// an empty share for a point collapsed to rest).
    fn signature(
        &self,
        problem: &mut NonsmoothSystem,
        p: &BackbonePoint,
        counted: Option<usize>,
    ) -> String {
        let cell = |value: Result<String, nonsmooth_modes::SettingsError>, what: &str| {
            value.unwrap_or_else(|e| {
                eprintln!("backbone: {what} of step {} not computed: {e}", p.step);
                String::new()
            })
        };
        // A converged point carries its contact count; the others are counted here.
        let contacts = match (counted, &p.character) {
            (Some(c), _) => Ok(c),
            (None, Some(c)) => Ok(c.contacts.iter().sum::<usize>()),
            (None, None) => {
                contact_intervals(problem, &p.x, p.omega).map(|c| c.iter().sum::<usize>())
            }
        };
        let mut cells = format!(
            ",{}",
            cell(contacts.map(|c| c.to_string()), "contacts_per_period")
        );
        if self.subharmonic > 1 && p.status == PointStatus::CollapsedToRest {
            // The share of a motion at rest is that of rounding noise: no number to report.
            cells.push(',');
        } else if self.subharmonic > 1 {
            let (system, basis) = (problem.system(), problem.basis());
            let share = subharmonic_share(system, basis, &p.x, p.omega, self.subharmonic);
            cells.push(',');
            cells.push_str(&cell(
                share.map(|s| format!("{s:.6e}")),
                "subharmonic_share",
            ));
        }
        cells
    }

    /// [`verification_cells`], or nothing without `--verify`.
    fn verification(&self, p: &BackbonePoint) -> String {
        if self.verify {
            verification_cells(p)
        } else {
            String::new()
        }
    }

    /// `,label,branch,dominant_harmonic` of a point (label and harmonic empty for a point
    /// that did not converge).
    fn label(p: &BackbonePoint) -> String {
        let label = p
            .label
            .as_ref()
            .map(ToString::to_string)
            .unwrap_or_default();
        let harmonic = p
            .character
            .as_ref()
            .map(|c| c.dominant_harmonic.to_string())
            .unwrap_or_default();
        format!(",{label},{},{harmonic}", p.branch)
    }

    /// [`stability_cells`] and [`hill_cells`], or nothing without `--stability` and `--hill`.
    fn stability(&self, p: &BackbonePoint) -> String {
        let mut cells = String::new();
        if self.stability {
            cells.push_str(&stability_cells(p));
        }
        if self.hill {
            cells.push_str(&hill_cells(p));
        }
        cells
    }

    /// Writes the row of `p`, a point of `problem` (whose system is the one at the point's
    /// parameter value `parameter`, NaN for period runs).
    pub fn row(
        &mut self,
        problem: &mut NonsmoothSystem,
        p: &BackbonePoint,
        parameter: f64,
    ) -> ControlFlow<()> {
        self.row_counted(problem, p, parameter, None)
    }

    /// Writes the row of a point of an exact branch, whose contacts were counted on its
    /// orbit (it has no harmonic-balance unknowns to count them on).
    pub fn exact_row(&mut self, problem: &mut NonsmoothSystem, e: &ExactPoint) -> ControlFlow<()> {
        self.row_counted(problem, &e.point, f64::NAN, Some(e.contacts.iter().sum()))
    }

    /// [`Sink::row`], with the contacts per period `counted` where they are known.
    fn row_counted(
        &mut self,
        problem: &mut NonsmoothSystem,
        p: &BackbonePoint,
        parameter: f64,
        counted: Option<usize>,
    ) -> ControlFlow<()> {
        self.total += 1;
        self.converged += usize::from(p.converged);
        let exact = self
            .exact
            .map(|gap| ClampedFirstMode::new(gap, p.period).energy_normalized());
        if self.progress && self.total % 25 == 0 {
            eprintln!(
                "step {:5}  T {:.5}  E/Eg {:.5e}  ds {:.3e}",
                p.step, p.period, p.energy_normalized, p.step_size
            );
        }
        let verification = self.verification(p);
        let signature = self.signature(problem, p, counted);
        let line = format!(
            "{},{:.10},{:.10},{:.10e},{:.10e},{},{},{},{:.3e},{},{:.6e},{},{}{}{}{}{}",
            p.step,
            p.period,
            p.omega,
            p.energy,
            p.energy_normalized,
            exact.map(|e| format!("{e:.10e}")).unwrap_or_default(),
            p.converged,
            p.status.label(),
            p.residual_norm,
            p.iterations,
            p.step_size,
            events(&p.events),
            if parameter.is_nan() {
                String::new()
            } else {
                format!("{parameter:.10e}")
            },
            verification,
            signature,
            Self::label(p),
            self.stability(p),
        );
        match writeln!(self.out, "{line}") {
            Ok(()) => ControlFlow::Continue(()),
            Err(e) => {
                self.error = Some(e);
                ControlFlow::Break(())
            }
        }
    }
}

/// [`VERIFY_COLUMNS`] of a point (the library's time-domain check of the run): the defects
/// and penetration where it was marched, and the outcome (`passed`, `failed`, `unchecked`,
/// `over-budget`, `not-run`); empty cells for a point that did not converge, and a message
/// saying why for a converged one that was not marched.
pub fn verification_cells(p: &BackbonePoint) -> String {
    let numbers = match p.time_domain {
        Some(r) => format!(
            ",{:.6e},{:.6e},{:.6e}",
            r.defect, r.displacement_defect, r.max_penetration
        ),
        None => ",,,".to_string(),
    };
    let outcome = p
        .check
        .as_ref()
        .map(ToString::to_string)
        .unwrap_or_default();
    if let Some(reason) = p.check.as_ref().and_then(|c| c.reason()) {
        eprintln!(
            "backbone: step {} not checked in the time domain ({outcome}): {reason}",
            p.step
        );
    }
    format!("{numbers},{outcome}")
}

/// `,stable,max_multiplier,stability_reason` of a point: `true`, `false` or `unresolved`,
/// `Floquet::max_multiplier` where there is a verdict (empty where unresolved: the number
/// means nothing there), and why there is no verdict: the `UnresolvedReason`, or the error
/// where the multipliers could not be computed (with a message on stderr); for a verdict,
/// empty, or the grid's damping a stable verdict holds up to. All empty for a point without
/// multipliers.
pub fn stability_cells(p: &BackbonePoint) -> String {
    let outcome = p.stability.as_ref().map(|o| {
        o.as_ref().map(|f| {
            let damped = f
                .damping
                .map(|d| format!("stable up to the grid's damping of {d:.1e} per period"));
            (
                f.verdict,
                f.max_multiplier,
                f.unresolved.map(|r| r.to_string()).or(damped),
            )
        })
    });
    outcome_cells(p.step, "multipliers", outcome)
}

/// `,hill_stable,hill_max_multiplier,hill_reason` of a point, as [`stability_cells`] for
/// `HillSpectrum`.
pub fn hill_cells(p: &BackbonePoint) -> String {
    let outcome = p.hill.as_ref().map(|o| {
        o.as_ref().map(|h| {
            (
                h.verdict,
                h.max_multiplier,
                h.unresolved.map(|r| r.to_string()),
            )
        })
    });
    outcome_cells(p.step, "Hill exponents", outcome)
}

/// A verdict, the largest multiplier and why there is no verdict.
type Assessed = (Verdict, f64, Option<String>);

/// `,verdict,max_multiplier,reason` of a stability outcome (verdict, largest multiplier and
/// why there is no verdict), or of the error that prevented it (said on stderr too), or
/// empty cells where none was asked.
fn outcome_cells<E: std::fmt::Display>(
    step: usize,
    what: &str,
    outcome: Option<Result<Assessed, E>>,
) -> String {
    match outcome {
        Some(Ok((verdict, max_multiplier, reason))) => format!(
            "{},{}",
            verdict_cells(verdict, max_multiplier),
            reason.map(|r| csv_text(&r)).unwrap_or_default()
        ),
        Some(Err(e)) => {
            eprintln!("backbone: no {what} for step {step}: {e}");
            format!(",,,{}", csv_text(&e.to_string()))
        }
        None => ",,,".to_string(),
    }
}

/// `,verdict,max_multiplier`: `true`, `false` or `unresolved`, and the largest multiplier
/// where there is a verdict.
fn verdict_cells(verdict: Verdict, max_multiplier: f64) -> String {
    match verdict {
        Verdict::Stable => format!(",true,{max_multiplier:.10e}"),
        Verdict::Unstable(_) => format!(",false,{max_multiplier:.10e}"),
        Verdict::Unresolved => ",unresolved,".to_string(),
    }
}

/// `text` as one CSV cell: commas become semicolons and line breaks spaces.
fn csv_text(text: &str) -> String {
    text.replace(',', ";").replace(['\n', '\r'], " ")
}
