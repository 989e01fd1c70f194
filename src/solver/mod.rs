//! Integrators, generic over a small right-hand-side trait. They know nothing of the model
//! behind the trait nor of FMI.

mod adaptive;
mod auto;
mod dop853;
mod dopri5;
mod fixed;
mod lawson;
mod sdirk4;

pub use adaptive::{Adaptive, Controls, Embedded};
pub use auto::Auto;
pub use dop853::{Dop853, Dop853Stages, DormandPrince8, Rk8};
pub use dopri5::{Dopri5, DormandPrince, DormandPrince5, Rk5};
pub use fixed::{Classical, FixedStep, Formula, Rk4};
pub use lawson::ExpRk4;
pub use sdirk4::{Sdirk4, Sdirk4Stages};

/// y' = f(t, y) for a state of fixed size N.
pub trait Rhs<const N: usize> {
    /// How many leading components error control may measure. The components past them are
    /// quadratures that ride along, never error-controlled (abs_scale 0): known at compile
    /// time, the error norm neither tests nor forms them.
    const CONTROLLED: usize = N;

    fn eval(&self, t: f64, y: &[f64; N], dy: &mut [f64; N]);

    /// Magnitude of the fastest local time scale |lambda|max at (t, y), in 1/s. The default is
    /// a Gershgorin bound on the Jacobian; a system that knows better should say so.
    fn stiffness(&self, t: f64, y: &[f64; N]) -> f64 {
        let mut jac = [[0.0; N]; N];
        self.jacobian(t, y, &mut jac);
        jac.iter()
            .map(|row| row.iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    }

    /// df/dy at (t, y), row i = derivative of f_i. The default differences `eval` forward; a
    /// system that knows its Jacobian should say so (implicit methods converge on it).
    fn jacobian(&self, t: f64, y: &[f64; N], jac: &mut [[f64; N]; N]) {
        let mut f0 = [0.0; N];
        self.eval(t, y, &mut f0);
        let mut yp = *y;
        let mut fp = [0.0; N];
        for j in 0..N {
            let d = f64::EPSILON.sqrt() * y[j].abs().max(1e-5);
            yp[j] = y[j] + d;
            self.eval(t, &yp, &mut fp);
            for i in 0..N {
                jac[i][j] = (fp[i] - f0[i]) / d;
            }
            yp[j] = y[j];
        }
    }
}

/// A right-hand side whose first two components are a damped linear oscillator plus a
/// remainder, y0' = y1, y1' = -w2 y0 - c y1 + r(t, y), the others being remainder alone:
/// exponential integrators take the oscillator by its exact flow.
pub trait OscillatorSplit<const N: usize>: Rhs<N> {
    /// (w2, c) of the linear part.
    fn oscillator(&self) -> (f64, f64);

    /// The linear part's exact flow over `tau`, (y0, y1)(tau) = P (y0, y1)(0), as P - I formed
    /// without forming P (applied as y + (P - I) y, short steps round relative to the change,
    /// not to the state).
    fn flow_change(&self, tau: f64) -> [[f64; 2]; 2];

    /// f minus the linear part into dy[1..]: r(t, y) in dy[1], f_i in dy[i] for i >= 2.
    /// dy[0] (the linear part's alone) is not read.
    fn remainder(&self, t: f64, y: &[f64; N], dy: &mut [f64; N]);
}

/// Why an integration over an interval could not be completed.
#[derive(Clone, Debug, PartialEq)]
pub enum SolveError {
    /// The work bound (internal steps per interval) was reached at time `t`.
    TooManySteps { limit: u64, t: f64 },
    /// The step size fell below what floating point can resolve at time `t`.
    StepTooSmall { h: f64, t: f64 },
    /// The state or its derivative stopped being finite at time `t`.
    NonFinite { t: f64 },
}

impl SolveError {
    /// The same error with its time moved by `t0` (an interval integrated in its own time).
    pub fn shifted(self, t0: f64) -> Self {
        match self {
            SolveError::TooManySteps { limit, t } => SolveError::TooManySteps { limit, t: t + t0 },
            SolveError::StepTooSmall { h, t } => SolveError::StepTooSmall { h, t: t + t0 },
            SolveError::NonFinite { t } => SolveError::NonFinite { t: t + t0 },
        }
    }
}

impl std::fmt::Display for SolveError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SolveError::TooManySteps { limit, t } => {
                write!(
                    f,
                    "more than {limit} internal steps were needed (stopped at t = {t:.9} s)"
                )
            }
            SolveError::StepTooSmall { h, t } => {
                write!(
                    f,
                    "the internal step shrank to {h:e} s at t = {t:.9} s: the solution is not resolvable"
                )
            }
            SolveError::NonFinite { t } => write!(f, "the state became non-finite at t = {t:.9} s"),
        }
    }
}

/// What an integration over one interval cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveStats {
    pub accepted: u64,
    pub rejected: u64,
    pub evaluations: u64,
}

/// Whether every value is finite. v - v is 0 for a finite v and NaN otherwise, and a sum of
/// them is 0 exactly when every term is: a chain of subtractions and additions, where a test per
/// value costs its bit masking and its branch (on every step of every solver).
#[inline(always)]
#[allow(clippy::eq_op)] // v - v is the test: 0 or NaN
pub(crate) fn all_finite<const N: usize>(y: &[f64; N]) -> bool {
    all_finite_in([y])
}

/// Whether every value of every array is finite: [`all_finite`] in one chain, one test.
#[inline(always)]
#[allow(clippy::eq_op)] // v - v is the test: 0 or NaN
pub(crate) fn all_finite_in<const N: usize, const K: usize>(ys: [&[f64; N]; K]) -> bool {
    ys.iter()
        .fold(0.0, |sum, y| y.iter().fold(sum, |sum, v| sum + (v - v)))
        == 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the test value by value: any non-finite value at any place, among finite values
    /// of every kind (zeros of both signs, subnormal, the largest).
    #[test]
    fn all_finite_is_every_value_finite() {
        let finite = [0.0, -0.0, 5e-324, -f64::MAX, f64::MAX, 1.5];
        for a in finite {
            for b in finite {
                assert!(all_finite(&[a, b, b, a]));
            }
        }
        assert!(all_finite::<0>(&[]));
        for bad in [f64::NAN, -f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for k in 0..4 {
                let mut y = [1.0, -0.0, f64::MAX, 5e-324];
                y[k] = bad;
                assert!(!all_finite(&y), "{y:?}");
            }
        }
        assert!(!all_finite(&[f64::INFINITY, f64::NEG_INFINITY]));
        // several arrays: a non-finite value in any of them
        let ok = [1.0, -0.0, f64::MAX];
        assert!(all_finite_in([&ok, &ok, &ok]));
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for which in 0..3 {
                for k in 0..3 {
                    let mut ys = [ok; 3];
                    ys[which][k] = bad;
                    assert!(!all_finite_in([&ys[0], &ys[1], &ys[2]]), "{ys:?}");
                }
            }
        }
    }

    /// x'' = -w^2 x: exact solution x = cos(w t), v = -w sin(w t).
    struct Oscillator(f64);

    impl Rhs<2> for Oscillator {
        fn eval(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
            dy[0] = y[1];
            dy[1] = -self.0 * self.0 * y[0];
        }
    }

    fn error_after(y: &[f64; 2], w: f64, t: f64) -> f64 {
        ((y[0] - (w * t).cos()).powi(2) + ((y[1] + w * (w * t).sin()) / w).powi(2)).sqrt()
    }

    #[test]
    fn dopri5_meets_its_tolerance_over_many_intervals() {
        let w = 5.6389;
        for rtol in [1e-6, 1e-9, 1e-12] {
            let mut dp = Dopri5::new(rtol, [1.0, w], f64::INFINITY, 100_000);
            let mut y = [1.0, 0.0];
            let h = 0.01;
            for k in 0..1000 {
                dp.integrate(&Oscillator(w), k as f64 * h, (k + 1) as f64 * h, &mut y)
                    .expect("step");
            }
            let e = error_after(&y, w, 10.0);
            // Global error grows with the number of steps: allow 100 x the local tolerance.
            assert!(e < 100.0 * rtol, "rtol {rtol}: error {e}");
            assert!(
                e > 1e-3 * rtol || rtol < 1e-11,
                "suspiciously exact at rtol {rtol}: {e}"
            );
        }
    }

    /// An error-controlled method meets its tolerance over 100 intervals, and with its step
    /// held fixed (max_step below what a loose tolerance needs) halving it divides the error by
    /// 2^order.
    fn check_tolerance_and_order<M: Embedded<2>>(
        tols: &[f64],
        steps: (f64, f64),
        span: f64,
        order: i32,
    ) {
        let w = 5.6389;
        for &rtol in tols {
            let mut m = Adaptive::<2, M>::new(rtol, [1.0, w], f64::INFINITY, 1_000_000);
            let mut y = [1.0, 0.0];
            for k in 0..100 {
                m.integrate(&Oscillator(w), k as f64 * 0.1, (k + 1) as f64 * 0.1, &mut y)
                    .expect("step");
            }
            let e = error_after(&y, w, 10.0);
            assert!(e < 100.0 * rtol, "rtol {rtol}: error {e}");
        }
        let run = |h: f64| {
            let mut m = Adaptive::<2, M>::new(1.0, [1e9, 1e9], h, 1_000_000);
            let mut y = [1.0, 0.0];
            m.integrate(&Oscillator(w), 0.0, span, &mut y).expect("run");
            error_after(&y, w, span)
        };
        let ratio = run(steps.0) / run(steps.1);
        let want = 2f64.powi(order);
        assert!(
            (ratio / want - 1.0).abs() < 0.25,
            "error ratio {ratio}, want {want}"
        );
    }

    #[test]
    fn sdirk4_meets_its_tolerance_and_is_fourth_order() {
        check_tolerance_and_order::<Sdirk4Stages<2>>(&[1e-6, 1e-8, 1e-10], (0.02, 0.01), 2.0, 4);
    }

    #[test]
    fn dop853_meets_its_tolerance_and_is_eighth_order() {
        check_tolerance_and_order::<Dop853Stages<2>>(&[1e-8, 1e-11, 1e-13], (0.2, 0.1), 4.0, 8);
    }

    #[test]
    fn dopri5_is_fifth_order() {
        check_tolerance_and_order::<DormandPrince<2>>(&[1e-6, 1e-9], (0.1, 0.05), 4.0, 5);
    }

    /// y' = -L (y - cos t) with L = 1e6: explicit steps are stability-limited to ~3/L, the
    /// L-stable implicit method takes steps set by cos t alone.
    #[test]
    fn sdirk4_takes_large_steps_on_a_stiff_problem() {
        struct Stiff;
        impl Rhs<1> for Stiff {
            fn eval(&self, t: f64, y: &[f64; 1], dy: &mut [f64; 1]) {
                dy[0] = -1e6 * (y[0] - t.cos());
            }
        }
        let mut implicit = Sdirk4::new(1e-8, [1.0], f64::INFINITY, 100_000);
        let mut y = [1.0];
        let stats = implicit
            .integrate(&Stiff, 0.0, 2.0, &mut y)
            .expect("implicit");
        // Exact up to O(1/L): y = cos t + sin t / L ...
        assert!((y[0] - 2f64.cos()).abs() < 1e-5, "{}", y[0]);
        assert!(stats.accepted < 1000, "{stats:?}");
        let mut explicit = Dopri5::new(1e-8, [1.0], f64::INFINITY, 100_000);
        let mut y = [1.0];
        let r = explicit.integrate(&Stiff, 0.0, 2.0, &mut y);
        assert!(
            matches!(r, Err(SolveError::TooManySteps { .. })),
            "explicit needs > 1e5 steps: {r:?}"
        );
    }

    #[test]
    fn auto_goes_implicit_only_where_the_problem_is_stiff() {
        struct Stiff;
        impl Rhs<1> for Stiff {
            fn eval(&self, t: f64, y: &[f64; 1], dy: &mut [f64; 1]) {
                dy[0] = -1e6 * (y[0] - t.cos());
            }
        }
        let mut auto = Auto::new(1e-8, [1.0], f64::INFINITY, 1_000_000);
        let mut y = [1.0];
        for k in 0..20 {
            auto.integrate(&Stiff, k as f64 * 0.1, (k + 1) as f64 * 0.1, &mut y)
                .expect("stiff");
        }
        assert!((y[0] - 2f64.cos()).abs() < 1e-5);
        assert!(auto.implicit_intervals >= 19, "{}", auto.implicit_intervals);
        // A lightly damped oscillator is not stiff, even over quarter-period intervals at a loose
        // tolerance (where an explicit step can reach h |lambda| ~ 3).
        let w = 5.6389;
        let mut auto = Auto::new(1e-6, [1.0, w], f64::INFINITY, 1_000_000);
        let mut y = [1.0, 0.0];
        let h = 0.25 * std::f64::consts::TAU / w;
        for k in 0..400 {
            auto.integrate(&Oscillator(w), k as f64 * h, (k + 1) as f64 * h, &mut y)
                .expect("oscillator");
        }
        assert_eq!(auto.implicit_intervals, 0);
        assert!(error_after(&y, w, 400.0 * h) < 1e-3);
    }

    /// Each fixed-step formula converges at its order: halving the step divides the error of
    /// a run over several periods by 2^order (a wrong coefficient drops the order).
    #[test]
    fn fixed_step_formulas_converge_at_their_order() {
        fn order<M: Formula>(coarse: f64) -> f64 {
            let w = 5.6389;
            let run = |step: f64| {
                let mut y = [1.0, 0.0];
                let stats = FixedStep::<M>::new(step, 1_000_000)
                    .integrate(&Oscillator(w), 0.0, 5.0, &mut y)
                    .expect("run");
                assert_eq!(stats.evaluations, M::EVALS * stats.accepted);
                error_after(&y, w, 5.0)
            };
            (run(coarse) / run(0.5 * coarse)).log2()
        }
        // steps where the error is far above round-off
        for (name, measured, want) in [
            ("RK4", order::<Classical>(0.01), 4.0),
            ("RK5", order::<DormandPrince5>(0.02), 5.0),
            ("RK8", order::<DormandPrince8>(0.1), 8.0),
        ] {
            assert!((measured - want).abs() < 0.3, "{name}: order {measured}");
        }
    }

    #[test]
    fn work_bound_refuses_and_leaves_state_alone() {
        let mut dp = Dopri5::new(1e-12, [1.0, 1.0], f64::INFINITY, 5);
        let mut y = [1.0, 0.0];
        let r = dp.integrate(&Oscillator(5.0), 0.0, 100.0, &mut y);
        assert!(
            matches!(r, Err(SolveError::TooManySteps { limit: 5, .. })),
            "{r:?}"
        );
        assert_eq!(y, [1.0, 0.0]);
        let r = Rk4::new(1e-3, 10).integrate(&Oscillator(5.0), 0.0, 1.0, &mut y);
        assert!(matches!(r, Err(SolveError::TooManySteps { .. })));
        assert_eq!(y, [1.0, 0.0]);
    }

    /// A damped, forced Duffing oscillator split as the exponential integrator sees it:
    /// x'' + c x' + w^2 x = -eps x^3 + force cos(2 t), with the dissipated energy c x'^2 as a
    /// quadrature (the forcing makes a wrong stage time show).
    struct Duffing {
        w: f64,
        c: f64,
        eps: f64,
        force: f64,
    }

    impl Rhs<3> for Duffing {
        fn eval(&self, t: f64, y: &[f64; 3], dy: &mut [f64; 3]) {
            dy[0] = y[1];
            dy[1] = -self.w * self.w * y[0] - self.c * y[1] - self.eps * y[0].powi(3)
                + self.force * (2.0 * t).cos();
            dy[2] = self.c * y[1] * y[1];
        }
    }

    impl OscillatorSplit<3> for Duffing {
        fn oscillator(&self) -> (f64, f64) {
            (self.w * self.w, self.c)
        }

        // Underdamped closed form, written here independently of the model's: e cos - 1 as
        // expm1 cos - 2 sin^2(half).
        fn flow_change(&self, tau: f64) -> [[f64; 2]; 2] {
            let sigma = 0.5 * self.c;
            let mu = (self.w * self.w - sigma * sigma).sqrt();
            let em1 = (-sigma * tau).exp_m1();
            let half = (0.5 * mu * tau).sin();
            let cm1 = em1 * (mu * tau).cos() - 2.0 * half * half;
            let sn = (1.0 + em1) * (mu * tau).sin() / mu;
            [
                [cm1 + sigma * sn, sn],
                [-self.w * self.w * sn, cm1 - sigma * sn],
            ]
        }

        fn remainder(&self, t: f64, y: &[f64; 3], dy: &mut [f64; 3]) {
            dy[1] = -self.eps * y[0].powi(3) + self.force * (2.0 * t).cos();
            dy[2] = self.c * y[1] * y[1];
        }
    }

    #[test]
    fn exp_rk4_takes_the_oscillator_exactly_and_the_rest_at_fourth_order() {
        let (w, c) = (5.6389, 0.2);
        // The state at the ends of ten intervals over (0, t1), several internal steps each, so
        // that the cached flows are used as well as made.
        let run = |eps: f64, force: f64, step: Option<f64>, t1: f64| {
            let f = Duffing { w, c, eps, force };
            let mut y = [0.1, 0.0, 0.0];
            let mut exp = ExpRk4::new(step.unwrap_or(1.0), 1_000_000);
            let mut reference = Dop853::new(1e-13, [0.1, 0.1 * w, 0.0], f64::INFINITY, 1_000_000);
            (0..10)
                .map(|k| {
                    let (a, b) = (k as f64 * t1 / 10.0, (k + 1) as f64 * t1 / 10.0);
                    match step {
                        Some(_) => exp.integrate(&f, a, b, &mut y),
                        None => reference.integrate(&f, a, b, &mut y),
                    }
                    .expect("run");
                    y
                })
                .collect::<Vec<_>>()
        };
        // Linear: exact with steps of a third of the period (RK4 would be off by percents),
        // the dissipated energy equal to the loss of stored energy to the quadrature's error.
        let y = run(0.0, 0.0, Some(0.37), 10.0)[9];
        let d = Duffing {
            w,
            c,
            eps: 0.0,
            force: 0.0,
        }
        .flow_change(10.0);
        let exact = [(1.0 + d[0][0]) * 0.1, d[1][0] * 0.1];
        assert!((y[0] - exact[0]).abs() < 1e-14, "{y:?}");
        assert!((y[1] - exact[1]).abs() < 1e-13 * w, "{y:?}");
        // ... and with 100,000 short steps the roundings do not pile up.
        let y = run(0.0, 0.0, Some(1e-4), 10.0)[9];
        assert!((y[0] - exact[0]).abs() < 1e-15, "{} vs {}", y[0], exact[0]);
        let stored = |x: f64, v: f64| 0.5 * (v * v + w * w * x * x);
        let loss = stored(0.1, 0.0) - stored(y[0], y[1]);
        assert!((y[2] - loss).abs() < 1e-3 * loss, "{} vs {loss}", y[2]);
        // Nonlinear (the cubic 30 % of the linear force at the start) and forced: every component
        // at fourth order against a DOP853 solution at 1e-13.
        let eps = 0.3 * w * w / 0.01;
        let reference = run(eps, 2.0, None, 5.0);
        let error = |step: f64| {
            let ys = run(eps, 2.0, Some(step), 5.0);
            std::array::from_fn::<f64, 3, _>(|i| {
                ys.iter()
                    .zip(&reference)
                    .map(|(y, r)| (y[i] - r[i]).abs())
                    .fold(0.0, f64::max)
            })
        };
        let (coarse, fine) = (error(0.01), error(0.005));
        for i in 0..3 {
            let order = (coarse[i] / fine[i]).log2();
            assert!((order - 4.0).abs() < 0.3, "component {i}: order {order}");
        }
    }

    #[test]
    fn exp_rk4_computes_the_flows_once_for_equal_steps() {
        struct Counted(Duffing, std::cell::Cell<u32>);
        impl Rhs<3> for Counted {
            fn eval(&self, t: f64, y: &[f64; 3], dy: &mut [f64; 3]) {
                self.0.eval(t, y, dy);
            }
        }
        impl OscillatorSplit<3> for Counted {
            fn oscillator(&self) -> (f64, f64) {
                self.0.oscillator()
            }
            fn flow_change(&self, tau: f64) -> [[f64; 2]; 2] {
                self.1.set(self.1.get() + 1);
                self.0.flow_change(tau)
            }
            fn remainder(&self, t: f64, y: &[f64; 3], dy: &mut [f64; 3]) {
                self.0.remainder(t, y, dy);
            }
        }
        let f = Counted(
            Duffing {
                w: 5.6,
                c: 0.2,
                eps: 100.0,
                force: 0.0,
            },
            std::cell::Cell::new(0),
        );
        // One, two and three internal steps per interval, over 100 intervals each integrated
        // in its own time (as the FMU's steps are).
        for (n, max_step) in [(1, 0.01), (2, 0.005), (3, 0.004)] {
            let mut m = ExpRk4::new(max_step, 100);
            let mut y = [0.1, 0.0, 0.0];
            f.1.set(0);
            for _ in 0..100 {
                let stats = m.integrate(&f, 0.0, 0.01, &mut y).expect("run");
                assert_eq!(stats.accepted, n);
            }
            assert!(f.1.get() <= 2, "{n} steps: {} flows", f.1.get());
        }
    }

    /// Damping that changes from one interval to the next (a tracked amplitude) and steps of
    /// another size: the cached flows follow, the same values as a fresh integrator's.
    #[test]
    fn exp_rk4_flows_follow_the_damping_and_the_step() {
        let (mut kept, mut y_kept, mut y_fresh) =
            (ExpRk4::new(0.004, 100), [0.1, 0.0, 0.0], [0.1, 0.0, 0.0]);
        for k in 0..50 {
            let f = Duffing {
                w: 5.6,
                c: 0.1 + 0.01 * (k % 7) as f64,
                eps: 100.0,
                force: 0.0,
            };
            let h = if k % 5 == 0 { 0.013 } else { 0.01 };
            kept.integrate(&f, 0.0, h, &mut y_kept).expect("kept");
            ExpRk4::new(0.004, 100)
                .integrate(&f, 0.0, h, &mut y_fresh)
                .expect("fresh");
            assert_eq!(y_kept, y_fresh, "interval {k}");
        }
    }

    /// A quadrature that overflows while every slope stays finite: each error-controlled
    /// method refuses the step (the state is not finite) and leaves the state alone.
    #[test]
    fn an_overflowing_quadrature_is_refused() {
        struct Overflow;
        impl Rhs<2> for Overflow {
            const CONTROLLED: usize = 1;
            fn eval(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
                dy[0] = -y[0];
                dy[1] = f64::MAX;
            }
        }
        fn check<M: Embedded<2>>() {
            let mut m = Adaptive::<2, M>::new(1e-8, [1.0, 0.0], f64::INFINITY, 100);
            // at the largest finite value: any step of more than 1e-16 overflows
            let mut y = [1.0, f64::MAX];
            let r = m.integrate(&Overflow, 0.0, 1.0, &mut y);
            assert!(matches!(r, Err(SolveError::NonFinite { .. })), "{r:?}");
            assert_eq!(y, [1.0, f64::MAX]);
        }
        check::<DormandPrince<2>>();
        check::<Dop853Stages<2>>();
        check::<Sdirk4Stages<2>>();
    }

    /// y' = y^2 blows up at t = 1: the integrator must stop with an error, not return garbage.
    #[test]
    fn blow_up_is_reported() {
        struct BlowUp;
        impl Rhs<1> for BlowUp {
            fn eval(&self, _t: f64, y: &[f64; 1], dy: &mut [f64; 1]) {
                dy[0] = y[0] * y[0];
            }
        }
        let mut dp = Dopri5::new(1e-8, [1.0], f64::INFINITY, 100_000);
        let mut y = [1.0];
        let r = dp.integrate(&BlowUp, 0.0, 2.0, &mut y);
        assert!(r.is_err(), "{r:?} {y:?}");
        assert_eq!(y, [1.0]);
    }
}
