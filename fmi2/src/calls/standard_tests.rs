//! The call table against the FMI 2.0 standard's state machines: the tables "allowed function
//! calls in the respective states" of FMI 2.0.x, section 3.2.3 (Model Exchange) and section
//! 4.2.4 (Co-Simulation), copied row by row below, and the refusals' hints checked against the
//! same table (a hint must name a call that is allowed now and that leads where the refused
//! call is allowed).

use super::*;

/// The states of the standard's tables that this FMU has, as its phases. A Co-Simulation
/// instance never is in stepInProgress, stepFailed or stepCanceled (it never steps
/// asynchronously, and a refused step leaves it in stepComplete); the standard's "error" is
/// `Broken` here (ordinary errors leave the instance in its phase); "fatal" never happens.
const ME_COLUMNS: [Phase; 6] = [
    Phase::Instantiated,
    Phase::InitializationMode,
    Phase::EventMode,
    Phase::ContinuousTimeMode,
    Phase::Terminated,
    Phase::Broken,
];
const CS_COLUMNS: [Phase; 5] = [
    Phase::Instantiated,
    Phase::InitializationMode,
    Phase::StepComplete,
    Phase::Terminated,
    Phase::Broken,
];

/// One row of the standard: the function, its Model Exchange row (instantiated, Initialization
/// Mode, Event Mode, Continuous-Time Mode, terminated, error) and its Co-Simulation row
/// (instantiated, Initialization Mode, stepComplete, terminated, error); `x` allowed (a number
/// of the standard, a condition on the variable or "values for debugging only", counts as
/// allowed), `-` not, an empty row: not a function of that interface.
struct Row {
    call: Call,
    me: &'static str,
    cs: &'static str,
    /// Phases the standard allows and this FMU refuses on purpose, and why.
    refused: &'static [Phase],
}

const fn row(call: Call, me: &'static str, cs: &'static str, refused: &'static [Phase]) -> Row {
    Row {
        call,
        me,
        cs,
        refused,
    }
}

/// "error" is Broken: only fmi2Reset (and fmi2FreeInstance, which has no mask) after a panic,
/// where the standard allows more (reading values for debugging, the FMU state functions).
const BROKEN: &[Phase] = &[Phase::Broken];
/// Model Exchange's state queries need the simulation fmi2ExitInitializationMode builds.
const NO_SIMULATION_YET: &[Phase] = &[Phase::InitializationMode, Phase::Broken];

fn standard() -> Vec<Row> {
    use Phase::*;
    vec![
        row(SET_DEBUG_LOGGING, "xxxxxx", "xxxxx", BROKEN),
        row(SETUP_EXPERIMENT, "x-----", "x----", &[]),
        row(ENTER_INITIALIZATION_MODE, "x-----", "x----", &[]),
        row(EXIT_INITIALIZATION_MODE, "-x----", "-x---", &[]),
        row(TERMINATE, "--xx--", "--x--", &[]),
        row(RESET, "xxxxxx", "xxxxx", &[]),
        row(GET_REAL, "-xxxxx", "-xxxx", BROKEN),
        row(GET_INTEGER, "-xxxxx", "-xxxx", BROKEN),
        row(GET_BOOLEAN, "-xxxxx", "-xxxx", BROKEN),
        row(GET_STRING, "-xxxxx", "-xxxx", BROKEN),
        row(SET_REAL, "xxxx--", "xxx--", &[]),
        row(SET_INTEGER, "xxx---", "xxx--", &[]),
        row(SET_BOOLEAN, "xxx---", "xxx--", &[]),
        row(SET_STRING, "xxx---", "xxx--", &[]),
        row(GET_FMU_STATE, "xxxxxx", "xxxxx", BROKEN),
        row(SET_FMU_STATE, "xxxxxx", "xxxxx", BROKEN),
        row(FREE_FMU_STATE, "xxxxxx", "xxxxx", BROKEN),
        row(SERIALIZED_FMU_STATE_SIZE, "xxxxxx", "xxxxx", BROKEN),
        row(SERIALIZE_FMU_STATE, "xxxxxx", "xxxxx", BROKEN),
        row(DE_SERIALIZE_FMU_STATE, "xxxxxx", "xxxxx", BROKEN),
        // Directional derivatives are offered by Model Exchange instances only, once the
        // simulation exists.
        row(
            GET_DIRECTIONAL_DERIVATIVE,
            "-xxxxx",
            "-xxxx",
            &[InitializationMode, StepComplete, Broken],
        ),
        row(ENTER_EVENT_MODE, "--xx--", "", &[]),
        row(NEW_DISCRETE_STATES, "--x---", "", &[]),
        row(ENTER_CONTINUOUS_TIME_MODE, "--x---", "", &[]),
        row(COMPLETED_INTEGRATOR_STEP, "---x--", "", &[]),
        // Event Mode: the standard's condition 8 (a pure discrete-time FMU); this FMU takes
        // it from every model.
        row(SET_TIME, "--xx--", "", &[]),
        row(SET_CONTINUOUS_STATES, "---x--", "", &[]),
        row(GET_EVENT_INDICATORS, "-xxxxx", "", NO_SIMULATION_YET),
        row(GET_CONTINUOUS_STATES, "-xxxxx", "", NO_SIMULATION_YET),
        row(GET_DERIVATIVES, "-xxxxx", "", NO_SIMULATION_YET),
        row(
            GET_NOMINALS_OF_CONTINUOUS_STATES,
            "xxxxxx",
            "",
            &[Instantiated, InitializationMode, Broken],
        ),
        row(SET_REAL_INPUT_DERIVATIVES, "", "xxx--", &[]),
        row(GET_REAL_OUTPUT_DERIVATIVES, "", "--xxx", BROKEN),
        row(DO_STEP, "", "--x--", &[]),
        // Only in stepInProgress, which this FMU never enters.
        row(CANCEL_STEP, "", "-----", &[]),
        row(GET_STATUS, "", "--xx-", &[]),
        row(GET_REAL_STATUS, "", "--xx-", &[]),
        row(GET_INTEGER_STATUS, "", "--xx-", &[]),
        row(GET_BOOLEAN_STATUS, "", "--xx-", &[]),
        row(GET_STRING_STATUS, "", "--xx-", &[]),
    ]
}

const ALL_PHASES: [Phase; 7] = [
    Phase::Instantiated,
    Phase::InitializationMode,
    Phase::StepComplete,
    Phase::Terminated,
    Phase::EventMode,
    Phase::ContinuousTimeMode,
    Phase::Broken,
];

/// The phases a row of the standard allows, both interfaces together (their running phases
/// are disjoint: one mask serves both).
fn allowed_by_standard(row: &Row) -> Vec<Phase> {
    let mut phases = Vec::new();
    for (marks, columns) in [(row.me, &ME_COLUMNS[..]), (row.cs, &CS_COLUMNS[..])] {
        assert!(
            marks.is_empty() || marks.len() == columns.len(),
            "{}: a row of {} marks",
            row.call.name,
            marks.len()
        );
        for (mark, &phase) in marks.chars().zip(columns) {
            assert!(mark == 'x' || mark == '-', "{}: mark {mark}", row.call.name);
            if mark == 'x' && !phases.contains(&phase) {
                phases.push(phase);
            }
        }
    }
    phases
}

fn allows(call: &Call, phase: Phase) -> bool {
    call.allowed & phase.bit() != 0
}

/// Every function of the table is allowed in exactly the phases where the standard allows it,
/// less the ones this FMU refuses on purpose (each a phase the standard allows: the FMU never
/// allows a call the standard forbids).
#[test]
fn every_call_is_allowed_where_the_fmi_2_0_tables_allow_it() {
    let rows = standard();
    assert_eq!(
        rows.len(),
        40,
        "a function of the table is missing from the test"
    );
    for row in &rows {
        let standard = allowed_by_standard(row);
        for &phase in row.refused {
            assert!(
                standard.contains(&phase),
                "{} in {phase:?}: refused on purpose, but the standard does not allow it",
                row.call.name
            );
        }
        for phase in ALL_PHASES {
            let expected = standard.contains(&phase) && !row.refused.contains(&phase);
            assert_eq!(
                allows(&row.call, phase),
                expected,
                "{} in {phase:?}",
                row.call.name
            );
        }
        assert_eq!(
            row.call.never.is_some(),
            row.call.allowed == allow::NONE,
            "{}: a call allowed nowhere says why",
            row.call.name
        );
    }
}

/// Each phase is one bit of its own, the bit its set in `allow` uses.
#[test]
fn each_phase_is_its_own_bit() {
    let mut seen = 0u8;
    for phase in ALL_PHASES {
        let bit = phase.bit();
        assert_eq!(bit.count_ones(), 1, "{phase:?}");
        assert_eq!(seen & bit, 0, "{phase:?} shares a bit");
        seen |= bit;
    }
    assert_eq!(allow::ANY | allow::BROKEN, seen);
    assert_eq!(allow::ANY & allow::BROKEN, 0);
}

/// A simulation exists from fmi2ExitInitializationMode to fmi2Reset: in the running phases of
/// both interfaces and once terminated, not before and not after an internal error.
#[test]
fn a_simulation_exists_between_exit_initialization_and_reset() {
    for phase in ALL_PHASES {
        let running = allows(&DO_STEP, phase) || allows(&ENTER_EVENT_MODE, phase);
        let expected = running || phase == Phase::Terminated;
        assert_eq!(phase.initialised(), expected, "{phase:?}");
    }
}

/// What a refusal's hint claims: the host should call `then` now (it must be allowed in this
/// phase), and from `leads_to` (one of them, the table's phases after that call) the refused
/// call becomes possible (allowed there, or the hint is the first of several calls).
struct Claim {
    hint: &'static str,
    then: Option<Call>,
    leads_to: u8,
}

fn claims() -> [Claim; 8] {
    use allow::*;
    [
        Claim {
            hint: "Call fmi2EnterInitializationMode first.",
            then: Some(ENTER_INITIALIZATION_MODE),
            leads_to: INITIALIZATION,
        },
        Claim {
            hint: "Initialise first:",
            then: Some(ENTER_INITIALIZATION_MODE),
            leads_to: STEP_COMPLETE | RUNNING_ME,
        },
        Claim {
            hint: "Call fmi2ExitInitializationMode first.",
            then: Some(EXIT_INITIALIZATION_MODE),
            leads_to: STEP_COMPLETE | RUNNING_ME,
        },
        Claim {
            hint: "Call fmi2EnterContinuousTimeMode first",
            then: Some(ENTER_CONTINUOUS_TIME_MODE),
            leads_to: CONTINUOUS,
        },
        Claim {
            hint: "Call fmi2EnterEventMode first.",
            then: Some(ENTER_EVENT_MODE),
            leads_to: EVENT,
        },
        Claim {
            hint: "That is only possible before initialisation: call fmi2Reset first.",
            then: Some(RESET),
            leads_to: INSTANTIATED,
        },
        Claim {
            hint: "The instance is terminated: call fmi2Reset",
            then: Some(RESET),
            // To start again: every phase is reachable from Instantiated.
            leads_to: ANY,
        },
        // The other interface: a new instance, no call of this one.
        Claim {
            hint: "need an instance made by fmi2Instantiate with fmuType",
            then: None,
            leads_to: 0,
        },
    ]
}

/// Every refusal of the whole table (every function in every phase that refuses it) names at
/// most one way out, and the way it names is one the state machine allows: the call to make is
/// allowed now, and the refused call is allowed where it leads. A refusal for the other
/// interface comes only from that interface's running phase, for a function of the other one.
#[test]
fn every_hint_names_a_way_the_state_machine_allows() {
    for row in standard() {
        let call = row.call;
        for phase in ALL_PHASES.into_iter().filter(|&p| !allows(&call, p)) {
            let message = phase.refusal(&call, "M");
            assert!(message.starts_with(call.name), "{message}");
            let named: Vec<Claim> = claims()
                .into_iter()
                .filter(|c| message.contains(c.hint))
                .collect();
            assert!(named.len() <= 1, "{message}");
            let Some(claim) = named.first() else {
                continue;
            };
            match claim.then {
                Some(then) => {
                    assert!(allows(&then, phase), "{message}: not callable now");
                    assert_ne!(call.allowed & claim.leads_to, 0, "{message}: no way");
                }
                None => {
                    let other = if phase == Phase::StepComplete {
                        allow::RUNNING_ME
                    } else {
                        assert!(matches!(
                            phase,
                            Phase::EventMode | Phase::ContinuousTimeMode
                        ));
                        allow::STEP_COMPLETE
                    };
                    assert_ne!(call.allowed & other, 0, "{message}");
                    assert_eq!(call.allowed & phase.bit(), 0, "{message}");
                }
            }
        }
    }
}

/// The refusals with no way out to name say so by naming none: the list of the states that
/// allow the call, complete, and nothing after it.
#[test]
fn refusals_without_a_way_out_end_with_the_states() {
    let cases = [
        (
            Phase::EventMode,
            EXIT_INITIALIZATION_MODE,
            "fmi2ExitInitializationMode is not allowed in state EventMode (allowed in: \
             InitializationMode).",
        ),
        (
            Phase::ContinuousTimeMode,
            EXIT_INITIALIZATION_MODE,
            "fmi2ExitInitializationMode is not allowed in state ContinuousTimeMode (allowed \
             in: InitializationMode).",
        ),
        (
            Phase::EventMode,
            SETUP_EXPERIMENT,
            "fmi2SetupExperiment is not allowed in state EventMode (allowed in: Instantiated). \
             That is only possible before initialisation: call fmi2Reset first.",
        ),
        (
            Phase::InitializationMode,
            DO_STEP,
            "fmi2DoStep is not allowed in state InitializationMode (allowed in: StepComplete). \
             Call fmi2ExitInitializationMode first.",
        ),
        (
            Phase::StepComplete,
            GET_NOMINALS_OF_CONTINUOUS_STATES,
            "fmi2GetNominalsOfContinuousStates is not allowed in state StepComplete (allowed \
             in: Terminated, EventMode, ContinuousTimeMode). This is a Co-Simulation instance: \
             Model Exchange functions need an instance made by fmi2Instantiate with fmuType \
             fmi2ModelExchange.",
        ),
        (
            Phase::InitializationMode,
            CANCEL_STEP,
            "fmi2CancelStep: no asynchronous step is ever running (fmi2DoStep never returns \
             fmi2Pending)",
        ),
    ];
    for (phase, call, expected) in cases {
        assert_eq!(phase.refusal(&call, "M"), expected);
    }
}
