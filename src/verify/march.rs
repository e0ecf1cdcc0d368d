//! The march: every step, each condition turns the waves arriving at its ends into outgoing
//! waves, resolving impacts and releases at their exact instants.

use super::state::State;
use super::wave::{Piece, TINY};
use super::{Condition, VerifyError};
use crate::bar::{End, EndRef};

/// How a ground spring, or a compliant obstacle while it is compressed, is advanced over a
/// piece of constant incoming wave `a`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SpringUpdate {
    /// Exact solution of `u' = a - beta u` (`beta = k_s / Z`); the outgoing wave is the exact
    /// mean of `b(t) = a - 2 beta u(t)` over the piece. End displacement exact, and with it
    /// the release of a compliant obstacle; the projection of `b` on constants loses a
    /// relative energy `O((beta dt)^2)` per unit time. The default.
    #[default]
    Exact,
    /// Spring law imposed at the midpoint of the piece (implicit midpoint rule): energy is
    /// conserved to rounding, the end displacement has an `O((beta dt)^2)` relative error
    /// (and a compliant obstacle releases where that displacement says).
    Midpoint,
}

impl SpringUpdate {
    /// The mean rate `Delta x / h` over a time `h` of `x' = f - beta x` (`f` constant), where
    /// `drive = f - beta x(0)` is the rate at the start: exactly
    /// `drive (1 - e^(-beta h)) / (beta h)`, or by the implicit midpoint rule
    /// `drive / (1 + beta h / 2)`.
    fn mean_rate(self, drive: f64, beta: f64, h: f64) -> f64 {
        match self {
            SpringUpdate::Exact => {
                let z = beta * h;
                let phi = if z > 0.0 { -(-z).exp_m1() / z } else { 1.0 };
                drive * phi
            }
            SpringUpdate::Midpoint => drive / (1.0 + 0.5 * beta * h),
        }
    }

    /// The time after which a compression `x0 > 0` obeying `x' = f - beta x` (`f` constant)
    /// returns to zero, `None` if it does not. Exactly, `x(t) = f/beta + (x0 - f/beta)
    /// e^(-beta t)` vanishes at `ln(1 + beta x0 / (-f)) / beta` when `f < 0` (never
    /// otherwise); by the midpoint rule, `x` is linear over a piece, `x0 + t (f - beta x0) /
    /// (1 + beta t / 2)`, and vanishes at `x0 / (beta x0 / 2 - f)` when that is positive.
    fn release(self, x0: f64, f: f64, beta: f64) -> Option<f64> {
        match self {
            SpringUpdate::Exact => (f < 0.0).then(|| (beta * x0 / -f).ln_1p() / beta),
            SpringUpdate::Midpoint => {
                let rate = 0.5 * beta * x0 - f;
                (rate > 0.0).then(|| x0 / rate)
            }
        }
    }
}

/// Options of [`march`](super::march) and [`Integrator`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MarchOptions {
    /// Update of ground springs (default [`SpringUpdate::Exact`]).
    pub spring: SpringUpdate,
    /// Keep a [`Snapshot`](super::Snapshot) of the fields every that many steps (0, the default: only none;
    /// the initial and final states are always available from the
    /// [`Trajectory`](super::Trajectory)).
    pub snapshot_every: usize,
}

/// What happened during one step.
#[derive(Debug, Clone, PartialEq)]
pub struct StepSummary {
    /// Time at the end of the step.
    pub time: f64,
    /// Length of the step (`dt`, or less for a partial step).
    pub duration: f64,
    /// Mean strain `u_x` over the step at `[x = 0, x = l]` of every bar.
    pub end_strain: Vec<[f64; 2]>,
    /// Mean contact force over the step, per condition (0 for linear conditions).
    pub contact_force: Vec<f64>,
    /// Smallest contact force during the step over all unilateral conditions (0 while a
    /// contact is open; `+inf` if there is no unilateral condition).
    pub min_contact_force: f64,
    /// Largest penetration `max(0, -g)` seen during the step.
    pub max_penetration: f64,
    /// Energy removed during the step by merging short pieces
    /// ([`State::projected_energy`]); 0 while no wave is at its piece limit.
    pub projected_energy: f64,
}

/// Steps a [`State`] forward, one (possibly partial) step at a time.
#[derive(Debug, Clone)]
pub struct Integrator {
    state: State,
    options: MarchOptions,
    incoming: Vec<Vec<Piece>>,
    outgoing: Vec<Vec<(f64, f64)>>,
    /// The last step's mean end strains and contact forces: kept here so that a march that
    /// does not record them allocates nothing per step.
    end_strain: Vec<[f64; 2]>,
    contact_force: Vec<f64>,
}

/// The numbers of one step that are not kept in the integrator's buffers.
#[derive(Debug, Clone, Copy)]
pub(super) struct StepScalars {
    min_contact_force: f64,
    max_penetration: f64,
    projected_energy: f64,
}

/// One end of a condition during a step.
#[derive(Debug, Clone, Copy)]
struct Port {
    /// Outward normal.
    n: f64,
    /// Wave speed.
    c: f64,
    /// Impedance `EA / c`.
    z: f64,
    /// Displacement.
    u: f64,
    /// `int u_x ds` over the step (clock units).
    strain: f64,
}

/// Observations of one condition during a step.
#[derive(Debug, Clone, Copy)]
struct Watch {
    force: f64,
    min_force: f64,
    penetration: f64,
}

impl Port {
    /// Records an outgoing value `b` against the incoming `a` for a duration `h` (clock units).
    fn emit(&mut self, out: &mut Vec<(f64, f64)>, until: f64, a: f64, b: f64, h: f64) {
        out.push((until, b));
        self.strain += h * self.n * (b - a) / (2.0 * self.c);
    }

    /// Free flight of an end facing an obstacle at offset `gap` from `s` towards `end`: the
    /// wave `a` goes out unchanged until the gap `g` (linear in time, closing at `n a` per
    /// unit time) closes, where the end is put on the obstacle exactly. Returns where it
    /// stopped.
    fn fly(
        &mut self,
        out: &mut Vec<(f64, f64)>,
        (s, end): (f64, f64),
        (g, a, dt): (f64, f64, f64),
        gap: f64,
    ) -> f64 {
        let hit = impact(s, end, g, self.n * a * dt);
        let stop = hit.unwrap_or(end);
        self.emit(out, stop, a, a, stop - s);
        if hit.is_some() {
            self.u = self.n * gap; // on the obstacle: g = 0 exactly
        } else {
            self.u += (stop - s) * dt * a;
        }
        stop
    }
}

/// Rounding tolerance for a closed gap.
fn gap_tolerance(g0: f64, u: &[f64]) -> f64 {
    8.0 * f64::EPSILON * (g0.abs() + u.iter().map(|v| v.abs()).sum::<f64>())
}

/// Clock of impact within `[s, end]` for a gap `g` closing at `rate` per step from clock
/// `s`, snapped to `s` or `end` when within rounding of them (so that an impact that falls on
/// a breakpoint in exact arithmetic leaves no sliver of a piece); `None` if the gap does not
/// close before `end`.
fn impact(s: f64, end: f64, g: f64, rate: f64) -> Option<f64> {
    if rate <= 0.0 {
        return None;
    }
    within(s, end, s + g / rate)
}

/// The clock `hit >= s` if it falls within `[s, end]`, snapped to `s` or `end` when within
/// rounding of them; `None` beyond `end`.
fn within(s: f64, end: f64, hit: f64) -> Option<f64> {
    let tol = TINY.max(64.0 * f64::EPSILON * end.abs());
    if hit - s < tol {
        Some(s)
    } else if (hit - end).abs() < tol {
        Some(end)
    } else if hit < end {
        Some(hit)
    } else {
        None
    }
}

/// The ends of `condition` without allocating: `(ends, how many)`.
fn ends_of(condition: &Condition) -> ([EndRef; 2], usize) {
    match *condition {
        Condition::Clamped { end }
        | Condition::Free { end }
        | Condition::Spring { end, .. }
        | Condition::Obstacle { end, .. }
        | Condition::CompliantObstacle { end, .. } => ([end, end], 1),
        Condition::Contact { first, second, .. } => ([first, second], 2),
    }
}

impl Integrator {
    /// An integrator starting from `state`.
    pub fn new(state: State, options: MarchOptions) -> Self {
        Self {
            state,
            options,
            incoming: vec![Vec::new(), Vec::new()],
            outgoing: vec![Vec::new(), Vec::new()],
            end_strain: Vec::new(),
            contact_force: Vec::new(),
        }
    }

    /// The current state.
    pub fn state(&self) -> &State {
        &self.state
    }

    /// The current state, consuming the integrator.
    pub fn into_state(self) -> State {
        self.state
    }

    /// One full step `dt`.
    pub fn step(&mut self) -> StepSummary {
        self.advance_unchecked(1.0)
    }

    /// A partial step of `fraction * dt`.
    ///
    /// # Errors
    /// [`VerifyError::InvalidParameter`] unless `0 < fraction <= 1`.
    pub fn advance(&mut self, fraction: f64) -> Result<StepSummary, VerifyError> {
        if !(fraction > 0.0 && fraction <= 1.0) {
            return Err(VerifyError::InvalidParameter {
                what: "step fraction",
                value: fraction,
            });
        }
        Ok(self.advance_unchecked(fraction))
    }

    /// A partial step of `fraction * dt` (`0 < fraction <= 1`), with its summary.
    pub(super) fn advance_unchecked(&mut self, fraction: f64) -> StepSummary {
        let scalars = self.advance_quietly(fraction);
        StepSummary {
            time: self.state.time(),
            duration: fraction * self.state.grid.dt(),
            end_strain: self.end_strain.clone(),
            contact_force: self.contact_force.clone(),
            min_contact_force: scalars.min_contact_force,
            max_penetration: scalars.max_penetration,
            projected_energy: scalars.projected_energy,
        }
    }

    /// A partial step of `fraction * dt` (`0 < fraction <= 1`); its end strains and contact
    /// forces are left in the integrator's buffers.
    pub(super) fn advance_quietly(&mut self, fraction: f64) -> StepScalars {
        let projected_before = self.state.projected_energy();
        let s0 = self.state.clock;
        let s1 = s0 + fraction;
        let dt = self.state.grid.dt();
        let nb = self.state.bars.len();
        let mut end_strain = std::mem::take(&mut self.end_strain);
        end_strain.clear();
        end_strain.resize(nb, [0.0; 2]);
        let count = self.state.model.conditions().len();
        let mut contact_force = std::mem::take(&mut self.contact_force);
        contact_force.clear();
        contact_force.resize(count, 0.0);
        let mut min_force = f64::INFINITY;
        let mut penetration: f64 = 0.0;
        for (ci, force) in contact_force.iter_mut().enumerate() {
            let condition = self.state.model.conditions()[ci];
            let (ends, ports_used) = ends_of(&condition);
            let ends = &ends[..ports_used];
            let mut ports = [None, None];
            for (k, end) in ends.iter().enumerate() {
                let b = end.bar.index();
                let bar = self.state.model.bars()[b];
                let waves = &mut self.state.bars[b];
                let side = usize::from(end.end == End::Right);
                self.incoming[k].clear();
                self.outgoing[k].clear();
                let wave = if side == 1 {
                    &mut waves.right
                } else {
                    &mut waves.left
                };
                wave.take_until(s1, &mut self.incoming[k]);
                ports[k] = Some(Port {
                    n: end.end.normal(),
                    c: bar.wave_speed(),
                    z: bar.stiffness() / bar.wave_speed(),
                    u: waves.ends[side],
                    strain: 0.0,
                });
            }
            let mut watch = Watch {
                force: 0.0,
                min_force: f64::INFINITY,
                penetration: 0.0,
            };
            let (inc, out) = (&self.incoming, &mut self.outgoing);
            match (condition, ports) {
                (Condition::Clamped { .. }, [Some(mut p), _]) => {
                    for q in &inc[0] {
                        p.emit(&mut out[0], q.end, q.value, -q.value, q.end - q.start);
                    }
                    ports[0] = Some(p);
                }
                (Condition::Free { .. }, [Some(mut p), _]) => {
                    for q in &inc[0] {
                        p.emit(&mut out[0], q.end, q.value, q.value, q.end - q.start);
                        p.u += (q.end - q.start) * dt * q.value;
                    }
                    ports[0] = Some(p);
                }
                (Condition::Spring { stiffness, .. }, [Some(mut p), _]) => {
                    let beta = stiffness / p.z;
                    for q in &inc[0] {
                        let h = (q.end - q.start) * dt;
                        let a = q.value;
                        // Mean end velocity over the piece, Delta u / h.
                        let rate = self.options.spring.mean_rate(a - beta * p.u, beta, h);
                        let b = 2.0 * rate - a;
                        p.emit(&mut out[0], q.end, a, b, q.end - q.start);
                        p.u += rate * h;
                    }
                    ports[0] = Some(p);
                }
                (Condition::Obstacle { gap, .. }, [Some(mut p), _]) => {
                    let n = p.n;
                    for q in &inc[0] {
                        let a = q.value;
                        let w = n * a;
                        let mut s = q.start;
                        while s < q.end {
                            let g = gap - n * p.u;
                            if g <= gap_tolerance(gap, &[p.u]) && w > 0.0 {
                                // Stuck: u_t = 0, lambda = Z w > 0.
                                p.emit(&mut out[0], q.end, a, -a, q.end - s);
                                let lambda = p.z * w;
                                watch.force += lambda * (q.end - s);
                                watch.min_force = watch.min_force.min(lambda);
                                s = q.end;
                            } else {
                                s = p.fly(&mut out[0], (s, q.end), (g, a, dt), gap);
                                watch.min_force = watch.min_force.min(0.0);
                            }
                            watch.penetration = watch.penetration.max(n * p.u - gap);
                        }
                    }
                    ports[0] = Some(p);
                }
                (Condition::CompliantObstacle { gap, stiffness, .. }, [Some(mut p), _]) => {
                    let (n, beta) = (p.n, stiffness / p.z);
                    let update = self.options.spring;
                    for q in &inc[0] {
                        let a = q.value;
                        let w = n * a;
                        let mut s = q.start;
                        while s < q.end {
                            // Compression of the spring, c = v - g0 (negative while open).
                            let c = n * p.u - gap;
                            let tol = gap_tolerance(gap, &[p.u]);
                            if c > tol || (c >= -tol && w > 0.0) {
                                // Pressed: c' = w - beta c, released where c returns to 0.
                                let c = c.max(0.0);
                                let release = (c > tol)
                                    .then(|| update.release(c, w, beta))
                                    .flatten()
                                    .and_then(|t| within(s, q.end, s + t / dt));
                                let stop = release.unwrap_or(q.end);
                                let h = (stop - s) * dt;
                                let rate = update.mean_rate(w - beta * c, beta, h);
                                p.emit(&mut out[0], stop, a, 2.0 * n * rate - a, stop - s);
                                let after = if release.is_some() { 0.0 } else { c + rate * h };
                                p.u = n * (gap + after);
                                // Mean force Z (w - rate) = k (mean c); c is monotone.
                                watch.force += p.z * (w - rate) * (stop - s);
                                let low = stiffness * c.min(after).max(0.0);
                                watch.min_force = watch.min_force.min(low);
                                s = stop;
                            } else {
                                s = p.fly(&mut out[0], (s, q.end), (-c, a, dt), gap);
                                watch.min_force = watch.min_force.min(0.0);
                            }
                        }
                    }
                    ports[0] = Some(p);
                }
                (Condition::Contact { gap, .. }, [Some(mut pa), Some(mut pb)]) => {
                    let (ia, ib) = (&inc[0], &inc[1]);
                    let (mut i, mut j) = (0, 0);
                    let mut s = s0;
                    let (out_a, out_b) = out.split_at_mut(1);
                    let (out_a, out_b) = (&mut out_a[0], &mut out_b[0]);
                    while i < ia.len() && j < ib.len() {
                        let e = ia[i].end.min(ib[j].end);
                        let (aa, ab) = (ia[i].value, ib[j].value);
                        let (wa, wb) = (pa.n * aa, pb.n * ab);
                        let w = wa + wb;
                        while s < e {
                            let g = gap - pa.n * pa.u - pb.n * pb.u;
                            if g <= gap_tolerance(gap, &[pa.u, pb.u]) && w > 0.0 {
                                // Stuck: common outward velocity V, lossless junction.
                                let v = (pa.z * wa - pb.z * wb) / (pa.z + pb.z);
                                let h = e - s;
                                pa.emit(out_a, e, aa, pa.n * (2.0 * v - wa), h);
                                pb.emit(out_b, e, ab, pb.n * (-2.0 * v - wb), h);
                                pa.u += pa.n * v * h * dt;
                                pb.u -= pb.n * v * h * dt;
                                let lambda = pa.z * pb.z * w / (pa.z + pb.z);
                                watch.force += lambda * h;
                                watch.min_force = watch.min_force.min(lambda);
                                s = e;
                            } else {
                                let hit = impact(s, e, g, w * dt);
                                let stop = hit.unwrap_or(e);
                                let h = stop - s;
                                pa.emit(out_a, stop, aa, aa, h);
                                pb.emit(out_b, stop, ab, ab, h);
                                pa.u += h * dt * aa;
                                pb.u += h * dt * ab;
                                if hit.is_some() {
                                    // Close the gap exactly (to rounding) at the impact.
                                    let r = gap - pa.n * pa.u - pb.n * pb.u;
                                    pa.u += pa.n * r;
                                }
                                watch.min_force = watch.min_force.min(0.0);
                                s = stop;
                            }
                            let g = gap - pa.n * pa.u - pb.n * pb.u;
                            watch.penetration = watch.penetration.max(-g);
                        }
                        if ia[i].end <= e {
                            i += 1;
                        }
                        if ib[j].end <= e {
                            j += 1;
                        }
                    }
                    ports = [Some(pa), Some(pb)];
                }
                _ => unreachable!("a condition has as many ports as ends"),
            }
            if condition.is_unilateral() {
                *force = watch.force / fraction;
                min_force = min_force.min(watch.min_force);
                penetration = penetration.max(watch.penetration);
            }
            for (k, end) in ends.iter().enumerate() {
                let Some(p) = ports[k] else { continue };
                let b = end.bar.index();
                let travel = self.state.grid.travel_steps(b);
                let side = usize::from(end.end == End::Right);
                let waves = &mut self.state.bars[b];
                waves.ends[side] = p.u;
                end_strain[b][side] = p.strain / fraction;
                let wave = if side == 1 {
                    &mut waves.left
                } else {
                    &mut waves.right
                };
                for &(until, value) in &self.outgoing[k] {
                    wave.push_until(until + travel, value);
                }
            }
        }
        self.state.clock = s1;
        (self.end_strain, self.contact_force) = (end_strain, contact_force);
        StepScalars {
            min_contact_force: min_force,
            max_penetration: penetration,
            projected_energy: self.state.projected_energy() - projected_before,
        }
    }
}
