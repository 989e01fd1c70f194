//! The FMI 2.0 Co-Simulation state machine as a table: the phases an instance can be in, and
//! for every function the phases in which it may be called (its mask). The exports check the
//! mask before anything else, in one place.

/// Phases of the FMI 2.0 Co-Simulation state machine this FMU can be in (it never runs
/// asynchronously, and a refused step leaves it in StepComplete at the step's start).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    Instantiated,
    InitializationMode,
    StepComplete,
    Terminated,
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
    pub const NONE: u8 = 0;
    pub const ANY: u8 = INSTANTIATED | INITIALIZATION | STEP_COMPLETE | TERMINATED;
    pub const GET: u8 = INITIALIZATION | STEP_COMPLETE | TERMINATED;
    pub const SET: u8 = INSTANTIATED | INITIALIZATION | STEP_COMPLETE;
    pub const STATUS: u8 = STEP_COMPLETE | TERMINATED;
}

impl Phase {
    pub const fn bit(self) -> u8 {
        match self {
            Phase::Instantiated => allow::INSTANTIATED,
            Phase::InitializationMode => allow::INITIALIZATION,
            Phase::StepComplete => allow::STEP_COMPLETE,
            Phase::Terminated => allow::TERMINATED,
            Phase::Broken => allow::BROKEN,
        }
    }

    fn describe(mask: u8) -> String {
        let names = [
            (allow::INSTANTIATED, "Instantiated"),
            (allow::INITIALIZATION, "InitializationMode"),
            (allow::STEP_COMPLETE, "StepComplete"),
            (allow::TERMINATED, "Terminated"),
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
            Phase::Instantiated if allowed & STEP_COMPLETE != 0 => {
                " Initialise first: fmi2SetupExperiment, fmi2EnterInitializationMode and fmi2ExitInitializationMode (again after fmi2Reset)."
            }
            Phase::InitializationMode if allowed & STEP_COMPLETE != 0 => {
                " Call fmi2ExitInitializationMode first."
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

/// `{model}` becomes the FMU's modelIdentifier in the refusal.
const CO_SIMULATION_ONLY: &str =
    "{model}.fmu is a Co-Simulation FMU; Model Exchange is not provided";

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
pub const TERMINATE: Call = call("fmi2Terminate", allow::STEP_COMPLETE);
/// The one way out of an internal error.
pub const RESET: Call = call("fmi2Reset", allow::ANY | allow::BROKEN);
pub const GET_REAL: Call = call("fmi2GetReal", allow::GET);
pub const GET_INTEGER: Call = call("fmi2GetInteger", allow::GET);
pub const GET_BOOLEAN: Call = call("fmi2GetBoolean", allow::GET);
pub const GET_STRING: Call = call("fmi2GetString", allow::GET);
pub const SET_REAL: Call = call("fmi2SetReal", allow::SET);
pub const SET_INTEGER: Call = call("fmi2SetInteger", allow::SET);
pub const SET_BOOLEAN: Call = call("fmi2SetBoolean", allow::SET);
pub const SET_STRING: Call = call("fmi2SetString", allow::SET);
pub const SET_REAL_INPUT_DERIVATIVES: Call = call("fmi2SetRealInputDerivatives", allow::SET);
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
pub const GET_DIRECTIONAL_DERIVATIVE: Call = never(
    "fmi2GetDirectionalDerivative",
    "providesDirectionalDerivative is false",
);
pub const ENTER_EVENT_MODE: Call = never("fmi2EnterEventMode", CO_SIMULATION_ONLY);
pub const NEW_DISCRETE_STATES: Call = never("fmi2NewDiscreteStates", CO_SIMULATION_ONLY);
pub const ENTER_CONTINUOUS_TIME_MODE: Call =
    never("fmi2EnterContinuousTimeMode", CO_SIMULATION_ONLY);
pub const COMPLETED_INTEGRATOR_STEP: Call =
    never("fmi2CompletedIntegratorStep", CO_SIMULATION_ONLY);
pub const SET_TIME: Call = never("fmi2SetTime", CO_SIMULATION_ONLY);
pub const SET_CONTINUOUS_STATES: Call = never("fmi2SetContinuousStates", CO_SIMULATION_ONLY);
pub const GET_DERIVATIVES: Call = never("fmi2GetDerivatives", CO_SIMULATION_ONLY);
pub const GET_EVENT_INDICATORS: Call = never("fmi2GetEventIndicators", CO_SIMULATION_ONLY);
pub const GET_CONTINUOUS_STATES: Call = never("fmi2GetContinuousStates", CO_SIMULATION_ONLY);
pub const GET_NOMINALS_OF_CONTINUOUS_STATES: Call =
    never("fmi2GetNominalsOfContinuousStates", CO_SIMULATION_ONLY);

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
            (
                Phase::StepComplete,
                SET_TIME,
                "TLD.fmu is a Co-Simulation FMU",
            ),
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
                "fmi2Terminate is not allowed in state Instantiated (allowed in: StepComplete). \
                 Initialise first: fmi2SetupExperiment, fmi2EnterInitializationMode and \
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
                 InitializationMode, StepComplete). The instance is terminated: call fmi2Reset \
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
