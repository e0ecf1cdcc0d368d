//! The CSV output: its header, one row per point and the `--verify` columns.

use crate::args::MAX_VERIFY_STEPS;
use nonsmooth_modes::continuation::Event;
use nonsmooth_modes::modal::BackbonePoint;
use nonsmooth_modes::reference::ClampedFirstMode;
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings};
use nonsmooth_modes::verify::{periodicity_check, PeriodicityOptions};
use std::f64::consts::PI;
use std::io::Write;
use std::ops::ControlFlow;

pub const HEADER: &str = "step,period,omega,energy,energy_normalized,exact_energy_normalized,converged,status,residual_norm,iterations,step_size,event,parameter";

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
    pub verify: Option<HarmonicBalanceSettings>,
    pub exact: Option<f64>,
    pub total: usize,
    pub converged: usize,
    pub error: Option<std::io::Error>,
    pub progress: bool,
}

impl Sink<'_> {
    /// `periodicity_defect,displacement_defect,max_penetration` of a point, or empty cells.
    fn verification(&self, system: &BarSystem, p: &BackbonePoint) -> String {
        let Some(settings) = self.verify else {
            return String::new();
        };
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
        let report = settings
            .cosine_basis()
            .map_err(|e| e.to_string())
            .and_then(|basis| {
                periodicity_check(system, &basis, &p.x, p.omega, &options)
                    .map_err(|e| e.to_string())
            });
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

    pub fn row(
        &mut self,
        system: &BarSystem,
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
        let verification = self.verification(system, p);
        let line = format!(
            "{},{:.10},{:.10},{:.10e},{:.10e},{},{},{},{:.3e},{},{:.6e},{},{}{}",
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
