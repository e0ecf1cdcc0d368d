//! What a forced response reports of each state: the amplitude at the first contact, the
//! mechanical energy averaged over the period, and how well the truncated motion meets the
//! contact laws between the samples.

use crate::bar::EndRef;
use crate::bc::Quantity;
use crate::bem::end_indices;
use crate::continuation::ContinuationProblem;
use crate::forced::waves::{squared_wavenumber, DampedMap};
use crate::forced::ForcedSystem;
use crate::fourier::{Basis, SineCosineBasis};
use crate::system::rows::quantity_weights;
use num_complex::Complex64;

/// Gauss–Legendre points per panel of the energy quadrature.
const GAUSS_POINTS: usize = 8;

/// The largest `|k| l` of a harmonic the energy quadrature integrates (a million radians of
/// the wave, eight million points): beyond it the energy is reported as NaN, which makes the
/// point's status [`PointStatus::NonFiniteEnergy`](crate::branches::PointStatus), rather than
/// spending hours on it.
const MAX_QUADRATURE_PHASE: f64 = 1e6;

/// Times finer than the basis' grid on which [`ForcedSystem::contact_defect`] samples.
const DEFECT_REFINEMENT: usize = 4;

/// Nodes and weights of the `n`-point Gauss–Legendre rule on `[-1, 1]` (Newton on the
/// Legendre polynomial from the Chebyshev guesses).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut derivative = 1.0;
            for _ in 0..100 {
                // P_n(x) and P_n'(x) by the three-term recurrence.
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let k = k as f64;
                    (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
                }
                derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / derivative;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * derivative * derivative))
        })
        .collect()
}

/// `int_0^l f(x) dx` by composite Gauss–Legendre on `panels` panels.
fn integrate(l: f64, panels: usize, rule: &[(f64, f64)], f: impl Fn(f64) -> f64) -> f64 {
    let h = l / panels as f64;
    (0..panels)
        .map(|p| {
            let mid = (p as f64 + 0.5) * h;
            rule.iter()
                .map(|&(x, w)| 0.5 * h * w * f(mid + 0.5 * h * x))
                .sum::<f64>()
        })
        .sum()
}

impl ForcedSystem {
    /// The complex amplitudes `(A, B)` of bar `b` at harmonic `n` of `x`:
    /// `Z = X_c - i X_s` (the constant's half for `n = 0`, as the basis counts it).
    fn amplitudes(&self, x: &[f64], n: usize, b: usize) -> (Complex64, Complex64) {
        let (u, m) = (self.unknowns(), self.basis().harmonics());
        let at = |i: usize, j: usize| x[i * u + 2 * b + j];
        if n == 0 {
            return (
                Complex64::new(0.5 * at(0, 0), 0.0),
                Complex64::new(0.5 * at(0, 1), 0.0),
            );
        }
        (
            Complex64::new(at(n, 0), -at(m + n, 0)),
            Complex64::new(at(n, 1), -at(m + n, 1)),
        )
    }

    /// The bars' mechanical energy averaged over the period (kinetic plus strain, plus what
    /// the conditions store): `E = sum_b EA/2 int <u_t^2>/c^2 + <u_x^2> dx + <E_cond>`. For
    /// an undamped, unforced motion it is the backbone's constant energy.
    ///
    /// Harmonics are orthogonal in time: `<u_t^2> = sum_n (n Omega)^2 |U_n|^2 / 2` and
    /// `<u_x^2> = U_0'^2 + sum_n |U_n'|^2 / 2`, integrated in `x` by Gauss–Legendre on
    /// panels of at most one radian of the wave. NaN when a harmonic's `|k| l` exceeds a
    /// million radians (a frequency or a damping beyond any physical use).
    pub fn average_energy(&self, x: &[f64]) -> f64 {
        let omega = self.parameter();
        let rule = gauss_legendre(GAUSS_POINTS);
        let mut energy = 0.0;
        for (b, bar) in self.system().bars().iter().enumerate() {
            let (l, c, ea) = (bar.length(), bar.wave_speed(), bar.stiffness());
            for n in 0..=self.basis().harmonics() {
                let (a, bb) = self.amplitudes(x, n, b);
                let (kappa, _) = squared_wavenumber(bar, n, omega, self.damping()[b]);
                let phase = kappa.norm().sqrt() * l;
                if phase.is_nan() || phase > MAX_QUADRATURE_PHASE {
                    return f64::NAN;
                }
                let panels = phase.ceil() as usize + 1;
                let (time_mean, speed) = if n == 0 {
                    (1.0, 0.0)
                } else {
                    (0.5, n as f64 * omega / c)
                };
                let density = |s: f64| {
                    let (value, slope) = DampedMap::field(s, kappa, a, bb);
                    time_mean * (speed * speed * value.norm_sqr() + slope.norm_sqr())
                };
                energy += 0.5 * ea * integrate(l, panels, &rule, density);
            }
        }
        energy + self.stored_energy(x)
    }

    /// The energy the conditions store (springs), averaged over the basis' time grid.
    fn stored_energy(&self, x: &[f64]) -> f64 {
        let samples = self.basis().samples();
        let ends: Vec<EndRef> = self.system().conditions().flat_map(|c| c.ends()).collect();
        // u and p of every end, sampled.
        let signals: Vec<(Vec<f64>, Vec<f64>)> = ends
            .iter()
            .map(|&e| {
                let (u, p) = end_indices(e.end);
                (self.end_signal(x, e, u), self.end_signal(x, e, p))
            })
            .collect();
        let mut total = 0.0;
        for k in 0..samples {
            let value = |end: EndRef, q: Quantity| {
                let i = ends
                    .iter()
                    .position(|&e| e == end)
                    .expect("an end of a condition");
                let (u, p) = (signals[i].0[k], signals[i].1[k]);
                let stiffness = self.system().stiffness_at(end);
                // quantity = w_u u + w_p p (exact for every quantity).
                let (wu, wp) = quantity_weights(q, end.end, stiffness);
                wu * u + wp * p
            };
            total += self
                .system()
                .conditions()
                .map(|c| c.stored_energy(&value))
                .sum::<f64>();
        }
        total / samples as f64
    }

    /// The complex amplitude `Z_n` of the displacement at `end` at harmonic `n` of `x`:
    /// `u(end, t) = sum_n Re(Z_n e^{i n Omega t})` (the constant, `n = 0`, real).
    pub fn end_displacement(&self, x: &[f64], end: EndRef, n: usize) -> Complex64 {
        self.end_value(x, end, end_indices(end.end).0, n)
    }

    /// `Z_n` of the end value `index` of `end`'s bar (in the order of `bem::end_indices`).
    fn end_value(&self, x: &[f64], end: EndRef, index: usize, n: usize) -> Complex64 {
        let b = end.bar.index();
        let bar = self.system().bars()[b];
        let (kappa, _) = squared_wavenumber(&bar, n, self.parameter(), self.damping()[b]);
        let map = DampedMap::new(bar.length(), kappa);
        let (a, bb) = self.amplitudes(x, n, b);
        map.rows[index][0] * a + map.rows[index][1] * bb
    }

    /// Samples over one period of the end value `index` of `end`'s bar.
    fn end_signal(&self, x: &[f64], end: EndRef, index: usize) -> Vec<f64> {
        let m = self.basis().harmonics();
        let mut coefficients = vec![0.0; self.basis().len()];
        for n in 0..=m {
            let z = self.end_value(x, end, index, n);
            if n == 0 {
                // The basis' constant is c_0 / 2.
                coefficients[0] = 2.0 * z.re;
            } else {
                coefficients[n] = z.re;
                coefficients[m + n] = -z.im;
            }
        }
        let mut out = vec![0.0; self.basis().samples()];
        self.basis().synthesize(&coefficients, &mut out);
        out
    }

    /// The amplitude at the first unilateral law: the largest closure of its gap over the
    /// period, `max (g_0 - g(t))`, divided by the gap at rest `g_0` (1 when the end just
    /// reaches its obstacle; the closure itself when `g_0 = 0`).
    pub fn amplitude(&self, x: &[f64]) -> f64 {
        let g0 = self.offsets()[0].0;
        // A state of another size has no gap here: as a state that is not finite.
        let gaps = self.gap_history(x, 0).unwrap_or_default();
        let closure = (gaps.iter())
            .map(|g| g0 - g)
            .fold(f64::NEG_INFINITY, f64::max);
        if !closure.is_finite() {
            // A state whose gap is not finite anywhere (a failed solve's last iterate).
            f64::NAN
        } else if g0 == 0.0 {
            closure
        } else {
            closure / g0.abs()
        }
    }

    /// How far the truncated motion is from the contact laws between the samples: the
    /// largest law residual `|r(g, lambda)|` (`|min(lambda, a_c g)|` for Signorini) of every law on a grid four times finer than the
    /// basis', relative to `a_c` times the largest gap at rest. The linear rows hold exactly
    /// (each harmonic solves the damped wave equation and the conditions), so this is the
    /// whole residual of the continuous problem.
    ///
    /// Where the finer grid would exceed the memory budget (a basis already near it), the
    /// residual is sampled on the basis' own grid, which the laws hold at by construction:
    /// the defect then reads 0 up to the solve's tolerance, and says nothing between samples.
    pub fn contact_defect(&self, x: &[f64]) -> f64 {
        let m = self.basis().harmonics();
        let per_harmonic = self.basis().samples() / m;
        let refined = SineCosineBasis::new(m, per_harmonic.saturating_mul(DEFECT_REFINEMENT));
        let fine = refined.as_ref().unwrap_or(self.basis());
        let a_c = self.complementarity();
        let scale = a_c * self.offsets().iter().map(|o| o.0.abs()).fold(0.0, f64::max);
        let mut worst: f64 = 0.0;
        for (l, law) in self.system().laws().enumerate() {
            let (g0, f0) = self.offsets()[l];
            let (mut gap, mut force) = (vec![0.0; fine.samples()], vec![0.0; fine.samples()]);
            fine.synthesize(&self.observable(x, l, true, false), &mut gap);
            fine.synthesize(&self.observable(x, l, false, false), &mut force);
            for (g, f) in gap.iter().zip(&force) {
                worst = worst.max(law.residual(g + g0, f + f0, a_c).value.abs());
            }
        }
        if scale > 0.0 {
            worst / scale
        } else {
            worst
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_of_degree_2n_minus_1() {
        let rule = gauss_legendre(GAUSS_POINTS);
        let weights: f64 = rule.iter().map(|r| r.1).sum();
        assert!((weights - 2.0).abs() < 1e-14);
        let x15 = integrate(1.0, 1, &rule, |x| x.powi(15));
        assert!((x15 - 1.0 / 16.0).abs() < 1e-14, "{x15}");
        let sine = integrate(3.0, 4, &rule, f64::sin);
        assert!((sine - (1.0 - 3f64.cos())).abs() < 1e-13);
    }
}
