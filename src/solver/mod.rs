//! Integrators, generic over a small right-hand-side trait. They know nothing of the model
//! behind the trait nor of FMI.

mod dopri5;
mod rk4;

pub use dopri5::Dopri5;
pub use rk4::Rk4;

/// y' = f(t, y) for a state of fixed size N.
pub trait Rhs<const N: usize> {
    fn eval(&self, t: f64, y: &[f64; N], dy: &mut [f64; N]);
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

pub(crate) fn all_finite<const N: usize>(y: &[f64; N]) -> bool {
    y.iter().all(|v| v.is_finite())
}
