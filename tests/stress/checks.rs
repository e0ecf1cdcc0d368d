//! What a case found beyond its result: non-finite numbers in `Ok` results, runs without a
//! consistent end reason, typed errors that do not display, results that contradict their
//! inputs (an error naming another index or size than the one asked for, more memory held
//! than the budget counted, a file read back with other numbers than were written); and which
//! inputs are moderate enough for the plain-number evaluators to be checked.

use nonsmooth_modes::branches::{BackbonePoint, ModeBranches, PointStatus};
use nonsmooth_modes::continuation::{Branch, EndReason, Event, Point};
use nonsmooth_modes::modal::Label;
use nonsmooth_modes::solve::SolveInfo;
use nonsmooth_modes::system::BarSystem;

/// The findings of one case beyond its result: non-finite numbers in `Ok` results and runs
/// whose end reason is missing or contradicts what happened.
#[derive(Default)]
pub(crate) struct Checks {
    pub(crate) non_finite: Vec<String>,
    pub(crate) no_end: Vec<String>,
    pub(crate) wrong: Vec<String>,
}

impl Checks {
    pub(crate) fn finite<'a>(&mut self, what: &str, values: impl IntoIterator<Item = &'a f64>) {
        if let Some(v) = values.into_iter().find(|v| !v.is_finite()) {
            self.non_finite.push(format!("{what} has {v}"));
        }
    }

    pub(crate) fn point(&mut self, what: &str, p: &Point) {
        self.finite(what, [&p.parameter, &p.residual_norm, &p.step_size]);
        self.finite(what, &p.x);
        self.events(what, &p.events);
    }

    fn events(&mut self, what: &str, events: &[Event]) {
        for e in events {
            match e {
                Event::Fold { parameter } => self.finite(what, [parameter]),
                Event::Jump { ratio } | Event::LeftBranch { ratio } => self.finite(what, [ratio]),
                _ => {}
            }
        }
    }

    /// A backbone point: its numbers are finite, except the energies of a point marked
    /// `NonFiniteEnergy` (which must then have one that is not), and `converged` agrees
    /// with the status.
    pub(crate) fn backbone_point(&mut self, what: &str, p: &BackbonePoint) {
        let energies = [("energy", p.energy), ("E/E_g", p.energy_normalized)];
        let others = [
            ("period", p.period),
            ("omega", p.omega),
            ("residual norm", p.residual_norm),
            ("step size", p.step_size),
        ];
        let unmeasured = p.status == PointStatus::NonFiniteEnergy;
        if unmeasured && energies.iter().all(|(_, v)| v.is_finite()) {
            self.wrong.push(format!(
                "{what}: NonFiniteEnergy with finite energies {energies:?}"
            ));
        }
        let checked = others
            .iter()
            .chain(if unmeasured { &[][..] } else { &energies });
        for (name, value) in checked {
            self.finite(&format!("{what} {name} ({})", p.status.label()), [value]);
        }
        self.finite(what, &p.x);
        self.events(what, &p.events);
    }

    pub(crate) fn solve_info(&mut self, what: &str, info: &SolveInfo, x: &[f64]) {
        self.finite(what, [&info.residual_norm]);
        self.finite(what, x);
    }

    /// The points of a branch, and its end reason against whether the observer stopped it.
    pub(crate) fn branch(&mut self, what: &str, branch: &Branch, stopped: bool) {
        for p in &branch.points {
            self.point(what, p);
        }
        let by_observer = branch.end == EndReason::StoppedByObserver;
        if by_observer != stopped {
            self.no_end.push(format!(
                "{what}: observer stopped = {stopped}, end = {:?}",
                branch.end
            ));
        }
    }

    /// A run of `branches::compute`: its grazing energy and points are finite (as
    /// [`Checks::backbone_point`]), and it says it was stopped exactly when its observer
    /// stopped it.
    pub(crate) fn mode_branches(&mut self, what: &str, run: &ModeBranches, stopped: bool) {
        self.finite(&format!("{what} E_g"), [&run.grazing_energy]);
        for p in &run.points {
            self.backbone_point(what, p);
        }
        self.groups(what, run);
        self.selection(what, run);
        let by_observer = run.end == EndReason::StoppedByObserver;
        if by_observer != stopped {
            self.no_end.push(format!(
                "{what}: {} points, observer stopped = {stopped}, end = {:?}",
                run.points.len(),
                run.end
            ));
        }
    }

    /// `ModeBranches::by_label` partitions the converged, labelled points: every one in exactly
    /// one non-empty group, one group per label, the mode's own branch before any other.
    fn groups(&mut self, what: &str, run: &ModeBranches) {
        let groups = run.by_label();
        let labelled = run.converged().filter(|p| p.label.is_some()).count();
        let grouped: usize = groups.iter().map(|g| g.points.len()).sum();
        self.expect(grouped == labelled, || {
            format!("{what}: {grouped} points in label groups for {labelled} labelled")
        });
        // Off-branch points form one group whatever their ratios (`group_by_label`).
        let same = |a: &Label, b: &Label| match (a, b) {
            (Label::OffBranch { .. }, Label::OffBranch { .. }) => true,
            (a, b) => a == b,
        };
        for (i, g) in groups.iter().enumerate() {
            let alone = groups[i + 1..].iter().all(|h| !same(&h.label, &g.label));
            let own_first = !g.is_own_branch() || groups[..i].iter().all(|h| h.is_own_branch());
            let consistent =
                (g.points.iter()).all(|p| p.label.as_ref().is_some_and(|l| same(l, &g.label)));
            self.expect(
                !g.points.is_empty() && alone && own_first && consistent,
                || {
                    format!(
                        "{what}: label group {i} ({}) is not a part of a partition",
                        g.label
                    )
                },
            );
        }
    }

    /// `Method::Auto`'s comparison with harmonic selection is consistent: its counts fit in
    /// the grid, it kept the selection exactly when that covered more periods, and the
    /// points solve the equations it says (the band of the run's problem).
    fn selection(&mut self, what: &str, run: &ModeBranches) {
        let Some(j) = run.selection else {
            return;
        };
        let band = run.problem().resonance_band();
        let consistent = j.covered_selected <= j.steps
            && j.covered_full <= j.steps
            && band == if j.selected() { j.width } else { 0.0 };
        self.expect(consistent, || {
            format!("{what}: selection {j:?} with a problem of band {band}")
        });
    }

    /// Records a result that contradicts its input when `ok` is false.
    pub(crate) fn expect(&mut self, ok: bool, what: impl FnOnce() -> String) {
        if !ok {
            self.wrong.push(what());
        }
    }

    /// A vector returned by a request whose memory was checked against the budget holds
    /// exactly its values (a capacity rounded up would be memory the budget did not count).
    pub(crate) fn exact(&mut self, what: &str, v: &Vec<f64>) {
        self.expect(v.capacity() == v.len(), || {
            format!("{what}: capacity {} for {} values", v.capacity(), v.len())
        });
    }

    /// A typed error: it displays (the message is the user's explanation).
    pub(crate) fn error(&mut self, what: &str, e: &impl std::fmt::Display) -> String {
        let message = e.to_string();
        if message.is_empty() {
            self.no_end
                .push(format!("{what}: an error with an empty message"));
        }
        message
    }
}

/// The result of a case's main call: `Err` carries the typed error's message.
pub(crate) type CaseResult = Result<(), String>;

/// Turns a typed error into the case's result, after checking that it displays.
pub(crate) fn typed<T, E: std::fmt::Display>(
    c: &mut Checks,
    what: &str,
    r: Result<T, E>,
) -> Result<T, String> {
    r.map_err(|e| format!("{what}: {}", c.error(what, &e)))
}

/// Whether `v` is finite and zero or of moderate size (`1e-100` to `1e100`).
fn moderate(v: f64) -> bool {
    v.is_finite() && (v == 0.0 || (1e-30..=1e30).contains(&v.abs()))
}

/// Whether a motion `x` at `omega` of `system` has moderate numbers only, so that the true
/// values of the plain-number evaluators (`energy`, the field) are representable: they
/// return numbers, not results, and are checked only there, while every `Result` API is
/// checked whatever its inputs.
pub(crate) fn moderate_motion(system: &BarSystem, x: &[f64], omega: f64) -> bool {
    let bars = system.bars().iter().all(|b| {
        [b.length(), b.wave_speed(), b.stiffness()]
            .into_iter()
            .all(moderate)
    });
    bars && x.iter().all(|&v| moderate(v)) && omega > 0.0 && moderate(omega)
}
