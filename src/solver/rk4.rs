//! Classical fourth-order Runge-Kutta with a fixed internal step.

use super::{Rhs, SolveError, SolveStats, all_finite};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rk4 {
    /// Largest internal step; each interval is cut into equal steps no longer than this.
    pub max_step: f64,
    /// Most internal steps per interval.
    pub max_steps: u64,
}

impl Rk4 {
    /// Advance `y` from `t0` to `t1`. On error `y` is left unchanged.
    pub fn integrate<const N: usize, F: Rhs<N>>(
        &self,
        f: &F,
        t0: f64,
        t1: f64,
        y: &mut [f64; N],
    ) -> Result<SolveStats, SolveError> {
        let span = t1 - t0;
        // One step when the interval fits (the common case: ceil is a libm call on baseline x86-64).
        let n = if span <= self.max_step {
            1.0
        } else {
            (span / self.max_step * (1.0 - 1e-12)).ceil().max(1.0)
        };
        if n > self.max_steps as f64 {
            return Err(SolveError::TooManySteps {
                limit: self.max_steps,
                t: t0,
            });
        }
        let n = n as u64;
        let h = span / n as f64;
        let mut z = *y;
        let (mut k1, mut k2, mut k3, mut k4, mut tmp) =
            ([0.0; N], [0.0; N], [0.0; N], [0.0; N], [0.0; N]);
        for i in 0..n {
            let t = t0 + i as f64 * h;
            f.eval(t, &z, &mut k1);
            for j in 0..N {
                tmp[j] = z[j] + 0.5 * h * k1[j];
            }
            f.eval(t + 0.5 * h, &tmp, &mut k2);
            for j in 0..N {
                tmp[j] = z[j] + 0.5 * h * k2[j];
            }
            f.eval(t + 0.5 * h, &tmp, &mut k3);
            for j in 0..N {
                tmp[j] = z[j] + h * k3[j];
            }
            f.eval(t + h, &tmp, &mut k4);
            for j in 0..N {
                z[j] += h / 6.0 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
            }
            if !all_finite(&z) {
                return Err(SolveError::NonFinite { t });
            }
        }
        *y = z;
        Ok(SolveStats {
            accepted: n,
            rejected: 0,
            evaluations: 4 * n,
        })
    }
}
