//! The linear multi-mode sloshing model (seed Eqs 2.1, 2.2): one damped oscillator per mode,
//! x_n'' + 2 zeta omega_n x_n' + omega_n^2 x_n = -a_b(t), advanced by its exact solution for a
//! base acceleration that is a polynomial of degree <= 2 over the step (held, or interpolated
//! from input derivatives): no integration error whatever the step.

use super::base::BaseAcceleration;

/// One mode as a damped oscillator with its exact propagator: for the free motion
/// x(s) = C(s) x0 + S(s) (v0 + sigma x0), with sigma = zeta omega, C = e^(-sigma s) cos(mu s),
/// S = e^(-sigma s) sin(mu s)/mu and mu^2 = omega^2 - sigma^2 (cosh/sinh when overdamped; the
/// limits when critically damped).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModalOscillator {
    pub omega: f64,
    pub zeta: f64,
    /// (h, zeta, C(h), S(h)) of the last step: communication steps are usually all alike, and
    /// the exponential and trigonometric functions would otherwise dominate a step's cost.
    free_cache: (f64, f64, f64, f64),
}

/// State of one mode and the energies it has exchanged (per unit modal mass).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ModeState {
    pub x: f64,
    pub v: f64,
    /// Work done on the mode by the base: integral of -a_b v.
    pub work_in: f64,
    /// Energy dissipated: integral of 2 zeta omega v^2.
    pub dissipated: f64,
}

/// (C(s), S(s)) of the free motion of x'' + 2 sigma x' + w2 x = 0 (see [`ModalOscillator`]):
/// x(s) = C x0 + S (v0 + sigma x0), v(s) = C v0 - S (w2 x0 + sigma v0).
pub fn free_motion(w2: f64, sigma: f64, s: f64) -> (f64, f64) {
    let m = FreeMotion::new(w2, sigma, s);
    (m.c, m.s)
}

/// (C(s) - 1, S(s)) of [`free_motion`], C - 1 formed without forming C: for short s it is
/// small, and a flow applied as y + (P - I) y rounds relative to the change, not to the state
/// (P rounded once and applied a million times would drift by a million roundings).
pub fn free_motion_change(w2: f64, sigma: f64, s: f64) -> (f64, f64) {
    let m = FreeMotion::new(w2, sigma, s);
    (m.c_minus_1, m.s)
}

/// C, C - 1 and S of the free motion, each from its own formula.
struct FreeMotion {
    c: f64,
    c_minus_1: f64,
    s: f64,
}

impl FreeMotion {
    fn new(w2: f64, sigma: f64, s: f64) -> Self {
        let mu2 = w2 - sigma * sigma;
        let z = mu2 * s * s;
        if mu2 < 0.0 && z.abs() >= 1e-6 {
            // Overdamped: two real decay rates, a = sigma - k (as w2 / (sigma + k), no
            // cancellation) and b = sigma + k; C = (e^(-a s) + e^(-b s))/2. Written with the
            // rates rather than e^(-sigma s) cosh(k s), which overflows against underflow.
            let k = (-mu2).sqrt();
            let (a, b) = (w2 / (sigma + k), sigma + k);
            let (ea, eb) = ((-a * s).exp(), (-b * s).exp());
            let sinc = if k * s < 1.0 {
                // sinh(k s)/k: no cancellation between two nearly equal exponentials
                (-sigma * s).exp() * (k * s).sinh() / k
            } else {
                (ea - eb) / (2.0 * k)
            };
            return FreeMotion {
                c: 0.5 * (ea + eb),
                c_minus_1: 0.5 * ((-a * s).exp_m1() + (-b * s).exp_m1()),
                s: sinc,
            };
        }
        // c = cos(mu s), its change c - 1 by the half angle, sinc = sin(mu s)/mu; near
        // critical damping their series in mu^2 s^2 (either sign of mu^2).
        let (c, c_minus_1, sinc) = if z.abs() < 1e-6 {
            (
                1.0 - z / 2.0 + z * z / 24.0,
                z * (z / 24.0 - 0.5),
                s * (1.0 - z / 6.0 + z * z / 120.0),
            )
        } else {
            let mu = mu2.sqrt();
            let half = (0.5 * mu * s).sin();
            ((mu * s).cos(), -2.0 * half * half, (mu * s).sin() / mu)
        };
        let decay = (-sigma * s).exp();
        FreeMotion {
            c: decay * c,
            // e^(-sigma s) c - 1 = (e^(-sigma s) - 1) c + (c - 1)
            c_minus_1: (-sigma * s).exp_m1() * c + c_minus_1,
            s: decay * sinc,
        }
    }
}

impl ModalOscillator {
    pub fn new(omega: f64, zeta: f64) -> Self {
        ModalOscillator {
            omega,
            zeta,
            free_cache: (f64::NAN, f64::NAN, 0.0, 0.0),
        }
    }

    /// (C(h), S(h)), from the cache when h and zeta are those of the last call.
    fn free_cached(&mut self, h: f64) -> (f64, f64) {
        let (hc, zc, c, s) = self.free_cache;
        if hc == h && zc == self.zeta {
            return (c, s);
        }
        let (c, s) = self.free(h);
        self.free_cache = (h, self.zeta, c, s);
        (c, s)
    }

    fn sigma(&self) -> f64 {
        self.zeta * self.omega
    }

    /// (C(s), S(s)) of the free motion.
    fn free(&self, s: f64) -> (f64, f64) {
        free_motion(self.omega * self.omega, self.sigma(), s)
    }

    /// The particular solution x_p(s) = p0 + p1 s + p2 s^2 for a_b = a0 + a1 s + a2 s^2/2.
    /// `inv_w2` = 1 / omega^2 (multiplications, not a chain of three divisions, in front of the
    /// state update).
    fn particular(&self, a: &[f64; 3], inv_w2: f64) -> [f64; 3] {
        let c = 2.0 * self.sigma();
        let p2 = -0.5 * a[2] * inv_w2;
        let p1 = (-a[1] - 2.0 * c * p2) * inv_w2;
        let p0 = (-a[0] - 2.0 * p2 - c * p1) * inv_w2;
        [p0, p1, p2]
    }

    /// Advance `state` exactly by `h` under the base acceleration `base` (polynomial about the
    /// step's start).
    pub fn advance(&mut self, state: &mut ModeState, h: f64, base: &BaseAcceleration) {
        let a = &base.a;
        let w2 = self.omega * self.omega;
        let inv_w2 = 1.0 / w2;
        let p = self.particular(a, inv_w2);
        let sigma = self.sigma();
        // Free part: what is left of the initial state after the particular solution.
        let (x0h, v0h) = (state.x - p[0], state.v - p[1]);
        let (c, s) = self.free_cached(h);
        let xh = c * x0h + s * (v0h + sigma * x0h);
        let vh = c * v0h - s * (w2 * x0h + sigma * v0h);
        let x1 = xh + p[0] + h * (p[1] + h * p[2]);
        let v1 = vh + p[1] + 2.0 * h * p[2];
        // Work input -integral a v ds, by parts: -[a x] + integral a' x ds with a' = a1 + a2 s.
        // The free part's moments follow from its own equation (x'' + 2 sigma x' + w^2 x = 0):
        //   w^2 int x = -(dv + 2 sigma dx),  w^2 int s x = -(h v(h) - dx) - 2 sigma (h x(h) - int x).
        let (dxh, dvh) = (xh - x0h, vh - v0h);
        let int_xh = -(dvh + 2.0 * sigma * dxh) * inv_w2;
        let int_sxh = (-(h * vh - dxh) - 2.0 * sigma * (h * xh - int_xh)) * inv_w2;
        let (h2, h3, h4) = (h * h, h * h * h, h * h * h * h);
        const THIRD: f64 = 1.0 / 3.0;
        let int_xp = p[0] * h + p[1] * h2 * 0.5 + p[2] * h3 * THIRD;
        let int_sxp = p[0] * h2 * 0.5 + p[1] * h3 * THIRD + p[2] * h4 * 0.25;
        let a_end = base.at(base.t0 + h);
        let work =
            -(a_end * x1 - a[0] * state.x) + a[1] * (int_xh + int_xp) + a[2] * (int_sxh + int_sxp);
        // Dissipation from the balance, exact with an exact propagator.
        let stored = |x: f64, v: f64| 0.5 * (v * v + w2 * x * x);
        let dissipated = work - (stored(x1, v1) - stored(state.x, state.v));
        state.x = x1;
        state.v = v1;
        state.work_in += work;
        state.dissipated += dissipated;
    }

    /// Kinetic plus potential energy per unit modal mass.
    pub fn stored_energy(&self, state: &ModeState) -> f64 {
        0.5 * (state.v * state.v + self.omega * self.omega * state.x * state.x)
    }

    /// Force on the tank per unit modal mass.
    pub fn tank_force(&self, state: &ModeState) -> f64 {
        2.0 * self.sigma() * state.v + self.omega * self.omega * state.x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn held(a: f64) -> BaseAcceleration {
        BaseAcceleration::held(a)
    }

    /// Free decay against the textbook closed form, over many steps of any size.
    #[test]
    fn free_decay_is_exact() {
        let mut m = ModalOscillator::new(5.6389, 0.02);
        let wd = m.omega * (1.0 - m.zeta * m.zeta).sqrt();
        for h in [1e-4, 0.01, 0.3, 2.0] {
            let mut s = ModeState {
                x: 0.01,
                ..Default::default()
            };
            let n = (10.0 / h) as usize;
            for _ in 0..n {
                m.advance(&mut s, h, &held(0.0));
            }
            let t = n as f64 * h;
            let exact = 0.01
                * (-m.zeta * m.omega * t).exp()
                * ((wd * t).cos() + m.zeta * m.omega / wd * (wd * t).sin());
            assert!((s.x - exact).abs() < 1e-13, "h {h}: {} vs {exact}", s.x);
        }
    }

    /// Over- and critically damped modes: against a fine RK4 integration.
    #[test]
    fn overdamped_and_critical_modes() {
        for zeta in [1.0, 1.0 + 1e-9, 2.5] {
            let mut m = ModalOscillator::new(3.0, zeta);
            let mut s = ModeState {
                x: 0.02,
                v: -0.1,
                ..Default::default()
            };
            m.advance(&mut s, 1.3, &held(0.5));
            let (mut x, mut v, h) = (0.02f64, -0.1f64, 1e-4);
            let f = |x: f64, v: f64| -0.5 - 2.0 * zeta * 3.0 * v - 9.0 * x;
            for _ in 0..13000 {
                let (k1x, k1v) = (v, f(x, v));
                let (k2x, k2v) = (v + 0.5 * h * k1v, f(x + 0.5 * h * k1x, v + 0.5 * h * k1v));
                let (k3x, k3v) = (v + 0.5 * h * k2v, f(x + 0.5 * h * k2x, v + 0.5 * h * k2v));
                let (k4x, k4v) = (v + h * k3v, f(x + h * k3x, v + h * k3v));
                x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
                v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            }
            assert!(
                (s.x - x).abs() < 1e-12 && (s.v - v).abs() < 1e-12,
                "zeta {zeta}: {} {}",
                s.x - x,
                s.v - v
            );
        }
    }

    /// Heavily overdamped free decay over long steps (sigma s up to 420, where e^(-sigma s)
    /// cosh(k s) would be 0 times infinity): against the closed form's slow mode
    /// x = x0 (b e^(-a t) - a e^(-b t)) / (b - a) from rest, relative to the true (small) x.
    #[test]
    fn overdamped_free_decay_over_long_steps() {
        let (omega, zeta) = (5.6f64, 5.0);
        let sigma = zeta * omega;
        let k = (sigma * sigma - omega * omega).sqrt();
        let (a, b) = (omega * omega / (sigma + k), sigma + k);
        for h in [1.0, 3.0, 15.0] {
            let mut m = ModalOscillator::new(omega, zeta);
            let mut s = ModeState {
                x: 0.01,
                ..Default::default()
            };
            m.advance(&mut s, h, &held(0.0));
            let exact = 0.01 * (b * (-a * h).exp() - a * (-b * h).exp()) / (b - a);
            let exact_v = 0.01 * a * b * ((-b * h).exp() - (-a * h).exp()) / (b - a);
            assert!(
                (s.x / exact - 1.0).abs() < 1e-12,
                "h {h}: {} vs {exact}",
                s.x
            );
            assert!(
                (s.v / exact_v - 1.0).abs() < 1e-12,
                "h {h}: {} vs {exact_v}",
                s.v
            );
        }
    }

    /// Quadratic input over one long step: against many fine RK4 steps of the same input, and
    /// the energy exchanged against its quadrature.
    #[test]
    fn polynomial_input_and_energies() {
        let mut m = ModalOscillator::new(4.0, 0.05);
        let base = BaseAcceleration {
            t0: 0.0,
            a: [0.3, -0.8, 1.1],
        };
        let mut s = ModeState {
            x: 0.01,
            v: 0.02,
            ..Default::default()
        };
        m.advance(&mut s, 0.7, &base);
        let (mut x, mut v, mut work, mut diss, h) = (0.01f64, 0.02f64, 0.0, 0.0, 1e-5);
        let c = 2.0 * 0.05 * 4.0;
        let f = |t: f64, x: f64, v: f64| {
            [
                v,
                -base.at(t) - c * v - 16.0 * x,
                -base.at(t) * v,
                c * v * v,
            ]
        };
        for k in 0..70000 {
            let t = k as f64 * h;
            let y = [x, v, work, diss];
            let add = |y: &[f64; 4], k: &[f64; 4], s: f64| {
                std::array::from_fn::<f64, 4, _>(|i| y[i] + s * k[i])
            };
            let k1 = f(t, y[0], y[1]);
            let y2 = add(&y, &k1, 0.5 * h);
            let k2 = f(t + 0.5 * h, y2[0], y2[1]);
            let y3 = add(&y, &k2, 0.5 * h);
            let k3 = f(t + 0.5 * h, y3[0], y3[1]);
            let y4 = add(&y, &k3, h);
            let k4 = f(t + h, y4[0], y4[1]);
            let n: [f64; 4] = std::array::from_fn(|i| {
                y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
            (x, v, work, diss) = (n[0], n[1], n[2], n[3]);
        }
        assert!((s.x - x).abs() < 1e-12, "{} {x}", s.x);
        assert!((s.v - v).abs() < 1e-12);
        assert!((s.work_in - work).abs() < 1e-12, "{} {work}", s.work_in);
        assert!(
            (s.dissipated - diss).abs() < 1e-12,
            "{} {diss}",
            s.dissipated
        );
    }

    /// Guards `tank_force`: what the mode pushes on the tank is what its own equation says,
    /// F = -a_b - x''. Over a short step the momentum balance int F ds = -(v(h) - v(0)) - int a
    /// is checked with Simpson's rule on F at 0, h/2, h (states from the exact propagator):
    /// its error, h^5 max|F^(4)| / 2880 ~ (omega h)^4 |F| h / 2880 ~ 1e-9 |F| h here, is far
    /// below the 1e-7 h allowed; a wrong damping or stiffness term is off by ~1e-2 h.
    /// Also the value by hand at one state.
    #[test]
    fn tank_force_is_the_modes_momentum_balance() {
        let m = ModalOscillator::new(4.0, 0.05);
        let st = ModeState {
            x: 0.01,
            v: 0.2,
            ..Default::default()
        };
        // 2 zeta omega v + omega^2 x = 0.4 * 0.2 + 16 * 0.01.
        assert!((m.tank_force(&st) - 0.24).abs() < 1e-15);
        let base = BaseAcceleration {
            t0: 0.0,
            a: [0.3, -0.8, 1.1],
        };
        let h = 0.01;
        let (mut mid, mut end) = (st, st);
        ModalOscillator::new(4.0, 0.05).advance(&mut mid, 0.5 * h, &base);
        ModalOscillator::new(4.0, 0.05).advance(&mut end, h, &base);
        let simpson = h / 6.0 * (m.tank_force(&st) + 4.0 * m.tank_force(&mid) + m.tank_force(&end));
        let balance = -(end.v - st.v) - base.integral(h);
        assert!(
            (simpson - balance).abs() < 1e-7 * h,
            "{simpson} vs {balance}"
        );
    }

    /// Guards `stored_energy`: its change over steps is the work input less the dissipation,
    /// both of which `polynomial_input_and_energies` checks against quadrature; and by hand.
    #[test]
    fn stored_energy_balances_the_exchanged_energies() {
        let mut m = ModalOscillator::new(4.0, 0.05);
        let start = ModeState {
            x: 0.01,
            v: 0.2,
            ..Default::default()
        };
        // (0.2^2 + 16 * 0.01^2) / 2
        assert!((m.stored_energy(&start) - 0.0208).abs() < 1e-15);
        let base = BaseAcceleration {
            t0: 0.0,
            a: [0.3, -0.8, 1.1],
        };
        let mut st = start;
        for _ in 0..7 {
            m.advance(&mut st, 0.1, &base);
        }
        let change = m.stored_energy(&st) - m.stored_energy(&start);
        assert!(
            (change - (st.work_in - st.dissipated)).abs() < 1e-15,
            "{change} vs {}",
            st.work_in - st.dissipated
        );
        assert!(change.abs() > 1e-3, "the test must move energy: {change}");
    }
}
