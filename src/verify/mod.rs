//! Exact time-domain integration of bar assemblies, and the periodicity check of computed
//! modes (formulation §10).
//!
//! # The scheme
//!
//! In each bar `u_tt = c^2 u_xx` splits into two characteristic waves
//!
//! ```text
//!   R = u_t - c u_x   (moves to the right at speed c),
//!   L = u_t + c u_x   (moves to the left at speed c),
//!   u_t = (R + L) / 2,   u_x = (L - R) / (2 c),
//!   EA/2 (u_t^2/c^2 + u_x^2) = EA / (4 c^2) (R^2 + L^2).
//! ```
//!
//! Each wave is stored as a **piecewise-constant function of its arrival time** at the end it
//! is travelling to (see [`State`](crate::verify::State)), in steps of a common `dt`: a part
//! that leaves one end of bar `b` at clock `s` reaches the other end at `s + nu_b`, with
//! `nu_b = l_b / (c_b dt)` ([`Grid::travel_steps`](crate::verify::Grid::travel_steps)).
//! Transport is this shift and introduces no error at all, whatever `nu_b`; a step is only
//! bookkeeping at the ends, where the incoming piece(s) of the step are turned into outgoing
//! piece(s) by the boundary condition. With the incoming value `a` and the outgoing value `b`
//! at an end of outward normal `n` (impedance `Z = EA / c`):
//!
//! ```text
//!   u_t = (a + b)/2,   u_x = n (b - a)/(2c),   contact force lambda = -EA u_x = n Z (a - b)/2,
//!   clamped: b = -a          free: b = a
//!   spring (EA n u_x + k_s u = 0):   u' = a - (k_s/Z) u,   b = a - 2 (k_s/Z) u
//!   obstacle at gap g0 (g = g0 - n u): free (b = a) unless g <= 0 and the incoming wave pushes
//!       outward (w = n a > 0); then stuck (b = -a), with lambda = Z w >= 0
//!   two ends A, B (g = g0 - n_A u_A - n_B u_B): free unless g <= 0 and w_A + w_B > 0; then
//!       stuck with the common outward velocity V = (Z_A w_A - Z_B w_B)/(Z_A + Z_B) and
//!       lambda = Z_A Z_B (w_A + w_B)/(Z_A + Z_B) >= 0.
//!   compliant obstacle (spring k at gap g0, compression p = n u - g0): free (b = a) while
//!       p < 0; pressed while p > 0 (or p = 0 and w > 0): p' = w - (k/Z) p,
//!       b = a - 2 n (k/Z) p, lambda = k p >= 0.
//! ```
//!
//! Within a piece the incoming value is constant, so in free flight the gap is linear in time:
//! the **instant of impact is found exactly** (`g / (w_A + w_B)`) and the step is split there;
//! the outgoing wave gets a breakpoint inside the cell, which is then transported exactly like
//! any other. **Release** happens when the incoming wave stops pushing (`w <= 0`), which can only
//! change at a breakpoint of the incoming wave: it is resolved exactly too, at no cost. Clamped,
//! free, obstacle and contact ends are lossless (`|b| = |a|` or a lossless impedance junction),
//! so the discrete energy — computed exactly from the pieces — is conserved to rounding (up
//! to what the merges below remove, which is reported).
//!
//! A **compliant obstacle** is free flight until the spring is touched, and a ground spring on
//! the compression `p` while it is pressed. Onset is found as an impact is (the gap `-p` is
//! linear in time within a piece); **release**, where `p` returns to zero, from the spring's
//! exact solution over the piece, `p(t) = w/beta + (p0 - w/beta) e^(-beta t)`: it happens only
//! if `w < 0`, at `t = ln(1 + beta p0 / (-w)) / beta`, and the piece is split there. The
//! spring stores `k p^2 / 2`; the pressed part is advanced as a ground spring below, with the
//! same energy error (exact update) or none (midpoint update). Unlike an obstacle's
//! penetration, the compression is the law: it is not reported as one.
//!
//! A ground spring is advanced with the **exact** solution of `u' = a - beta u`
//! (`beta = k_s / Z`) over each piece, and the outgoing wave keeps the exact mean of
//! `b(t) = a - 2 beta u(t)` over the piece (so end displacement and field stay consistent).
//! Replacing the exponential `b(t)` by its mean is an `L2` projection: it loses
//! `Z/4 int (b - mean b)^2 dt`, i.e. a relative energy error `O((beta dt)^2)` per unit time
//! that vanishes as `dt -> 0` ([`SpringUpdate::Exact`](crate::verify::SpringUpdate::Exact)). [`SpringUpdate::Midpoint`](crate::verify::SpringUpdate::Midpoint) instead
//! imposes the spring law at the midpoint of each piece (implicit midpoint rule): energy is then
//! conserved to rounding, and the end displacement is second-order accurate.
//!
//! # Any travel times
//!
//! The initial state holds `N_b = ceil(nu_b)` cells per bar, of length `l_b / N_b` and of
//! duration `h_b = nu_b / N_b` steps (1 on a **commensurate** grid, where every `nu_b` is an
//! integer, between 1/2 and 1 otherwise): one piece per cell and wave (the cell means of
//! `u_t -/+ c u_x`). Snapshots, the energy and the norm are computed on the same cells. The
//! only requirement is `nu_b >= 1` (a step no longer than any travel time), so that what an
//! end emits during a step reaches the other end after the step
//! ([`VerifyError::NonMatchingGrid`](crate::verify::VerifyError::NonMatchingGrid) otherwise).
//!
//! On a commensurate grid every breakpoint stays on the lattice of steps, but for those of
//! impacts. Otherwise the breakpoints of bars of different travel times meet at every
//! contact that is stuck (and a spring splits its outgoing wave at every step): their
//! offsets never repeat, and the number of pieces grows with time. The same happens on any
//! grid under persistent chattering impacts. To keep a step's work bounded, a wave that holds
//! more than a cap of pieces merges any new piece shorter than `h_b /`
//! [`PIECES_PER_CELL`](crate::verify::PIECES_PER_CELL) into its neighbour, by their
//! length-weighted mean: an `L2` projection onto a coarser partition that keeps the
//! integral of the wave, hence every displacement, and removes exactly
//!
//! ```text
//!   Delta E = Z dt / 4  h_1 h_2 / (h_1 + h_2)  (v_1 - v_2)^2      (h in steps)
//! ```
//!
//! of energy. A wave then never holds more than `cap + PIECES_PER_CELL N_b + 2` pieces (all
//! but those pushed below the cap are at least `h_b / PIECES_PER_CELL` long). The cap is
//! `PIECES_PER_CELL N_b` for an [`Integrator`](crate::verify::Integrator) stepping on its own
//! and, for a [`march`](crate::verify::march), whatever its share of
//! [`MARCH_WORK`](crate::verify::MARCH_WORK) allows, so that a march of ordinary length
//! (one or a few periods) is exact and merges nothing. The energy removed is
//! reported ([`State::projected_energy`](crate::verify::State::projected_energy),
//! [`StepSummary::projected_energy`](crate::verify::StepSummary::projected_energy),
//! [`Trajectory::projected_energy`](crate::verify::Trajectory::projected_energy),
//! [`PeriodicityReport::projected_energy`](crate::verify::PeriodicityReport::projected_energy)):
//! the lossless conditions conserve `E + removed` to rounding. Each removed part is
//! orthogonal to what its merge keeps and has the state norm `sqrt(2 Delta E)`; the periodicity
//! report gives `sqrt(2 sum Delta E) / |X(0)|` as the estimate of the merges' share of its
//! defect ([`PeriodicityReport::projection_error`](crate::verify::PeriodicityReport::projection_error)).
//!
//! Accuracy then is that of the initial cell averages: the defect of an exact linear mode of
//! two or three bars with incommensurate travel times is first order in `dt`
//! (`docs/validation.md`). A commensurate grid ([`Grid::nearest`](crate::verify::Grid::nearest),
//! [`PeriodicityOptions::adjust_grid`](crate::verify::PeriodicityOptions::adjust_grid)) is
//! never needed, but is still preferred on request.
//!
//! Why this rather than a common grid with interpolation: the transport and the impact
//! instants stay exact for any travel times, the only approximation (the merges) acts where
//! and when the pieces would multiply and nowhere else, and its error is known exactly. An
//! interpolating grid would dissipate at every step of every bar, commensurate or not.
//!
//! **Cost.** A step takes the pieces that reach the ends during it; a wave holds exactly the
//! pieces that arrive within the next `nu_b` steps, so with the cap the work of a march is
//! linear in its steps ([`Grid::march_work`](crate::verify::Grid::march_work) gives the bound),
//! and marches whose bound exceeds [`MAX_MARCH_WORK`](crate::verify::MAX_MARCH_WORK) are
//! refused ([`VerifyError::TooCostly`](crate::verify::VerifyError::TooCostly)). The energy
//! history costs nothing per step: each wave keeps the integral of its square up to date
//! (compensated sums) as pieces come and go.
//!
//! # Which conditions are marched
//!
//! [`Model::from_system`](crate::verify::Model::from_system) takes each condition of a
//! [`BarSystem`](crate::system::BarSystem) as the form it declares,
//! [`BoundaryCondition::time_domain_form`](crate::bc::BoundaryCondition::time_domain_form)
//! ([`TimeDomainForm`](crate::bc::TimeDomainForm), which is
//! [`Condition`](crate::verify::Condition)): clamped, free, ground spring, rigid or compliant
//! obstacle, two-end contact. Every built-in condition
//! declares its own. Nothing is read from rows or observables: a unilateral law's residual is
//! an opaque function, so a penalty law `lambda - k max(0, -g)` has the same gap and force
//! as a rigid obstacle, and marching what the observables suggest would check a motion of
//! another system. A condition that declares no form (an end mass, a law of another kind)
//! gives [`VerifyError::NoTimeDomainForm`](crate::verify::VerifyError::NoTimeDomainForm), and
//! the annotated points of [`compute`](crate::branches::compute) are then
//! [`CheckOutcome::Unchecked`](crate::branches::CheckOutcome::Unchecked), not unverified.
//!
//! # The periodicity check
//!
//! [`periodicity_check`](crate::verify::periodicity_check) starts from the fields of a harmonic-balance point at `t = 0`,
//! marches one period and reports `|X(T) - X(0)| / |X(0)|` in the state norm
//!
//! ```text
//!   |X|^2 = sum_b [ EA_b int_0^l (u_t^2 / c_b^2 + u_x^2) dx + (EA_b / l_b) (u_b(0)^2 + u_b(l)^2) ]
//! ```
//!
//! (twice the elastic energy, plus the end displacements so that rigid shifts count), together
//! with the largest penetration, the smallest contact force, the energy drift and what the
//! merges removed.

mod exact;
mod grid;
mod march;
mod model;
mod periodicity;
mod state;
mod trajectory;
mod wave;

pub use crate::error::VerifyError;
pub use exact::clamped_first_mode;
pub use grid::{Grid, MARCH_WORK, MAX_MARCH_WORK, PIECES_PER_CELL};
pub use march::{Integrator, MarchOptions, SpringUpdate, StepSummary};
pub use model::{Condition, Model};
pub use periodicity::{
    periodicity_check, periodicity_of_state, PeriodicityOptions, PeriodicityReport,
};
pub(crate) use state::check_fundamental_frequency;
pub use state::{BarCells, BarSnapshot, Snapshot, State};
pub use trajectory::{advance, march, ContactHistory, MarchedEnd, Trajectory};
