//! Dormand-Prince 5(4): explicit embedded Runge-Kutta pair with local error control
//! (Hairer, Norsett & Wanner, Solving ODEs I, section II.4 and II.5).

use super::{Rhs, SolveError, SolveStats, all_finite};

// Butcher tableau.
const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const B1: f64 = 35.0 / 384.0;
const B3: f64 = 500.0 / 1113.0;
const B4: f64 = 125.0 / 192.0;
const B5: f64 = -2187.0 / 6784.0;
const B6: f64 = 11.0 / 84.0;
// Fifth minus fourth order weights: the local error estimate.
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;

/// Adaptive Dormand-Prince 5(4) integrator. The last accepted step size is carried from one
/// interval to the next, so consecutive communication steps do not restart from scratch.
#[derive(Clone, Debug, PartialEq)]
pub struct Dopri5<const N: usize> {
    /// Relative tolerance per step.
    pub rtol: f64,
    /// Absolute scale of each component: the error of component i is measured against
    /// rtol (abs_scale[i] + |y_i|). A component with abs_scale 0 is not error-controlled
    /// (quadratures that ride along).
    pub abs_scale: [f64; N],
    /// Largest internal step (f64::INFINITY: none).
    pub max_step: f64,
    /// Most internal steps (accepted + rejected) per interval.
    pub max_steps: u64,
    h_next: f64,
}

impl<const N: usize> Dopri5<N> {
    pub fn new(rtol: f64, abs_scale: [f64; N], max_step: f64, max_steps: u64) -> Self {
        Dopri5 {
            rtol,
            abs_scale,
            max_step,
            max_steps,
            h_next: 0.0,
        }
    }

    /// The step size carried into the next interval (0: none yet), for saving the state.
    pub fn carried_step(&self) -> f64 {
        self.h_next
    }

    /// Restore a carried step size saved with [`Dopri5::carried_step`].
    pub fn set_carried_step(&mut self, h: f64) {
        self.h_next = if h.is_finite() && h > 0.0 { h } else { 0.0 };
    }

    fn norm(&self, e: &[f64; N], y0: &[f64; N], y1: &[f64; N]) -> f64 {
        let (mut sum, mut n) = (0.0, 0usize);
        for i in 0..N {
            if self.abs_scale[i] > 0.0 {
                let sc = self.rtol * (self.abs_scale[i] + y0[i].abs().max(y1[i].abs()));
                sum += (e[i] / sc).powi(2);
                n += 1;
            }
        }
        if n == 0 { 0.0 } else { (sum / n as f64).sqrt() }
    }

    /// Starting step from the size of y and y' (Hairer's heuristic, simplified).
    fn initial_step<F: Rhs<N>>(
        &self,
        f: &F,
        t: f64,
        y: &[f64; N],
        f0: &[f64; N],
        span: f64,
    ) -> f64 {
        let zero = [0.0; N];
        let d0 = self.norm(y, &zero, &zero);
        let d1 = self.norm(f0, y, y);
        // From rest the state says nothing of the time scale: let the second estimate decide.
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            0.01 * span
        } else {
            0.01 * d0 / d1
        };
        let mut y1 = [0.0; N];
        for i in 0..N {
            y1[i] = y[i] + h0 * f0[i];
        }
        let mut f1 = [0.0; N];
        f.eval(t + h0, &y1, &mut f1);
        let mut df = [0.0; N];
        for i in 0..N {
            df[i] = (f1[i] - f0[i]) / h0;
        }
        let d2 = self.norm(&df, y, y);
        // Nothing moves: any step is exact, so take the whole interval.
        let h1 = if d1.max(d2) <= 1e-15 {
            span
        } else {
            (0.01 / d1.max(d2)).powf(0.2)
        };
        let h = (100.0 * h0).min(h1);
        if h.is_finite() && h > 0.0 {
            h
        } else {
            1e-6 * span
        }
    }

    /// Advance `y` from `t0` to `t1` (> t0) to tolerance. On error `y` and the carried step
    /// size are left unchanged.
    pub fn integrate<F: Rhs<N>>(
        &mut self,
        f: &F,
        t0: f64,
        t1: f64,
        y: &mut [f64; N],
    ) -> Result<SolveStats, SolveError> {
        let span = t1 - t0;
        let mut stats = SolveStats::default();
        let mut z = *y;
        let mut k1 = [0.0; N];
        f.eval(t0, &z, &mut k1);
        stats.evaluations += 1;
        if !all_finite(&k1) || !all_finite(&z) {
            return Err(SolveError::NonFinite { t: t0 });
        }
        let mut h = if self.h_next > 0.0 {
            self.h_next
        } else {
            self.initial_step(f, t0, &z, &k1, span)
        };
        h = h.min(self.max_step);
        let mut t = t0;
        let (mut k2, mut k3, mut k4, mut k5, mut k6, mut k7) =
            ([0.0; N], [0.0; N], [0.0; N], [0.0; N], [0.0; N], [0.0; N]);
        let (mut tmp, mut y_new, mut err) = ([0.0; N], [0.0; N], [0.0; N]);
        let mut just_rejected = false;
        let carried = loop {
            if stats.accepted + stats.rejected >= self.max_steps {
                return Err(SolveError::TooManySteps {
                    limit: self.max_steps,
                    t,
                });
            }
            let remaining = t1 - t;
            let last = h >= remaining;
            let hs = if last { remaining } else { h };
            for i in 0..N {
                tmp[i] = z[i] + hs * A21 * k1[i];
            }
            f.eval(t + C2 * hs, &tmp, &mut k2);
            for i in 0..N {
                tmp[i] = z[i] + hs * (A31 * k1[i] + A32 * k2[i]);
            }
            f.eval(t + C3 * hs, &tmp, &mut k3);
            for i in 0..N {
                tmp[i] = z[i] + hs * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
            }
            f.eval(t + C4 * hs, &tmp, &mut k4);
            for i in 0..N {
                tmp[i] = z[i] + hs * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
            }
            f.eval(t + C5 * hs, &tmp, &mut k5);
            for i in 0..N {
                tmp[i] = z[i]
                    + hs * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
            }
            f.eval(t + hs, &tmp, &mut k6);
            for i in 0..N {
                y_new[i] =
                    z[i] + hs * (B1 * k1[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i] + B6 * k6[i]);
            }
            f.eval(t + hs, &y_new, &mut k7);
            stats.evaluations += 6;
            for i in 0..N {
                err[i] = hs
                    * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
            }
            let e = if all_finite(&y_new) && all_finite(&k7) {
                self.norm(&err, &z, &y_new)
            } else {
                f64::INFINITY
            };
            if e <= 1.0 {
                stats.accepted += 1;
                let fac = if e == 0.0 {
                    5.0
                } else {
                    (0.9 * e.powf(-0.2)).clamp(0.2, 5.0)
                };
                let fac = if just_rejected { fac.min(1.0) } else { fac };
                just_rejected = false;
                let proposal = (hs * fac).min(self.max_step);
                z = y_new;
                k1 = k7;
                if last {
                    // A step cut short to land on t1 says little about the natural step.
                    break if hs < h { h.max(proposal) } else { proposal };
                }
                t += hs;
                h = proposal;
            } else {
                stats.rejected += 1;
                just_rejected = true;
                let fac = if e.is_finite() {
                    (0.9 * e.powf(-0.2)).clamp(0.2, 1.0)
                } else {
                    0.25
                };
                h = hs * fac;
                if h <= 1e-14 * t.abs().max(span) {
                    return Err(if e.is_finite() {
                        SolveError::StepTooSmall { h, t }
                    } else {
                        SolveError::NonFinite { t }
                    });
                }
            }
        };
        *y = z;
        self.h_next = carried;
        Ok(stats)
    }
}
