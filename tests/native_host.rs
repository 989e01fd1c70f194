//! The FMU driven through its C entry points by a native host (dlopen of the built library).

mod common;

use common::*;
use std::ffi::CString;
use tld_fmu::fmi::vars::{AmplitudeModeItem, GUID, vr};
use tld_fmu::model::{Damper, Inputs, Output, StartValues};

/// The FMI layer adds nothing and loses nothing: the same run through the C interface and
/// directly through the simulation is bit-identical.
#[test]
fn fmi_layer_is_transparent() {
    let mut inst = Instance::new("transparent");
    inst.initialise();
    let x_fmu = inst.run_harmonic(500, 0.01);
    // The model description's defaults, which the instance runs too.
    let (mut sim, _) = Damper::configure(&StartValues::default()).expect("defaults");
    let w = 6.0;
    let mut t = 0.0;
    for _ in 0..500 {
        let inputs = Inputs {
            a: -w * w * 0.004 * f64::sin(w * t),
            ..Inputs::default()
        };
        sim.step(t, 0.01, &inputs).expect("step");
        t += 0.01;
    }
    let direct = sim.output(Output::X, &Inputs::default());
    assert_eq!(x_fmu.to_bits(), direct.to_bits(), "{x_fmu} vs {direct}");
    assert!(x_fmu.abs() > 1e-3, "the run must actually slosh: {x_fmu}");
}

#[test]
fn calculated_parameters_and_outputs_in_initialization_mode() {
    let inst = Instance::new("init-values");
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.set_integer(vr::TANKS, 3), OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.set_real(vr::SLOSH_X0, 0.01), OK);
    let (s, m) = inst.get_real(vr::MASS_LIQUID);
    assert_eq!(s, OK);
    assert!((m - 3.0 * 1.68).abs() < 1e-12);
    let (_, ms) = inst.get_real(vr::MASS_SLOSH);
    assert!((ms / m - 0.7923).abs() < 5e-5);
    let (_, w) = inst.get_real(vr::OMEGA_F);
    assert!((w - 5.6389).abs() < 5e-5);
    let (_, x) = inst.get_real(vr::SLOSH_X);
    assert_eq!(x, 0.01);
    let (_, f) = inst.get_real(vr::FORCE);
    // force = m w^2 x (1 + phi (2x/a)^2) at rest.
    let want = ms * w * w * 0.01 * (1.0 + (0.02f64 / 0.25).powi(2));
    assert!((f - want).abs() < 1e-9 * want, "{f} vs {want}");
    assert_eq!(inst.set_real(vr::BASE_A, 2.0), OK);
    let (_, shear) = inst.get_real(vr::BASE_SHEAR);
    let (_, inactive) = inst.get_real(vr::MASS_INACTIVE);
    assert!((shear - (f - inactive * 2.0)).abs() < 1e-12);
}

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
fn bad_values_are_refused_logged_and_change_nothing() {
    let reference = {
        let mut clean = Instance::new("bad-values-clean");
        clean.initialise();
        clean.run_harmonic(100, 0.01);
        clean.run_harmonic(100, 0.01)
    };
    let mut inst = Instance::new("bad-values");
    inst.initialise();
    inst.run_harmonic(100, 0.01);
    let before = inst.logs().len();
    let lib = inst.lib;
    let c = inst.c;
    let mut count = 0;
    let mut expect = |status: u32, want: u32, what: &str| {
        assert_eq!(status, want, "{what}");
        count += 1;
    };
    unsafe {
        expect(inst.set_real(vr::BASE_A, f64::NAN), ERROR, "NaN input");
        expect(inst.set_real(vr::BASE_A, f64::INFINITY), ERROR, "Inf input");
        expect(
            inst.set_real(vr::BASE_V, f64::NEG_INFINITY),
            ERROR,
            "-Inf input",
        );
        expect(inst.set_real(9999, 1.0), ERROR, "unknown value reference");
        expect(
            inst.get_real(9999).0,
            ERROR,
            "unknown value reference (get)",
        );
        expect(
            inst.get_real(vr::TANKS).0,
            ERROR,
            "Real getter on an Integer",
        );
        expect(
            inst.get_real(vr::MODEL).0,
            ERROR,
            "Real getter on an Enumeration",
        );
        expect(
            inst.set_real(vr::ETA, 3.0),
            ERROR,
            "fixed parameter after initialisation",
        );
        expect(inst.set_real(vr::FORCE, 3.0), ERROR, "setting an output");
        expect(
            inst.set_real(vr::OMEGA_F, 3.0),
            ERROR,
            "setting a calculated parameter",
        );
        expect(
            inst.set_integer(vr::BASE_A, 1),
            ERROR,
            "integer setter on a Real",
        );
        expect(
            lib.fmi2SetReal(c, std::ptr::null(), 1, &1.0),
            ERROR,
            "null vr",
        );
        expect(
            lib.fmi2SetReal(c, &vr::BASE_A, 1, std::ptr::null()),
            ERROR,
            "null value",
        );
        expect(
            lib.fmi2GetReal(c, &vr::FORCE, 1, std::ptr::null_mut()),
            ERROR,
            "null output",
        );
        // Two values, the second bad: neither may be applied.
        let vrs = [vr::BASE_A, vr::BASE_V];
        expect(
            lib.fmi2SetReal(c, vrs.as_ptr(), 2, [5.0, f64::NAN].as_ptr()),
            ERROR,
            "partly bad array",
        );
        expect(lib.fmi2DoStep(c, inst.time, 0.0, 1), ERROR, "zero step");
        expect(
            lib.fmi2DoStep(c, inst.time, -0.01, 1),
            ERROR,
            "negative step",
        );
        expect(lib.fmi2DoStep(c, inst.time, f64::NAN, 1), ERROR, "NaN step");
        expect(
            lib.fmi2DoStep(c, inst.time + 0.5, 0.01, 1),
            ERROR,
            "time mismatch",
        );
        expect(
            lib.fmi2DoStep(c, f64::INFINITY, 0.01, 1),
            ERROR,
            "infinite time",
        );
        let names = [
            CString::new("logCalls").unwrap(),
            CString::new("%s%n%s nonsense").unwrap(),
        ];
        let ptrs = [names[0].as_ptr(), names[1].as_ptr()];
        expect(
            lib.fmi2SetDebugLogging(c, 0, 2, ptrs.as_ptr()),
            WARNING,
            "unknown log category",
        );
        expect(
            lib.fmi2SetDebugLogging(c, 0, 1, std::ptr::null()),
            ERROR,
            "null categories",
        );
        expect(
            lib.fmi2GetFMUstate(c, std::ptr::null_mut()),
            ERROR,
            "null FMU state slot",
        );
        expect(
            lib.fmi2GetDerivatives(c, std::ptr::null_mut(), 0),
            ERROR,
            "Model Exchange function",
        );
        expect(
            lib.fmi2DoStep(std::ptr::null_mut(), 0.0, 0.01, 1),
            ERROR,
            "null instance",
        );
    }
    let logs = inst.logs();
    // Every refusal on this instance logged a reason (the null instance cannot log).
    assert!(
        logs.len() - before >= count - 1,
        "{count} refusals, {} messages: {logs:?}",
        logs.len() - before
    );
    assert!(
        logs.iter().any(|m| m.contains("%s%n%s nonsense")),
        "untrusted text is echoed verbatim: {logs:?}"
    );
    assert!(
        logs.iter().any(|m| m.contains("must be finite")),
        "{logs:?}"
    );
    let after = inst.run_harmonic(100, 0.01);
    assert_eq!(
        after.to_bits(),
        reference.to_bits(),
        "bad calls changed the instance"
    );
}

#[test]
fn out_of_range_and_inconsistent_parameters() {
    let inst = Instance::new("ranges");
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.set_real(vr::TANK_LENGTH, -1.0), ERROR);
    assert_eq!(inst.set_real(vr::ETA, 0.5), ERROR);
    assert_eq!(inst.set_real(vr::PHI, -1.0), ERROR);
    assert_eq!(
        inst.set_integer(vr::DAMPING, 7),
        ERROR,
        "not an enumeration item"
    );
    assert_eq!(
        inst.set_integer(vr::MODEL, 5),
        ERROR,
        "not an item of ModelKind"
    );
    assert_eq!(inst.set_integer(vr::MODES, 51), ERROR, "at most 50 modes");
    assert_eq!(inst.set_integer(vr::TANKS, 0), ERROR);
    assert_eq!(
        inst.get_real(vr::TANK_LENGTH).0,
        ERROR,
        "getters are not allowed before initialisation mode"
    );
    assert_eq!(inst.enter(), OK);
    assert_eq!(
        inst.get_real(vr::TANK_LENGTH),
        (OK, 0.25),
        "refused values were not stored"
    );
    // Each value in range, together inconsistent: refused at exit, still in initialisation mode.
    assert_eq!(inst.set_real(vr::LAMBDA_MIN, 0.09), OK);
    assert_eq!(inst.set_real(vr::LAMBDA_MAX, 0.05), OK);
    assert_eq!(inst.exit(), ERROR);
    assert!(
        inst.logs().iter().any(|m| m.contains("lambda.min")),
        "{:?}",
        inst.logs()
    );
    assert_eq!(inst.set_real(vr::LAMBDA_MAX, 0.1), OK);
    // S^2 with a clearance wider than the tank: refused at exit too.
    assert_eq!(inst.set_integer(vr::MODEL, 3), OK);
    assert_eq!(inst.set_real(vr::SLAMMING_CLEARANCE, 0.3), OK);
    assert_eq!(inst.exit(), ERROR);
    assert!(
        inst.logs().iter().any(|m| m.contains("slamming.clearance")),
        "{:?}",
        inst.logs()
    );
    assert_eq!(inst.set_real(vr::SLAMMING_CLEARANCE, 0.1), OK);
    assert_eq!(inst.exit(), OK);
}

#[test]
fn instantiate_refuses_what_it_cannot_serve() {
    let lib = library();
    let callbacks = callbacks();
    let name = CString::new("refuse").unwrap();
    let guid = CString::new(GUID).unwrap();
    let wrong = CString::new("{00000000-0000-0000-0000-000000000000}").unwrap();
    unsafe {
        let c = lib.fmi2Instantiate(
            name.as_ptr(),
            fmi_sys::fmi2::fmi2Type_fmi2ModelExchange,
            guid.as_ptr(),
            std::ptr::null(),
            &*callbacks,
            0,
            0,
        );
        assert!(c.is_null(), "Model Exchange");
        let c = lib.fmi2Instantiate(
            name.as_ptr(),
            fmi_sys::fmi2::fmi2Type_fmi2CoSimulation,
            wrong.as_ptr(),
            std::ptr::null(),
            &*callbacks,
            0,
            0,
        );
        assert!(c.is_null(), "wrong GUID");
        let c = lib.fmi2Instantiate(
            std::ptr::null(),
            fmi_sys::fmi2::fmi2Type_fmi2CoSimulation,
            guid.as_ptr(),
            std::ptr::null(),
            &*callbacks,
            0,
            0,
        );
        assert!(c.is_null(), "null name");
        let c = lib.fmi2Instantiate(
            name.as_ptr(),
            fmi_sys::fmi2::fmi2Type_fmi2CoSimulation,
            guid.as_ptr(),
            std::ptr::null(),
            std::ptr::null(),
            0,
            0,
        );
        assert!(c.is_null(), "null callbacks");
        // A null logger is fine: errors then go nowhere, but nothing crashes.
        let quiet = Box::new(fmi_sys::fmi2::fmi2CallbackFunctions {
            logger: None,
            ..*callbacks
        });
        let c = lib.fmi2Instantiate(
            name.as_ptr(),
            fmi_sys::fmi2::fmi2Type_fmi2CoSimulation,
            guid.as_ptr(),
            std::ptr::null(),
            &*quiet,
            0,
            1,
        );
        assert!(!c.is_null());
        assert_eq!(lib.fmi2DoStep(c, 0.0, 0.1, 0), ERROR);
        lib.fmi2FreeInstance(c);
        // Freeing twice or freeing null is survived.
        lib.fmi2FreeInstance(std::ptr::null_mut());
    }
    let logs: Vec<String> = Instance::new("refuse-probe").logs();
    assert!(logs.is_empty());
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

#[test]
fn too_many_substeps_is_a_discard_that_keeps_the_state() {
    let mut inst = Instance::new("discard");
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.set_integer(vr::SOLVER_MAX_SUBSTEPS, 5), OK);
    assert_eq!(inst.exit(), OK);
    assert_eq!(inst.set_real(vr::BASE_A, 1.0), OK);
    let x0 = inst.get_real(vr::SLOSH_X).1;
    assert_eq!(inst.do_step(30.0), DISCARD);
    assert!(
        inst.logs()
            .iter()
            .any(|m| m.contains("smaller communication step")),
        "{:?}",
        inst.logs()
    );
    assert_eq!(inst.get_real(vr::SLOSH_X).1, x0);
    let mut t = 0.0;
    unsafe {
        inst.lib.fmi2GetRealStatus(
            inst.c,
            fmi_sys::fmi2::fmi2StatusKind_fmi2LastSuccessfulTime,
            &mut t,
        )
    };
    assert_eq!(t, 0.0);
    assert_eq!(
        inst.do_step(1e-4),
        OK,
        "a smaller step goes through within 5 substeps: {:?}",
        inst.logs()
    );
}

#[test]
fn concurrent_instances_match_serial_runs() {
    let serial: Vec<u64> = (0..4)
        .map(|k| {
            let mut inst = Instance::new(&format!("serial-{k}"));
            inst.initialise();
            inst.run_harmonic(300 + 50 * k, 0.01).to_bits()
        })
        .collect();
    let threads: Vec<_> = (0..4usize)
        .map(|k| {
            std::thread::spawn(move || {
                let mut inst = Instance::new(&format!("thread-{k}"));
                inst.initialise();
                inst.run_harmonic(300 + 50 * k, 0.01).to_bits()
            })
        })
        .collect();
    let parallel: Vec<u64> = threads
        .into_iter()
        .map(|t| t.join().expect("thread"))
        .collect();
    assert_eq!(serial, parallel);
}

/// The library exports the 44 fmi2 functions and nothing of its own, except `callback_log`:
/// a #[no_mangle] function inside the fmi-sys crate (its logger shim for FMU importers), which
/// rustc exports from every cdylib that links fmi-sys. It is never called by this FMU.
#[test]
fn exports_only_fmi2_functions() {
    let out = std::process::Command::new("nm")
        .args(["-D", "--defined-only"])
        .arg(library_path())
        .output()
        .expect("nm (binutils) must be installed");
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    let symbols: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split_whitespace().nth(2))
        .collect();
    let fmi: Vec<&&str> = symbols.iter().filter(|s| s.starts_with("fmi2")).collect();
    let other: Vec<&&str> = symbols.iter().filter(|s| !s.starts_with("fmi2")).collect();
    assert_eq!(fmi.len(), 44, "{fmi:?}");
    assert_eq!(other, vec![&"callback_log"], "unexpected exports");
}

fn get_state(inst: &Instance) -> fmi_sys::fmi2::fmi2FMUstate {
    let mut s: fmi_sys::fmi2::fmi2FMUstate = std::ptr::null_mut();
    assert_eq!(
        unsafe { inst.lib.fmi2GetFMUstate(inst.c, &mut s) },
        OK,
        "{:?}",
        inst.logs()
    );
    assert!(!s.is_null());
    s
}

fn serialize(inst: &Instance, s: fmi_sys::fmi2::fmi2FMUstate) -> Vec<u8> {
    let mut n = 0usize;
    unsafe {
        assert_eq!(inst.lib.fmi2SerializedFMUstateSize(inst.c, s, &mut n), OK);
        let mut bytes = vec![0u8; n];
        assert_eq!(
            inst.lib
                .fmi2SerializeFMUstate(inst.c, s, bytes.as_mut_ptr() as *mut _, n),
            OK
        );
        bytes
    }
}

fn deserialize(inst: &Instance, bytes: &[u8]) -> (u32, fmi_sys::fmi2::fmi2FMUstate) {
    let mut s: fmi_sys::fmi2::fmi2FMUstate = std::ptr::null_mut();
    let status = unsafe {
        inst.lib
            .fmi2DeSerializeFMUstate(inst.c, bytes.as_ptr() as *const _, bytes.len(), &mut s)
    };
    (status, s)
}

fn tracked(name: &str) -> Instance {
    let inst = Instance::new(name);
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.set_integer(vr::AMPLITUDE, 2), OK);
    assert_eq!(inst.exit(), OK);
    inst
}

/// Get a state, run on, set it back, run the same again: bit-identical.
#[test]
fn fmu_state_round_trip_is_bit_identical() {
    let mut inst = tracked("state-roundtrip");
    inst.run_harmonic(150, 0.01);
    let s = get_state(&inst);
    let t_saved = inst.time;
    let first = inst.run_harmonic(200, 0.01);
    let first_estimate = inst.get_real(vr::A_E_ESTIMATE).1;
    assert_eq!(unsafe { inst.lib.fmi2SetFMUstate(inst.c, s) }, OK);
    inst.time = t_saved;
    let again = inst.run_harmonic(200, 0.01);
    assert_eq!(first.to_bits(), again.to_bits());
    assert_eq!(
        first_estimate.to_bits(),
        inst.get_real(vr::A_E_ESTIMATE).1.to_bits()
    );
    // Overwriting an existing state in place, then freeing it (twice: the slot is nulled).
    let mut s2 = s;
    unsafe {
        assert_eq!(inst.lib.fmi2GetFMUstate(inst.c, &mut s2), OK);
        assert_eq!(s2, s, "the host's state is reused");
        assert_eq!(inst.lib.fmi2FreeFMUstate(inst.c, &mut s2), OK);
        assert!(s2.is_null());
        assert_eq!(inst.lib.fmi2FreeFMUstate(inst.c, &mut s2), OK);
    }
}

/// A serialised state restores in another instance that never ran, and continues exactly as
/// the uninterrupted run.
#[test]
fn serialized_state_restores_in_another_instance() {
    let mut a = tracked("state-source");
    a.run_harmonic(120, 0.01);
    let s = get_state(&a);
    let bytes = serialize(&a, s);
    let t_saved = a.time;
    let uninterrupted = a.run_harmonic(180, 0.01);
    let mut b = Instance::new("state-target");
    let (status, restored) = deserialize(&b, &bytes);
    assert_eq!(status, OK, "{:?}", b.logs());
    assert_eq!(
        unsafe { b.lib.fmi2SetFMUstate(b.c, restored) },
        OK,
        "{:?}",
        b.logs()
    );
    b.time = t_saved;
    let continued = b.run_harmonic(180, 0.01);
    assert_eq!(uninterrupted.to_bits(), continued.to_bits());
    // A state taken before initialisation brings an initialised instance back there.
    let fresh = Instance::new("state-early");
    assert_eq!(fresh.setup(), OK);
    assert_eq!(fresh.enter(), OK);
    let early = get_state(&fresh);
    assert_eq!(unsafe { b.lib.fmi2SetFMUstate(b.c, early) }, OK);
    assert_eq!(b.exit(), OK, "back in initialisation mode");
    unsafe {
        let mut s = s;
        let mut restored = restored;
        let mut early = early;
        a.lib.fmi2FreeFMUstate(a.c, &mut s);
        b.lib.fmi2FreeFMUstate(b.c, &mut restored);
        fresh.lib.fmi2FreeFMUstate(fresh.c, &mut early);
    }
}

/// Truncated, corrupted, foreign and wrong-version buffers are refused with a reason, and the
/// instance is unharmed.
#[test]
fn bad_serialized_states_are_refused() {
    let mut inst = Instance::new("state-bad");
    inst.initialise();
    inst.run_harmonic(50, 0.01);
    let s = get_state(&inst);
    let bytes = serialize(&inst, s);
    let reference = {
        let mut clean = Instance::new("state-bad-clean");
        clean.initialise();
        clean.run_harmonic(50, 0.01);
        clean.run_harmonic(50, 0.01)
    };
    let mut refused = 0;
    for len in 0..bytes.len() {
        assert_eq!(
            deserialize(&inst, &bytes[..len]).0,
            ERROR,
            "truncated to {len}"
        );
        refused += 1;
    }
    for at in 0..bytes.len() {
        let mut bad = bytes.clone();
        bad[at] ^= 0x5a;
        assert_eq!(deserialize(&inst, &bad).0, ERROR, "byte {at} flipped");
        refused += 1;
    }
    let mut longer = bytes.clone();
    longer.push(0);
    assert_eq!(deserialize(&inst, &longer).0, ERROR, "trailing byte");
    let foreign: Vec<u8> = (0..bytes.len()).map(|i| (i * 37 % 251) as u8).collect();
    assert_eq!(deserialize(&inst, &foreign).0, ERROR, "foreign bytes");
    // A well-formed buffer of another format version (checksum recomputed).
    let mut other = bytes[..bytes.len() - 8].to_vec();
    other[4] = 2;
    let sum = other.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    });
    other.extend_from_slice(&sum.to_le_bytes());
    assert_eq!(deserialize(&inst, &other).0, ERROR, "version 2");
    let logs = inst.logs();
    assert!(logs.iter().any(|m| m.contains("truncated")), "{logs:?}");
    assert!(logs.iter().any(|m| m.contains("checksum")), "{logs:?}");
    assert!(logs.iter().any(|m| m.contains("version 2")), "{logs:?}");
    assert!(refused > 2 * 100);
    unsafe {
        // Pointers that are not states of ours.
        let mut junk = 7u64;
        assert_eq!(
            inst.lib
                .fmi2SetFMUstate(inst.c, &mut junk as *mut u64 as *mut _),
            ERROR
        );
        assert_eq!(
            inst.lib.fmi2SetFMUstate(inst.c, std::ptr::null_mut()),
            ERROR
        );
        let mut s = s;
        inst.lib.fmi2FreeFMUstate(inst.c, &mut s);
    }
    assert_eq!(inst.run_harmonic(50, 0.01).to_bits(), reference.to_bits());
}

/// fmi2GetRealOutputDerivatives against central differences of the outputs themselves, taken
/// with tiny steps forward and backward in time (the FMU state rewinds between them).
#[test]
fn output_derivatives_match_finite_differences() {
    let mut inst = Instance::new("output-derivatives");
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.set_real(vr::ETA, 3.0), OK);
    // A fixed amplitude: a tracked one moves the damping at every communication point (by
    // O(h) per step), which a difference over steps of d would count as a rate.
    assert_eq!(
        inst.set_integer(vr::AMPLITUDE, AmplitudeModeItem::Fixed.value() as i32),
        OK
    );
    assert_eq!(inst.exit(), OK);
    inst.run_harmonic(120, 0.01);
    let a_now = 0.7;
    assert_eq!(inst.set_real(vr::BASE_A, a_now), OK);
    let outputs = [
        vr::FORCE,
        vr::BASE_SHEAR,
        vr::SLOSH_X,
        vr::SLOSH_V,
        vr::ENERGY_INPUT,
        vr::ENERGY_DISSIPATED,
        vr::ENERGY_STORED,
    ];
    let orders = [1i32; 7];
    let mut exact = [0.0; 7];
    let s = get_state(&inst);
    let status = unsafe {
        inst.lib.fmi2GetRealOutputDerivatives(
            inst.c,
            outputs.as_ptr(),
            7,
            orders.as_ptr(),
            exact.as_mut_ptr(),
        )
    };
    assert_eq!(status, OK, "{:?}", inst.logs());
    // Forward by +d with the input held, and the same system integrated back from the same state
    // by stepping from the state at t - d: emulate with two forward runs of d and 2d.
    let d = 1e-5;
    let t0 = inst.time;
    let values =
        |inst: &Instance| -> Vec<f64> { outputs.iter().map(|&r| inst.get_real(r).1).collect() };
    let y0 = values(&inst);
    assert_eq!(inst.do_step(d), OK);
    let y1 = values(&inst);
    assert_eq!(unsafe { inst.lib.fmi2SetFMUstate(inst.c, s) }, OK);
    inst.time = t0;
    assert_eq!(inst.do_step(2.0 * d), OK);
    let y2 = values(&inst);
    for k in 0..7 {
        // Second-order one-sided difference: (-3 y0 + 4 y1 - y2) / (2 d).
        let fd = (-3.0 * y0[k] + 4.0 * y1[k] - y2[k]) / (2.0 * d);
        let scale = exact[k].abs().max(1e-6);
        // base_shear's derivative also holds -mass.inactive * d(base.a)/dt = 0 (held input).
        assert!(
            (fd - exact[k]).abs() < 1e-5 * scale + 1e-9,
            "output {k}: exact {} vs difference {fd}",
            exact[k]
        );
    }
    unsafe {
        let mut s = s;
        inst.lib.fmi2FreeFMUstate(inst.c, &mut s);
        // Refusals: order 2 of an output, an input's derivative, a NaN input derivative, order 3.
        let mut out = 0.0;
        let two = 2i32;
        assert_eq!(
            inst.lib
                .fmi2GetRealOutputDerivatives(inst.c, &vr::FORCE, 1, &two, &mut out),
            ERROR
        );
        assert_eq!(
            inst.lib
                .fmi2GetRealOutputDerivatives(inst.c, &vr::BASE_A, 1, &orders[0], &mut out),
            ERROR
        );
        assert_eq!(
            inst.lib
                .fmi2SetRealInputDerivatives(inst.c, &vr::BASE_A, 1, &orders[0], &f64::NAN),
            ERROR
        );
        assert_eq!(
            inst.lib
                .fmi2SetRealInputDerivatives(inst.c, &vr::BASE_A, 1, &3, &1.0),
            ERROR
        );
        assert_eq!(
            inst.lib
                .fmi2SetRealInputDerivatives(inst.c, &vr::FORCE, 1, &orders[0], &1.0),
            ERROR
        );
        assert_eq!(
            inst.lib
                .fmi2SetRealInputDerivatives(inst.c, &vr::BASE_V, 1, &orders[0], &1.0),
            OK
        );
    }
}

/// Input derivatives act on the next step only: after it the input is held again.
#[test]
fn input_derivatives_last_one_step() {
    let run = |with_derivative: bool| {
        let mut inst = Instance::new(&format!("derivative-scope-{with_derivative}"));
        inst.initialise();
        assert_eq!(inst.set_real(vr::BASE_A, 1.0), OK);
        if with_derivative {
            assert_eq!(
                unsafe {
                    inst.lib
                        .fmi2SetRealInputDerivatives(inst.c, &vr::BASE_A, 1, &1, &50.0)
                },
                OK
            );
        }
        assert_eq!(inst.do_step(0.01), OK);
        let after_first = inst.get_real(vr::SLOSH_V).1;
        let before = inst.get_real(vr::SLOSH_V).1;
        assert_eq!(inst.do_step(0.01), OK);
        (after_first, inst.get_real(vr::SLOSH_V).1 - before)
    };
    let (v_held, dv_held) = run(false);
    let (v_ramp, dv_ramp) = run(true);
    // During the first step the ramp adds 50 * h^2 / 2 = 2.5e-3 m/s of base velocity change.
    assert!((v_held - v_ramp - 2.5e-3).abs() < 1e-4, "{v_held} {v_ramp}");
    // The second step sees the same held input in both runs: its velocity change differs only
    // through the slightly different state, not by another 2.5e-3 or more.
    assert!((dv_held - dv_ramp).abs() < 5e-4, "{dv_held} {dv_ramp}");
}

/// The S^2 model's state (impact mass position, velocity, wall contact, count) survives a
/// serialised round trip into another instance, bit for bit.
#[test]
fn slamming_state_round_trip() {
    let start = |name: &str| {
        let inst = Instance::new(name);
        assert_eq!(inst.setup(), OK);
        assert_eq!(inst.enter(), OK);
        assert_eq!(inst.set_integer(vr::MODEL, 3), OK);
        assert_eq!(inst.set_real(vr::SLAMMING_OMEGA, 0.9), OK);
        assert_eq!(inst.exit(), OK);
        inst
    };
    let mut a = start("s2-source");
    a.run_harmonic(300, 0.01);
    let s = get_state(&a);
    let bytes = serialize(&a, s);
    let t_saved = a.time;
    let uninterrupted = a.run_harmonic(300, 0.01);
    let impacts = |i: &Instance| {
        let mut n = 0;
        unsafe { i.lib.fmi2GetInteger(i.c, &vr::IMPACTS, 1, &mut n) };
        n
    };
    let n_a = impacts(&a);
    assert!(n_a >= 1, "the scene must slam: {n_a} impacts");
    let mut b = start("s2-target");
    let (status, restored) = deserialize(&b, &bytes);
    assert_eq!(status, OK, "{:?}", b.logs());
    assert_eq!(
        unsafe { b.lib.fmi2SetFMUstate(b.c, restored) },
        OK,
        "{:?}",
        b.logs()
    );
    b.time = t_saved;
    assert_eq!(b.run_harmonic(300, 0.01).to_bits(), uninterrupted.to_bits());
    assert_eq!(impacts(&b), n_a);
    assert_eq!(
        b.get_real(vr::IMPACT_Z).1.to_bits(),
        a.get_real(vr::IMPACT_Z).1.to_bits()
    );
    unsafe {
        let (mut s, mut r) = (s, restored);
        a.lib.fmi2FreeFMUstate(a.c, &mut s);
        b.lib.fmi2FreeFMUstate(b.c, &mut r);
    }
}

/// The per-step calls have fast paths; they must step aside when the host asks for every
/// call to be logged, and refuse exactly as before.
#[test]
fn per_step_calls_are_logged_when_asked_and_refused_as_before() {
    let mut inst = Instance::new("per-step-calls");
    inst.initialise();
    let lib = library();
    let count =
        |inst: &Instance, name: &str| inst.logs().iter().filter(|m| m.contains(name)).count();
    assert_eq!(inst.set_real(vr::BASE_A, 0.5), OK);
    assert_eq!(inst.get_real(vr::SLOSH_X).0, OK);
    assert_eq!(inst.do_step(0.01), OK);
    assert_eq!(
        count(&inst, "fmi2SetReal") + count(&inst, "fmi2GetReal"),
        0,
        "not asked"
    );

    let name = CString::new("logCalls").unwrap();
    let ptrs = [name.as_ptr()];
    assert_eq!(
        unsafe { lib.fmi2SetDebugLogging(inst.c, 1, 1, ptrs.as_ptr()) },
        OK
    );
    assert_eq!(inst.set_real(vr::BASE_A, 0.25), OK);
    let (s, x) = inst.get_real(vr::SLOSH_X);
    assert_eq!(s, OK);
    assert!(x.is_finite());
    assert_eq!(inst.do_step(0.01), OK);
    assert_eq!(count(&inst, "fmi2SetReal"), 1, "{:?}", inst.logs());
    assert_eq!(count(&inst, "fmi2GetReal"), 1, "{:?}", inst.logs());
    assert_eq!(count(&inst, "fmi2DoStep"), 1, "{:?}", inst.logs());

    // Refusals while stepping, logging off again: the same statuses and reasons as ever.
    assert_eq!(
        unsafe { lib.fmi2SetDebugLogging(inst.c, 0, 0, std::ptr::null()) },
        OK
    );
    let before = inst.logs().len();
    assert_eq!(inst.set_real(vr::BASE_A, f64::NAN), ERROR);
    assert_eq!(inst.set_real(vr::FORCE, 1.0), ERROR);
    assert_eq!(inst.set_real(vr::ETA, 3.0), ERROR);
    assert_eq!(inst.get_real(9999).0, ERROR);
    let logs = inst.logs()[before..].to_vec();
    assert_eq!(logs.len(), 4, "{logs:?}");
    assert!(logs[0].contains("must be finite"), "{logs:?}");
    assert!(logs[1].contains("cannot be set"), "{logs:?}");
    assert!(logs[2].contains("fixed parameter"), "{logs:?}");
    assert!(logs[3].contains("unknown value reference"), "{logs:?}");
    // Every input: any finite value is taken as given, an infinite one refused and the
    // value kept.
    for r in [vr::BASE_A, vr::BASE_V, vr::BASE_X] {
        for v in [f64::MAX, -f64::MAX, 0.0, -0.0, 5e-324] {
            assert_eq!(inst.set_real(r, v), OK, "vr {r} = {v}");
            assert_eq!(inst.get_real(r).1.to_bits(), v.to_bits(), "vr {r} = {v}");
        }
        for v in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
            assert_eq!(inst.set_real(r, v), ERROR, "vr {r} = {v}");
            assert_eq!(inst.get_real(r).1, 5e-324, "vr {r} after {v}");
        }
        assert_eq!(inst.set_real(r, 0.0), OK);
    }
    assert_eq!(inst.set_real(vr::BASE_A, 0.25), OK);
    // Two values at once, one of them an output: neither is applied, by the general path.
    let vrs = [vr::BASE_A, vr::FORCE];
    let before_a = inst.get_real(vr::BASE_A).1;
    assert_eq!(
        unsafe { lib.fmi2SetReal(inst.c, vrs.as_ptr(), 2, [9.0, 1.0].as_ptr()) },
        ERROR
    );
    assert_eq!(inst.get_real(vr::BASE_A).1, before_a);
    // Reads of several kinds in one call: outputs, an input, a parameter, a calculated one.
    let vrs = [vr::SLOSH_X, vr::BASE_A, vr::ETA, vr::OMEGA_F, vr::FORCE];
    let mut out = [f64::NAN; 5];
    assert_eq!(
        unsafe { lib.fmi2GetReal(inst.c, vrs.as_ptr(), 5, out.as_mut_ptr()) },
        OK
    );
    assert_eq!(out[0], inst.get_real(vr::SLOSH_X).1);
    assert_eq!(out[1], 0.25);
    assert_eq!(out[2], inst.get_real(vr::ETA).1);
    assert!((out[3] - 5.6389).abs() < 5e-5, "{out:?}");
    assert_eq!(out[4], inst.get_real(vr::FORCE).1);
    // A count no array can hold (a host's -1 as size_t) is refused before anything is
    // written, even where the first entries would be readable.
    let vrs = [vr::SLOSH_X, vr::SLOSH_X, vr::SLOSH_X, 9999];
    let mut out = [f64::NAN; 3];
    assert_eq!(
        unsafe { lib.fmi2GetReal(inst.c, vrs.as_ptr(), usize::MAX, out.as_mut_ptr()) },
        ERROR
    );
    assert!(out.iter().all(|v| v.is_nan()), "{out:?}");
}
