//! The Model Exchange side of the contract between the shared FMI layer and one FMU: what a
//! slave answers when the host's own solver integrates it (continuous states, derivatives,
//! nominals, event indicators, the event update, directional derivatives). Every method has a
//! default that says "not offered", so a slave offers Model Exchange by overriding them; the
//! layer has checked the call's phase, the host's pointers and the array lengths (the numbers
//! of states and event indicators the model description declares) before any method runs.

use crate::slave::Context;
use crate::status::{Refusal, Reply, Status, refuse};

/// What fmi2NewDiscreteStates tells the host.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EventUpdate {
    /// The continuous states were changed at the event (re-read them).
    pub states_changed: bool,
    /// Time of the next time event, if any.
    pub next_event: Option<f64>,
}

/// Model Exchange for one FMU; the defaults refuse it.
pub trait Continuous: Sized {
    /// Continuous states and event indicators, as the model description declares them.
    const STATES: usize = 0;
    const EVENT_INDICATORS: usize = 0;
    /// What a Model Exchange instance offers and does not (which models, why), logged by
    /// fmi2Instantiate for Model Exchange when logging is on.
    const MODEL_EXCHANGE_NOTE: Option<&'static str> = None;

    /// Whether the simulation just initialised can run in Model Exchange: Err(reason) if not
    /// (fmi2ExitInitializationMode of a Model Exchange instance then refuses, with the reason).
    fn offers_model_exchange(&self) -> Result<(), String> {
        Err("this FMU does not offer Model Exchange".into())
    }

    /// The continuous states into `x` (exactly [`Continuous::STATES`] long).
    fn states(&self, x: &mut [f64]) -> Reply {
        let _ = x;
        Err(not_offered("fmi2GetContinuousStates"))
    }

    /// Take the continuous states `x` (finite, exactly STATES long); all or nothing.
    fn set_states(&mut self, context: &Context, x: &[f64]) -> Reply {
        let _ = (context, x);
        Err(not_offered("fmi2SetContinuousStates"))
    }

    /// The states' time derivatives at `context.time`, the states and the inputs now.
    fn derivatives(&self, context: &Context, dx: &mut [f64]) -> Reply {
        let _ = (context, dx);
        Err(not_offered("fmi2GetDerivatives"))
    }

    /// Nominal magnitudes of the states (for the host's error control).
    fn nominals(&self, out: &mut [f64]) -> Reply {
        out.fill(1.0);
        Ok(Status::Ok)
    }

    /// The event indicators now (a state event where one changes sign).
    fn event_indicators(&self, context: &Context, out: &mut [f64]) -> Reply {
        let _ = context;
        out.fill(1.0);
        Ok(Status::Ok)
    }

    /// fmi2CompletedIntegratorStep: the host accepted the states at `context.time`. Ok(true):
    /// the FMU asks for event mode.
    fn completed_step(&mut self, context: &Context) -> Result<bool, Refusal> {
        let _ = context;
        Ok(false)
    }

    /// fmi2NewDiscreteStates: handle the event at `context.time`.
    fn event_update(&mut self, context: &Context) -> Result<EventUpdate, Refusal> {
        let _ = context;
        Ok(EventUpdate::default())
    }

    /// fmi2GetDirectionalDerivative: `dv_unknown` = J `dv_known` for the unknowns' and knowns'
    /// value references (derivatives and outputs; states and inputs).
    fn directional_derivative(
        &self,
        context: &Context,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Reply {
        let _ = (context, unknowns, knowns, dv_known, dv_unknown);
        Err(refuse(
            "fmi2GetDirectionalDerivative: providesDirectionalDerivative is false",
        ))
    }
}

#[cold]
fn not_offered(function: &str) -> Refusal {
    refuse(format!(
        "{function}: this FMU does not offer Model Exchange"
    ))
}

#[cfg(test)]
#[path = "continuous_tests.rs"]
mod tests;
