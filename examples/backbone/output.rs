//! The CSV output: its header, one row per point, the `--verify` columns and the signature
//! columns (contact intervals, subharmonic share), last so that every other column keeps its
//! place.

use crate::args::MAX_VERIFY_STEPS;
use nonsmooth_modes::branches::{BackbonePoint, PointStatus};
use nonsmooth_modes::continuation::Event;
use nonsmooth_modes::modal::{contact_intervals, subharmonic_share};
use nonsmooth_modes::reference::ClampedFirstMode;
use nonsmooth_modes::system::NonsmoothSystem;
use nonsmooth_modes::verify::{periodicity_check, PeriodicityOptions};
use std::f64::consts::PI;
use std::io::Write;
use std::ops::ControlFlow;

pub const HEADER: &str = "step,period,omega,energy,energy_normalized,exact_energy_normalized,converged,status,residual_norm,iterations,step_size,event,parameter";

/// The whole header: [`HEADER`], the `--verify` columns if `verify`, then
/// `contacts_per_period`, and `subharmonic_share` for a subharmonic order `K > 1`.
pub fn header(verify: bool, subharmonic: usize) -> String {
    let mut header = HEADER.to_string();
    if verify {
        header.push_str(",periodicity_defect,displacement_defect,max_penetration");
    }
    header.push_str(",contacts_per_period");
    if subharmonic > 1 {
        header.push_str(",subharmonic_share");
    }
    header
}

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
}

impl Sink<'_> {
    /// `,contacts_per_period` and, for `K > 1`, `,subharmonic_share` of a point (empty cells
    /// where they cannot be computed, e.g. the unknowns of a failed step are not finite, and
    /// an empty share for a point collapsed to rest).
    fn signature(&self, problem: &mut NonsmoothSystem, p: &BackbonePoint) -> String {
        let cell = |value: Result<String, nonsmooth_modes::SettingsError>, what: &str| {
            value.unwrap_or_else(|e| {
                eprintln!("backbone: {what} of step {} not computed: {e}", p.step);
                String::new()
            })
        };
        let contacts = contact_intervals(problem, &p.x, p.omega).map(|c| c.iter().sum::<usize>());
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

    /// `periodicity_defect,displacement_defect,max_penetration` of a point, or empty cells.
    fn verification(&self, problem: &NonsmoothSystem, p: &BackbonePoint) -> String {
        if !self.verify {
            return String::new();
        }
        let options = PeriodicityOptions {
            adjust_grid: true,
            ..Default::default()
        };
        let steps = 2.0 * PI / p.omega / options.dt;
        if steps > MAX_VERIFY_STEPS {
            eprintln!(
                "backbone: verification of step {} skipped: its march of {steps:.3e} time steps \
                 is over the example's limit of {MAX_VERIFY_STEPS:.0e}",
                p.step
            );
            return ",,,".to_string();
        }
        let (system, basis) = (problem.system(), problem.basis());
        let report = periodicity_check(system, basis, &p.x, p.omega, &options);
        match report {
            Ok(r) => format!(
                ",{:.6e},{:.6e},{:.6e}",
                r.defect, r.displacement_defect, r.max_penetration
            ),
            Err(e) => {
                eprintln!("backbone: verification of step {} failed: {e}", p.step);
                ",,,".to_string()
            }
        }
    }

    /// Writes the row of `p`, a point of `problem` (whose system is the one at the point's
    /// parameter value `parameter`, NaN for period runs).
    pub fn row(
        &mut self,
        problem: &mut NonsmoothSystem,
        p: &BackbonePoint,
        parameter: f64,
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
        let verification = self.verification(problem, p);
        let signature = self.signature(problem, p);
        let line = format!(
            "{},{:.10},{:.10},{:.10e},{:.10e},{},{},{},{:.3e},{},{:.6e},{},{}{}{}",
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
