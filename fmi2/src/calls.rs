//! The FMI 2.0 state machines (Co-Simulation and Model Exchange) as a table: the phases an
//! instance can be in, and for every function the phases in which it may be called (its mask).
//! The exports check the mask before anything else, in one place. A Co-Simulation instance
//! runs in StepComplete, a Model Exchange one in EventMode and ContinuousTimeMode: a function
//! of the other interface is refused by its mask, with the way to the right instance.

/// Phases of the FMI 2.0 state machines this FMU can be in (it never runs asynchronously, and
/// a refused step leaves it in StepComplete at the step's start).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    Instantiated,
    InitializationMode,
    StepComplete,
    Terminated,
    /// Model Exchange: after fmi2ExitInitializationMode and fmi2EnterEventMode.
    EventMode,
    /// Model Exchange: after fmi2EnterContinuousTimeMode, while the host integrates.
    ContinuousTimeMode,
    /// After an internal error (a caught panic): only fmi2Reset and fmi2FreeInstance work.
    Broken,
}

/// Sets of phases, one bit each.
pub mod allow {
    pub const INSTANTIATED: u8 = 1;
    pub const INITIALIZATION: u8 = 2;
    pub const STEP_COMPLETE: u8 = 4;
    pub const TERMINATED: u8 = 8;
    pub const BROKEN: u8 = 16;
    pub const EVENT: u8 = 32;
    pub const CONTINUOUS: u8 = 64;
    pub const NONE: u8 = 0;
    /// Model Exchange's running phases.
    pub const RUNNING_ME: u8 = EVENT | CONTINUOUS;
    pub const ANY: u8 = INSTANTIATED | INITIALIZATION | STEP_COMPLETE | TERMINATED | RUNNING_ME;
    pub const GET: u8 = INITIALIZATION | STEP_COMPLETE | TERMINATED | RUNNING_ME;
    /// Inputs may be set while the host integrates; the table says which variables when.
    pub const SET: u8 = INSTANTIATED | INITIALIZATION | STEP_COMPLETE | RUNNING_ME;
    /// Integer and Boolean variables are discrete: not in continuous-time mode.
    pub const SET_DISCRETE: u8 = INSTANTIATED | INITIALIZATION | STEP_COMPLETE | EVENT;
    /// Co-Simulation's input derivatives.
    pub const SET_CS: u8 = INSTANTIATED | INITIALIZATION | STEP_COMPLETE;
    pub const STATUS: u8 = STEP_COMPLETE | TERMINATED;
    /// Model Exchange's state queries.
    pub const STATES: u8 = RUNNING_ME | TERMINATED;
}

impl Phase {
    pub const fn bit(self) -> u8 {
        match self {
            Phase::Instantiated => allow::INSTANTIATED,
            Phase::InitializationMode => allow::INITIALIZATION,
            Phase::StepComplete => allow::STEP_COMPLETE,
            Phase::Terminated => allow::TERMINATED,
            Phase::Broken => allow::BROKEN,
            Phase::EventMode => allow::EVENT,
            Phase::ContinuousTimeMode => allow::CONTINUOUS,
        }
    }

    /// Whether the instance has been initialised and not reset (a simulation exists).
    pub const fn initialised(self) -> bool {
        matches!(
            self,
            Phase::StepComplete | Phase::Terminated | Phase::EventMode | Phase::ContinuousTimeMode
        )
    }

    fn describe(mask: u8) -> String {
        let names = [
            (allow::INSTANTIATED, "Instantiated"),
            (allow::INITIALIZATION, "InitializationMode"),
            (allow::STEP_COMPLETE, "StepComplete"),
            (allow::TERMINATED, "Terminated"),
            (allow::EVENT, "EventMode"),
            (allow::CONTINUOUS, "ContinuousTimeMode"),
        ];
        let list: Vec<&str> = names
            .iter()
            .filter(|(b, _)| mask & b != 0)
            .map(|(_, n)| *n)
            .collect();
        if list.is_empty() {
            "no state of this FMU".into()
        } else {
            list.join(", ")
        }
    }

    /// What the host should call to reach a phase of `allowed` from this one.
    fn way_to(self, allowed: u8) -> &'static str {
        use allow::*;
        match self {
            Phase::Instantiated if allowed & INITIALIZATION != 0 => {
                " Call fmi2EnterInitializationMode first."
            }
            Phase::Instantiated if allowed & (STEP_COMPLETE | RUNNING_ME) != 0 => {
                " Initialise first: fmi2SetupExperiment, fmi2EnterInitializationMode and fmi2ExitInitializationMode (again after fmi2Reset)."
            }
            Phase::InitializationMode if allowed & (STEP_COMPLETE | RUNNING_ME) != 0 => {
                " Call fmi2ExitInitializationMode first."
            }
            Phase::StepComplete if allowed & RUNNING_ME != 0 => {
                " This is a Co-Simulation instance: Model Exchange functions need an instance made by fmi2Instantiate with fmuType fmi2ModelExchange."
            }
            Phase::EventMode | Phase::ContinuousTimeMode
                if allowed & STEP_COMPLETE != 0 && allowed & RUNNING_ME == 0 =>
            {
                " This is a Model Exchange instance: Co-Simulation functions need an instance made by fmi2Instantiate with fmuType fmi2CoSimulation."
            }
            Phase::EventMode if allowed & CONTINUOUS != 0 => {
                " Call fmi2EnterContinuousTimeMode first (after fmi2NewDiscreteStates reports no new discrete states needed)."
            }
            Phase::ContinuousTimeMode if allowed & EVENT != 0 => " Call fmi2EnterEventMode first.",
            Phase::EventMode | Phase::ContinuousTimeMode if allowed & INSTANTIATED != 0 => {
                " That is only possible before initialisation: call fmi2Reset first."
            }
            Phase::InitializationMode | Phase::StepComplete if allowed & INSTANTIATED != 0 => {
                " That is only possible before initialisation: call fmi2Reset first."
            }
            Phase::Terminated => {
                " The instance is terminated: call fmi2Reset to start again, or fmi2FreeInstance."
            }
            _ => "",
        }
    }

    /// Why a call of `call` is refused in this phase, and what to do (`model`: the FMU's
    /// modelIdentifier).
    #[cold]
    pub fn refusal(self, call: &Call, model: &str) -> String {
        if self == Phase::Broken {
            return format!(
                "{} refused: an internal error made this instance unusable; call fmi2Reset or fmi2FreeInstance",
                call.name
            );
        }
        if let Some(why) = call.never {
            return format!("{}: {}", call.name, why.replace("{model}", model));
        }
        format!(
            "{} is not allowed in state {self:?} (allowed in: {}).{}",
            call.name,
            Phase::describe(call.allowed),
            self.way_to(call.allowed)
        )
    }
}

/// One FMI function: its name, the phases that allow it, and for a function this FMU never
/// carries out, why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Call {
    pub name: &'static str,
    pub allowed: u8,
    pub never: Option<&'static str>,
}

const fn call(name: &'static str, allowed: u8) -> Call {
    Call {
        name,
        allowed,
        never: None,
    }
}

const fn never(name: &'static str, why: &'static str) -> Call {
    Call {
        name,
        allowed: allow::NONE,
        never: Some(why),
    }
}

pub const SET_DEBUG_LOGGING: Call = call("fmi2SetDebugLogging", allow::ANY);
pub const SETUP_EXPERIMENT: Call = call("fmi2SetupExperiment", allow::INSTANTIATED);
pub const ENTER_INITIALIZATION_MODE: Call =
    call("fmi2EnterInitializationMode", allow::INSTANTIATED);
pub const EXIT_INITIALIZATION_MODE: Call =
    call("fmi2ExitInitializationMode", allow::INITIALIZATION);
pub const TERMINATE: Call = call("fmi2Terminate", allow::STEP_COMPLETE | allow::RUNNING_ME);
/// The one way out of an internal error.
pub const RESET: Call = call("fmi2Reset", allow::ANY | allow::BROKEN);
pub const GET_REAL: Call = call("fmi2GetReal", allow::GET);
pub const GET_INTEGER: Call = call("fmi2GetInteger", allow::GET);
pub const GET_BOOLEAN: Call = call("fmi2GetBoolean", allow::GET);
pub const GET_STRING: Call = call("fmi2GetString", allow::GET);
pub const SET_REAL: Call = call("fmi2SetReal", allow::SET);
pub const SET_INTEGER: Call = call("fmi2SetInteger", allow::SET_DISCRETE);
pub const SET_BOOLEAN: Call = call("fmi2SetBoolean", allow::SET_DISCRETE);
pub const SET_STRING: Call = call("fmi2SetString", allow::SET_DISCRETE);
pub const SET_REAL_INPUT_DERIVATIVES: Call = call("fmi2SetRealInputDerivatives", allow::SET_CS);
pub const GET_REAL_OUTPUT_DERIVATIVES: Call = call("fmi2GetRealOutputDerivatives", allow::STATUS);
pub const DO_STEP: Call = call("fmi2DoStep", allow::STEP_COMPLETE);
pub const CANCEL_STEP: Call = never(
    "fmi2CancelStep",
    "no asynchronous step is ever running (fmi2DoStep never returns fmi2Pending)",
);
pub const GET_STATUS: Call = call("fmi2GetStatus", allow::STATUS);
pub const GET_REAL_STATUS: Call = call("fmi2GetRealStatus", allow::STATUS);
pub const GET_INTEGER_STATUS: Call = call("fmi2GetIntegerStatus", allow::STATUS);
pub const GET_BOOLEAN_STATUS: Call = call("fmi2GetBooleanStatus", allow::STATUS);
pub const GET_STRING_STATUS: Call = call("fmi2GetStringStatus", allow::STATUS);
pub const GET_FMU_STATE: Call = call("fmi2GetFMUstate", allow::ANY);
pub const SET_FMU_STATE: Call = call("fmi2SetFMUstate", allow::ANY);
pub const FREE_FMU_STATE: Call = call("fmi2FreeFMUstate", allow::ANY);
pub const SERIALIZED_FMU_STATE_SIZE: Call = call("fmi2SerializedFMUstateSize", allow::ANY);
pub const SERIALIZE_FMU_STATE: Call = call("fmi2SerializeFMUstate", allow::ANY);
pub const DE_SERIALIZE_FMU_STATE: Call = call("fmi2DeSerializeFMUstate", allow::ANY);
/// Model Exchange (masks as in the FMI 2.0 standard's state machine; the state queries need
/// the simulation that fmi2ExitInitializationMode builds, so they start in EventMode).
pub const GET_DIRECTIONAL_DERIVATIVE: Call = call("fmi2GetDirectionalDerivative", allow::STATES);
pub const ENTER_EVENT_MODE: Call = call("fmi2EnterEventMode", allow::RUNNING_ME);
pub const NEW_DISCRETE_STATES: Call = call("fmi2NewDiscreteStates", allow::EVENT);
pub const ENTER_CONTINUOUS_TIME_MODE: Call = call("fmi2EnterContinuousTimeMode", allow::EVENT);
pub const COMPLETED_INTEGRATOR_STEP: Call = call("fmi2CompletedIntegratorStep", allow::CONTINUOUS);
pub const SET_TIME: Call = call("fmi2SetTime", allow::RUNNING_ME);
pub const SET_CONTINUOUS_STATES: Call = call("fmi2SetContinuousStates", allow::CONTINUOUS);
pub const GET_DERIVATIVES: Call = call("fmi2GetDerivatives", allow::STATES);
pub const GET_EVENT_INDICATORS: Call = call("fmi2GetEventIndicators", allow::STATES);
pub const GET_CONTINUOUS_STATES: Call = call("fmi2GetContinuousStates", allow::STATES);
pub const GET_NOMINALS_OF_CONTINUOUS_STATES: Call =
    call("fmi2GetNominalsOfContinuousStates", allow::STATES);

/// The table against the FMI 2.0 standard's tables, and the hints against the table.
#[cfg(test)]
mod standard_tests;

#[cfg(test)]
mod tests {
    use super::*;

    /// Every refusal for the call order names the way out (what to call first).
    #[test]
    fn call_order_refusals_say_what_to_call_first() {
        let cases = [
            (Phase::Instantiated, DO_STEP, "fmi2ExitInitializationMode"),
            (
                Phase::Instantiated,
                EXIT_INITIALIZATION_MODE,
                "fmi2EnterInitializationMode",
            ),
            (
                Phase::InitializationMode,
                DO_STEP,
                "fmi2ExitInitializationMode first",
            ),
            (Phase::StepComplete, SETUP_EXPERIMENT, "fmi2Reset"),
            (Phase::Terminated, DO_STEP, "fmi2Reset"),
            (Phase::Broken, DO_STEP, "fmi2Reset"),
            (Phase::StepComplete, CANCEL_STEP, "asynchronous"),
            (Phase::StepComplete, SET_TIME, "fmi2ModelExchange"),
            (Phase::EventMode, DO_STEP, "fmi2CoSimulation"),
            (
                Phase::EventMode,
                SET_CONTINUOUS_STATES,
                "fmi2EnterContinuousTimeMode first",
            ),
            (
                Phase::ContinuousTimeMode,
                NEW_DISCRETE_STATES,
                "fmi2EnterEventMode first",
            ),
            (
                Phase::InitializationMode,
                GET_DERIVATIVES,
                "fmi2ExitInitializationMode first",
            ),
            (Phase::Instantiated, SET_TIME, "Initialise first"),
            (Phase::ContinuousTimeMode, SETUP_EXPERIMENT, "fmi2Reset"),
        ];
        for (phase, call, hint) in cases {
            let message = phase.refusal(&call, "TLD");
            assert!(message.contains(hint), "{phase:?} {}: {message}", call.name);
            assert!(message.starts_with(call.name), "{message}");
        }
    }

    /// The whole refusal, for each way out and for none: the states that allow the call,
    /// listed exactly, and the hint that fits this phase alone.
    #[test]
    fn refusals_list_the_allowed_states_and_the_one_way_out() {
        let cases = [
            (
                Phase::InitializationMode,
                SETUP_EXPERIMENT,
                "fmi2SetupExperiment is not allowed in state InitializationMode (allowed in: \
                 Instantiated). That is only possible before initialisation: call fmi2Reset first.",
            ),
            (
                Phase::StepComplete,
                EXIT_INITIALIZATION_MODE,
                "fmi2ExitInitializationMode is not allowed in state StepComplete (allowed in: \
                 InitializationMode).",
            ),
            (
                Phase::Instantiated,
                TERMINATE,
                "fmi2Terminate is not allowed in state Instantiated (allowed in: StepComplete, \
                 EventMode, ContinuousTimeMode). Initialise first: fmi2SetupExperiment, fmi2EnterInitializationMode and \
                 fmi2ExitInitializationMode (again after fmi2Reset).",
            ),
            (
                Phase::Instantiated,
                GET_REAL_STATUS,
                "fmi2GetRealStatus is not allowed in state Instantiated (allowed in: \
                 StepComplete, Terminated). Initialise first: fmi2SetupExperiment, \
                 fmi2EnterInitializationMode and fmi2ExitInitializationMode (again after \
                 fmi2Reset).",
            ),
            (
                Phase::Terminated,
                SET_REAL,
                "fmi2SetReal is not allowed in state Terminated (allowed in: Instantiated, \
                 InitializationMode, StepComplete, EventMode, ContinuousTimeMode). The instance is terminated: call fmi2Reset \
                 to start again, or fmi2FreeInstance.",
            ),
        ];
        for (phase, call, expected) in cases {
            assert_eq!(phase.refusal(&call, "TLD"), expected);
        }
    }

    /// Only fmi2Reset gets an instance out of an internal error.
    #[test]
    fn a_broken_instance_allows_reset_only() {
        assert_ne!(RESET.allowed & Phase::Broken.bit(), 0);
        for call in [
            SETUP_EXPERIMENT,
            GET_REAL,
            SET_REAL,
            DO_STEP,
            GET_FMU_STATE,
            TERMINATE,
        ] {
            assert_eq!(call.allowed & Phase::Broken.bit(), 0, "{}", call.name);
        }
    }
}
