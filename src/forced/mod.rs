//! Forced, damped responses with exact unilateral contact: the harmonic balance of bars with
//! viscous damping under harmonic excitation, in the full Fourier basis, and its
//! frequency-response curves.
//!
//! # The equations
//!
//! Each bar obeys `u_tt + eta u_t = c^2 u_xx` (viscous damping `eta >= 0`, per bar). Its
//! harmonic `n` of the forcing frequency `Omega`, `Re(U(x) e^{i n Omega t})`, solves
//! `U'' + kappa U = 0` with the complex
//!
//! ```text
//! kappa = (n^2 Omega^2 - i eta n Omega) / c^2,
//! ```
//!
//! so `U = A cos(kx) + B sin(kx)/k` as without damping, at a complex wave number whose
//! end values are entire in `kappa` ([`waves`]): damping moves the poles of the linear
//! response off the real axis and adds none. Each harmonic's condition rows and law
//! observables are those of the undamped system with these maps; a complex row acting on
//! `Z = X_c - i X_s` is two real rows, one for the cosine and one for the sine.
//! Damping couples a harmonic's cosine and sine, which is why the response needs the full
//! basis.
//!
//! An excitation `F cos(Omega t)` (a force at an end, or a motion of the ground a clamped or
//! sprung end is tied to) is the right-hand side of that end's condition row at harmonic 1
//! ([`Excitation`]). The contact laws are enforced in time as in
//! [`NonsmoothSystem`](crate::system::NonsmoothSystem) (alternating frequency–time, the
//! complementarity function sampled and projected). The excitation fixes the time origin,
//! so the system needs no phase condition: [`ForcedSystem`] is square and regular. A bar held
//! by contacts only would leave its mean position free while they are open: the mean of every
//! law its rigid-body motion moves is tied by a spring of `1e-8 EA / l` across the gap.
//!
//! # What is checked
//!
//! Every harmonic solves the damped wave equation and its conditions exactly; the only
//! approximation is the truncated contact law. [`ForcedSystem::contact_defect`] measures it
//! between the samples, on a grid four times finer. The time-domain integrator of
//! [`crate::verify`] is exact for undamped waves only; it does not take forced or damped
//! systems, whose points this defect certifies instead.
//!
//! # Example
//!
//! ```
//! use nonsmooth_modes::forced::{
//!     forced_response, Damping, Excitation, Forcing, ResponseMethod, ResponseRequest,
//! };
//! use nonsmooth_modes::reference::clamped_bar_with_obstacle;
//! use nonsmooth_modes::system::HarmonicBalanceSettings;
//!
//! let system = clamped_bar_with_obstacle(1e-3)?;
//! let clamped = system.bar_id(0).unwrap().left();
//! let request = ResponseRequest {
//!     settings: HarmonicBalanceSettings { harmonics: 8, ..Default::default() },
//!     forcing: Forcing {
//!         damping: Damping::Uniform(0.05),
//!         excitations: vec![Excitation::base_motion(clamped, 1e-5)],
//!     },
//!     omega_range: (1.0, 1.4),
//!     steps: 5,
//!     method: ResponseMethod::Sequential,
//!     solver: Default::default(),
//! };
//! let response = forced_response(&system, &request)?;
//! assert!(response.points.iter().all(|p| p.converged && p.amplitude < 1.0));
//! # Ok::<(), nonsmooth_modes::Error>(())
//! ```

mod arclength;
mod excitation;
mod folds;
mod gaps;
mod hold;
mod leap;
mod measures;
mod open;
mod point;
mod response;
pub(crate) mod rows;
mod system;
mod tether;
pub mod waves;

pub use excitation::{Damping, Excitation, ExcitationKind};
pub use point::ResponsePoint;
pub use response::{forced_response, ForcedResponse, ResponseMethod, ResponseRequest};
pub use system::{ForcedSystem, Forcing};
