//! Auto: per interval, the explicit Dormand-Prince 5(4) where it is efficient, the L-stable
//! SDIRK4 where the local stiffness makes explicit steps collapse.
//!
//! Two tests decide. Before an interval: the explicit method's carried step times the local
//! stiffness |lambda| (from the system); above 3.3, the edge of DOPRI5's stability region, its
//! steps are set by stability, not accuracy, and the implicit method takes the interval. During
//! it: the explicit attempt gets a bounded budget of steps; if it runs out, the interval is
//! redone implicitly (the wasted work is bounded by the budget).

use nalgebra::{Const, DimMin};

use super::{Dopri5, Rhs, Sdirk4, SolveError, SolveStats};

/// |h lambda| beyond which DOPRI5 is stability-bound.
const STABILITY_LIMIT: f64 = 3.3;
/// Explicit steps per interval before it counts as stiff.
const EXPLICIT_BUDGET: u64 = 2000;

#[derive(Clone, Debug, PartialEq)]
pub struct Auto<const N: usize> {
    explicit: Dopri5<N>,
    implicit: Sdirk4<N>,
    max_steps: u64,
    /// Intervals taken by the implicit method so far.
    pub implicit_intervals: u64,
}

impl<const N: usize> Auto<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    pub fn new(rtol: f64, abs_scale: [f64; N], max_step: f64, max_steps: u64) -> Self {
        Auto {
            explicit: Dopri5::new(rtol, abs_scale, max_step, max_steps.min(EXPLICIT_BUDGET)),
            implicit: Sdirk4::new(rtol, abs_scale, max_step, max_steps),
            max_steps,
            implicit_intervals: 0,
        }
    }

    /// Carried step sizes (explicit, implicit), for saving the state.
    pub fn carried_steps(&self) -> [f64; 2] {
        [self.explicit.carried_step(), self.implicit.carried_step()]
    }

    pub fn set_carried_steps(&mut self, h: [f64; 2]) {
        self.explicit.set_carried_step(h[0]);
        self.implicit.set_carried_step(h[1]);
    }

    /// Advance `y` from `t0` to `t1`. On error `y` is left unchanged.
    pub fn integrate<F: Rhs<N>>(
        &mut self,
        f: &F,
        t0: f64,
        t1: f64,
        y: &mut [f64; N],
    ) -> Result<SolveStats, SolveError> {
        let h = self.explicit.carried_step();
        let stability_bound = h > 0.0 && h * f.stiffness(t0, y) > STABILITY_LIMIT;
        let mut spent = SolveStats::default();
        if !stability_bound {
            match self.explicit.integrate(f, t0, t1, y) {
                // The budget ran out while the caller's bound was not reached: stiff.
                Err(SolveError::TooManySteps { limit, .. }) if limit < self.max_steps => {
                    spent.rejected = limit;
                }
                other => return other,
            }
        }
        let mut stats = self.implicit.integrate(f, t0, t1, y)?;
        self.implicit_intervals += 1;
        stats.rejected += spent.rejected;
        Ok(stats)
    }
}
