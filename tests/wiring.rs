//! Every output and calculated parameter through the C entry points, by its value reference,
//! against the closed form of the linear model (MODEL.md Eqs 2.1, 2.2): a variable wired to
//! the wrong quantity, or an input to the wrong place, fails here (issue 30). The models' own
//! outputs are checked against references in src/model/wiring_tests; this is the FMI layer's
//! map from variables onto them.

mod common;

use common::*;
use std::f64::consts::PI;
use tld_fmu::fmi::vars::vr;

const A: f64 = 0.25;
const B: f64 = 0.32;
const H: f64 = 0.021;
const RHO: f64 = 1000.0;
const G: f64 = 9.81;
const TANKS: f64 = 2.0;
const ZETA: f64 = 0.03;

/// Eqs 2.1 and 2.2, fundamental mode of one tank: (mass, frequency).
fn fundamental() -> (f64, f64) {
    let th = (PI * H / A).tanh();
    (
        RHO * A * B * H * 8.0 * th / (PI.powi(3) * H / A),
        (G * PI * th / A).sqrt(),
    )
}

/// One step of x'' + 2 zeta w x' + w^2 x = -(a0 + a1 s), from (x, v): the particular solution
/// p0 + p1 s plus the damped free motion of what is left.
fn step(w: f64, (x, v): (f64, f64), a0: f64, a1: f64, h: f64) -> (f64, f64) {
    let s = ZETA * w;
    let wd = w * (1.0 - ZETA * ZETA).sqrt();
    let p1 = -a1 / (w * w);
    let p0 = (-a0 - 2.0 * s * p1) / (w * w);
    let (u0, u1) = (x - p0, v - p1);
    let b = (u1 + s * u0) / wd;
    let (c, sn, e) = ((wd * h).cos(), (wd * h).sin(), (-s * h).exp());
    let u = e * (u0 * c + b * sn);
    let du = e * (-s * (u0 * c + b * sn) + wd * (b * c - u0 * sn));
    (u + p0 + p1 * h, du + p1)
}

fn close(got: f64, want: f64, scale: f64, what: &str) {
    assert!(
        (got - want).abs() <= 1e-9 * scale,
        "{what}: {got} against {want}"
    );
}

#[test]
fn every_variable_is_wired_to_its_quantity() {
    let mut inst = Instance::new("wiring");
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.enter(), OK);
    for (r, v) in [
        (vr::TANKS, 2),
        (vr::MODEL, 1),     // Linear
        (vr::DAMPING, 1),   // Constant
        (vr::AMPLITUDE, 1), // Fixed
    ] {
        assert_eq!(inst.set_integer(r, v), OK, "{:?}", inst.logs());
    }
    for (r, v) in [
        (vr::ZETA, ZETA),
        (vr::A_E, 0.003),
        (vr::SLOSH_X0, 0.005),
        (vr::SLOSH_V0, -0.02),
    ] {
        assert_eq!(inst.set_real(r, v), OK, "{:?}", inst.logs());
    }
    assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
    let (m1, w) = fundamental();
    let (slosh, liquid) = (m1 * TANKS, RHO * A * B * H * TANKS);
    let inactive = liquid - slosh;
    close(inst.real(vr::OMEGA_F), w, w, "omega_f");
    close(inst.real(vr::MASS_SLOSH), slosh, liquid, "mass.slosh");
    close(inst.real(vr::MASS_LIQUID), liquid, liquid, "mass.liquid");
    close(
        inst.real(vr::MASS_INACTIVE),
        inactive,
        liquid,
        "mass.inactive",
    );
    let surface = -PI * PI * m1 / (2.0 * RHO * B * A * A);
    let stored = |(x, v): (f64, f64)| 0.5 * slosh * (v * v + w * w * x * x);
    let mut state = (0.005, -0.02);
    let initial = stored(state);
    let mut work = 0.0;
    let h = 0.01;
    for k in 0..300 {
        let t = f64::from(k) * h;
        let a = 0.8 * (1.1 * w * t).sin() + 0.1;
        // A ramp over some steps (its rate given as the input's derivative); no work checked
        // then: the work of a held input is -a dx.
        let a1 = if k % 3 == 1 { 2.5 } else { 0.0 };
        assert_eq!(inst.set_real(vr::BASE_A, a), OK);
        assert_eq!(inst.set_real(vr::BASE_V, 0.1 * a), OK);
        let status = unsafe {
            inst.lib
                .fmi2SetRealInputDerivatives(inst.c, &vr::BASE_A, 1, &1, &a1)
        };
        assert_eq!(status, OK, "{:?}", inst.logs());
        assert_eq!(inst.do_step(h), OK, "{:?}", inst.logs());
        let before = state;
        state = step(w, state, a, a1, h);
        let (x, v) = state;
        let force = slosh * (2.0 * ZETA * w * v + w * w * x);
        let fscale = slosh * w * w * 0.01;
        let impulse = slosh * (-(v - before.1) - (a * h + 0.5 * a1 * h * h));
        close(inst.real(vr::SLOSH_X), x, 0.01, "slosh.x");
        close(inst.real(vr::SLOSH_V), v, 0.01 * w, "slosh.v");
        close(inst.real(vr::FORCE), force, fscale, "force");
        close(inst.real(vr::FORCE_MEAN), impulse / h, fscale, "force.mean");
        // base_shear with the input now: the one set for the step, unless set anew.
        assert_eq!(inst.set_real(vr::BASE_A, -0.3), OK);
        close(
            inst.real(vr::BASE_SHEAR),
            force + inactive * 0.3,
            fscale,
            "base_shear",
        );
        close(inst.real(vr::A_E_ESTIMATE), 0.003, 0.003, "A_e.estimate");
        close(inst.real(vr::ZETA_EFFECTIVE), ZETA, ZETA, "zeta.effective");
        close(
            inst.real(vr::SURFACE_LEFT),
            surface * x,
            0.01,
            "surface.left",
        );
        close(
            inst.real(vr::SURFACE_RIGHT),
            -surface * x,
            0.01,
            "surface.right",
        );
        close(inst.real(vr::IMPACT_Z), 0.0, 1.0, "impact.z");
        let mut impacts = -1;
        let status = unsafe {
            inst.lib
                .fmi2GetInteger(inst.c, &vr::IMPACTS, 1, &mut impacts)
        };
        assert_eq!((status, impacts), (OK, 0), "impacts");
        let escale = initial;
        close(
            inst.real(vr::ENERGY_STORED),
            stored(state),
            escale,
            "energy.stored",
        );
        if a1 == 0.0 {
            work += -a * slosh * (x - before.0);
            close(
                inst.real(vr::ENERGY_INPUT),
                initial + work,
                escale,
                "energy.input",
            );
            close(
                inst.real(vr::ENERGY_DISSIPATED),
                initial + work - stored(state),
                escale,
                "energy.dissipated",
            );
        } else {
            // The ramp's work from the balance the model keeps (checked on the held steps).
            work = inst.real(vr::ENERGY_INPUT) - initial;
        }
        // The rates the FMU reports, under the input now: -0.3, its rate 1.7 (the step
        // cleared the step's; the next step sets its own).
        let status = unsafe {
            inst.lib
                .fmi2SetRealInputDerivatives(inst.c, &vr::BASE_A, 1, &1, &1.7)
        };
        assert_eq!(status, OK, "{:?}", inst.logs());
        let outputs = [
            vr::SLOSH_X,
            vr::SLOSH_V,
            vr::FORCE,
            vr::BASE_SHEAR,
            vr::SURFACE_LEFT,
        ];
        let orders = [1i32; 5];
        let mut rates = [f64::NAN; 5];
        let status = unsafe {
            inst.lib.fmi2GetRealOutputDerivatives(
                inst.c,
                outputs.as_ptr(),
                5,
                orders.as_ptr(),
                rates.as_mut_ptr(),
            )
        };
        assert_eq!(status, OK, "{:?}", inst.logs());
        let acc = 0.3 - 2.0 * ZETA * w * v - w * w * x;
        let rate_force = slosh * (2.0 * ZETA * w * acc + w * w * v);
        close(rates[0], v, 0.01 * w, "der(slosh.x)");
        close(rates[1], acc, 0.01 * w * w, "der(slosh.v)");
        close(rates[2], rate_force, fscale * w, "der(force)");
        close(
            rates[3],
            rate_force - inactive * 1.7,
            fscale * w,
            "der(base_shear)",
        );
        close(rates[4], surface * v, 0.01 * w, "der(surface.left)");
    }
}

/// fmi2SetupExperiment with a stop time: taken when it is finite and not before the start,
/// refused (fmi2Error) otherwise.
#[test]
fn setup_experiment_takes_a_stop_time() {
    for (start, stop, ok) in [
        (0.0, 10.0, true),
        (2.0, 2.0, true),
        (2.0, 1.0, false),
        (0.0, f64::NAN, false),
        (0.0, f64::INFINITY, false),
    ] {
        let inst = Instance::new("stop-time");
        let status = unsafe { inst.lib.fmi2SetupExperiment(inst.c, 0, 0.0, start, 1, stop) };
        assert_eq!(
            status == OK,
            ok,
            "start {start} stop {stop}: {:?}",
            inst.logs()
        );
    }
    for (tolerance, ok) in [
        (1e-6, true),
        (0.0, false),
        (-1e-6, false),
        (f64::NAN, false),
    ] {
        let inst = Instance::new("tolerance");
        let status = unsafe {
            inst.lib
                .fmi2SetupExperiment(inst.c, 1, tolerance, 0.0, 0, 0.0)
        };
        assert_eq!(status == OK, ok, "tolerance {tolerance}: {:?}", inst.logs());
    }
}

/// An instance at `start`, stopping at `stop`, ready to step.
fn started(name: &str, start: f64, stop: f64) -> Instance {
    let mut inst = Instance::new(name);
    let status = unsafe { inst.lib.fmi2SetupExperiment(inst.c, 0, 0.0, start, 1, stop) };
    assert_eq!(status, OK, "{:?}", inst.logs());
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.exit(), OK);
    inst.time = start;
    inst
}

/// fmi2DoStep takes the host's time with its rounding (1e-9 relative, here 1e-3 s at 1e6 s,
/// and 1e-6 of the step), not more; it reaches the stop time, to the same slack, not beyond.
#[test]
fn do_step_takes_the_hosts_rounding_and_stops_at_the_stop_time() {
    let step = |inst: &Instance, t: f64, h: f64| unsafe { inst.lib.fmi2DoStep(inst.c, t, h, 1) };
    let at = 1e6;
    for (offset, ok) in [(5e-4, true), (-5e-4, true), (2e-3, false), (-2e-3, false)] {
        let inst = started("rounding", at, 2e6);
        let status = step(&inst, at + offset, 0.01);
        assert_eq!(status == OK, ok, "offset {offset}: {:?}", inst.logs());
    }
    // A step exactly to the stop time, one just past it within the slack, one past it; near
    // 1 s (the step's slack 1e-6 h counts) and near 1e6 s (the stop's 1e-9 relative, 1e-3 s).
    for (start, stop, h, ok) in [
        (0.5, 1.5, 1.0, true),
        (0.5, 1.5, 1.0 + 1e-7, true),
        (0.5, 1.5, 1.001, false),
        (0.5, 1.5, 1.02, false),
        (at - 1.0, at, 1.0, true),
        (at - 1.0, at, 1.0005, true),
        (at - 1.0, at, 1.002, false),
        // A short step: its own slack, 1e-6 h, is 1e-8 s.
        (0.5, 0.51, 0.01, true),
        (0.5, 0.51, 0.01005, false),
    ] {
        let inst = started("stop", start, stop);
        let status = step(&inst, start, h);
        assert_eq!(
            status == OK,
            ok,
            "{start} + {h} to {stop}: {:?}",
            inst.logs()
        );
    }
}

/// Motion far beyond the walls is told once, as a warning of fmi2DoStep that names the step's
/// end and the damper's reason; the next steps are quiet.
#[test]
fn implausible_motion_is_a_warning_once() {
    let mut inst = Instance::new("notice");
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.set_integer(vr::MODEL, 1), OK);
    assert_eq!(inst.exit(), OK);
    let (_, w) = fundamental();
    // A static deflection of 20 m (the tank is 0.25 m long), for a quarter period.
    assert_eq!(inst.set_real(vr::BASE_A, -20.0 * w * w), OK);
    let quarter = 0.5 * PI / w;
    assert_eq!(inst.do_step(quarter), WARNING, "{:?}", inst.logs());
    let logs = inst.logs();
    let told: Vec<&String> = logs.iter().filter(|m| m.contains("implausible")).collect();
    assert_eq!(told.len(), 1, "{logs:?}");
    // 65 g of base acceleration: the reason is the acceleration's.
    let expected = format!(
        "fmi2DoStep to t = {quarter}: base.a = {} m/s^2 is 65 g",
        -20.0 * w * w
    );
    assert!(told[0].starts_with(&expected), "{}", told[0]);
    // The host helper counts time on fmi2OK only.
    inst.time += quarter;
    assert_eq!(inst.do_step(0.001), OK, "{:?}", inst.logs());
}

/// A tolerance given to fmi2SetupExperiment travels with the saved state: the state of such
/// an instance is serialised, read back and set.
#[test]
fn a_state_with_a_tolerance_round_trips() {
    let mut inst = Instance::new("tolerance-state");
    let status = unsafe { inst.lib.fmi2SetupExperiment(inst.c, 1, 1e-7, 0.0, 0, 0.0) };
    assert_eq!(status, OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.exit(), OK);
    assert_eq!(inst.do_step(0.01), OK);
    let bytes = inst.serialised();
    let mut restored = restore(&inst, &bytes);
    assert_eq!(inst.serialised(), bytes);
    assert_eq!(
        unsafe { inst.lib.fmi2FreeFMUstate(inst.c, &mut restored) },
        OK
    );
}

/// fmi2SetupExperiment's tolerance is the solver's when the host did not set
/// solver.tolerance: the same run, to the last bit, as with solver.tolerance set to it.
#[test]
fn the_experiments_tolerance_is_the_solvers() {
    let run = |experiment: bool| {
        let mut inst = Instance::new("experiment-tolerance");
        let defined = i32::from(experiment);
        let status = unsafe {
            inst.lib
                .fmi2SetupExperiment(inst.c, defined, 1e-9, 0.0, 0, 0.0)
        };
        assert_eq!(status, OK);
        assert_eq!(inst.enter(), OK);
        if !experiment {
            assert_eq!(inst.set_real(vr::SOLVER_TOLERANCE, 1e-9), OK);
        }
        assert_eq!(inst.exit(), OK);
        inst.run_harmonic(100, 0.05)
    };
    assert_eq!(run(true).to_bits(), run(false).to_bits());
}
