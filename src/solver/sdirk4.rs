//! SDIRK4: the L-stable, stiffly accurate singly diagonally implicit Runge-Kutta method of
//! order 4 with an embedded order-3 estimate (Hairer & Wanner, Solving ODEs II, IV.6, table
//! 6.5; gamma = 1/4). Each stage is solved by simplified Newton iterations with one LU
//! factorisation of I - h gamma J per step (nalgebra). For large eta and excursions beyond the
//! walls, where the local stiffness explodes and explicit steps shrink to their stability limit.

use nalgebra::{Const, DimMin, SMatrix, SVector};

use super::adaptive::{Adaptive, Controls, Embedded};
use super::{Rhs, SolveStats, all_finite};

const GAMMA: f64 = 0.25;
const C: [f64; 5] = [0.25, 0.75, 11.0 / 20.0, 0.5, 1.0];
const A: [[f64; 5]; 5] = [
    [0.25, 0.0, 0.0, 0.0, 0.0],
    [0.5, 0.25, 0.0, 0.0, 0.0],
    [17.0 / 50.0, -1.0 / 25.0, 0.25, 0.0, 0.0],
    [371.0 / 1360.0, -137.0 / 2720.0, 15.0 / 544.0, 0.25, 0.0],
    [25.0 / 24.0, -49.0 / 48.0, 125.0 / 16.0, -85.0 / 12.0, 0.25],
];
/// Weights of the embedded order-3 solution (the order-4 weights are the last row of A).
const B_HAT: [f64; 5] = [59.0 / 48.0, -17.0 / 96.0, 225.0 / 32.0, -85.0 / 12.0, 0.0];
/// Newton iterations per stage before the step is given up and retried smaller.
const MAX_NEWTON: usize = 8;

/// Adaptive SDIRK4 with Newton iterations on the system's Jacobian.
pub type Sdirk4<const N: usize> = Adaptive<N, Sdirk4Stages<N>>;

/// SDIRK4's stages: nothing is kept between steps.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sdirk4Stages<const N: usize>;

impl<const N: usize> Embedded<N> for Sdirk4Stages<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    const ORDER: f64 = 4.0;

    fn begin<F: Rhs<N>>(&mut self, f: &F, t: f64, y: &[f64; N], f0: &mut [f64; N]) {
        f.eval(t, y, f0);
    }

    fn attempt<F: Rhs<N>>(
        &mut self,
        f: &F,
        t: f64,
        y: &[f64; N],
        h: f64,
        y_new: &mut [f64; N],
        err: &mut [f64; N],
        ctl: &Controls<N>,
        stats: &mut SolveStats,
    ) -> bool {
        let mut jac = [[0.0; N]; N];
        f.jacobian(t, y, &mut jac);
        let m = SMatrix::<f64, N, N>::from_fn(|i, j| {
            f64::from(u8::from(i == j)) - h * GAMMA * jac[i][j]
        });
        let lu = m.lu();
        let mut k = [[0.0; N]; 5];
        let mut z = *y;
        for s in 0..5 {
            // base = y + h sum_{j<s} a_sj k_j; solve Z = base + h gamma f(t + c_s h, Z).
            let mut base = *y;
            for (j, kj) in k.iter().enumerate().take(s) {
                for i in 0..N {
                    base[i] += h * A[s][j] * kj[i];
                }
            }
            // Predictor: the previous stage's slope.
            let slope = if s == 0 { [0.0; N] } else { k[s - 1] };
            for i in 0..N {
                z[i] = base[i] + h * GAMMA * slope[i];
            }
            let mut converged = false;
            let mut fz = [0.0; N];
            for _ in 0..MAX_NEWTON {
                f.eval(t + C[s] * h, &z, &mut fz);
                stats.evaluations += 1;
                let r = SVector::<f64, N>::from_fn(|i, _| base[i] + h * GAMMA * fz[i] - z[i]);
                let Some(dz) = lu.solve(&r) else { return false };
                let mut dz_arr = [0.0; N];
                for i in 0..N {
                    dz_arr[i] = dz[i];
                    z[i] += dz[i];
                }
                // Converged well below the step tolerance.
                if ctl.norm(F::CONTROLLED, &dz_arr, &z, &z) < 1e-3 {
                    converged = true;
                    break;
                }
                if !dz_arr.iter().all(|v| v.is_finite()) {
                    return false;
                }
            }
            if !converged {
                return false;
            }
            for i in 0..N {
                k[s][i] = (z[i] - base[i]) / (h * GAMMA);
            }
        }
        // Stiffly accurate: the solution is the last stage.
        *y_new = z;
        let mut e = SVector::<f64, N>::zeros();
        for (s, ks) in k.iter().enumerate() {
            for i in 0..N {
                e[i] += h * (A[4][s] - B_HAT[s]) * ks[i];
            }
        }
        // Filtered estimate (I - h gamma J)^-1 e: keeps stiff components from inflating it.
        let Some(e) = lu.solve(&e) else { return false };
        for i in 0..N {
            err[i] = e[i];
        }
        all_finite(y_new)
    }

    fn accepted(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tableau satisfies the order conditions up to order 4 (and the embedded one to 3).
    #[test]
    fn order_conditions() {
        let b = A[4];
        let dot = |w: &[f64; 5], v: &[f64; 5]| w.iter().zip(v).map(|(x, y)| x * y).sum::<f64>();
        let ac = |v: &[f64; 5]| -> [f64; 5] { std::array::from_fn(|i| dot(&A[i], v)) };
        let c2: [f64; 5] = std::array::from_fn(|i| C[i] * C[i]);
        let c3: [f64; 5] = std::array::from_fn(|i| C[i] * C[i] * C[i]);
        for i in 0..5 {
            assert!(
                (A[i].iter().sum::<f64>() - C[i]).abs() < 1e-14,
                "row sum {i}"
            );
        }
        for w in [&b, &B_HAT] {
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-13);
            assert!((dot(w, &C) - 0.5).abs() < 1e-13);
            assert!((dot(w, &c2) - 1.0 / 3.0).abs() < 1e-13);
            assert!((dot(w, &ac(&C)) - 1.0 / 6.0).abs() < 1e-13);
        }
        assert!((dot(&b, &c3) - 0.25).abs() < 1e-13);
        let bc: [f64; 5] = std::array::from_fn(|i| b[i] * C[i]);
        assert!((dot(&bc, &ac(&C)) - 1.0 / 8.0).abs() < 1e-13);
        assert!((dot(&b, &ac(&c2)) - 1.0 / 12.0).abs() < 1e-13);
        assert!((dot(&b, &ac(&ac(&C))) - 1.0 / 24.0).abs() < 1e-13);
        // ... and the embedded solution is not of order 4 (else the estimate would be void).
        assert!((dot(&B_HAT, &c3) - 0.25).abs() > 1e-6);
    }
}
