//! Output and input derivatives through the C entry points of the built library
//! (fmi2GetRealOutputDerivatives, fmi2SetRealInputDerivatives).

mod common;

use common::*;
use tld_fmu::fmi::vars::{AmplitudeModeItem, vr};

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
