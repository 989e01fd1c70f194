//! Values through the C entry points of the built library: calculated parameters and outputs in
//! initialisation mode, refused values and parameters (logged, nothing stored), instantiation a
//! host cannot be served, a step that needs more substeps than allowed, and the per-step calls'
//! logging and refusals.

mod common;

use common::*;
use std::ffi::CString;
use tld_fmu::fmi::vars::{GUID, vr};

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
        inst.set_integer(vr::MODEL, 6),
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
    // Screens: 17 screens are out of range; three screens 0.2 m apart do not fit a 0.25 m tank
    // (refused at exit, the reason logged); a pair 0.05 m apart does.
    assert_eq!(inst.set_integer(vr::SCREENS_COUNT, 17), ERROR);
    assert_eq!(inst.set_real(vr::SCREENS_SOLIDITY, 0.99), ERROR);
    assert_eq!(inst.set_integer(vr::SCREENS_COUNT, 3), OK);
    assert_eq!(inst.set_real(vr::SCREENS_SPACING, 0.2), OK);
    assert_eq!(inst.exit(), ERROR);
    assert!(
        inst.logs().iter().any(|m| m.contains("screens.spacing")),
        "{:?}",
        inst.logs()
    );
    assert_eq!(inst.set_integer(vr::SCREENS_COUNT, 2), OK);
    assert_eq!(inst.set_real(vr::SCREENS_SPACING, 0.05), OK);
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
        // Neither fmi2ModelExchange (0) nor fmi2CoSimulation (1).
        let c = lib.fmi2Instantiate(
            name.as_ptr(),
            7,
            guid.as_ptr(),
            std::ptr::null(),
            &*callbacks,
            0,
            0,
        );
        assert!(c.is_null(), "unknown fmuType");
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

/// The per-step calls have fast paths; they must step aside when the host asks for every
/// call to be logged, and refuse with the statuses and reasons of the general path.
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

    // Refusals while stepping, logging off again: the statuses and reasons of the general path.
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

/// A finite input too large for the model's arithmetic (base.v = 1e300, squared in the
/// amplitude estimator; coverage-guided fuzzing found it in a restored state) never comes out
/// as an infinite or NaN value, in Co-Simulation or Model Exchange: what a getter hands out
/// with fmi2OK is finite, and a refusal says why. Before the check, A_e.tracker.v2[1] and its
/// derivative were handed out as inf with fmi2OK.
#[test]
fn an_overflowing_input_never_hands_out_a_non_finite_value() {
    use tld_fmu::fmi::vars::{VARIABLES, VarType};
    const N: usize = tld_fmu::model::continuous::ALL_STATES;
    for me in [false, true] {
        let mut inst = configured("overflow", me, &[(vr::AMPLITUDE, 2)], &[]);
        assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
        assert_eq!(inst.set_real(vr::BASE_A, 0.5), OK);
        assert_eq!(inst.set_real(vr::BASE_V, 1e300), OK, "a finite input");
        let mut refused = 0;
        if me {
            // The measured base.v switches the estimator (an event), whose rates then read it.
            assert_eq!(inst.new_discrete_states().0, OK, "{:?}", inst.logs());
            assert_eq!(inst.enter_continuous_time_mode(), OK);
            for (s, values) in [inst.derivatives(N), inst.states(N)] {
                if s == OK {
                    assert!(values.iter().all(|v| v.is_finite()), "{values:?}");
                } else {
                    refused += 1;
                }
            }
        } else {
            for _ in 0..3 {
                let _ = inst.do_step(1e-3);
            }
        }
        for v in VARIABLES.iter().filter(|v| v.ty == VarType::Real) {
            let (s, x) = inst.get_real(v.vr);
            if s == OK {
                assert!(x.is_finite(), "{} = {x} handed out (me = {me})", v.name);
            } else {
                refused += 1;
                let logs = inst.logs().join("\n");
                assert!(logs.contains("too large"), "{}: {logs}", v.name);
            }
        }
        assert!(
            refused > 0,
            "me = {me}: the overflow was not met (the test lost its case)"
        );
        // The instance stays usable: a sane input, and every variable reads again.
        assert_eq!(inst.set_real(vr::BASE_V, 0.0), OK);
        let _ = inst.get_real(vr::FORCE);
    }
}
