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
    bound: StepBound,
    formula: PhantomData<M>,
}

/// How [`fixed_steps`] cuts an interval: into equal steps no longer than `max_step`, at most
/// `max_steps` of them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct StepBound {
    max_step: f64,
    max_steps: u64,
    /// Steps per unit of time: 1/max_step less a relative 1e-12, so that an interval a hair
    /// longer than n steps (by the rounding of the host's time) still takes n. Formed once: a
    /// division in every interval would be on the path to its first step.
    per_step: f64,
}

impl StepBound {
    pub(super) fn new(max_step: f64, max_steps: u64) -> Self {
        StepBound {
            max_step,
            max_steps,
            per_step: (1.0 - 1e-12) / max_step,
        }
    }
}

/// Classical fourth-order Runge-Kutta with a fixed internal step.
pub type Rk4 = FixedStep<Classical>;

impl<M: Formula> FixedStep<M> {
    pub fn new(max_step: f64, max_steps: u64) -> Self {
        FixedStep {
            bound: StepBound::new(max_step, max_steps),
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
        fixed_steps(t0, t1, &self.bound, M::EVALS, y, &mut formula)
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
/// as `bound` cuts it. On error `y` is left unchanged.
#[inline(always)]
pub(super) fn fixed_steps<const N: usize>(
    t0: f64,
    t1: f64,
    bound: &StepBound,
    evals: u64,
    y: &mut [f64; N],
    method: &mut impl OneStep<N>,
) -> Result<SolveStats, SolveError> {
    let StepBound {
        max_step,
        max_steps,
        per_step,
    } = *bound;
    let span = t1 - t0;
    // One step when the interval fits: the common case, kept free of the step count.
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
    // n = ceil(q) steps, and ceil(q) <= max_steps exactly when q <= max_steps. The step size
    // waits for n: formed with a product and in floating point (see ceil_count), two
    // substeps took 0.87x the time of a quotient and an integer round trip.
    let q = span * per_step;
    if q.is_nan() || q > max_steps as f64 {
        return Err(SolveError::TooManySteps {
            limit: max_steps,
            t: t0,
        });
    }
    let count = ceil_count(q);
    let h = span / count;
    let n = count as i64;
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

/// ceil(q), at least 1, as a float, for q not NaN: without libm's ceil (a call on baseline
/// x86-64) and without a round trip through an integer (two conversions in a row).
#[inline(always)]
fn ceil_count(q: f64) -> f64 {
    // Every float from 2^52 up is whole; below it, adding and removing 2^52 rounds q to a
    // nearest whole number.
    const WHOLE: f64 = 4_503_599_627_370_496.0;
    let c = if q < WHOLE {
        let r = (q + WHOLE) - WHOLE;
        if r < q { r + 1.0 } else { r }
    } else {
        q
    };
    if c < 1.0 { 1.0 } else { c }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The float-only ceil is libm's ceil (at least 1) wherever the count can be: whole
    /// numbers and their neighbours a few ulps away, fractions of every magnitude, the top
    /// of the exactly representable integers and beyond, and what is not a count.
    #[test]
    fn ceil_count_is_ceil() {
        let mut qs = vec![0.0, -0.0, -1.0, -3.7, 1e-300, 0.25, 0.5, 0.999_999, 1e300];
        qs.extend([
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN_POSITIVE,
        ]);
        for k in [
            1.0,
            2.0,
            3.0,
            7.0,
            1000.0,
            1e6,
            2f64.powi(51),
            2f64.powi(52),
            2f64.powi(60),
        ] {
            let (mut up, mut down) = (k, k);
            for _ in 0..4 {
                qs.extend([up, down, up + 0.5, down - 0.5]);
                up = up.next_up();
                down = down.next_down();
            }
        }
        // fractions over every scale, from a fixed-seed sequence
        let mut bits: u64 = 0x9e37_79b9_7f4a_7c15;
        for _ in 0..100_000 {
            bits ^= bits << 13;
            bits ^= bits >> 7;
            bits ^= bits << 17;
            let q = (bits >> 11) as f64 / (1u64 << 53) as f64 * 2f64.powi((bits % 64) as i32);
            qs.push(q);
        }
        for q in qs {
            assert_eq!(ceil_count(q), q.ceil().max(1.0), "q = {q:e}");
        }
    }

    /// x' = 1: the state at the end counts the time integrated.
    struct Clock;
    impl Rhs<1> for Clock {
        fn eval(&self, _t: f64, _y: &[f64; 1], dy: &mut [f64; 1]) {
            dy[0] = 1.0;
        }
    }

    /// An interval of n steps by the host's rounding takes n of them, one a hair longer than
    /// the tolerance takes n + 1, and the bound refuses one step more than it allows.
    #[test]
    fn intervals_take_the_steps_their_length_needs() {
        for max_step in [1e-3, 5e-4, 2.5e-4, 1.0 / 3.0, 0.1, 0.01, 7.3e-5] {
            for n in 1..=400_u64 {
                let run = |span: f64, bound: u64| {
                    let mut y = [0.0];
                    Rk4::new(max_step, bound)
                        .integrate(&Clock, 0.0, span, &mut y)
                        .map(|stats| (stats.accepted, stats.evaluations, y[0]))
                };
                for span in [n as f64 * max_step, (0..n).map(|_| max_step).sum::<f64>()] {
                    let (steps, evaluations, end) = run(span, n).expect("n steps allowed");
                    assert_eq!((steps, evaluations), (n, 4 * n), "{n} x {max_step}");
                    assert!((end - span).abs() <= 1e-12 * span, "{end} {span}");
                    if n > 1 {
                        let refused = run(span, n - 1);
                        assert!(
                            matches!(refused, Err(SolveError::TooManySteps { limit, .. }) if limit == n - 1),
                            "{refused:?}"
                        );
                    }
                }
                let longer = n as f64 * max_step * (1.0 + 1e-9);
                assert_eq!(
                    run(longer, n + 1).expect("run").0,
                    n + 1,
                    "{n} x {max_step}"
                );
            }
        }
    }
}
