//! The plain-Rust baseline: Eq 2.11 with the power law of Eq 2.13 and constant damping, no FMI
//! layer, stepped per communication step with the base acceleration held. Written for the
//! benchmark from MODEL.md, sharing no code with the FMU: what a careful hand-written C FMU
//! would do inside its doStep.
//!
//!   x'' + 2 zeta w_f x' + Phi(x) = -a_b,   Phi(x) = w_f^2 x [1 + phi |2x/a|^(2 eta - 2)]

#[path = "dp45_tableau.rs"]
mod dp45_tableau;
use dp45_tableau::*;

/// Model constants (per unit sloshing mass, except `m`).
#[derive(Clone, Copy, Debug)]
pub struct Model {
    /// w_f^2
    pub w2: f64,
    /// c = 2 zeta w_f
    pub c: f64,
    /// phi (2/a)^(2 eta - 2): Phi = w2 x (1 + q |x|^p)
    pub q: f64,
    /// p = 2 eta - 2 as an integer when it is one (powi), else as a real (powf)
    pub p_int: Option<i32>,
    pub p: f64,
    /// sloshing mass (force = m (c v + Phi(x)))
    pub m: f64,
    /// error scales of the adaptive method: a/2 and w_f a/2
    pub scale: [f64; 2],
}

impl Model {
    pub fn new(omega: f64, zeta: f64, eta: f64, phi: f64, a: f64, m: f64) -> Self {
        let p = 2.0 * eta - 2.0;
        let p_int = if p.fract() == 0.0 && p.abs() <= 64.0 {
            Some(p as i32)
        } else {
            None
        };
        Model {
            w2: omega * omega,
            c: 2.0 * zeta * omega,
            q: phi * (2.0 / a).powf(p),
            p_int,
            p,
            m,
            scale: [0.5 * a, 0.5 * a * omega],
        }
    }

    #[inline(always)]
    pub fn phi(&self, x: f64) -> f64 {
        let ax = x.abs();
        let h = match self.p_int {
            Some(0) => 1.0,
            Some(n) => ax.powi(n),
            None => ax.powf(self.p),
        };
        self.w2 * x * (1.0 + self.q * h)
    }

    #[inline(always)]
    pub fn accel(&self, x: f64, v: f64, ab: f64) -> f64 {
        -ab - self.c * v - self.phi(x)
    }

    #[inline(always)]
    pub fn force(&self, x: f64, v: f64) -> f64 {
        self.m * (self.c * v + self.phi(x))
    }
}

/// Classical RK4, `sub` equal substeps per communication step.
#[derive(Clone, Copy, Debug)]
pub struct Rk4 {
    pub sub: u32,
}

impl Rk4 {
    #[inline]
    pub fn step(&self, m: &Model, ab: f64, y: &mut [f64; 2], dt: f64) -> Result<(), String> {
        let h = dt / self.sub as f64;
        let (mut x, mut v) = (y[0], y[1]);
        for _ in 0..self.sub {
            let k1x = v;
            let k1v = m.accel(x, v, ab);
            let (x2, v2) = (x + 0.5 * h * k1x, v + 0.5 * h * k1v);
            let k2x = v2;
            let k2v = m.accel(x2, v2, ab);
            let (x3, v3) = (x + 0.5 * h * k2x, v + 0.5 * h * k2v);
            let k3x = v3;
            let k3v = m.accel(x3, v3, ab);
            let (x4, v4) = (x + h * k3x, v + h * k3v);
            let k4x = v4;
            let k4v = m.accel(x4, v4, ab);
            x += h / 6.0 * (k1x + 2.0 * (k2x + k3x) + k4x);
            v += h / 6.0 * (k1v + 2.0 * (k2v + k3v) + k4v);
        }
        if !(x.is_finite() && v.is_finite()) || x.abs() > 1e3 {
            return Err(format!("RK4 diverged (x = {x:e})"));
        }
        y[0] = x;
        y[1] = v;
        Ok(())
    }
}

/// Dormand-Prince 5(4) with error control per internal step; the step size is carried from
/// one communication step to the next.
#[derive(Clone, Copy, Debug)]
pub struct Dp45 {
    pub rtol: f64,
    pub h: f64,
    pub max_steps: u32,
}

impl Dp45 {
    pub fn new(rtol: f64) -> Self {
        Dp45 {
            rtol,
            h: 0.0,
            max_steps: 100_000,
        }
    }

    #[inline]
    pub fn step(&mut self, m: &Model, ab: f64, y: &mut [f64; 2], dt: f64) -> Result<(), String> {
        let f = |x: f64, v: f64| -> (f64, f64) { (v, m.accel(x, v, ab)) };
        let (mut x, mut v) = (y[0], y[1]);
        let mut h = if self.h > 0.0 {
            self.h
        } else {
            // first step: a fifth-root-of-tolerance fraction of the natural period
            (0.5 * self.rtol.powf(0.2) / m.w2.sqrt()).min(dt)
        };
        let mut t = 0.0;
        let mut k1 = f(x, v);
        let mut rejected = false;
        let mut steps = 0u32;
        loop {
            steps += 1;
            if steps > self.max_steps {
                return Err("DP45: too many steps".into());
            }
            let rem = dt - t;
            let last = h >= rem;
            let hs = if last { rem } else { h };
            let k2 = f(x + hs * A21 * k1.0, v + hs * A21 * k1.1);
            let k3 = f(
                x + hs * (A31 * k1.0 + A32 * k2.0),
                v + hs * (A31 * k1.1 + A32 * k2.1),
            );
            let k4 = f(
                x + hs * (A41 * k1.0 + A42 * k2.0 + A43 * k3.0),
                v + hs * (A41 * k1.1 + A42 * k2.1 + A43 * k3.1),
            );
            let k5 = f(
                x + hs * (A51 * k1.0 + A52 * k2.0 + A53 * k3.0 + A54 * k4.0),
                v + hs * (A51 * k1.1 + A52 * k2.1 + A53 * k3.1 + A54 * k4.1),
            );
            let k6 = f(
                x + hs * (A61 * k1.0 + A62 * k2.0 + A63 * k3.0 + A64 * k4.0 + A65 * k5.0),
                v + hs * (A61 * k1.1 + A62 * k2.1 + A63 * k3.1 + A64 * k4.1 + A65 * k5.1),
            );
            let xn = x + hs * (B1 * k1.0 + B3 * k3.0 + B4 * k4.0 + B5 * k5.0 + B6 * k6.0);
            let vn = v + hs * (B1 * k1.1 + B3 * k3.1 + B4 * k4.1 + B5 * k5.1 + B6 * k6.1);
            let k7 = f(xn, vn);
            let ex = hs * (E1 * k1.0 + E3 * k3.0 + E4 * k4.0 + E5 * k5.0 + E6 * k6.0 + E7 * k7.0);
            let ev = hs * (E1 * k1.1 + E3 * k3.1 + E4 * k4.1 + E5 * k5.1 + E6 * k6.1 + E7 * k7.1);
            let sx = self.rtol * (m.scale[0] + x.abs().max(xn.abs()));
            let sv = self.rtol * (m.scale[1] + v.abs().max(vn.abs()));
            let err = (0.5 * ((ex / sx).powi(2) + (ev / sv).powi(2))).sqrt();
            if err <= 1.0 {
                let mut fac = if err == 0.0 {
                    5.0
                } else {
                    (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
                };
                if rejected {
                    fac = fac.min(1.0);
                }
                rejected = false;
                x = xn;
                v = vn;
                k1 = k7;
                let proposal = hs * fac;
                if last {
                    // a step shortened to land on the communication point does not set the pace
                    self.h = if hs < h { h.max(proposal) } else { proposal };
                    break;
                }
                t += hs;
                h = proposal;
            } else {
                rejected = true;
                h = hs
                    * if err.is_finite() {
                        (0.9 * err.powf(-0.2)).clamp(0.2, 1.0)
                    } else {
                        0.25
                    };
                if h < 1e-14 * dt {
                    return Err("DP45: step size underflow".into());
                }
            }
        }
        if !(x.is_finite() && v.is_finite()) || x.abs() > 1e3 {
            return Err(format!("DP45 diverged (x = {x:e})"));
        }
        y[0] = x;
        y[1] = v;
        Ok(())
    }
}
