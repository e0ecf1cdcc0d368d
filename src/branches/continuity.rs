//! Whether a point continues the branch its run has followed so far, measured on the points
//! themselves, so that every driver's run is judged alike.
//!
//! # Why
//! A point's harmonic content says which mode it resembles, not which solution it is: after
//! a jump of the corrector to a neighbouring solution of the truncated equations (a spike
//! of an internal resonance, or a branch of its own that a change of the harmonic
//! selection's set lands on), harmonic 1 still dominates. Such points used to be labelled
//! skeleton next to the family they were 20 to 50 % away from.
//!
//! # The test
//! The last two points of the branch, `(T_a, x_a)` and `(T_b, x_b)`, predict by their
//! secant in the period
//!
//! ```text
//!   x^ = x_b + f (x_b - x_a),    f = (T - T_b) / (T_b - T_a)
//! ```
//!
//! and a point `(T, x)` continues the branch when its distance to the prediction is at most
//! [`JUMP_RATIO`] times the predicted step, `|x - x^|_W <= JUMP_RATIO |x^ - x_b|_W`, in the
//! energy weights `W` of the arclength norm
//! ([`Structured::state_weights`](crate::solve::Structured::state_weights)). The ratio is
//! free of units and of the grid: on a smooth branch it is of the order of the step (the
//! secant's error is quadratic), so it falls as the grid is refined; at a kink of the branch
//! (a contact that appears, a harmonic the selection drops) it stays of order one; a jump to
//! another solution keeps a distance of order one over a step that shrinks, so its ratio grows
//! without bound. The harmonics the harmonic selection holds at zero at any of the three
//! points are left out of both norms: where the selection's set changes, the equations
//! change, and the coefficient it drops or restores steps by its whole content, which says
//! nothing of whether the rest of the motion stayed on its branch.
//!
//! Where the secant cannot predict (fewer than two points, a period that turns
//! back at a fold or does not move), the point is taken as it comes. A point that fails the
//! test is not added to the branch: the next points are measured against the last two that
//! passed, so that a run that comes back from an excursion is recognised.
//!
//! # Spikes
//! The state distance is dominated by the harmonics of small content, whose coefficients
//! move from point to point by more than their share of the energy: at `m = 80` on the
//! clamped bar, the predicted step itself is a few per cent of the state while the energy
//! moves by 1 %, and a point with 25 % more energy than the family (17 % of it in harmonics
//! 22 and 24, near a natural frequency) lies only three predicted steps off. Its energy says
//! more: one point alone does not tell a kink of the branch from a one-point excursion, but
//! the point after it does. With `b` the point before a point `k` and `q` the point after
//! it, `k` is a *spike* where its energy is off the chord of its neighbours' energies,
//!
//! ```text
//!   d = |E_k / L - 1| > SPIKE_ENERGY,   L = E_b + (E_q - E_b) (T_k - T_b) / (T_q - T_b),
//! ```
//!
//! by more than [`SPIKE_SPREAD`] times what the neighbours differ by, `s = |E_q / E_b - 1|`,
//! with `T_k` in the middle three fifths of `[T_b, T_q]` (neighbours at comparable distances).
//! On a smooth branch `d` is the chord's error, of the order of the step times `s`; past a
//! kink `q` continues from `k`, so `d <= s / 2`; after a jump to another solution `k` and `q`
//! both lie on it, `d ~ s / 2` again. Only a point that leaves and comes back has `d >> s`.
//! The energy floor keeps the test off the points where the neighbours' energies nearly
//! agree (an energy extremum along the branch), where `s` vanishes while `d` is the chord's
//! small error. So a point whose energy is off the secant prediction of the two before it by
//! more than half the floor is held as a suspect, and leaves the branch when the next point
//! shows it to be a spike.

use crate::continuation::Event;

/// The largest ratio of a point's distance to the branch's secant prediction over the
/// predicted step that still continues the branch (module docs).
///
/// Measured with the default request on the two exact families (the clamped bar and the
/// free–free bar between walls, `tests/convergence_in_m.rs`): at `m = 20`, `40` and `80` no
/// point more than 20 % off its family is labelled skeleton (with the spike test of the
/// module docs, which takes the one that lies only 3.1 predicted steps off: the clamped bar
/// at `m = 80`, `T = 3.835`), and at least 97 % of the points within 2 % are. A ratio of 3
/// would label that spike too, but also 8 to 14 % of the points within 2 % (the kinks of a
/// coarse grid near the clamped family's singularity at `T = 3`).
pub const JUMP_RATIO: f64 = 6.0;

/// The relative distance `|E_k / L - 1|` of a point's energy from the chord `L` of its two
/// neighbours' energies above which it may be a one-point spike: a point that left its
/// branch and came back, whose state may lie only a few predicted steps off (the energy of a
/// truncation resonance sits in harmonics of small coefficients).
///
/// Measured with the default request on the two exact families at `m = 20`, `40` and `80`
/// (and the clamped bar on 10 steps): the points more than 20 % off their family that come
/// back at the next point lie 21 to 54 % off the chord, 10 to 25 times what their neighbours
/// differ by; no point within 2 % of its family lies more than 7 % off the chord unless a
/// neighbour is such a spike.
pub const SPIKE_ENERGY: f64 = 0.1;

/// How many times what a point's neighbours differ by in energy, `|E_q / E_b - 1|`, its
/// distance from their chord must exceed for a spike ([`SPIKE_ENERGY`]). Past a kink of the
/// branch, or after a jump to another solution, the distance is at most about half that
/// difference; measured with [`SPIKE_ENERGY`]: at most 3.8 for points within 2 % of their
/// family, at least 10 for the spikes.
pub const SPIKE_SPREAD: f64 = 5.0;

/// A point as the test sees it: its period, unknowns and the basis coefficients the
/// harmonic selection holds at zero there.
#[derive(Debug, Clone, Default)]
pub(crate) struct Sample {
    pub(crate) period: f64,
    pub(crate) energy: f64,
    pub(crate) x: Vec<f64>,
    pub(crate) held: Vec<usize>,
}

/// What the test says of a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Verdict {
    /// The point continues the branch (or cannot be measured).
    Continues,
    /// The point lies off the branch, at this ratio.
    Off(f64),
    /// The point continues the branch, and the one before it, held with this ratio, was a
    /// one-point excursion off it.
    ContinuesAfterSpike(f64),
}

/// The last points of a branch, to measure the next against ([module docs](self)).
#[derive(Debug, Clone, Default)]
pub(crate) struct BranchTail {
    /// The last three points that continued the branch, the oldest first (the last two
    /// predict; the third is the branch again when the last turns out a spike).
    points: Vec<Sample>,
    /// The ratio of the last point, where its energy was off the secant prediction of the
    /// two before it by more than half [`SPIKE_ENERGY`].
    suspect: Option<f64>,
}

/// The ratio of the distance from `p` to the secant prediction of `a` and `b` over the
/// predicted step, leaving out coefficients held at any of the three points; `None` where
/// the secant cannot predict (module docs).
fn secant_ratio(a: &Sample, b: &Sample, p: &Sample, weights: &[f64], per: usize) -> Option<f64> {
    let f = (p.period - b.period) / (b.period - a.period);
    let n = p.x.len();
    if !(f.is_finite() && f > 0.0) || a.x.len() != n || b.x.len() != n || weights.len() != n {
        return None;
    }
    if per == 0 {
        return None;
    }
    let held = |i: usize| {
        [&a.held, &b.held, &p.held]
            .iter()
            .any(|h| h.contains(&(i / per)))
    };
    let (mut off, mut step) = (0.0, 0.0);
    for i in (0..n).filter(|&i| !held(i)) {
        let predicted = b.x[i] + f * (b.x[i] - a.x[i]);
        off += weights[i] * (p.x[i] - predicted).powi(2);
        step += weights[i] * (predicted - b.x[i]).powi(2);
    }
    let ratio = (off / step).sqrt();
    (step > 0.0 && ratio.is_finite()).then_some(ratio)
}

/// Whether `k`, between `b` and `q`, is a spike: its energy off their chord by more than
/// [`SPIKE_ENERGY`] and [`SPIKE_SPREAD`] times what they differ by (module docs). Only where
/// `k` lies in the middle three fifths of the chord's periods: a neighbour much farther than
/// the other (a run that comes back after many failed steps) leaves the chord no measure of
/// the branch at `k`.
fn is_spike(b: &Sample, k: &Sample, q: &Sample) -> bool {
    let f = (k.period - b.period) / (q.period - b.period);
    if !(0.2..=0.8).contains(&f) {
        return false;
    }
    let chord = b.energy + f * (q.energy - b.energy);
    let d = (k.energy / chord - 1.0).abs();
    let s = (q.energy / b.energy - 1.0).abs();
    d > SPIKE_ENERGY && d > SPIKE_SPREAD * s
}

impl BranchTail {
    /// The ratio of the distance from `p` to the branch's secant prediction (its last two
    /// points) over the predicted step, in the weights `weights` of unknowns grouped `per` a
    /// basis coefficient; `None` where the secant cannot predict (module docs).
    pub(crate) fn ratio(&self, p: &Sample, weights: &[f64], per: usize) -> Option<f64> {
        match self.points.as_slice() {
            [.., a, b] => secant_ratio(a, b, p, weights, per),
            _ => None,
        }
    }

    /// Whether `p` continues the branch: its ratio is at most [`JUMP_RATIO`] or cannot be
    /// measured. A point that continues the branch becomes its last; where the last point
    /// was held as a suspect and `p` shows it to be a spike, that point leaves the branch
    /// instead (module docs, "Spikes").
    pub(crate) fn continues(&mut self, p: Sample, weights: &[f64], per: usize) -> Verdict {
        let spike = self
            .suspect
            .take()
            .filter(|_| match self.points.as_slice() {
                [.., b, k] => is_spike(b, k, &p),
                _ => false,
            });
        if spike.is_some() {
            self.points.pop();
        }
        let ratio = self.ratio(&p, weights, per);
        if let Some(ratio) = ratio.filter(|&r| r > JUMP_RATIO) {
            return Verdict::Off(ratio);
        }
        self.suspect = ratio.filter(|_| self.energy_off_secant(&p));
        if self.points.len() == 3 {
            self.points.remove(0);
        }
        self.points.push(p);
        spike.map_or(Verdict::Continues, Verdict::ContinuesAfterSpike)
    }

    /// Whether `p`'s energy is off the secant prediction of the branch's last two points by
    /// more than half [`SPIKE_ENERGY`] (relative).
    fn energy_off_secant(&self, p: &Sample) -> bool {
        let [.., a, b] = self.points.as_slice() else {
            return false;
        };
        let f = (p.period - b.period) / (b.period - a.period);
        let predicted = b.energy + f * (b.energy - a.energy);
        (p.energy / predicted - 1.0).abs() > 0.5 * SPIKE_ENERGY
    }

    /// Whether the last point is held as a suspect, so that the next one may yet show it to
    /// be a spike.
    pub(crate) fn holds_suspect(&self) -> bool {
        self.suspect.is_some()
    }

    /// Keeps the suspect on the branch: the point after it is not one the test measures (a
    /// point of other content, or one whose content could not be read).
    pub(crate) fn forget_suspect(&mut self) {
        self.suspect = None;
    }
}

/// What a [`Splitter`] needs of a point: to set its branch index and add events, whether the
/// driver jumped to reach it, and to mark it off the branch when it turns out a spike.
pub(crate) trait OnBranch {
    /// Sets the index of the branch the point lies on.
    fn set_branch(&mut self, branch: usize);
    /// Adds an event to the point.
    fn push_event(&mut self, event: Event);
    /// Whether the driver jumped to reach the point ([`Event::Jump`]).
    fn jumped(&self) -> bool;
    /// The point, first taken as continuing its branch, is a spike off it at `ratio`.
    fn left_branch(&mut self, ratio: f64);
}

/// A run's points on their way out: each gets the index of the branch it lies on, a point of
/// the branch's own content that does not continue it is marked off the branch (a new index,
/// with [`Event::LeftBranch`]; the first point back opens another, with [`Event::Rejoined`]),
/// and a suspect is held, with the points after it, until the next point of the branch's own
/// content says whether it was a spike ([module docs](self)). `T` is what a driver keeps with
/// each point (the parameter value of a parameter branch).
#[derive(Debug)]
pub(crate) struct Splitter<P, T = ()> {
    tail: BranchTail,
    branch: usize,
    /// Whether the last point of the branch's own content was off it.
    off_branch: bool,
    /// Whether a point has entered yet.
    started: bool,
    /// Points not released yet.
    queue: Vec<(P, T)>,
    /// The suspect's index in `queue`, while one is held.
    suspect: Option<usize>,
}

impl<P, T> Default for Splitter<P, T> {
    fn default() -> Self {
        Self {
            tail: BranchTail::default(),
            branch: 0,
            off_branch: false,
            started: false,
            queue: Vec::new(),
            suspect: None,
        }
    }
}

impl<P: OnBranch, T> Splitter<P, T> {
    /// Gives `point` its branch index: a new one after a jump of the driver
    /// ([`Event::Jump`]: the stall escape, a corrector that lands far from its prediction, a
    /// switch onto a crossing branch).
    pub(crate) fn enter(&mut self, point: &mut P) {
        if point.jumped() && self.started {
            self.branch += 1;
        }
        self.started = true;
        point.set_branch(self.branch);
    }

    /// Judges a converged `point` of the branch's own content, seen by the test as `sample`:
    /// the ratio where it lies off the branch (it then opens a new branch index, once per
    /// excursion), `None` where it continues it. A suspect it shows to be a spike leaves the
    /// branch, with the points queued after it.
    pub(crate) fn judge(
        &mut self,
        point: &mut P,
        sample: Sample,
        weights: &[f64],
        per: usize,
    ) -> Option<f64> {
        let verdict = self.tail.continues(sample, weights, per);
        if let Verdict::ContinuesAfterSpike(ratio) = verdict {
            self.leave_at_spike(ratio);
        }
        // The point is queued next.
        self.suspect = self.tail.holds_suspect().then_some(self.queue.len());
        let event = match (verdict, self.off_branch) {
            (Verdict::Off(ratio), false) => Event::LeftBranch { ratio },
            (Verdict::Continues | Verdict::ContinuesAfterSpike(_), true) => Event::Rejoined,
            _ => return verdict_ratio(verdict),
        };
        self.off_branch = !self.off_branch;
        self.branch += 1;
        point.set_branch(self.branch);
        point.push_event(event);
        verdict_ratio(verdict)
    }

    /// A converged point that is not of the branch's own content (an internal resonance), or
    /// whose content could not be read: a suspect before it stays on the branch.
    pub(crate) fn other(&mut self) {
        self.tail.forget_suspect();
        self.suspect = None;
    }

    /// The suspect left the branch after all: it opens a new branch index with
    /// [`Event::LeftBranch`], and so do the points queued after it.
    fn leave_at_spike(&mut self, ratio: f64) {
        let Some(index) = self.suspect.take() else {
            return;
        };
        self.branch += 1;
        self.off_branch = true;
        let queued = self.queue.get_mut(index..).unwrap_or_default();
        for (point, _) in queued.iter_mut() {
            point.set_branch(self.branch);
        }
        if let Some((spike, _)) = queued.first_mut() {
            spike.push_event(Event::LeftBranch { ratio });
            spike.left_branch(ratio);
        }
    }

    /// Queues `point` with what the driver keeps with it.
    pub(crate) fn push(&mut self, point: P, kept: T) {
        self.queue.push((point, kept));
    }

    /// The points that may go out now, in order: those before the suspect held, all of them
    /// without one.
    pub(crate) fn release(&mut self) -> std::vec::Drain<'_, (P, T)> {
        let ready = self
            .suspect
            .map_or(self.queue.len(), |s| s.min(self.queue.len()));
        if let Some(suspect) = &mut self.suspect {
            *suspect -= ready;
        }
        self.queue.drain(..ready)
    }

    /// Every point still queued (the run ended: a suspect at its end stays on the branch).
    pub(crate) fn flush(&mut self) -> std::vec::Drain<'_, (P, T)> {
        self.suspect = None;
        self.queue.drain(..)
    }
}

/// The ratio of a point off the branch.
fn verdict_ratio(verdict: Verdict) -> Option<f64> {
    match verdict {
        Verdict::Off(ratio) => Some(ratio),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The point at `t` of the curve `x(T) = (T, T^2)`, of energy `T^2`, nothing held.
    fn on_curve(t: f64) -> Sample {
        Sample {
            period: t,
            energy: t * t,
            x: vec![t, t * t],
            ..Sample::default()
        }
    }

    const UNIT: [f64; 2] = [1.0, 1.0];

    #[test]
    fn a_smooth_branch_continues_and_its_ratio_falls_with_the_step() {
        let mut ratios = Vec::new();
        for h in [0.1, 0.05, 0.025] {
            let mut tail = BranchTail::default();
            for k in 0..2 {
                assert!(
                    tail.continues(on_curve(1.0 + k as f64 * h), &UNIT, 1) == Verdict::Continues
                );
            }
            let p = on_curve(1.0 + 2.0 * h);
            ratios.push(tail.ratio(&p, &UNIT, 1).expect("a ratio"));
            assert!(tail.continues(p, &UNIT, 1) == Verdict::Continues);
        }
        assert!(ratios.windows(2).all(|w| w[1] < 0.6 * w[0]), "{ratios:?}");
    }

    #[test]
    fn a_jump_is_refused_and_the_branch_is_found_again() {
        let mut tail = BranchTail::default();
        for k in 0..3 {
            assert!(
                tail.continues(on_curve(1.0 + 0.01 * k as f64), &UNIT, 1) == Verdict::Continues
            );
        }
        // A point 0.5 away from the curve, where a step moves it by about 0.03.
        let mut off = on_curve(1.03);
        off.x[1] += 0.5;
        let Verdict::Off(ratio) = tail.continues(off, &UNIT, 1) else {
            panic!("a jump taken as the branch");
        };
        assert!(ratio > 3.0 * JUMP_RATIO, "{ratio}");
        // The next point of the curve is measured against the two before the jump.
        assert!(tail.continues(on_curve(1.04), &UNIT, 1) == Verdict::Continues);
    }

    /// The branch `x(T) = (T, T^2)` from `T = 1` by steps of 0.01 up to `1.02`.
    fn three_points() -> BranchTail {
        let mut tail = BranchTail::default();
        for k in 0..3 {
            let verdict = tail.continues(on_curve(1.0 + 0.01 * k as f64), &UNIT, 1);
            assert_eq!(verdict, Verdict::Continues);
        }
        tail
    }

    /// `p` with its energy raised by the fraction `by`, its state by a tenth of that (the
    /// energy of a resonance sits in harmonics of small coefficients).
    fn raised(mut p: Sample, by: f64) -> Sample {
        p.x[1] += 0.1 * by;
        p.energy *= 1.0 + by;
        p
    }

    #[test]
    fn a_one_point_excursion_leaves_the_branch_once_the_next_point_is_back() {
        let mut tail = three_points();
        // 25 % more energy, about one predicted step off: below the jump ratio.
        let off = raised(on_curve(1.03), 0.25);
        let ratio = tail.ratio(&off, &UNIT, 1).expect("a ratio");
        assert!(ratio < JUMP_RATIO, "{ratio}");
        assert_eq!(tail.continues(off, &UNIT, 1), Verdict::Continues);
        assert!(tail.holds_suspect());
        let verdict = tail.continues(on_curve(1.04), &UNIT, 1);
        assert_eq!(verdict, Verdict::ContinuesAfterSpike(ratio));
        // The branch goes on from the points before the excursion.
        assert_eq!(tail.continues(on_curve(1.05), &UNIT, 1), Verdict::Continues);
        assert!(!tail.holds_suspect());
    }

    #[test]
    fn a_kink_is_not_an_excursion() {
        let mut tail = three_points();
        // From T = 1.02 on, the curve turns up with seven times its slope: the first point
        // past the kink is held, and kept.
        let kinked = |t: f64| {
            let y = 1.02f64.powi(2) + 7.0 * 2.04 * (t - 1.02);
            Sample {
                period: t,
                energy: y,
                x: vec![t, y],
                ..Sample::default()
            }
        };
        assert_eq!(tail.continues(kinked(1.03), &UNIT, 1), Verdict::Continues);
        assert!(tail.holds_suspect());
        assert_eq!(tail.continues(kinked(1.04), &UNIT, 1), Verdict::Continues);
        assert_eq!(tail.continues(kinked(1.05), &UNIT, 1), Verdict::Continues);
    }

    #[test]
    fn a_small_excursion_is_no_spike() {
        let mut tail = three_points();
        // 4 % more energy: below the floor, not even held.
        assert_eq!(
            tail.continues(raised(on_curve(1.03), 0.04), &UNIT, 1),
            Verdict::Continues
        );
        assert!(!tail.holds_suspect());
        assert_eq!(tail.continues(on_curve(1.04), &UNIT, 1), Verdict::Continues);
    }

    #[test]
    fn a_suspect_followed_by_a_point_of_other_content_stays() {
        let mut tail = three_points();
        assert_eq!(
            tail.continues(raised(on_curve(1.03), 0.25), &UNIT, 1),
            Verdict::Continues
        );
        tail.forget_suspect();
        assert!(!tail.holds_suspect());
        // Back on the curve: measured from the suspect, which stayed on the branch.
        assert!(!matches!(
            tail.continues(on_curve(1.04), &UNIT, 1),
            Verdict::ContinuesAfterSpike(_)
        ));
    }

    /// A point as a splitter sees it.
    #[derive(Debug, Default)]
    struct Seen {
        period: f64,
        branch: usize,
        events: Vec<Event>,
        off: Option<f64>,
    }

    impl OnBranch for Seen {
        fn set_branch(&mut self, branch: usize) {
            self.branch = branch;
        }
        fn push_event(&mut self, event: Event) {
            self.events.push(event);
        }
        fn jumped(&self) -> bool {
            false
        }
        fn left_branch(&mut self, ratio: f64) {
            self.off = Some(ratio);
        }
    }

    /// Feeds `(sample, converged)` through a splitter; returns the points in the order
    /// released and how many were out after each.
    fn split(samples: Vec<(Sample, bool)>) -> (Vec<Seen>, Vec<usize>) {
        let mut splitter = Splitter::<Seen>::default();
        let (mut out, mut counts) = (Vec::new(), Vec::new());
        for (sample, converged) in samples {
            let mut p = Seen {
                period: sample.period,
                ..Seen::default()
            };
            splitter.enter(&mut p);
            if converged {
                p.off = splitter.judge(&mut p, sample, &UNIT, 1);
            }
            splitter.push(p, ());
            out.extend(splitter.release().map(|(p, ())| p));
            counts.push(out.len());
        }
        out.extend(splitter.flush().map(|(p, ())| p));
        (out, counts)
    }

    #[test]
    fn a_spike_and_the_failed_steps_after_it_are_held_then_split_off() {
        let mut samples: Vec<_> = (0..3)
            .map(|k| (on_curve(1.0 + 0.01 * k as f64), true))
            .collect();
        samples.push((raised(on_curve(1.03), 0.25), true));
        samples.push((on_curve(1.035), false));
        samples.push((on_curve(1.04), true));
        samples.push((on_curve(1.05), true));
        let (out, counts) = split(samples);
        // The spike and the failed step wait for the point after them.
        assert_eq!(counts, [1, 2, 3, 3, 3, 6, 7]);
        let periods: Vec<f64> = out.iter().map(|p| p.period).collect();
        assert_eq!(periods, [1.0, 1.01, 1.02, 1.03, 1.035, 1.04, 1.05]);
        let branches: Vec<usize> = out.iter().map(|p| p.branch).collect();
        assert_eq!(branches, [0, 0, 0, 1, 1, 2, 2]);
        assert!(out[3].off.is_some());
        assert!(matches!(out[3].events[..], [Event::LeftBranch { .. }]));
        assert_eq!(out[5].events, [Event::Rejoined]);
        assert!(out
            .iter()
            .enumerate()
            .all(|(i, p)| p.off.is_some() == (i == 3)));
    }

    #[test]
    fn a_suspect_at_the_end_of_the_run_stays_on_the_branch() {
        let mut samples: Vec<_> = (0..3)
            .map(|k| (on_curve(1.0 + 0.01 * k as f64), true))
            .collect();
        samples.push((raised(on_curve(1.03), 0.25), true));
        let (out, counts) = split(samples);
        assert_eq!(counts, [1, 2, 3, 3]);
        assert_eq!(out.len(), 4);
        assert!(out
            .iter()
            .all(|p| p.branch == 0 && p.off.is_none() && p.events.is_empty()));
    }

    #[test]
    fn a_coefficient_held_at_any_of_the_points_is_left_out() {
        let mut tail = BranchTail::default();
        for k in 0..2 {
            assert!(
                tail.continues(on_curve(1.0 + 0.01 * k as f64), &UNIT, 1) == Verdict::Continues
            );
        }
        // The second coefficient steps by its whole content where the selection drops it.
        let mut dropped = on_curve(1.02);
        dropped.x[1] = 0.0;
        dropped.held = vec![1];
        let ratio = tail.ratio(&dropped, &UNIT, 1).expect("a ratio");
        assert!(ratio < 1e-9, "{ratio}");
        assert!(tail.continues(dropped, &UNIT, 1) == Verdict::Continues);
        // Restored at the next point: still left out, since it was held at one of the three.
        assert!(tail.continues(on_curve(1.03), &UNIT, 1) == Verdict::Continues);
    }

    #[test]
    fn no_prediction_no_verdict() {
        let mut tail = BranchTail::default();
        assert_eq!(tail.ratio(&on_curve(1.0), &UNIT, 1), None);
        assert!(tail.continues(on_curve(1.0), &UNIT, 1) == Verdict::Continues);
        assert!(tail.continues(on_curve(1.1), &UNIT, 1) == Verdict::Continues);
        // The period turns back (a fold): no secant in the period.
        let back = Sample {
            period: 1.05,
            energy: 1.0,
            x: vec![0.0, 9.0],
            ..Sample::default()
        };
        assert_eq!(tail.ratio(&back, &UNIT, 1), None);
        // A state of another length (another problem): no verdict either.
        let other = Sample {
            period: 1.2,
            energy: 1.0,
            x: vec![1.2],
            ..Sample::default()
        };
        assert_eq!(tail.ratio(&other, &UNIT, 1), None);
    }
}
