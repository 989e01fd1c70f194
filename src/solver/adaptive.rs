//! Step-size control shared by the embedded methods: the method supplies one attempted step and
//! its error estimate; this driver chooses step sizes, lands exactly on the interval's end,
//! bounds the work and carries the step size to the next interval.

use super::{Rhs, SolveError, SolveStats, all_finite_in};

/// Error tolerance and work bounds of an adaptive integrator.
#[derive(Clone, Debug, PartialEq)]
pub struct Controls<const N: usize> {
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
}

impl<const N: usize> Controls<N> {
    /// RMS of the controlled components of `e`, each over its tolerance at y0 and y1, among
    /// the first `leading` (a right-hand side's [`Rhs::CONTROLLED`]: the rest have abs_scale 0).
    #[inline(always)]
    pub fn norm(&self, leading: usize, e: &[f64; N], y0: &[f64; N], y1: &[f64; N]) -> f64 {
        let (mut sum, mut n) = (0.0, 0usize);
        for i in 0..leading.min(N) {
            if self.abs_scale[i] > 0.0 {
                // The larger magnitude; a NaN in y1 (a failed step's state) gives NaN. Not
                // f64::max, which would take y0's then: its NaN test costs five instructions
                // per component on every step, and the driver rejects a non-finite y1 anyway.
                let (a, b) = (y0[i].abs(), y1[i].abs());
                let sc = self.rtol * (self.abs_scale[i] + if a > b { a } else { b });
                sum += (e[i] / sc).powi(2);
                n += 1;
            }
        }
        if n == 0 { 0.0 } else { (sum / n as f64).sqrt() }
    }
}

/// One embedded Runge-Kutta method, as the driver sees it.
pub trait Embedded<const N: usize>: Default {
    /// Order of the error estimate plus one: the step factor is err^(-1/ORDER).
    const ORDER: f64;

    /// Below this error the step factor SAFETY err^(-1/ORDER) is past its cap MAX_GROWTH for
    /// sure (a margin under (SAFETY/MAX_GROWTH)^ORDER): the usual case when the communication
    /// step is shorter than the natural step, and it saves a libm pow per step.
    const GROWS_FULLY_BELOW: f64 = 0.99 * powi_const(SAFETY / MAX_GROWTH, ceil_u32(Self::ORDER));

    /// Start of an interval at (t, y): f(t, y) into `f0` (a method may keep it, FSAL).
    fn begin<F: Rhs<N>>(&mut self, f: &F, t: f64, y: &[f64; N], f0: &mut [f64; N]);

    /// Attempt a step of `h` from (t, y): the new state into `y_new`, the error estimate into
    /// `err`. Returns false if the attempt failed outright (e.g. Newton did not converge) or
    /// `y_new` is not finite (a method tests it with its own values, in one chain).
    #[allow(clippy::too_many_arguments)]
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
    ) -> bool;

    /// The last attempt was accepted.
    fn accepted(&mut self);
}

/// The step factor after a step with error norm e is SAFETY e^(-1/ORDER), within
/// [MIN_SHRINK, MAX_GROWTH] (and at most 1 right after a rejection).
const SAFETY: f64 = 0.9;
const MIN_SHRINK: f64 = 0.2;
const MAX_GROWTH: f64 = 5.0;

/// f64::min(a, b) for an `a` that is not NaN (a step size), without f64::min's NaN test of `a`
/// on every step: a NaN `b` still gives `a`.
#[inline(always)]
fn at_most(a: f64, b: f64) -> f64 {
    if b < a { b } else { a }
}

/// f64::max(a, b) for an `a` that is not NaN, as [`at_most`].
#[inline(always)]
fn at_least(a: f64, b: f64) -> f64 {
    if b > a { b } else { a }
}

/// The smallest integer >= x >= 0, usable in constants.
const fn ceil_u32(x: f64) -> u32 {
    let n = x as u32;
    if (n as f64) < x { n + 1 } else { n }
}

/// x^n, usable in constants.
const fn powi_const(x: f64, n: u32) -> f64 {
    let mut out = 1.0;
    let mut k = 0;
    while k < n {
        out *= x;
        k += 1;
    }
    out
}

/// An error-controlled integrator: an embedded method `M` under this module's step-size
/// control. The last accepted step size is carried from one interval to the next, so
/// consecutive communication steps do not restart from scratch.
#[derive(Clone, Debug, PartialEq)]
pub struct Adaptive<const N: usize, M> {
    pub controls: Controls<N>,
    h_next: f64,
    method: std::marker::PhantomData<M>,
}

impl<const N: usize, M: Embedded<N>> Adaptive<N, M> {
    pub fn new(rtol: f64, abs_scale: [f64; N], max_step: f64, max_steps: u64) -> Self {
        Adaptive {
            controls: Controls {
                rtol,
                abs_scale,
                max_step,
                max_steps,
            },
            h_next: 0.0,
            method: std::marker::PhantomData,
        }
    }

    /// The step size carried into the next interval (0: none yet), for saving the state.
    pub fn carried_step(&self) -> f64 {
        self.h_next
    }

    /// Restore a carried step size saved with [`Adaptive::carried_step`].
    pub fn set_carried_step(&mut self, h: f64) {
        self.h_next = if h.is_finite() && h > 0.0 { h } else { 0.0 };
    }

    /// Advance `y` from `t0` to `t1` (> t0) to tolerance. On error `y` and the carried step
    /// size are left unchanged.
    #[inline(never)]
    pub fn integrate<F: Rhs<N>>(
        &mut self,
        f: &F,
        t0: f64,
        t1: f64,
        y: &mut [f64; N],
    ) -> Result<SolveStats, SolveError> {
        self.integrate_inlined(f, t0, t1, y)
    }

    /// [`Adaptive::integrate`] inlined into the caller, for a cheap explicit method: with the
    /// caller's copy of the state and its checks in the same function, the stages and the
    /// state stay in registers (an implicit method's linear algebra is better left where the
    /// compiler puts it).
    #[inline(always)]
    pub fn integrate_inlined<F: Rhs<N>>(
        &mut self,
        f: &F,
        t0: f64,
        t1: f64,
        y: &mut [f64; N],
    ) -> Result<SolveStats, SolveError> {
        integrate(
            &mut M::default(),
            &self.controls,
            &mut self.h_next,
            f,
            t0,
            t1,
            y,
        )
    }
}

/// Starting step from the size of y and y' (Hairer, Norsett & Wanner I, II.4).
fn initial_step<const N: usize, F: Rhs<N>>(
    ctl: &Controls<N>,
    order: f64,
    f: &F,
    t: f64,
    y: &[f64; N],
    f0: &[f64; N],
    span: f64,
) -> f64 {
    let zero = [0.0; N];
    let d0 = ctl.norm(F::CONTROLLED, y, &zero, &zero);
    let d1 = ctl.norm(F::CONTROLLED, f0, y, y);
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
    let d2 = ctl.norm(F::CONTROLLED, &df, y, y);
    // Nothing moves: any step is exact, so take the whole interval.
    let h1 = if d1.max(d2) <= 1e-15 {
        span
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / order)
    };
    let h = (100.0 * h0).min(h1);
    if h.is_finite() && h > 0.0 {
        h
    } else {
        1e-6 * span
    }
}

/// Whether the step size an accepted step of `hs` with error norm `e` proposes, SAFETY
/// e^(-1/order) hs before its caps (which only shorten it, or bound it by MIN_SHRINK hs), is
/// surely below `h` > `hs`: e >= (SAFETY hs / h)^order, with a margin (1e-9 relative) far above
/// the rounding of either side, so that max(h, proposal) is h to the bit. Multiplications
/// only (an integer order): a tight tolerance's factor otherwise costs a libm pow per step.
#[inline(always)]
fn proposal_below(order: f64, e: f64, hs: f64, h: f64) -> bool {
    let n = order as i32;
    f64::from(n) == order && e >= (1.0 + 1e-9) * (SAFETY * hs / h).powi(n)
}

/// Advance `y` from `t0` to `t1` (> t0) to tolerance with `method`, starting from the carried
/// step `*h_next` (0: choose). On error `y` and `*h_next` are left unchanged.
#[inline(always)]
fn integrate<const N: usize, M: Embedded<N>, F: Rhs<N>>(
    method: &mut M,
    ctl: &Controls<N>,
    h_next: &mut f64,
    f: &F,
    t0: f64,
    t1: f64,
    y: &mut [f64; N],
) -> Result<SolveStats, SolveError> {
    debug_assert!(
        ctl.abs_scale[F::CONTROLLED.min(N)..]
            .iter()
            .all(|&s| s == 0.0),
        "components past Rhs::CONTROLLED are not error-controlled"
    );
    let span = t1 - t0;
    let mut stats = SolveStats::default();
    let mut z = *y;
    let mut f0 = [0.0; N];
    method.begin(f, t0, &z, &mut f0);
    stats.evaluations += 1;
    if !all_finite_in([&f0, &z]) {
        return Err(SolveError::NonFinite { t: t0 });
    }
    let mut h = if *h_next > 0.0 {
        *h_next
    } else {
        initial_step(ctl, M::ORDER, f, t0, &z, &f0, span)
    };
    h = at_most(h, ctl.max_step);
    let mut t = t0;
    let (mut y_new, mut err) = ([0.0; N], [0.0; N]);
    let mut just_rejected = false;
    let carried = loop {
        if stats.accepted + stats.rejected >= ctl.max_steps {
            return Err(SolveError::TooManySteps {
                limit: ctl.max_steps,
                t,
            });
        }
        let remaining = t1 - t;
        let last = h >= remaining;
        let hs = if last { remaining } else { h };
        let ok = method.attempt(f, t, &z, hs, &mut y_new, &mut err, ctl, &mut stats);
        let e = if ok {
            ctl.norm(F::CONTROLLED, &err, &z, &y_new)
        } else {
            f64::INFINITY
        };
        if e <= 1.0 {
            stats.accepted += 1;
            method.accepted();
            z = y_new;
            if last && hs < h && proposal_below(M::ORDER, e, hs, h) {
                // Cut short to land on t1 (below), and the proposal surely shorter than h: the
                // carried step is h, the same bits without the step factor's libm pow.
                break h;
            }
            let fac = if e <= M::GROWS_FULLY_BELOW {
                MAX_GROWTH
            } else {
                (SAFETY * e.powf(-1.0 / M::ORDER)).clamp(MIN_SHRINK, MAX_GROWTH)
            };
            let fac = if just_rejected { fac.min(1.0) } else { fac };
            just_rejected = false;
            let proposal = at_most(hs * fac, ctl.max_step);
            if last {
                // A step cut short to land on t1 says little about the natural step.
                break if hs < h {
                    at_least(h, proposal)
                } else {
                    proposal
                };
            }
            t += hs;
            h = proposal;
        } else {
            stats.rejected += 1;
            just_rejected = true;
            let fac = if e.is_finite() {
                (SAFETY * e.powf(-1.0 / M::ORDER)).clamp(MIN_SHRINK, 1.0)
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
    *h_next = carried;
    Ok(stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::dop853::Dop853Stages;
    use crate::solver::dopri5::DormandPrince;
    use crate::solver::sdirk4::Sdirk4Stages;

    /// The norm against its formula with f64::max, bit for bit, over finite states of every
    /// kind; a NaN in the new state gives NaN.
    #[test]
    fn the_norm_takes_the_larger_magnitude() {
        let ctl = Controls {
            rtol: 1e-7,
            abs_scale: [0.125, 2.0, 0.0],
            max_step: 1.0,
            max_steps: 10,
        };
        let values = [0.0, -0.0, 5e-324, -3.5, 2.25, 1e300, -f64::MAX];
        for &a in &values {
            for &b in &values {
                let (y0, y1, e) = ([a, b, 1.0], [b, -a, 7.0], [1e-9, -3e-8, 1.0]);
                let want = ((0..2)
                    .map(|i| {
                        let sc = ctl.rtol * (ctl.abs_scale[i] + y0[i].abs().max(y1[i].abs()));
                        (e[i] / sc).powi(2)
                    })
                    .fold(0.0, |s, t| s + t)
                    / 2.0)
                    .sqrt();
                assert_eq!(
                    ctl.norm(3, &e, &y0, &y1).to_bits(),
                    want.to_bits(),
                    "{a} {b}"
                );
            }
        }
        assert!(
            ctl.norm(3, &[1.0; 3], &[0.5; 3], &[f64::NAN, 0.5, 0.5])
                .is_nan()
        );
    }

    /// at_most and at_least against f64::min and max, bit for bit, for every `a` not NaN.
    #[test]
    fn at_most_and_at_least_are_min_and_max() {
        let values = [0.0, 5e-324, 1e-3, 2.5, f64::MAX, f64::INFINITY, -1.0];
        for a in values {
            for b in values.into_iter().chain([f64::NAN]) {
                assert_eq!(at_most(a, b).to_bits(), a.min(b).to_bits(), "{a} {b}");
                assert_eq!(at_least(a, b).to_bits(), a.max(b).to_bits(), "{a} {b}");
            }
        }
    }

    #[test]
    fn the_full_growth_shortcut_agrees_with_the_formula() {
        // Below the shortcut's bound the step factor formula is capped at 5, for every method.
        for (bound, order) in [
            (<DormandPrince<2> as Embedded<2>>::GROWS_FULLY_BELOW, 5.0),
            (<Dop853Stages<2> as Embedded<2>>::GROWS_FULLY_BELOW, 8.0),
            (<Sdirk4Stages<2> as Embedded<2>>::GROWS_FULLY_BELOW, 4.0),
        ] {
            for e in [bound, 0.5 * bound, 1e-3 * bound, f64::MIN_POSITIVE] {
                assert_eq!(
                    (0.9 * e.powf(-1.0_f64 / order)).clamp(0.2, 5.0),
                    5.0,
                    "{order} {e}"
                );
            }
            // and it starts just under where the cap does
            assert!(bound > 0.98 * 0.18f64.powf(order), "{order}: {bound}");
        }
        assert_eq!(ceil_u32(4.0), 4);
        assert_eq!(ceil_u32(4.5), 5);
    }

    /// The carried step as the driver forms it for a last step cut short (hs < h) with error
    /// norm `e`, the factor from its formula.
    fn carried_in_full(order: f64, e: f64, hs: f64, h: f64, just_rejected: bool) -> f64 {
        let fac = (SAFETY * e.powf(-1.0 / order)).clamp(MIN_SHRINK, MAX_GROWTH);
        let fac = if just_rejected { fac.min(1.0) } else { fac };
        h.max(hs * fac)
    }

    /// Wherever `proposal_below` says so, the full formula's carried step is h to the bit:
    /// error norms spread over 16 decades and packed around each threshold (within 1e-6
    /// relative of it, both sides), for the orders of the three methods; and it says so for
    /// most of them (the shortcut is taken) and not for norms just under the threshold.
    #[test]
    fn the_carried_step_shortcut_is_the_formula_to_the_bit() {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut uniform = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut taken, mut refused_near) = (0, 0);
        for order in [5.0, 8.0, 4.0] {
            for k in 0..40_000 {
                let hs = 1e-3 * (0.5 + uniform());
                let h = hs * (1.0 + 6.0 * uniform());
                let threshold = (SAFETY * hs / h).powf(order);
                let e = if k % 2 == 0 {
                    10f64.powf(-16.0 * uniform())
                } else {
                    threshold * (1.0 + 2e-6 * (uniform() - 0.5))
                };
                if e > 1.0 {
                    continue;
                }
                let shortcut = proposal_below(order, e, hs, h);
                for just_rejected in [false, true] {
                    if shortcut {
                        let full = carried_in_full(order, e, hs, h, just_rejected);
                        assert_eq!(full.to_bits(), h.to_bits(), "{order} {e} {hs} {h}");
                    }
                }
                taken += usize::from(shortcut);
                refused_near += usize::from(!shortcut && e < threshold);
            }
        }
        assert!(taken > 40_000, "{taken}");
        assert!(refused_near > 10_000, "{refused_near}");
        // Not an integer order: never taken.
        assert!(!proposal_below(4.5, 1.0, 1e-3, 1e-2));
    }
}
