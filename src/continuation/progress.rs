//! Observers for long runs: a progress printer and the quiet default.

use super::{ArclengthOutcome, Point};
use std::io::Write;
use std::ops::ControlFlow;

/// The quiet observer: sees everything, says nothing, never stops the run.
pub fn quiet<T: ?Sized>(_: &T) -> ControlFlow<()> {
    ControlFlow::Continue(())
}

/// Prints `step, parameter, measure, step size` every `every` accepted points (and every
/// rejection with its reason) to a writer, standard error by default.
///
/// ```
/// use nonsmooth_modes::continuation::Progress;
///
/// let mut progress = Progress::new(10, Vec::new()).with_measure("|x|", |p| p.x[0].abs());
/// ```
pub struct Progress<W: Write> {
    every: usize,
    writer: W,
    measure: Option<(&'static str, Measure)>,
    accepted: usize,
}

/// A column computed from each point.
type Measure = Box<dyn FnMut(&Point) -> f64>;

impl Progress<std::io::Stderr> {
    /// Every `every` accepted points, to standard error.
    pub fn stderr(every: usize) -> Self {
        Self::new(every, std::io::stderr())
    }
}

impl<W: Write> Progress<W> {
    /// Every `every` accepted points (at least 1), to `writer`.
    pub fn new(every: usize, writer: W) -> Self {
        Self {
            every: every.max(1),
            writer,
            measure: None,
            accepted: 0,
        }
    }

    /// Adds a column computed from each point (an energy, an amplitude...).
    pub fn with_measure(
        mut self,
        name: &'static str,
        measure: impl FnMut(&Point) -> f64 + 'static,
    ) -> Self {
        self.measure = Some((name, Box::new(measure)));
        self
    }

    /// The writer (to inspect what was printed).
    pub fn writer(&self) -> &W {
        &self.writer
    }

    /// Observes an accepted point. Write errors are ignored: progress is advisory.
    pub fn point(&mut self, p: &Point) -> ControlFlow<()> {
        self.accepted += 1;
        if self.accepted % self.every == 0 {
            let measure = match &mut self.measure {
                Some((name, f)) => format!("  {name} {:.6e}", f(p)),
                None => String::new(),
            };
            let events: Vec<&str> = p.events.iter().map(|e| e.label()).collect();
            let _ = writeln!(
                self.writer,
                "step {:6}  parameter {:.8}{}  ds {:.3e}{}{}",
                p.step,
                p.lambda,
                measure,
                p.step_size,
                if events.is_empty() { "" } else { "  " },
                events.join(",")
            );
        }
        ControlFlow::Continue(())
    }

    /// Observes an arclength outcome (accepted points, rejections and the end).
    pub fn outcome(&mut self, outcome: &ArclengthOutcome) -> ControlFlow<()> {
        match outcome {
            ArclengthOutcome::Accepted(p) => self.point(p),
            ArclengthOutcome::Rejected(r) => {
                let _ = writeln!(
                    self.writer,
                    "rejected  parameter {:.8}  ds {:.3e}  {:?}",
                    r.lambda, r.ds, r.reason
                );
                ControlFlow::Continue(())
            }
            ArclengthOutcome::Finished(end) => {
                let _ = writeln!(self.writer, "finished: {end:?}");
                ControlFlow::Continue(())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prints_every_nth_point_with_measure() {
        let mut progress = Progress::new(2, Vec::new()).with_measure("x0", |p| p.x[0]);
        for step in 0..5 {
            let p = Point {
                step,
                lambda: step as f64,
                x: vec![2.0 * step as f64],
                residual_norm: 0.0,
                iterations: 1,
                converged: true,
                error: None,
                step_size: 1.0,
                events: Vec::new(),
            };
            assert!(progress.point(&p).is_continue());
        }
        let text = String::from_utf8(progress.writer().clone()).unwrap();
        assert_eq!(text.lines().count(), 2);
        assert!(text.lines().nth(1).unwrap().contains("x0 6.0"));
        assert!(quiet(&0).is_continue());
    }
}
