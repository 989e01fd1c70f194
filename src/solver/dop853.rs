//! Dormand-Prince 8(5,3) ("DOP853"): an explicit pair of order 8 with a combined order-5/3
//! error estimate, for tight tolerances where the 5(4) pair needs many more steps.

use super::adaptive::{Adaptive, Controls, Embedded};
use super::fixed::{FixedStep, Formula};
use super::{Rhs, SolveStats, all_finite_in};

// The DOP853 tableau of Hairer, Norsett & Wanner (Solving ODEs I, II.10): 12 stages of
// order 8, error estimators of orders 5 and 3. Generated from the published coefficients.
const S: usize = 12;
const C: [f64; S] = [
    0.0,
    0.05260015195876773,
    0.0789002279381516,
    0.1183503419072274,
    0.2816496580927726,
    0.3333333333333333,
    0.25,
    0.3076923076923077,
    0.6512820512820513,
    0.6,
    0.8571428571428571,
    1.0,
];
const A: [[f64; S]; S] = [
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [
        0.05260015195876773,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.0197250569845379,
        0.0591751709536137,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.02958758547680685,
        0.0,
        0.08876275643042054,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.2413651341592667,
        0.0,
        -0.8845494793282861,
        0.924834003261792,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.037037037037037035,
        0.0,
        0.0,
        0.17082860872947386,
        0.12546768756682242,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.037109375,
        0.0,
        0.0,
        0.17025221101954405,
        0.06021653898045596,
        -0.017578125,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.03709200011850479,
        0.0,
        0.0,
        0.17038392571223998,
        0.10726203044637328,
        -0.015319437748624402,
        0.008273789163814023,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.6241109587160757,
        0.0,
        0.0,
        -3.3608926294469414,
        -0.868219346841726,
        27.59209969944671,
        20.154067550477894,
        -43.48988418106996,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        0.47766253643826434,
        0.0,
        0.0,
        -2.4881146199716677,
        -0.590290826836843,
        21.230051448181193,
        15.279233632882423,
        -33.28821096898486,
        -0.020331201708508627,
        0.0,
        0.0,
        0.0,
    ],
    [
        -0.9371424300859873,
        0.0,
        0.0,
        5.186372428844064,
        1.0914373489967295,
        -8.149787010746927,
        -18.52006565999696,
        22.739487099350505,
        2.4936055526796523,
        -3.0467644718982196,
        0.0,
        0.0,
    ],
    [
        2.273310147516538,
        0.0,
        0.0,
        -10.53449546673725,
        -2.0008720582248625,
        -17.9589318631188,
        27.94888452941996,
        -2.8589982771350235,
        -8.87285693353063,
        12.360567175794303,
        0.6433927460157636,
        0.0,
    ],
];
const B: [f64; S] = [
    0.054293734116568765,
    0.0,
    0.0,
    0.0,
    0.0,
    4.450312892752409,
    1.8915178993145003,
    -5.801203960010585,
    0.3111643669578199,
    -0.1521609496625161,
    0.20136540080403034,
    0.04471061572777259,
];
/// Order-5 and order-3 error weights over the 12 stages and f(t + h, y_new).
const E5: [f64; S + 1] = [
    0.01312004499419488,
    0.0,
    0.0,
    0.0,
    0.0,
    -1.2251564463762044,
    -0.4957589496572502,
    1.6643771824549864,
    -0.35032884874997366,
    0.3341791187130175,
    0.08192320648511571,
    -0.022355307863886294,
    0.0,
];
const E3: [f64; S + 1] = [
    -0.18980075407240762,
    0.0,
    0.0,
    0.0,
    0.0,
    4.450312892752409,
    1.8915178993145003,
    -5.801203960010585,
    -0.4226823213237919,
    -0.1521609496625161,
    0.20136540080403034,
    0.02265179219836082,
    0.0,
];

/// Adaptive Dormand-Prince 8(5,3).
pub type Dop853<const N: usize> = Adaptive<N, Dop853Stages<N>>;

/// The pair's eighth-order solution with a fixed step: twelve evaluations, no error estimate.
pub type Rk8 = FixedStep<DormandPrince8>;

/// sum_j w_j k_j[i] over the nonzero weights, in order: the tableau is a constant, so once
/// unrolled the zero terms cost nothing.
#[inline(always)]
fn weighted<const N: usize>(w: &[f64], k: &[[f64; N]], i: usize) -> f64 {
    let mut acc = 0.0;
    for (wj, kj) in w.iter().zip(k) {
        if *wj != 0.0 {
            acc += wj * kj[i];
        }
    }
    acc
}

/// Slope k[J] (J = 1 to 11: stages 2 to 12) of a step of `h` from (t, y), from k[..J]. `J` is a
/// constant so that each stage is compiled with its own row of the tableau.
#[inline(always)]
fn stage<const J: usize, const N: usize, F: Rhs<N>>(
    f: &F,
    t: f64,
    y: &[f64; N],
    h: f64,
    k: &mut [[f64; N]; S + 1],
) {
    let tmp: [f64; N] = std::array::from_fn(|i| y[i] + h * weighted(&A[J][..J], &k[..J], i));
    f.eval(t + C[J] * h, &tmp, &mut k[J]);
}

/// Stages 2 to 12 of a step of `h` from (t, y) into k[1..S], k[0] being the slope at (t, y),
/// and the eighth-order solution.
#[inline(always)]
fn eighth_order<const N: usize, F: Rhs<N>>(
    f: &F,
    t: f64,
    y: &[f64; N],
    h: f64,
    k: &mut [[f64; N]; S + 1],
) -> [f64; N] {
    stage::<1, N, F>(f, t, y, h, k);
    stage::<2, N, F>(f, t, y, h, k);
    stage::<3, N, F>(f, t, y, h, k);
    stage::<4, N, F>(f, t, y, h, k);
    stage::<5, N, F>(f, t, y, h, k);
    stage::<6, N, F>(f, t, y, h, k);
    stage::<7, N, F>(f, t, y, h, k);
    stage::<8, N, F>(f, t, y, h, k);
    stage::<9, N, F>(f, t, y, h, k);
    stage::<10, N, F>(f, t, y, h, k);
    stage::<11, N, F>(f, t, y, h, k);
    std::array::from_fn(|i| y[i] + h * weighted(&B, &k[..S], i))
}

/// The eighth-order formula of DOP853 on its own (twelve evaluations).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DormandPrince8;

impl Formula for DormandPrince8 {
    const EVALS: u64 = S as u64;

    #[inline(always)]
    fn step<const N: usize, F: Rhs<N>>(f: &F, t: f64, h: f64, z: &[f64; N]) -> [f64; N] {
        let mut k = [[0.0; N]; S + 1];
        f.eval(t, z, &mut k[0]);
        eighth_order(f, t, z, h, &mut k)
    }
}

/// The stages of DOP853; the last slope is kept between steps (first same as last).
#[derive(Clone, Debug, PartialEq)]
pub struct Dop853Stages<const N: usize> {
    k: [[f64; N]; S + 1],
}

impl<const N: usize> Default for Dop853Stages<N> {
    fn default() -> Self {
        Dop853Stages {
            k: [[0.0; N]; S + 1],
        }
    }
}

impl<const N: usize> Embedded<N> for Dop853Stages<N> {
    const ORDER: f64 = 8.0;

    fn begin<F: Rhs<N>>(&mut self, f: &F, t: f64, y: &[f64; N], f0: &mut [f64; N]) {
        f.eval(t, y, &mut self.k[0]);
        *f0 = self.k[0];
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
        *y_new = eighth_order(f, t, y, h, &mut self.k);
        f.eval(t + h, y_new, &mut self.k[S]);
        stats.evaluations += S as u64;
        // The combined estimate of Hairer's DOP853: err5^2 / sqrt(err5^2 + 0.01 err3^2), in the
        // controller's norm: scale the order-5 estimate by err5 / sqrt(err5^2 + 0.01 err3^2).
        let (mut e5, mut e3) = ([0.0; N], [0.0; N]);
        for (j, k) in self.k.iter().enumerate() {
            for i in 0..N {
                e5[i] += h * E5[j] * k[i];
                e3[i] += h * E3[j] * k[i];
            }
        }
        let (n5, n3) = (
            ctl.norm(F::CONTROLLED, &e5, y, y_new),
            ctl.norm(F::CONTROLLED, &e3, y, y_new),
        );
        let denom = (n5 * n5 + 0.01 * n3 * n3).sqrt();
        let factor = if denom > 0.0 { n5 / denom } else { 0.0 };
        for i in 0..N {
            err[i] = e5[i] * factor;
        }
        all_finite_in([y_new, &self.k[S]])
    }

    fn accepted(&mut self) {
        self.k[0] = self.k[S];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Row sums give C, and the weights satisfy the quadrature conditions up to order 8.
    #[test]
    fn tableau_conditions() {
        for s in 0..S {
            let row: f64 = A[s].iter().sum();
            assert!((row - C[s]).abs() < 1e-14, "row {s}: {row} vs {}", C[s]);
        }
        for q in 0..8 {
            let sum: f64 = (0..S).map(|j| B[j] * C[j].powi(q)).sum();
            assert!(
                (sum - 1.0 / (q as f64 + 1.0)).abs() < 1e-13,
                "b c^{q}: {sum}"
            );
        }
        // The error weights annihilate constants (an estimate of zero for y' = 1 ... up to
        // their orders).
        assert!(E5.iter().sum::<f64>().abs() < 1e-14 && E3.iter().sum::<f64>().abs() < 1e-14);
    }
}
