//! # nonsmooth-modes
//!
//! Nonsmooth modal analysis of elastic bar assemblies with unilateral contact: families of
//! periodic motions (nonsmooth modes, backbone curves) computed by the Frequency-Domain
//! Boundary Element Method, the Harmonic Balance Method and numerical continuation, after
//! T. Lu and M. Legrand, *Nonsmooth Modal Analysis via the Boundary Element Method for
//! one-dimensional bar systems*, Nonlinear Dynamics (2021).
//!
//! ## The model
//!
//! Each bar `b` (length `l`, wave speed `c`, axial stiffness `EA`) obeys `u_tt = c^2 u_xx`.
//! A `T`-periodic motion is expanded in a harmonic basis of fundamental frequency
//! `Omega = 2 pi / T`; each harmonic `n` of each bar solves a Helmholtz equation with wave
//! number `k = n Omega / c`, whose solutions `A cos(kx) + B sin(kx)/k` are the unknowns.
//! Linear boundary conditions (clamped, free, ground spring, contact force balance) are rows
//! per harmonic; unilateral contact (`g >= 0`, `lambda >= 0`, `g lambda = 0`) is written as
//! `r = -min(lambda, a_c g) = 0` in time and projected on the basis (weighted residuals).
//! The square nonsmooth system `F(x; Omega) = 0` is solved by semismooth Newton (or Powell's
//! dogleg) with an analytic generalised Jacobian, and followed in `Omega` or `T` by
//! continuation. No equation divides by `sin`, `cos` or `tan` of a frequency: nothing has a
//! pole at a natural frequency. `docs/theory.md` has the whole derivation.
//!
//! ## Main types
//!
//! | type | role |
//! |---|---|
//! | [`bar::Bar`], [`bar::EndRef`] | a bar; one of its ends |
//! | [`bc::BoundaryCondition`] | trait of all conditions: [`bc::Dirichlet`], [`bc::Neumann`], [`bc::Robin`], [`bc::Signorini`], [`bc::Contact`] |
//! | [`system::AssemblyBuilder`] → [`system::BarSystem`] | compose and validate |
//! | [`system::NonsmoothSystem`] | `F(x; Omega)`, Jacobian, `dF/dOmega` for a [`fourier::Basis`] |
//! | [`solve::NonlinearSolver`] | [`solve::SemismoothNewton`], [`solve::Dogleg`], [`solve::SmoothingHomotopy`] |
//! | [`solve::Problem`], [`solve::Structured`] | what a solver sees: residual, Jacobian, and optional capabilities (structured solve, line-search residual, smoothing, weights, active sets) |
//! | [`continuation::ContinuationProblem`] | a problem with a parameter: [`continuation::Sequential`], [`continuation::Speculative`], [`continuation::Arclength`], all with one shape ([`continuation::Step`], iterator, `run` with an [`continuation::Observer`]) |
//! | [`branches::compute`] with a [`branches::Request`] → [`branches::ModeBranches`] | the one call: a branch of NSM `i` (sub `K`) by a [`branches::Method`] (period grid, arclength with the [`branches::StallEscape`], switch at a branch point, energy level, genuine subharmonic, or `Auto`), every point with its status, branch, [`modal::Character`], [`modal::Label`] and, when asked, time-domain check |
//! | [`branches::parameter_branch`] | a point continued in any system parameter |
//! | [`modal::character`], [`modal::label`] | what a motion is: contacts and grazings per period, energy by bar and harmonic, dominant modes; skeleton, internal resonance, subharmonic or unverified |
//! | [`Solution`] | a computed motion (problem, unknowns, frequency): energy, `E/E_g`, fields, end and law histories, diagnostics, time-domain check |
//! | [`modal::diagnose`], [`modal::FieldEvaluator`] | residual norm `R^(m)`, penetration, fields, histories of a point |
//! | [`verify::periodicity_check`] | exact time-domain march of a point: periodicity defect |
//! | [`mod@reference`] | the paper's systems and exact solutions |
//! | [`io`] | CSV, and JSON with the `serde` feature; with it, assemblies from TOML/JSON files |
//! | [`exact`] | exact nonsmooth modes: branches of the integrator's one-period map, continued in the period, with a Floquet verdict at every point |
//! | [`sweep::backbones`] | many requests at once; in parallel with the `parallel` feature (rayon), results identical to the serial run |
//!
//! ## Features
//!
//! | feature | adds |
//! |---|---|
//! | `parallel` | [`sweep::backbones`] on rayon's thread pool, and the columns of every monodromy matrix ([`stability`], [`exact`]) |
//! | `serde` (default) | `Serialize` on points, branches and diagnostics; `io::to_json`; assemblies read from and written to TOML or JSON files (`io::assembly`); `default-features = false` leaves it out |
//! | `plot` | the `plot` module: SVG figures |
//! | `proptest` | the `strategies` module: proptest strategies |
//!
//! ## Quick start
//!
//! ```
//! use nonsmooth_modes::branches::{compute, Request};
//! use nonsmooth_modes::reference::{clamped_bar_with_obstacle, ClampedFirstMode};
//!
//! let system = clamped_bar_with_obstacle(1e-3)?;
//! // NSM 1 with 10 harmonics; the method and its grid are derived from the system.
//! let run = compute(&system, &Request::new(1).harmonics(10))?;
//! let point = run.converged().find(|p| p.period <= 3.7 + 1e-9).unwrap();
//! let exact = ClampedFirstMode::new(1e-3, point.period).energy_normalized();
//! assert!((point.energy_normalized / exact - 1.0).abs() < 0.1);
//! # Ok::<(), nonsmooth_modes::Error>(())
//! ```

/// The README's quick start, compiled and run as a doctest so that it cannot rot.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

pub mod bar;
pub mod bc;
pub mod bem;
pub mod branches;
mod check;
pub mod continuation;
mod end;
pub mod error;
pub mod exact;
pub mod forced;
pub mod fourier;
pub mod io;
pub mod linalg;
pub mod modal;
#[cfg(feature = "plot")]
pub mod plot;
pub mod reference;
pub mod solution;
pub mod solve;
pub mod stability;
mod status;
/// Proptest strategies for bars, frequencies, Helmholtz coefficients, the paper's systems and
/// periods, for property tests of the crate's identities (feature `proptest`).
#[cfg(feature = "proptest")]
pub mod strategies;
pub mod sweep;
pub mod system;
mod verdict;
/// Exact time-domain integration of bar assemblies (d'Alembert on a grid with `dx = c dt`,
/// impacts resolved inside the step) and the periodicity check of computed modes.
pub mod verify;

pub use error::{
    BadRange, ContinuationError, Error, ForcingError, ModelError, RangeDefect, SettingsError,
    SolveError, StabilityError,
};
pub use solution::Solution;
