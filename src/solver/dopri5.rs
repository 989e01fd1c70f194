//! Dormand-Prince 5(4): explicit embedded Runge-Kutta pair with local error control
//! (Hairer, Norsett & Wanner, Solving ODEs I, section II.4 and II.5).

use super::adaptive::{Adaptive, Controls, Embedded};
use super::fixed::{FixedStep, Formula};
use super::{Rhs, SolveStats, all_finite_in};

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

/// Adaptive Dormand-Prince 5(4).
pub type Dopri5<const N: usize> = Adaptive<N, DormandPrince<N>>;

/// The pair's fifth-order solution with a fixed step: six evaluations, no error estimate.
pub type Rk5 = FixedStep<DormandPrince5>;

/// Stages 2 to 6 of a step of `hs` from (t, z) with slope `k1` there: the slopes the error
/// estimate needs besides k1 (k3 to k6) and the fifth-order solution.
#[inline(always)]
fn fifth_order<const N: usize, F: Rhs<N>>(
    f: &F,
    t: f64,
    z: &[f64; N],
    hs: f64,
    k1: &[f64; N],
) -> ([[f64; N]; 4], [f64; N]) {
    let (mut k2, mut k3, mut k4, mut k5, mut k6) =
        ([0.0; N], [0.0; N], [0.0; N], [0.0; N], [0.0; N]);
    let mut tmp = [0.0; N];
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
        tmp[i] = z[i] + hs * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
    }
    f.eval(t + hs, &tmp, &mut k6);
    let y = std::array::from_fn(|i| {
        z[i] + hs * (B1 * k1[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i] + B6 * k6[i])
    });
    ([k3, k4, k5, k6], y)
}

/// The fifth-order formula of the Dormand-Prince pair on its own (six evaluations).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DormandPrince5;

impl Formula for DormandPrince5 {
    const EVALS: u64 = 6;

    #[inline(always)]
    fn step<const N: usize, F: Rhs<N>>(f: &F, t: f64, h: f64, z: &[f64; N]) -> [f64; N] {
        let mut k1 = [0.0; N];
        f.eval(t, z, &mut k1);
        fifth_order(f, t, z, h, &k1).1
    }
}

/// The Dormand-Prince 5(4) pair's stages; k1 is kept between steps (first same as last).
#[derive(Clone, Debug, PartialEq)]
pub struct DormandPrince<const N: usize> {
    k1: [f64; N],
    k7: [f64; N],
}

impl<const N: usize> Default for DormandPrince<N> {
    fn default() -> Self {
        DormandPrince {
            k1: [0.0; N],
            k7: [0.0; N],
        }
    }
}

impl<const N: usize> Embedded<N> for DormandPrince<N> {
    const ORDER: f64 = 5.0;

    #[inline(always)]
    fn begin<F: Rhs<N>>(&mut self, f: &F, t: f64, y: &[f64; N], f0: &mut [f64; N]) {
        f.eval(t, y, &mut self.k1);
        *f0 = self.k1;
    }

    #[inline(always)]
    fn attempt<F: Rhs<N>>(
        &mut self,
        f: &F,
        t: f64,
        z: &[f64; N],
        hs: f64,
        y_new: &mut [f64; N],
        err: &mut [f64; N],
        _ctl: &Controls<N>,
        stats: &mut SolveStats,
    ) -> bool {
        let ([k3, k4, k5, k6], y) = fifth_order(f, t, z, hs, &self.k1);
        *y_new = y;
        let k1 = &self.k1;
        f.eval(t + hs, y_new, &mut self.k7);
        stats.evaluations += 6;
        let k7 = &self.k7;
        for i in 0..N {
            err[i] =
                hs * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
        }
        all_finite_in([y_new, k7])
    }

    #[inline(always)]
    fn accepted(&mut self) {
        self.k1 = self.k7;
    }
}
