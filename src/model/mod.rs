//! The damper's models behind one contract. Each model is a module with a type implementing
//! [`Model`]; [`registry`] lists them under their `model` items; [`Damper`] adds what every
//! model shares (damping law, amplitude tracking, mean force, energies at the start, the saved
//! state's frame). Knows no FMI: parameters arrive through [`Parameters`] by value reference.

mod common;
pub mod continuous;
mod damper;
pub mod events;
mod parameters;
mod rates;
mod registry;

pub mod auto;
pub mod linear;
pub mod nonlinear;
pub mod shallow_water;
pub mod slamming;

#[cfg(test)]
mod wiring_tests;

pub use common::{AmplitudeSource, Common, Derived};
pub use damper::{Damper, PER_STEP, Report, Unknown};
pub use parameters::{Parameters, StartValues, choice};
pub use registry::AnyModel;

use crate::physics::base::BaseAcceleration;
use crate::solver::{SolveError, SolveStats};

/// Base motion over a communication step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Inputs {
    /// Absolute acceleration of the tank at the step's start [m/s^2].
    pub a: f64,
    /// Its velocity [m/s] (0: not connected; the amplitude tracker then rebuilds it).
    pub v: f64,
    /// First and second time derivatives of `a` at the step's start (0: held).
    pub a_derivatives: [f64; 2],
}

/// Where base.a and base.v are in memory for a step, a place that outlives it (the host's
/// values, or an [`Inputs`]): [`Damper::step_at`] reads base.a from there before the step, and
/// both again after it for the amplitude tracker, with nothing copied for the step.
#[derive(Clone, Copy, Debug)]
pub struct InputAt<'a> {
    pub a: &'a f64,
    pub v: &'a f64,
}

/// The outputs of the damper.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    // The three a master reads after every step come first: their discriminants index the
    // damper's array of them (`Damper::per_step_output`, a load with no branch on which).
    /// Force of the liquid on the tanks [N].
    Force,
    /// Relative displacement [m] and velocity [m/s] of the (fundamental) sloshing mass.
    X,
    V,
    /// Impulse of `Force` over the last step / its length [N].
    ForceMean,
    /// `Force` minus the inertia of the liquid that moves with the tanks [N].
    BaseShear,
    /// Energies [J]: work input, dissipated, stored.
    EnergyInput,
    EnergyDissipated,
    EnergyStored,
    /// Excitation amplitude in use [m].
    Amplitude,
    /// Damping ratio in use.
    Zeta,
    /// S^2: position of the impact mass relative to the tank centre [m], and impacts so far.
    ImpactZ,
    Impacts,
    /// S^2: momentum the impacts handed to the tanks so far [N s].
    ImpactImpulse,
    /// Wave height above the still level at the walls x = 0 and x = a [m].
    SurfaceLeft,
    SurfaceRight,
}

/// The quantities of a model's state that the outputs are made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Observable {
    /// Work done by the base since the start [J].
    WorkIn,
    /// Energy dissipated since the start [J].
    Dissipated,
    /// Kinetic plus potential energy now [J].
    Stored,
    /// S^2's impact mass: position [m] and impacts so far (0 for the other models).
    ImpactZ,
    Impacts,
    /// S^2: momentum the impacts handed to the tanks so far [N s] (0 for the other models).
    ImpactImpulse,
}

/// Why a communication step was refused. The model is left as it was before the step.
#[derive(Clone, Debug, PartialEq)]
pub enum StepError {
    /// The integrator could not finish the step within its bounds; a smaller step may work.
    Solver(SolveError),
    /// The sloshing displacement left any physical range: the model is meaningless there.
    Runaway { x: f64, limit: f64 },
    /// S^2 impacts did not come to rest within the step's bound.
    Chattering(String),
}

impl std::fmt::Display for StepError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StepError::Solver(e) => write!(f, "{e}"),
            StepError::Runaway { x, limit } => write!(
                f,
                "the sloshing displacement ran away to {x:e} m (limit {limit} m, 100 tank lengths)"
            ),
            StepError::Chattering(why) => write!(f, "{why}"),
        }
    }
}

/// A communication step as the models take it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Time at the step's start [s] (for messages: each step is integrated in its own time).
    pub t: f64,
    /// Length [s].
    pub h: f64,
    /// Damping ratio over the step.
    pub zeta: f64,
    /// The base acceleration, a polynomial in the step's own time 0..h.
    pub base: BaseAcceleration,
    /// Largest displacement [m] a state may reach before the step is refused as a runaway.
    pub limit: f64,
}

/// What a step hands back besides the new state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stepped {
    pub stats: SolveStats,
    /// Impulse of the force on the tanks over the step [N s].
    pub impulse: f64,
    /// Force on the tanks at the step's end [N].
    pub force: f64,
    /// [`Model::sloshing`] at the step's end.
    pub sloshing: (f64, f64),
}

impl Stepped {
    /// A step taken by an exact solution: one step, no evaluations.
    pub fn exact(impulse: f64, force: f64, sloshing: (f64, f64)) -> Self {
        Stepped {
            stats: SolveStats {
                accepted: 1,
                ..SolveStats::default()
            },
            impulse,
            force,
            sloshing,
        }
    }
}

/// The start of a run as every model sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Start {
    /// Damping ratio at the start.
    pub zeta: f64,
    /// Excitation amplitude at the start [m].
    pub amplitude: f64,
}

/// One model of the damper. A model knows its own parameters (read once, in `configure`), its
/// state, and how to step it; everything about FMI and the shared laws is elsewhere.
pub trait Model: Sized {
    /// The model with its own parameters read from `p` (the shared ones are in `common`), in its
    /// initial state. Err: the parameters cannot be simulated, with the reason.
    fn configure(p: &dyn Parameters, common: &Common, start: Start) -> Result<Self, String>;

    /// Mass of the liquid that sloshes, all tanks [kg].
    fn sloshing_mass(&self) -> f64;

    /// Advance over `step`. All or nothing: on error the model is unchanged.
    fn step(&mut self, step: &Interval) -> Result<Stepped, StepError>;

    /// Relative displacement and velocity of the (fundamental) sloshing mass.
    fn sloshing(&self) -> (f64, f64);

    /// Force of the liquid on the tanks at the current state [N].
    fn force(&self) -> f64;

    /// Mass that moves with the tanks beyond the inactive liquid now (S^2: the impact mass
    /// resting on a wall) [kg].
    fn rigid_mass(&self) -> f64 {
        0.0
    }

    fn observe(&self, which: Observable) -> f64;

    /// Wave heights at the walls x = 0 and x = a [m], for a model that resolves the surface;
    /// None: the damper shows the fundamental mode's from x (its rates then from x's).
    fn surface(&self) -> Option<[f64; 2]> {
        None
    }

    /// Exact first time derivative of `which` now, with base acceleration `a` and its rate
    /// `a_rate`; only the outputs the model's state makes (force, x, v, energies).
    fn rate(&self, which: Output, a: f64, a_rate: f64) -> f64;

    /// The damping ratio of the last step (after a restore: the model keeps it for `rate`).
    fn set_damping(&mut self, zeta: f64);

    /// Numbers of [`Model::save`].
    fn state_len(&self) -> usize;

    /// Append what evolves (what the configuration does not determine).
    fn save(&self, out: &mut Vec<f64>);

    /// Take the state [`Model::save`] wrote (exactly `state_len` finite numbers).
    fn load(&mut self, state: &[f64]) -> Result<(), String>;

    /// A number the model carries beyond [`Model::save`]'s, whose layout tests/golden pins:
    /// S^2's impulse handed to the tank so far, per unit impact mass (impact.impulse). Saved
    /// apart; 0 for the models without one.
    fn extra(&self) -> f64 {
        0.0
    }

    /// Take [`Model::extra`] back: a finite number, only 0 for a model without one.
    fn load_extra(&mut self, x: f64) -> Result<(), String> {
        if x == 0.0 {
            Ok(())
        } else {
            Err(format!(
                "an impact impulse ({x}) for a model without impacts"
            ))
        }
    }
}

/// Refuse a step whose sloshing displacement left any physical range.
pub(crate) fn check_runaway(x: f64, limit: f64) -> Result<(), StepError> {
    if x.is_nan() || x.abs() > limit {
        Err(StepError::Runaway { x, limit })
    } else {
        Ok(())
    }
}
