//! The design excitations of tld-design (docs/DESIGN.md) on one structural mode carrying a
//! linear tuned mass (the TLD's fundamental sloshing mode as its mechanical equivalent):
//! Warburton's optimum tuning for each, the stationary response to a white-noise force (the
//! Lyapunov equation, exact) and the response to a ground-motion record (RK4).
//!
//! The mode: modal mass M (mode shape 1 at the damper's floor), frequency omega, damping zeta;
//! the sloshing mass m = mu M at gamma omega with damping zeta_d, its displacement x_d relative
//! to the floor. With F the modal force and a_g the ground acceleration (L the participation
//! factor, phi^T M 1):
//!
//! ```text
//! M x'' + 2 zeta omega M x' + omega^2 M x = F - L a_g + m (2 zeta_d omega_d x_d' + omega_d^2 x_d)
//! x_d'' + 2 zeta_d omega_d x_d' + omega_d^2 x_d = -(x'' + a_g)
//! ```
//!
//! Warburton (1982, "Optimum absorber parameters for various combinations of response and
//! excitation parameters", Earthquake Eng. Struct. Dyn. 10:381-401, Table I; undamped
//! structure), the optimum frequency ratio gamma and damping zeta_d for the structure's
//! displacement:
//! - harmonic force: gamma = 1/(1 + mu), zeta_d = sqrt(3 mu / (8 (1 + mu))) (Den Hartog);
//! - white-noise force: gamma = sqrt(1 + mu/2)/(1 + mu),
//!   zeta_d = sqrt(mu (1 + 3 mu/4) / (4 (1 + mu)(1 + mu/2)));
//! - harmonic ground acceleration: gamma = sqrt(1 - mu/2)/(1 + mu),
//!   zeta_d = sqrt(3 mu / (8 (1 + mu)(1 - mu/2))).
//!
//! The tests check each against this module's own response computations (the white-noise pair
//! minimises the Lyapunov variance, the ground pair's gamma minimises the resonant peak).

use nalgebra::{DMatrix, DVector, Matrix4, Vector4};
use std::f64::consts::PI;

/// Which optimum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Optimum {
    HarmonicForce,
    WhiteNoiseForce,
    HarmonicGround,
}

/// Warburton's (gamma, zeta_d) for mass ratio `mu` (module docs).
pub fn warburton(kind: Optimum, mu: f64) -> (f64, f64) {
    match kind {
        Optimum::HarmonicForce => (1.0 / (1.0 + mu), (3.0 * mu / (8.0 * (1.0 + mu))).sqrt()),
        Optimum::WhiteNoiseForce => (
            (1.0 + mu / 2.0).sqrt() / (1.0 + mu),
            (mu * (1.0 + 0.75 * mu) / (4.0 * (1.0 + mu) * (1.0 + mu / 2.0))).sqrt(),
        ),
        Optimum::HarmonicGround => (
            (1.0 - mu / 2.0).sqrt() / (1.0 + mu),
            (3.0 * mu / (8.0 * (1.0 + mu) * (1.0 - mu / 2.0))).sqrt(),
        ),
    }
}

/// A mode with a tuned mass (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwoDof {
    /// Modal mass [kg], circular frequency [rad/s], damping ratio.
    pub mass: f64,
    pub omega: f64,
    pub zeta: f64,
    /// Mass ratio, frequency ratio and damping ratio of the tuned mass.
    pub mu: f64,
    pub gamma: f64,
    pub zeta_d: f64,
}

impl TwoDof {
    /// z' = A z + b_f F + b_g a_g, z = [x, x_d, x', x_d'].
    fn system(&self) -> (Matrix4<f64>, Vector4<f64>, Vector4<f64>, f64) {
        let (w, wd) = (self.omega, self.gamma * self.omega);
        let (c, cd) = (2.0 * self.zeta * w, 2.0 * self.zeta_d * wd);
        // x'' row (per unit modal mass), then x_d'' = -x'' - a_g - cd x_d' - wd^2 x_d.
        let r = [-w * w, self.mu * wd * wd, -c, self.mu * cd];
        let mut a = Matrix4::zeros();
        a[(0, 2)] = 1.0;
        a[(1, 3)] = 1.0;
        for j in 0..4 {
            a[(2, j)] = r[j];
            a[(3, j)] = -r[j];
        }
        a[(3, 1)] -= wd * wd;
        a[(3, 3)] -= cd;
        let b_f = Vector4::new(0.0, 0.0, 1.0 / self.mass, -1.0 / self.mass);
        (a, b_f, Vector4::new(0.0, 0.0, 0.0, -1.0), c)
    }

    /// The standard deviations of x and x_d under a white-noise modal force of two-sided
    /// spectral density `s0` [N^2 s/rad] (E[F(t) F(t+s)] = 2 pi s0 delta(s)): the stationary
    /// covariance P from A P + P A^T + 2 pi s0 b b^T = 0, solved as a 16 x 16 linear system.
    pub fn white_noise_rms(&self, s0: f64) -> Result<(f64, f64), String> {
        let (a, b, _, _) = self.system();
        let q = b * b.transpose() * (2.0 * PI * s0);
        let eye = Matrix4::<f64>::identity();
        let kron = |x: &Matrix4<f64>, y: &Matrix4<f64>| {
            DMatrix::from_fn(16, 16, |i, j| x[(i / 4, j / 4)] * y[(i % 4, j % 4)])
        };
        // vec(A P + P A^T) = (I (x) A + A (x) I) vec(P), column-major vec.
        let lhs = kron(&eye, &a) + kron(&a, &eye);
        let rhs = DVector::from_iterator(16, q.iter().map(|v| -v));
        let p = lhs
            .lu()
            .solve(&rhs)
            .ok_or("the structure with the damper is not stable (no stationary response)")?;
        Ok((p[0].max(0.0).sqrt(), p[5].max(0.0).sqrt()))
    }

    /// The peaks of |x| and |x_d| under the ground acceleration `a_g` sampled every `h` s
    /// (linear in between), the modal force -`participation` a_g, from rest (RK4, at least 40
    /// substeps per period of the faster mode).
    pub fn record_peaks(&self, participation: f64, h: f64, a_g: &[f64]) -> (f64, f64) {
        let (a, _, b_g, _) = self.system();
        let b = Vector4::new(0.0, 0.0, -participation / self.mass, 0.0) + b_g;
        let fastest = self.omega.max(self.gamma * self.omega) * (1.0 + self.mu).sqrt() * 1.2;
        let n = ((h * fastest / (2.0 * PI) * 40.0).ceil() as usize).max(1);
        let dt = h / n as f64;
        let f = |z: &Vector4<f64>, g: f64| a * z + b * g;
        let (mut z, mut peaks) = (Vector4::zeros(), (0.0f64, 0.0f64));
        for w in a_g.windows(2) {
            for k in 0..n {
                let g = |s: f64| w[0] + (w[1] - w[0]) * (k as f64 + s) / n as f64;
                let k1 = f(&z, g(0.0));
                let k2 = f(&(z + k1 * (0.5 * dt)), g(0.5));
                let k3 = f(&(z + k2 * (0.5 * dt)), g(0.5));
                let k4 = f(&(z + k3 * dt), g(1.0));
                z += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0);
                peaks = (peaks.0.max(z[0].abs()), peaks.1.max(z[1].abs()));
            }
        }
        peaks
    }

    /// |x| per unit amplitude of a harmonic ground acceleration of circular frequency `w`.
    pub fn ground_transfer(&self, participation: f64, w: f64) -> f64 {
        let (a, _, b_g, _) = self.system();
        let b = Vector4::new(0.0, 0.0, -participation / self.mass, 0.0) + b_g;
        // (i w I - A) Z = b, complex, as a real 8 x 8 system.
        let m = DMatrix::from_fn(8, 8, |i, j| {
            let (bi, bj) = (i / 4, j / 4);
            let (r, c) = (i % 4, j % 4);
            match (bi, bj) {
                (0, 0) | (1, 1) => -a[(r, c)],
                (0, 1) => {
                    if r == c {
                        -w
                    } else {
                        0.0
                    }
                }
                _ => {
                    if r == c {
                        w
                    } else {
                        0.0
                    }
                }
            }
        });
        let rhs = DVector::from_fn(8, |i, _| if i < 4 { b[i] } else { 0.0 });
        match m.lu().solve(&rhs) {
            Some(z) => z[0].hypot(z[4]),
            None => f64::INFINITY,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mode(mu: f64, zeta: f64) -> TwoDof {
        TwoDof {
            mass: 2.0e6,
            omega: 1.5,
            zeta,
            mu,
            gamma: 1.0,
            zeta_d: 0.05,
        }
    }

    /// Without the tuned mass the variance is the single oscillator's closed form
    /// sigma_x^2 = pi s0 / (K C).
    #[test]
    fn white_noise_variance_of_one_mode() {
        let s = mode(0.0, 0.02);
        let s0 = 3.0e7;
        let (sx, _) = s.white_noise_rms(s0).expect("stable");
        let k = s.mass * s.omega * s.omega;
        let c = 2.0 * s.zeta * s.mass * s.omega;
        let want = (PI * s0 / (k * c)).sqrt();
        assert!((sx / want - 1.0).abs() < 1e-10, "{sx} vs {want}");
    }

    /// Warburton's white-noise pair minimises the undamped structure's variance: 2 % off in
    /// gamma or 10 % off in zeta_d is worse.
    #[test]
    fn white_noise_optimum_is_a_minimum() {
        for mu in [0.01, 0.03, 0.08] {
            let (g, z) = warburton(Optimum::WhiteNoiseForce, mu);
            let at = |g: f64, z: f64| {
                TwoDof {
                    gamma: g,
                    zeta_d: z,
                    ..mode(mu, 0.0)
                }
                .white_noise_rms(1.0)
                .expect("stable")
                .0
            };
            let best = at(g, z);
            for (dg, dz) in [(1.02, 1.0), (0.98, 1.0), (1.0, 1.1), (1.0, 0.9)] {
                assert!(at(g * dg, z * dz) > best, "mu {mu}: {dg} {dz}");
            }
        }
    }

    /// Warburton's ground-acceleration tuning minimises the resonant peak of the relative
    /// displacement (participation M: a one-storey building): 3 % off in gamma raises the peak,
    /// and the harmonic-force tuning 1/(1 + mu) is worse for ground motion.
    #[test]
    fn ground_optimum_minimises_the_peak() {
        let mu = 0.03;
        let (g, z) = warburton(Optimum::HarmonicGround, mu);
        let peak = |g: f64| {
            let s = TwoDof {
                gamma: g,
                zeta_d: z,
                ..mode(mu, 0.0)
            };
            (0..3000)
                .map(|k| s.ground_transfer(s.mass, s.omega * (0.7 + 0.6 * k as f64 / 3000.0)))
                .fold(0.0, f64::max)
        };
        let best = peak(g);
        assert!(peak(1.03 * g) > best && peak(0.97 * g) > best);
        assert!(peak(warburton(Optimum::HarmonicForce, mu).0) > best);
    }

    /// Under a long resonant sine of ground acceleration the single mode's peak reaches the
    /// steady amplitude (L/M) / (2 zeta omega^2) from below (RK4 against the closed form), and
    /// the frequency-domain transfer agrees.
    #[test]
    fn record_peak_of_one_mode() {
        let s = mode(0.0, 0.05);
        let h = 0.02;
        let a_g: Vec<f64> = (0..30000).map(|k| (s.omega * h * k as f64).sin()).collect();
        let l = 0.8 * s.mass;
        let (peak, _) = s.record_peaks(l, h, &a_g);
        let want = 0.8 / (2.0 * s.zeta * s.omega * s.omega);
        assert!((peak / want - 1.0).abs() < 1e-3, "{peak} vs {want}");
        assert!((s.ground_transfer(l, s.omega) / want - 1.0).abs() < 1e-9);
    }

    /// The random factor by quadrature: E|u|^3/E[u^2] for a unit Gaussian (Simpson on
    /// [-12, 12]) over the same for a unit sinusoid (the mean of |cos|^3 over the mean of
    /// cos^2, Simpson over a period), and its closed form 3 sqrt(pi/8).
    #[test]
    fn random_screens_factor_by_quadrature() {
        use crate::physics::screens::RANDOM_SCREENS;
        let simpson = |f: &dyn Fn(f64) -> f64, a: f64, b: f64| {
            let n = 20000;
            let h = (b - a) / n as f64;
            (0..=n)
                .map(|k| {
                    let w = if k == 0 || k == n {
                        1.0
                    } else if k % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    };
                    w * f(a + h * k as f64)
                })
                .sum::<f64>()
                * h
                / 3.0
        };
        let pdf = |u: f64| (-0.5 * u * u).exp() / (2.0 * PI).sqrt();
        let gauss = simpson(&|u| u.abs().powi(3) * pdf(u), -12.0, 12.0)
            / simpson(&|u| u * u * pdf(u), -12.0, 12.0);
        let sine = simpson(&|t: f64| t.cos().abs().powi(3), 0.0, 2.0 * PI)
            / simpson(&|t: f64| t.cos().powi(2), 0.0, 2.0 * PI);
        assert!(
            (gauss / sine / RANDOM_SCREENS - 1.0).abs() < 1e-9,
            "{}",
            gauss / sine
        );
        assert!((3.0 * (PI / 8.0).sqrt() / RANDOM_SCREENS - 1.0).abs() < 1e-15);
    }
}
