//! Explicit Runge-Kutta formulas with a fixed internal step: each interval is cut into equal
//! steps no longer than a bound, with no error estimate and no rejected steps. Cheapest where
//! the communication step is already short against the dynamics; the higher orders reach
//! round-off in one step there.

use std::marker::PhantomData;

use super::{Rhs, SolveError, SolveStats, all_finite};

/// One step of an explicit Runge-Kutta formula.
pub trait Formula {
    /// Right-hand side evaluations per step.
    const EVALS: u64;

    /// The state after one step of `h` from (t, z).
    fn step<const N: usize, F: Rhs<N>>(f: &F, t: f64, h: f64, z: &[f64; N]) -> [f64; N];
}

/// A formula stepped with equal internal steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedStep<M> {
    /// Largest internal step; each interval is cut into equal steps no longer than this.
    pub max_step: f64,
    /// Most internal steps per interval.
    pub max_steps: u64,
    formula: PhantomData<M>,
}

/// Classical fourth-order Runge-Kutta with a fixed internal step.
pub type Rk4 = FixedStep<Classical>;

impl<M: Formula> FixedStep<M> {
    pub fn new(max_step: f64, max_steps: u64) -> Self {
        FixedStep {
            max_step,
            max_steps,
            formula: PhantomData,
        }
    }

    /// Advance `y` from `t0` to `t1`. On error `y` is left unchanged.
    pub fn integrate<const N: usize, F: Rhs<N>>(
        &self,
        f: &F,
        t0: f64,
        t1: f64,
        y: &mut [f64; N],
    ) -> Result<SolveStats, SolveError> {
        struct Formula<'a, M, F>(&'a F, PhantomData<M>);
        impl<const N: usize, M: self::Formula, F: Rhs<N>> OneStep<N> for Formula<'_, M, F> {
            #[inline(always)]
            fn step(&mut self, t: f64, h: f64, z: &[f64; N]) -> [f64; N] {
                M::step(self.0, t, h, z)
            }
        }
        let mut formula = Formula::<M, F>(f, PhantomData);
        fixed_steps(
            t0,
            t1,
            self.max_step,
            self.max_steps,
            M::EVALS,
            y,
            &mut formula,
        )
    }
}

/// One step of some method, as [`fixed_steps`] repeats it.
pub(super) trait OneStep<const N: usize> {
    /// Called once per interval with the step size all its steps will have.
    #[inline(always)]
    fn prepare(&mut self, _h: f64) {}

    /// The state after one step of `h` from (t, z).
    fn step(&mut self, t: f64, h: f64, z: &[f64; N]) -> [f64; N];
}

/// Advance `y` from `t0` to `t1` by `method`'s steps (`evals` evaluations each) in equal steps
/// no longer than `max_step`, at most `max_steps` of them. On error `y` is left unchanged.
#[inline(always)]
pub(super) fn fixed_steps<const N: usize>(
    t0: f64,
    t1: f64,
    max_step: f64,
    max_steps: u64,
    evals: u64,
    y: &mut [f64; N],
    method: &mut impl OneStep<N>,
) -> Result<SolveStats, SolveError> {
    let span = t1 - t0;
    // One step when the interval fits: the common case, kept free of the step count's
    // integer-float conversions (u64 to f64 takes several instructions on x86-64) and of
    // ceil (a libm call on baseline x86-64).
    if span <= max_step && max_steps >= 1 {
        method.prepare(span);
        let z = method.step(t0, span, y);
        if !all_finite(&z) {
            return Err(SolveError::NonFinite { t: t0 });
        }
        *y = z;
        return Ok(SolveStats {
            accepted: 1,
            rejected: 0,
            evaluations: evals,
        });
    }
    // n = ceil(q) steps, and ceil(q) <= max_steps exactly when q <= max_steps; formed
    // without libm's ceil (a call on baseline x86-64), counted in i64 (one instruction
    // to f64, where u64 takes several).
    let q = span / max_step * (1.0 - 1e-12);
    if q.is_nan() || q > max_steps as f64 {
        return Err(SolveError::TooManySteps {
            limit: max_steps,
            t: t0,
        });
    }
    let whole = q as i64;
    let n = if (whole as f64) < q { whole + 1 } else { whole }.max(1);
    let h = span / n as f64;
    method.prepare(h);
    let mut z = *y;
    for i in 0..n {
        let t = t0 + i as f64 * h;
        z = method.step(t, h, &z);
        if !all_finite(&z) {
            return Err(SolveError::NonFinite { t });
        }
    }
    let n = n as u64;
    *y = z;
    Ok(SolveStats {
        accepted: n,
        rejected: 0,
        evaluations: evals * n,
    })
}

/// The classical fourth-order formula (four evaluations).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Classical;

impl Formula for Classical {
    const EVALS: u64 = 4;

    #[inline(always)]
    fn step<const N: usize, F: Rhs<N>>(f: &F, t: f64, h: f64, z: &[f64; N]) -> [f64; N] {
        let eval = |t: f64, y: &[f64; N]| {
            let mut dy = [0.0; N];
            f.eval(t, y, &mut dy);
            dy
        };
        let half = 0.5 * h;
        let k1 = eval(t, z);
        let k2 = eval(t + half, &std::array::from_fn(|j| z[j] + half * k1[j]));
        let k3 = eval(t + half, &std::array::from_fn(|j| z[j] + half * k2[j]));
        let k4 = eval(t + h, &std::array::from_fn(|j| z[j] + h * k3[j]));
        let sixth = h / 6.0;
        std::array::from_fn(|j| z[j] + sixth * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]))
    }
}
