//! The FMI 2.0 Co-Simulation calling sequence (standard section 4.2.4), through the C entry
//! points of the built library: every call the current state does not allow is refused, logged
//! and harmless; fmi2Reset returns to a fresh instance.

mod common;

use common::*;
use tld_fmu::fmi::vars::vr;

/// Functions whose legality depends on the state, with valid arguments.
#[derive(Clone, Copy, Debug)]
enum Call {
    SetupExperiment,
    EnterInit,
    ExitInit,
    Terminate,
    DoStep,
    GetReal,
    SetInput,
    SetFixedParameter,
    GetRealStatus,
    CancelStep,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum State {
    Instantiated,
    Initialization,
    StepComplete,
    Terminated,
}

const CALLS: [Call; 10] = [
    Call::SetupExperiment,
    Call::EnterInit,
    Call::ExitInit,
    Call::Terminate,
    Call::DoStep,
    Call::GetReal,
    Call::SetInput,
    Call::SetFixedParameter,
    Call::GetRealStatus,
    Call::CancelStep,
];

/// FMI 2.0 Co-Simulation calling sequence (standard section 4.2.4), for the states this FMU has.
fn allowed(call: Call, state: State) -> bool {
    use State::*;
    match call {
        Call::SetupExperiment | Call::EnterInit => state == Instantiated,
        Call::ExitInit => state == Initialization,
        Call::Terminate | Call::DoStep => state == StepComplete,
        Call::GetReal => matches!(state, Initialization | StepComplete | Terminated),
        Call::SetInput => matches!(state, Instantiated | Initialization | StepComplete),
        Call::SetFixedParameter => matches!(state, Instantiated | Initialization),
        Call::GetRealStatus => matches!(state, StepComplete | Terminated),
        Call::CancelStep => false,
    }
}

fn function_name(call: Call) -> &'static str {
    match call {
        Call::SetupExperiment => "fmi2SetupExperiment",
        Call::EnterInit => "fmi2EnterInitializationMode",
        Call::ExitInit => "fmi2ExitInitializationMode",
        Call::Terminate => "fmi2Terminate",
        Call::DoStep => "fmi2DoStep",
        Call::GetReal => "fmi2GetReal",
        Call::SetInput | Call::SetFixedParameter => "fmi2SetReal",
        Call::GetRealStatus => "fmi2GetRealStatus",
        Call::CancelStep => "fmi2CancelStep",
    }
}

fn drive(inst: &Instance, state: State) {
    if state == State::Instantiated {
        return;
    }
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.enter(), OK);
    if state == State::Initialization {
        return;
    }
    assert_eq!(inst.exit(), OK);
    if state == State::Terminated {
        assert_eq!(inst.terminate(), OK);
    }
}

fn perform(inst: &mut Instance, call: Call) -> u32 {
    unsafe {
        match call {
            Call::SetupExperiment => inst.setup(),
            Call::EnterInit => inst.enter(),
            Call::ExitInit => inst.exit(),
            Call::Terminate => inst.terminate(),
            Call::DoStep => inst.lib.fmi2DoStep(inst.c, inst.time, 0.01, 1),
            Call::GetReal => inst.get_real(vr::SLOSH_X).0,
            // The value set is the one the reference run uses first, so a legal set is harmless.
            Call::SetInput => inst.set_real(vr::BASE_A, 0.0),
            Call::SetFixedParameter => inst.set_real(vr::ETA, 2.0),
            Call::GetRealStatus => {
                let mut t = 0.0;
                inst.lib.fmi2GetRealStatus(
                    inst.c,
                    fmi_sys::fmi2::fmi2StatusKind_fmi2LastSuccessfulTime,
                    &mut t,
                )
            }
            Call::CancelStep => inst.lib.fmi2CancelStep(inst.c),
        }
    }
}

/// Carry on from `state` to a finished harmonic run; the result must not depend on what
/// illegal calls came before.
fn finish(inst: &mut Instance, state: State) -> f64 {
    match state {
        State::Instantiated => inst.initialise(),
        State::Initialization => assert_eq!(inst.exit(), OK),
        State::StepComplete => {}
        State::Terminated => return inst.get_real(vr::SLOSH_X).1,
    }
    inst.run_harmonic(200, 0.01)
}

#[test]
fn every_illegal_call_is_refused_logged_and_harmless() {
    let states = [
        State::Instantiated,
        State::Initialization,
        State::StepComplete,
        State::Terminated,
    ];
    let mut refused = 0;
    for state in states {
        let reference = {
            let mut clean = Instance::new(&format!("clean-{state:?}"));
            drive(&clean, state);
            finish(&mut clean, state)
        };
        for call in CALLS {
            if allowed(call, state) {
                let mut inst = Instance::new(&format!("legal-{state:?}-{call:?}"));
                drive(&inst, state);
                assert_eq!(
                    perform(&mut inst, call),
                    OK,
                    "{call:?} must be allowed in {state:?}: {:?}",
                    inst.logs()
                );
                continue;
            }
            let name = format!("illegal-{state:?}-{call:?}");
            let mut inst = Instance::new(&name);
            drive(&inst, state);
            let status = perform(&mut inst, call);
            assert_eq!(status, ERROR, "{call:?} in {state:?} must be refused");
            let logs = inst.logs();
            assert!(!logs.is_empty(), "{call:?} in {state:?}: no log message");
            assert!(
                logs.iter().any(|m| m.contains(function_name(call))),
                "{call:?}: {logs:?}"
            );
            let after = finish(&mut inst, state);
            assert_eq!(
                after.to_bits(),
                reference.to_bits(),
                "{call:?} in {state:?} changed the instance"
            );
            refused += 1;
        }
    }
    assert_eq!(
        refused, 25,
        "the table above has 6 + 6 + 5 + 8 illegal (state, call) pairs"
    );
}

#[test]
fn reset_returns_to_a_fresh_instance() {
    let mut inst = Instance::new("reset");
    inst.initialise();
    let first = inst.run_harmonic(100, 0.01);
    assert_eq!(inst.reset(), OK);
    inst.time = 0.0;
    inst.initialise();
    assert_eq!(inst.run_harmonic(100, 0.01).to_bits(), first.to_bits());
}

/// With every call logged, a refused call logs its refusal only (not an OK line for the call
/// first), and the refusal of a step before initialisation says what to call; a call that is
/// carried out is traced after it.
#[test]
fn logged_calls_are_traced_after_they_succeed() {
    let mut inst = Instance::new("traced");
    // SAFETY: our instance; no categories (all of them).
    let on = unsafe { inst.lib.fmi2SetDebugLogging(inst.c, 1, 0, std::ptr::null()) };
    assert_eq!(on, OK);
    let before = inst.logs().len();
    assert_eq!(inst.do_step(0.01), ERROR);
    let refused: Vec<String> = inst.logs()[before..].to_vec();
    assert_eq!(refused.len(), 1, "{refused:?}");
    for hint in [
        "fmi2SetupExperiment",
        "fmi2EnterInitializationMode",
        "fmi2ExitInitializationMode",
    ] {
        assert!(refused[0].contains(hint), "{}", refused[0]);
    }
    let before = inst.logs().len();
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.logs()[before..], ["fmi2SetupExperiment".to_string()]);
}
