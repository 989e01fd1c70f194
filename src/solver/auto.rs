//! Auto: per interval, the explicit Dormand-Prince 5(4) where it is efficient, the L-stable
//! SDIRK4 where the local stiffness makes explicit steps collapse.
//!
//! The explicit attempt at an interval gets a bounded budget of steps; if it runs out, the
//! problem is stiff there and the interval is redone implicitly (the wasted work is bounded by
//! the budget). The following intervals stay implicit as long as the implicit steps are long
//! against the local time scale (h |lambda| above 3.3, the edge of DOPRI5's stability region,
//! |lambda| from the system), and go back to the explicit method when they are not.

use nalgebra::{Const, DimMin};

use super::{Dopri5, Rhs, Sdirk4, SolveError, SolveStats};

/// |h lambda| beyond which DOPRI5 would be stability-bound.
const STABILITY_LIMIT: f64 = 3.3;
/// Explicit steps per interval before it counts as stiff.
const EXPLICIT_BUDGET: u64 = 2000;

#[derive(Clone, Debug, PartialEq)]
pub struct Auto<const N: usize> {
    explicit: Dopri5<N>,
    implicit: Sdirk4<N>,
    max_steps: u64,
    /// The last interval needed the implicit method.
    stiff: bool,
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
            stiff: false,
            implicit_intervals: 0,
        }
    }

    /// What is carried between intervals (explicit and implicit step sizes, and 1 if the last
    /// interval was stiff), for saving the state.
    pub fn memory(&self) -> [f64; 3] {
        [
            self.explicit.carried_step(),
            self.implicit.carried_step(),
            f64::from(u8::from(self.stiff)),
        ]
    }

    pub fn set_memory(&mut self, m: [f64; 3]) {
        self.explicit.set_carried_step(m[0]);
        self.implicit.set_carried_step(m[1]);
        self.stiff = m[2] == 1.0;
    }

    /// Advance `y` from `t0` to `t1`. On error `y` is left unchanged.
    pub fn integrate<F: Rhs<N>>(
        &mut self,
        f: &F,
        t0: f64,
        t1: f64,
        y: &mut [f64; N],
    ) -> Result<SolveStats, SolveError> {
        let still_stiff =
            self.stiff && self.implicit.carried_step() * f.stiffness(t0, y) > STABILITY_LIMIT;
        let mut spent = SolveStats::default();
        if !still_stiff {
            match self.explicit.integrate(f, t0, t1, y) {
                // The budget ran out while the caller's bound was not reached: stiff.
                Err(SolveError::TooManySteps { limit, .. }) if limit < self.max_steps => {
                    spent.rejected = limit;
                }
                other => {
                    if other.is_ok() {
                        self.stiff = false;
                    }
                    return other;
                }
            }
        }
        let mut stats = self.implicit.integrate(f, t0, t1, y)?;
        self.stiff = true;
        self.implicit_intervals += 1;
        stats.rejected += spent.rejected;
        Ok(stats)
    }
}
