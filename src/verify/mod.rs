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
//! On a grid with `dx = c dt` a wave moves exactly one cell per step, so transporting it is a
//! shift and introduces no error at all. Each wave is stored as a **piecewise-constant function
//! of its arrival time** at the end it is travelling to (see [`State`](crate::verify::State)): initially one piece per
//! cell (the cell averages of `u_t -/+ c u_x`), and at an end the incoming piece(s) of a step are
//! turned into outgoing piece(s) by the boundary condition. With the incoming value `a` and the
//! outgoing value `b` at an end of outward normal `n` (impedance `Z = EA / c`):
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
//! ```
//!
//! Within a piece the incoming value is constant, so in free flight the gap is linear in time:
//! the **instant of impact is found exactly** (`g / (w_A + w_B)`) and the step is split there;
//! the outgoing wave gets a breakpoint inside the cell, which is then transported exactly like
//! any other. **Release** happens when the incoming wave stops pushing (`w <= 0`), which can only
//! change at a breakpoint of the incoming wave: it is resolved exactly too, at no cost. Clamped,
//! free, obstacle and contact ends are lossless (`|b| = |a|` or a lossless impedance junction),
//! so the discrete energy — computed exactly from the pieces — is conserved to rounding.
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
//! # Which conditions are supported
//!
//! [`Model::from_system`](crate::verify::Model::from_system) reads each condition of a [`BarSystem`](crate::system::BarSystem) from
//! its rows and observables (it does not need to know the concrete type): one row
//! `alpha u + gamma u_x = 0` gives clamped (`gamma = 0`), free (`alpha = 0`) or a ground spring
//! (`k_s = n EA alpha / gamma > 0`); a law with gap `g0 - kappa v` and a compressive force gives an
//! obstacle; a law on two ends with gap `g0 - kappa (v_A + v_B)` and the balance
//! `lambda_A = lambda_B` gives a two-end contact. Anything else (frequency-dependent rows such
//! as an end mass, tensile springs, other laws) is [`VerifyError::Unsupported`](crate::verify::VerifyError::Unsupported).
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
//! with the largest penetration, the smallest contact force and the energy drift.

mod exact;
mod grid;
mod march;
mod model;
mod periodicity;
mod state;
mod wave;

pub use crate::error::VerifyError;
pub use exact::clamped_first_mode;
pub use grid::Grid;
pub use march::{
    march, ContactHistory, Integrator, MarchOptions, MarchedEnd, SpringUpdate, StepSummary,
    Trajectory,
};
pub use model::{Condition, Model};
pub use periodicity::{
    periodicity_check, periodicity_of_state, PeriodicityOptions, PeriodicityReport,
};
pub use state::{BarCells, BarSnapshot, Snapshot, State};
