//! Observers for long runs: a progress printer and the quiet default.

use super::{Observer, Point, Step};
use std::io::Write;
use std::ops::ControlFlow;

/// The quiet observer: sees everything, says nothing, never stops the run.
pub fn quiet<T: ?Sized>(_: &T) -> ControlFlow<()> {
    ControlFlow::Continue(())
}

/// An [`Observer`] that prints `step, parameter, measure, step size` every `every` accepted
/// points, every rejection with its reason, and the end of the run, to a writer (standard
/// error by default). Write errors are ignored: progress is advisory.
///
/// ```
/// use nonsmooth_modes::continuation::Progress;
///
/// let mut progress = Progress::new(10, Vec::new()).with_measure("|x|", |p| p.x[0].abs());
/// ```
pub struct Progress<'a, W: Write> {
    every: usize,
    writer: W,
    measure: Option<(&'static str, Measure<'a>)>,
    accepted: usize,
}

/// A column computed from each point (it may borrow from the caller for the lifetime `'a`).
type Measure<'a> = Box<dyn FnMut(&Point) -> f64 + 'a>;

impl Progress<'_, std::io::Stderr> {
    /// Every `every` accepted points, to standard error.
    pub fn stderr(every: usize) -> Self {
        Self::new(every, std::io::stderr())
    }
}

impl<'a, W: Write> Progress<'a, W> {
    /// Every `every` accepted points (at least 1), to `writer`.
    pub fn new(every: usize, writer: W) -> Self {
        Self {
            every: every.max(1),
            writer,
            measure: None,
            accepted: 0,
        }
    }

    /// Adds a column computed from each point (an energy, an amplitude...); it may borrow
    /// from the caller (the system it measures energies with) for the lifetime `'a`.
    pub fn with_measure(
        mut self,
        name: &'static str,
        measure: impl FnMut(&Point) -> f64 + 'a,
    ) -> Self {
        self.measure = Some((name, Box::new(measure)));
        self
    }

    /// The writer (to inspect what was printed).
    pub fn writer(&self) -> &W {
        &self.writer
    }

    /// Prints an accepted point if it is the `every`-th.
    fn point(&mut self, p: &Point) {
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
                p.parameter,
                measure,
                p.step_size,
                if events.is_empty() { "" } else { "  " },
                events.join(",")
            );
        }
    }
}

impl<W: Write> Observer for Progress<'_, W> {
    fn observe(&mut self, step: &Step) -> ControlFlow<()> {
        match step {
            Step::Accepted(p) => self.point(p),
            Step::Rejected(r) => {
                let _ = writeln!(
                    self.writer,
                    "rejected  parameter {:.8}  step {:.3e}  {:?}",
                    r.parameter, r.step_size, r.reason
                );
            }
            Step::Finished(end) => {
                let _ = writeln!(self.writer, "finished: {end:?}");
            }
        }
        ControlFlow::Continue(())
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
                parameter: step as f64,
                x: vec![2.0 * step as f64],
                residual_norm: 0.0,
                iterations: 1,
                converged: true,
                error: None,
                step_size: 1.0,
                events: Vec::new(),
            };
            assert!(progress.observe(&Step::Accepted(p)).is_continue());
        }
        let end = Step::Finished(super::super::EndReason::Completed);
        assert!(progress.observe(&end).is_continue());
        let text = String::from_utf8(progress.writer().clone()).unwrap();
        assert_eq!(text.lines().count(), 3);
        assert!(text.lines().nth(1).unwrap().contains("x0 6.0"));
        assert!(text.lines().nth(2).unwrap().contains("Completed"));
        assert!(quiet(&0).is_continue());
    }
}
