//! TLD.fmu in Model Exchange through its C entry points, driven as an ME host drives it: the
//! call sequence (event mode, continuous-time mode), a host-side integration against the
//! closed-form free decay, the refusals of calls out of order (each says what to call first),
//! the models not offered, and FMU states saved and restored in ME.

mod common;

use common::*;
use tld_fmu::fmi::vars::vr;

/// Continuous states of TLD.fmu in ME: slosh.x, slosh.v, energy.input, energy.dissipated,
/// impact.z, impact.v, the Linear model's mode[n].x, mode[n].v (n = 2..10), the amplitude
/// estimator's 7 (frozen at 0 where unused).
const N: usize = tld_fmu::model::continuous::ALL_STATES;
/// Items: model = Linear (1), Nonlinear (2), SloshingSlamming (3); damping Constant (1);
/// amplitude Fixed (1).
const LINEAR: i32 = 1;
const NONLINEAR: i32 = 2;
const SLAMMING: i32 = 3;
const SHALLOW_WATER: i32 = 5;

/// An ME instance with `model`, constant damping 0.02, amplitude Fixed, slosh.x0 = x0, in
/// initialisation mode.
fn in_initialisation(name: &str, model: i32, x0: f64) -> Instance {
    let inst = Instance::model_exchange(name);
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.set_integer(vr::MODEL, model), OK);
    assert_eq!(inst.set_integer(vr::DAMPING, 1), OK);
    assert_eq!(inst.set_real(vr::ZETA, 0.02), OK);
    assert_eq!(inst.set_integer(vr::AMPLITUDE, 1), OK);
    assert_eq!(inst.set_real(vr::SLOSH_X0, x0), OK);
    assert_eq!(inst.enter(), OK);
    inst
}

/// Out of initialisation, through the first event iteration, into continuous-time mode.
fn running(name: &str, model: i32, x0: f64) -> Instance {
    let inst = in_initialisation(name, model, x0);
    assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
    let (s, info) = inst.new_discrete_states();
    assert_eq!(s, OK);
    assert_eq!(info.newDiscreteStatesNeeded, 0);
    assert_eq!(info.terminateSimulation, 0);
    assert_eq!(info.nextEventTimeDefined, 0);
    assert_eq!(inst.enter_continuous_time_mode(), OK);
    inst
}

/// The host integrates the Linear model's free decay from slosh.x0 by RK4 through the ME
/// calls; against the closed form x = e^(-zeta w t) (x0 cos(w_d t) + zeta w x0/w_d sin(w_d t)),
/// and the energies balance (input = stored + dissipated, the stored energy at the start
/// counted as input).
#[test]
fn a_host_integrates_the_free_decay_to_its_closed_form() {
    let x0 = 0.01;
    let inst = running("me-decay", LINEAR, x0);
    let (s, x) = inst.states(N);
    assert_eq!(s, OK);
    assert_eq!(x[..2], [x0, 0.0]);
    let (s, nominal) = inst.nominals(N);
    assert_eq!(s, OK);
    assert!(
        nominal.iter().all(|v| *v > 0.0 && v.is_finite()),
        "{nominal:?}"
    );
    // Two event indicators (S^2's walls); a model without events: never crossing.
    let (s, z) = inst.event_indicators(2);
    assert_eq!((s, z), (OK, vec![1.0, 1.0]));
    let w = inst.real(vr::OMEGA_F);
    let zeta: f64 = 0.02;
    let t1: f64 = 4.0;
    inst.rk4(N, 0.0, t1, 4000, |_, _| {});
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let want =
        (-zeta * w * t1).exp() * (x0 * (wd * t1).cos() + zeta * w * x0 / wd * (wd * t1).sin());
    let got = inst.real(vr::SLOSH_X);
    // RK4 at h = 1e-3 (w h = 0.0056): global error ~ (w h)^4 per period, far below 1e-9 x0.
    assert!((got - want).abs() < 1e-9 * x0, "{got} vs {want}");
    let (input, stored, dissipated) = (
        inst.real(vr::ENERGY_INPUT),
        inst.real(vr::ENERGY_STORED),
        inst.real(vr::ENERGY_DISSIPATED),
    );
    assert!(dissipated > 0.0);
    assert!(
        (input - stored - dissipated).abs() < 1e-9 * input,
        "{input} {stored} {dissipated}"
    );
    // The derivatives are readable as variables too.
    let (s, d) = inst.derivatives(N);
    assert_eq!(s, OK);
    assert_eq!(inst.real(vr::DER_SLOSH_V_), d[1]);
    assert_eq!(inst.terminate(), OK);
}

/// Under base motion the Nonlinear model's derivative is Eq 2.11's right-hand side:
/// v' = -a - c v - Phi(x), so changing base.a by da changes v' by -da, and x' = v.
#[test]
fn the_input_enters_the_derivative_of_the_velocity() {
    let inst = running("me-input", NONLINEAR, 0.02);
    assert_eq!(inst.set_real(vr::BASE_A, 0.0), OK);
    let (_, d0) = inst.derivatives(N);
    assert_eq!(inst.set_real(vr::BASE_A, 0.5), OK);
    let (_, d1) = inst.derivatives(N);
    assert_eq!(d1[0], d0[0]);
    assert!((d1[1] - d0[1] + 0.5).abs() < 1e-14, "{d0:?} {d1:?}");
    // x = 0.02 at rest: the restoring force pulls back, v' < 0.
    assert!(d0[1] < 0.0);
}

/// Calls out of order are refused with fmi2Error and a message that says what to call first;
/// the instance stays usable.
#[test]
fn calls_out_of_order_say_what_to_call_first() {
    let inst = in_initialisation("me-order", NONLINEAR, 0.0);
    assert_eq!(inst.derivatives(N).0, ERROR);
    // The derivative variables are initial unknowns: readable in initialisation mode (FMI
    // Library hosts read them there), from the state the parameters start.
    assert_eq!(inst.get_real(vr::DER_SLOSH_X_), (OK, 0.0));
    assert_eq!(inst.exit(), OK);
    // Event mode: states are set in continuous-time mode only.
    assert_eq!(inst.set_states(&[0.0; N]), ERROR);
    let (s, _) = inst.completed_integrator_step();
    assert_eq!(s, ERROR);
    let mut me = inst;
    assert_eq!(me.do_step(0.01), ERROR);
    assert_eq!(me.enter_continuous_time_mode(), OK);
    assert_eq!(me.new_discrete_states().0, ERROR);
    // Wrong array lengths, and a non-finite state.
    assert_eq!(me.derivatives(N + 1).0, ERROR);
    let mut bad = [0.0; N];
    bad[1] = f64::NAN;
    assert_eq!(me.set_states(&bad), ERROR);
    let mut far = [0.0; N];
    far[0] = 1e6;
    assert_eq!(me.set_states(&far), ERROR);
    let (_, x) = me.states(N);
    assert_eq!(
        x, [0.0; N],
        "a refused fmi2SetContinuousStates changed the states"
    );
    let logs = me.logs().join("\n");
    for hint in [
        "Call fmi2ExitInitializationMode first",
        "Call fmi2EnterContinuousTimeMode first",
        "fmi2DoStep is not allowed in state EventMode",
        "fmi2CoSimulation",
        "Call fmi2EnterEventMode first",
        "the model description declares 31",
        "state 1 is NaN",
        "ran away",
    ] {
        assert!(logs.contains(hint), "no '{hint}' in:\n{logs}");
    }
    assert_eq!(me.enter_event_mode(), OK);
    assert_eq!(me.terminate(), OK);

    // A Co-Simulation instance refuses the ME functions and says which instance to make.
    let cs = Instance::new("cs-order");
    cs.initialise();
    assert_eq!(cs.set_time(0.0), ERROR);
    assert_eq!(cs.derivatives(N).0, ERROR);
    assert!(cs.logs().join("\n").contains("fmi2ModelExchange"));
}

/// A model not offered in ME is refused at fmi2ExitInitializationMode with its reason; the
/// instance stays in initialisation mode, where another model can be chosen.
#[test]
fn a_model_not_offered_says_why_and_another_can_be_chosen() {
    let inst = in_initialisation("me-shallow", SHALLOW_WATER, 0.0);
    // More cells than the bank the model description declares.
    assert_eq!(inst.set_integer(vr::SWE_CELLS, 201), OK);
    assert_eq!(inst.exit(), ERROR);
    assert!(
        inst.logs().join("\n").contains("swe.cells = 201"),
        "{:?}",
        inst.logs()
    );
    assert_eq!(inst.derivatives(N).0, ERROR);
    assert_eq!(inst.set_integer(vr::MODEL, NONLINEAR), OK);
    assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
    // amplitude = Tracked is offered (its estimator's states follow the host's solution), with
    // its directional derivatives (tests/me_jacobian_tracked.rs): at rest der(slosh.v) by
    // slosh.x is -Phi'(0) = -omega_f^2.
    let tracked = in_initialisation("me-tracked", NONLINEAR, 0.0);
    assert_eq!(tracked.set_integer(vr::AMPLITUDE, 2), OK);
    assert_eq!(tracked.exit(), OK, "{:?}", tracked.logs());
    let mut out = [0.0];
    let status = unsafe {
        tracked.lib.fmi2GetDirectionalDerivative(
            tracked.c,
            [vr::DER_SLOSH_V_].as_ptr(),
            1,
            [vr::SLOSH_X].as_ptr(),
            1,
            [1.0].as_ptr(),
            out.as_mut_ptr(),
        )
    };
    assert_eq!(status, OK, "{:?}", tracked.logs());
    let w = tracked.real(vr::OMEGA_F);
    assert!((out[0] + w * w).abs() <= 1e-13 * w * w, "{out:?}");
}

/// An FMU state saved in continuous-time mode restores (in this and in a new ME instance, from
/// its serialised bytes) to the same states and the same continuation, bit for bit; it does not
/// restore into a Co-Simulation instance.
#[test]
fn states_save_and_restore_in_model_exchange() {
    let base = |inst: &Instance, t: f64| {
        assert_eq!(inst.set_real(vr::BASE_A, -0.1 * (6.0 * t).sin()), OK);
    };
    let inst = running("me-save", NONLINEAR, 0.005);
    inst.rk4(N, 0.0, 0.5, 100, base);
    let bytes = inst.serialised();
    let (_, saved) = inst.states(N);
    inst.rk4(N, 0.5, 1.0, 100, base);
    let (_, end) = inst.states(N);

    let other = running("me-restored", NONLINEAR, 0.0);
    let mut s = restore(&other, &bytes);
    let (st, x) = other.states(N);
    assert_eq!(st, OK);
    assert_eq!(x, saved);
    other.rk4(N, 0.5, 1.0, 100, base);
    let (_, again) = other.states(N);
    assert_eq!(again, end);
    assert_eq!(unsafe { other.lib.fmi2FreeFMUstate(other.c, &mut s) }, OK);

    let cs = Instance::new("cs-restore");
    let (status, _) = deserialize(&cs, &bytes);
    assert_eq!(status, ERROR);
    assert!(cs.logs().join("\n").contains("Model Exchange"));
}

/// ME instances integrated in threads give the serial runs' numbers bit for bit (no state
/// shared between instances, none in the library).
#[test]
fn model_exchange_instances_in_threads_match_serial_runs() {
    let cases: Vec<(i32, f64)> = vec![
        (LINEAR, 0.01),
        (NONLINEAR, 0.02),
        (NONLINEAR, -0.015),
        (4, 0.03),
        (SLAMMING, 0.02),
    ];
    assert_threads_match_serial(&cases, |name, (model, x0)| {
        let inst = running(&name, model, x0);
        inst.rk4(N, 0.0, 1.0, 200, |i, t| {
            assert_eq!(i.set_real(vr::BASE_A, 0.2 * (5.0 * t).sin()), OK);
        });
        let (_, x) = inst.states(N);
        x.iter().fold(0u64, |h, v| h.rotate_left(7) ^ v.to_bits())
    });
}

/// With logging on, fmi2Instantiate for Model Exchange says what ME offers and what not.
#[test]
fn instantiating_for_model_exchange_says_what_is_offered() {
    let lib = library();
    let callbacks = callbacks();
    let name = std::ffi::CString::new("me-note").expect("name");
    let guid = std::ffi::CString::new(GUID).expect("guid");
    // SAFETY: valid strings and callbacks that outlive the instance, freed below.
    let c = unsafe {
        lib.fmi2Instantiate(
            name.as_ptr(),
            fmi_sys::fmi2::fmi2Type_fmi2ModelExchange,
            guid.as_ptr(),
            std::ptr::null(),
            &*callbacks,
            0,
            1,
        )
    };
    assert!(!c.is_null());
    unsafe { lib.fmi2FreeInstance(c) };
    let said = logs_of("me-note").join("\n");
    for part in [
        "Linear (modes <= 10)",
        "SloshingSlamming (impacts as state events)",
        "ShallowWater (2 x swe.cells states) are Co-Simulation only",
        "amplitude = Fixed or Tracked",
    ] {
        assert!(said.contains(part), "no '{part}' in: {said}");
    }
}
