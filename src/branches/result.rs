//! What [`compute`](crate::branches::compute) returns, and how each point gets its branch
//! index, its time-domain defect and its label on the way.

use crate::branches::backbone::BackboneObserver;
use crate::branches::continuity::{Sample, Splitter};
use crate::branches::judge::check_point;
use crate::branches::point::{BackbonePoint, CheckOutcome};
use crate::branches::request::{AutoChoice, Method, Request, SelectionJudgement, TimeDomainCheck};
use crate::continuation::{EndReason, Event, Rejection};
use crate::error::{ContinuationError, Error, SettingsError};
use crate::exact::types::ExactBranch;
use crate::fourier::{Basis, CosineBasis};
use crate::modal::{character, label, nearest_mode, ContactState, Label};
use crate::solution::Solution;
use crate::stability::{floquet, hill, Floquet, HillOptions, StabilityOptions, Verdict};
use crate::system::linear::natural_frequency_values;
use crate::system::linear::Resolution;
use crate::system::{HarmonicBalanceSettings, NonsmoothSystem};
use std::f64::consts::PI;
use std::ops::ControlFlow;

/// The branches of a nonsmooth mode that one request computed: every point (converged or
/// not, in the run's order) with its status, branch index and label, the rejected
/// arclength steps, why the run ended and which method ran. It keeps the discretization its
/// points solve, so that a point's [`Solution`] needs no rebuilt problem.
#[derive(Debug, Clone)]
pub struct ModeBranches {
    problem: NonsmoothSystem,
    /// The method that ran, with the options it used (for [`Method::Auto`], the one chosen).
    pub method: Method,
    /// Why [`Method::Auto`] chose [`ModeBranches::method`] (`None` for a method asked).
    pub auto: Option<AutoChoice>,
    /// The first grazing energy `E_g` the energies are normalised by.
    pub grazing_energy: f64,
    /// Every point computed.
    pub points: Vec<BackbonePoint>,
    /// Rejected corrector steps of an arclength run (a period or energy grid reports its
    /// failed steps as points, with their status).
    pub rejected_steps: usize,
    /// Why the run ended.
    pub end: EndReason,
    /// How [`Method::Auto`] chose between the paper's equations and harmonic selection
    /// (`None` where it did not compare them: a method asked, a request with a band of its
    /// own, or a subharmonic order). The equations the points solve are
    /// [`ModeBranches::problem`]'s ([`NonsmoothSystem::resonance_band`](crate::system::NonsmoothSystem::resonance_band)).
    pub selection: Option<SelectionJudgement>,
    /// The exact branch [`Request::exact`] asked for, continued from these points (`None`
    /// where it was not asked). An error computing it keeps the harmonic-balance points: it
    /// is stored here, not returned.
    pub exact: Option<Result<ExactBranch, Error>>,
}

impl ModeBranches {
    /// The discretization the points solve.
    pub fn problem(&self) -> &NonsmoothSystem {
        &self.problem
    }

    /// The converged points.
    pub fn converged(&self) -> impl Iterator<Item = &BackbonePoint> {
        self.points.iter().filter(|p| p.converged())
    }

    /// The points of branch `index` ([`BackbonePoint::branch`]).
    pub fn branch(&self, index: usize) -> impl Iterator<Item = &BackbonePoint> {
        self.points.iter().filter(move |p| p.branch == index)
    }

    /// The converged points grouped by label: the mode's own branch (skeleton or subharmonic)
    /// first, then each internal resonance apart, then the unverified points
    /// ([`group_by_label`](crate::branches::group_by_label)).
    pub fn by_label(&self) -> Vec<crate::branches::PointGroup<'_>> {
        crate::branches::group_by_label(&self.points)
    }

    /// The number of branches (one more than the largest branch index; 0 without points).
    pub fn branch_count(&self) -> usize {
        self.points.iter().map(|p| p.branch + 1).max().unwrap_or(0)
    }

    /// Point `index` as a [`Solution`], to ask it for fields, histories, diagnostics and
    /// the time-domain check.
    ///
    /// # Errors
    /// [`SettingsError::IndexOutOfRange`] for an index past the points, and the errors of
    /// [`Solution::new`] for a point whose unknowns are not a motion (a failed step's last
    /// iterate that is not finite).
    pub fn solution(&self, index: usize) -> Result<Solution<'_>, SettingsError> {
        let point = self
            .points
            .get(index)
            .ok_or(SettingsError::IndexOutOfRange {
                what: "point",
                index,
                count: self.points.len(),
            })?;
        Solution::new(&self.problem, &point.x, point.omega)
    }

    /// The error of a run that ended on one (a stall, too many failures or rejections),
    /// `None` for a run that completed or was stopped by its observer.
    pub fn error(&self) -> Option<ContinuationError> {
        self.end.error()
    }
}

/// Annotates each point a driver hands over (branch index, character, time-domain check,
/// label) before the user's observer sees it, and keeps it.
pub(crate) struct Annotator<O, B: Basis = CosineBasis> {
    problem: NonsmoothSystem<B>,
    check: Option<TimeDomainCheck>,
    stability: Option<StabilityOptions>,
    /// Hill's method on every converged point, with the run's settings.
    hill: Option<(HillOptions, HarmonicBalanceSettings)>,
    /// The verdict of the last converged point whose multipliers were computed, and its
    /// branch.
    last_verdict: Option<(usize, Verdict)>,
    order: usize,
    observer: O,
    points: Vec<BackbonePoint>,
    /// Whether the observer stopped the run.
    stopped: bool,
    converged: usize,
    /// Open-contact natural frequencies up to `natural_up_to` (computed as points need).
    natural: Vec<f64>,
    natural_up_to: f64,
    /// Branch indices, and whether the points of the mode's own content continue the branch
    /// their run followed ([`crate::branches::continuity`]).
    splitter: Splitter<BackbonePoint>,
}

impl<O: BackboneObserver, B: Basis> Annotator<O, B> {
    /// The annotator of the points of `problem` asked by `request`.
    pub(crate) fn new(problem: NonsmoothSystem<B>, request: &Request, observer: O) -> Self {
        Self {
            problem,
            check: request.check,
            stability: request.stability,
            hill: request.hill.map(|o| (o, request.settings)),
            last_verdict: None,
            order: request.subharmonic,
            observer,
            points: Vec::new(),
            stopped: false,
            converged: 0,
            natural: Vec::new(),
            natural_up_to: 0.0,
            splitter: Splitter::default(),
        }
    }

    /// The annotator of a candidate run of [`Method::Auto`], judged before it is shown: as
    /// [`Annotator::new`] without the time-domain check, which the request's own annotator
    /// adds to the points of the run kept ([`Annotator::replay`]).
    pub(crate) fn unchecked(problem: NonsmoothSystem<B>, request: &Request, observer: O) -> Self {
        Self {
            check: None,
            ..Self::new(problem, request, observer)
        }
    }

    /// Annotates `point`, shows it to the observer and keeps it (moved in, not copied). A
    /// point held as a possible spike is shown, with the points after it, once the next
    /// converged point of the mode's own content has said whether it left the branch.
    pub(crate) fn point(&mut self, mut point: BackbonePoint) -> ControlFlow<()> {
        self.splitter.enter(&mut point);
        if point.converged() {
            self.converged += 1;
            self.describe(&mut point);
        }
        self.splitter.push(point, ());
        let released = self.splitter.release().map(|(p, ())| p);
        show(
            &mut self.observer,
            (&mut self.points, &mut self.stopped),
            released,
        )
    }

    /// Shows the points still held (the run ended); returns whether the observer stopped the
    /// run, then or before.
    fn flush(&mut self) -> bool {
        let held = self.splitter.flush().map(|(p, ())| p);
        show(
            &mut self.observer,
            (&mut self.points, &mut self.stopped),
            held,
        )
        .is_break()
    }

    /// Shows a rejected step to the observer. A rejection may come while a point is held as
    /// a possible spike: an observer that stops the run on it has stopped it there, so the
    /// held point is not shown afterwards (nor kept), and an observer that has stopped is
    /// not called again.
    pub(crate) fn rejected(&mut self, rejection: &Rejection) -> ControlFlow<()> {
        if !self.stopped {
            self.stopped = self.observer.rejected(rejection).is_break();
        }
        if self.stopped {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }

    /// Shows points annotated by another annotator of the same request to the observer and
    /// keeps them, up to the one at which it stops the run; returns `end`, or
    /// [`EndReason::StoppedByObserver`] if it stopped. The time-domain check, multipliers and
    /// Hill exponents this request asks are added to converged points that the other run
    /// left without them.
    pub(crate) fn replay(&mut self, points: Vec<BackbonePoint>, end: EndReason) -> EndReason {
        for mut point in points {
            self.converged += usize::from(point.converged());
            if point.converged() && point.character.is_some() {
                self.check(&mut point);
                self.assess(&mut point);
            }
            let kept = (&mut self.points, &mut self.stopped);
            if show(&mut self.observer, kept, [point]).is_break() {
                return EndReason::StoppedByObserver;
            }
        }
        end
    }

    /// The points kept, in order (a point still held is shown to the observer first).
    pub(crate) fn into_points(mut self) -> Vec<BackbonePoint> {
        self.flush();
        self.points
    }

    /// The converged points so far.
    pub(crate) fn converged(&self) -> usize {
        self.converged
    }

    /// Whether the observer stopped the run.
    pub(crate) fn stopped(&self) -> bool {
        self.stopped
    }

    /// The character, time-domain check and label of a converged point. A point whose
    /// character cannot be computed (its motion overflows) keeps none and no label. Only a
    /// check that ran and failed labels the point unverified; a check that did not run (a
    /// condition without a time-domain form, a march beyond the cost bound) keeps the label
    /// of its harmonic content and says why in [`BackbonePoint::check`].
    fn describe(&mut self, point: &mut BackbonePoint) {
        let (x, omega) = (&point.x, point.omega);
        let Ok(mut described) = character(&mut self.problem, x, omega, &self.natural) else {
            self.splitter.other();
            return;
        };
        // The natural frequencies are computed only as far as the points name modes: a
        // skeleton point needs them just beyond its fundamental, a resonance further.
        if self.extend_natural_frequencies(described.named_frequencies(omega)) {
            described.name_modes(omega, &self.natural);
        }
        let natural = &self.natural;
        let content = label(&described, self.order, omega, natural, None).ok();
        point.character = Some(described);
        point.label = match content {
            Some(content) => Some(self.on_branch(content, point)),
            None => {
                self.splitter.other();
                None
            }
        };
        self.check(point);
        self.assess(point);
    }

    /// The time-domain check the request asks of a converged point, where it has none yet;
    /// the report goes to [`BackbonePoint::time_domain`], and a point that fails it is
    /// labelled [`Label::Unverified`] (after the branch's continuity was judged from its
    /// content, so that the labels of the other points do not depend on the check).
    fn check(&mut self, point: &mut BackbonePoint) {
        let (Some(check), None) = (self.check, &point.check) else {
            return;
        };
        let problem = (self.problem.system(), self.problem.basis());
        let (outcome, report) = check_point(&check, problem, point);
        if outcome == CheckOutcome::Failed {
            point.label = Some(Label::Unverified);
        }
        point.time_domain = report;
        point.check = Some(outcome);
    }

    /// `label` where the point continues the mode's own branch, [`Label::OffBranch`] where
    /// its content reads as the branch's (skeleton, subharmonic) but it lies off the branch
    /// followed so far ([`crate::branches::continuity`]); a point off the branch, and the
    /// first point back, open new branch indices.
    fn on_branch(&mut self, label: Label, point: &mut BackbonePoint) -> Label {
        if !matches!(label, Label::Skeleton | Label::Subharmonic { .. }) {
            self.splitter.other();
            return label;
        }
        let weights = self.problem.description().state_weights(point.omega);
        let per = self.problem.description().unknowns;
        let sample = Sample {
            period: point.period,
            energy: point.energy,
            x: point.x.clone(),
            held: self.problem.held_at(point.omega),
        };
        match self.splitter.judge(point, sample, &weights, per) {
            Some(ratio) => Label::OffBranch { ratio },
            None => label,
        }
    }

    /// The Floquet multipliers and Hill exponents the request asks of a converged point, where
    /// it has none yet (a point replayed from a run that did not ask them).
    fn assess(&mut self, point: &mut BackbonePoint) {
        let omega = point.omega;
        if let (Some(options), None) = (&self.stability, &point.stability) {
            let (system, basis) = (self.problem.system(), self.problem.basis());
            let outcome = floquet(system, basis, &point.x, omega, options);
            if let Ok(f) = &outcome {
                self.stability_event(point, f);
            }
            point.stability = Some(outcome);
        }
        if let (Some((options, settings)), None) = (&self.hill, &point.hill) {
            let system = self.problem.system();
            point.hill = Some(hill(system, *settings, &point.x, omega, options));
        }
    }

    /// Adds [`Event::StabilityLost`] or [`Event::StabilityGained`] to `point` when its
    /// verdict differs from that of the last resolved point before it on the same branch.
    fn stability_event(&mut self, point: &mut BackbonePoint, f: &Floquet) {
        if f.verdict == Verdict::Unresolved {
            return;
        }
        if let Some((branch, before)) = self.last_verdict {
            let event = Event::of_verdicts(before, f.verdict);
            if let Some(event) = event.filter(|_| branch == point.branch) {
                point.events.push(event);
            }
        }
        self.last_verdict = Some((point.branch, f.verdict));
    }

    /// Extends the open-contact natural frequencies until the nearest of each frequency `f`
    /// of `named` is known to be right: the list is complete up to `U` and `f + d <= U`, `d`
    /// the distance from `f` to the nearest listed mode (a mode beyond `U` is farther).
    /// Returns whether the list changed. The first extension reaches a mode spacing `pi c / l`
    /// of the shortest-period bar beyond `f`; each further one at least a quarter more, so a
    /// run scans a few times at most. A scan that fails (too long) keeps the list it had:
    /// labels then name the nearest mode found, and the scan is not repeated.
    fn extend_natural_frequencies(&mut self, named: impl Iterator<Item = f64> + Clone) -> bool {
        let system = self.problem.system();
        let spacing = (system.bars().iter())
            .map(|b| PI * b.wave_speed() / b.length())
            .fold(f64::INFINITY, f64::min);
        let mut changed = false;
        for _ in 0..8 {
            // Beyond the list, a mode spacing further; within it, as far again as the
            // nearest mode listed.
            let reach = |f: f64| match nearest_mode(f, &self.natural) {
                Some((_, w)) if f <= self.natural_up_to => f + (w - f).abs(),
                _ => f + spacing,
            };
            let need = named.clone().map(reach).fold(0.0, f64::max);
            if need <= self.natural_up_to {
                break;
            }
            let up_to = need.max(1.25 * self.natural_up_to);
            if let Ok(omegas) =
                natural_frequency_values(system, ContactState::Open, up_to, Resolution::LABELS)
            {
                self.natural = omegas;
                changed = true;
            }
            self.natural_up_to = up_to;
        }
        changed
    }
}

/// Shows `points` to `observer` and keeps them in `kept`, up to the one at which it stops
/// the run (`stopped`): the result holds the points the observer saw (a point computed after
/// a held one at which it stops is past where it asked to stop).
fn show<O: BackboneObserver>(
    observer: &mut O,
    (kept, stopped): (&mut Vec<BackbonePoint>, &mut bool),
    points: impl IntoIterator<Item = BackbonePoint>,
) -> ControlFlow<()> {
    for point in points {
        if *stopped {
            break;
        }
        *stopped = observer.point(&point).is_break();
        kept.push(point);
    }
    if *stopped {
        ControlFlow::Break(())
    } else {
        ControlFlow::Continue(())
    }
}

impl<O: BackboneObserver> Annotator<O> {
    /// The points kept, in order, and the problem they were annotated on.
    pub(crate) fn into_parts(mut self) -> (Vec<BackbonePoint>, NonsmoothSystem) {
        self.flush();
        (self.points, self.problem)
    }

    /// The result of the run.
    pub(crate) fn finish(
        mut self,
        (method, auto): (Method, Option<AutoChoice>),
        grazing_energy: f64,
        end: EndReason,
        rejected_steps: usize,
    ) -> ModeBranches {
        // An observer that stops the run at a point shown only now (held until the run ended)
        // stops it all the same: what came after is past where it asked to stop.
        let end = if self.flush() {
            EndReason::StoppedByObserver
        } else {
            end
        };
        ModeBranches {
            problem: self.problem,
            method,
            auto,
            grazing_energy,
            points: self.points,
            rejected_steps,
            end,
            selection: None,
            exact: None,
        }
    }
}
