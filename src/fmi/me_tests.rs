//! TLD's Model Exchange functions (me.rs) through the shared layer's contract ([`Continuous`],
//! [`Slave`]), as a host calls them once the layer has checked the phase and the array lengths:
//! against references written here: Eq 2.1's fundamental mode (its mass and frequency from
//! the tank, MODEL.md) and its oscillator's rates, energies' rates and output force, and their
//! partial derivatives in closed form; the amplitude estimator's ODEs (v' = a - w_c v and the
//! filter pairs f1' = (s - f1)/tau, f2' = (f1 - f2)/tau, MODEL.md section 2); the S^2 gaps to the
//! walls; and the FMI 2.0 rules for Model Exchange (the states in the order of the model
//! description, nominals finite and positive, refusals that leave the instance and the host's
//! arrays as they were).

use super::slave::Tld;
use super::vars::{VARIABLES, VarType, vr};
use crate::model::continuous::{ALL_STATES, BANK, STATES};
use crate::physics::amplitude::TRACKER_CONTINUOUS;
use fmi2_slave::calls::Phase;
use fmi2_slave::frame::Experiment;
use fmi2_slave::{Context, Continuous, Refusal, Slave, Status};

/// Enumeration items (modelDescription.xml).
pub(super) const LINEAR: i32 = 1;
pub(super) const SLAMMING: i32 = 3;
const SHALLOW_WATER: i32 = 5;
const CONSTANT: i32 = 1;
pub(super) const FIXED: i32 = 1;
pub(super) const TRACKED: i32 = 2;
/// A tank that is not the defaults' (no product of its numbers 1), two of them.
pub(super) const A: f64 = 0.6;
pub(super) const B: f64 = 0.25;
pub(super) const H: f64 = 0.07;
pub(super) const TANKS: f64 = 2.0;
pub(super) const ZETA: f64 = 0.04;
pub(super) const X0: f64 = 0.015;
/// The tracker's position among all states.
pub(super) const T0: usize = STATES;

pub(super) fn context(phase: Phase) -> Context {
    Context {
        phase,
        experiment: Experiment::default(),
        time: 0.0,
    }
}

/// The value reference of the variable named `name` in the model description.
pub(super) fn named(name: &str) -> u32 {
    VARIABLES
        .iter()
        .find(|v| v.name == name)
        .unwrap_or_else(|| panic!("no variable {name}"))
        .vr
}

/// The estimator's state k and its derivative, by name.
pub(super) fn tracker_vr(k: usize, derivative: bool) -> u32 {
    let names = [
        "v",
        "v2[1]",
        "v2[2]",
        "a2[1]",
        "a2[2]",
        "weight[1]",
        "weight[2]",
    ];
    let state = format!("A_e.tracker.{}", names[k]);
    named(&if derivative {
        format!("der({state})")
    } else {
        state
    })
}

/// An instance in initialisation mode with one mode of `model` in the test's tank, constant
/// damping, the amplitude `amplitude` with A_e = `a_e`, and `more` parameters.
pub(super) fn instance(model: i32, amplitude: i32, a_e: f64, more: &[(u32, f64)]) -> Tld {
    let mut tld = Tld::new();
    let c = context(Phase::InitializationMode);
    let ints = [
        (vr::MODEL, model),
        (vr::MODES, 1),
        (vr::DAMPING, CONSTANT),
        (vr::AMPLITUDE, amplitude),
        (vr::TANKS, TANKS as i32),
    ];
    for (r, v) in ints {
        let set = tld.set(
            &c,
            &[r],
            &[v],
            VarType::Integer,
            "fmi2SetInteger",
            f64::from,
        );
        assert_eq!(set.map_err(|e| e.message), Ok(Status::Ok), "{r} = {v}");
    }
    let reals = [
        (vr::TANK_LENGTH, A),
        (vr::TANK_BREADTH, B),
        (vr::TANK_DEPTH, H),
        (vr::ZETA, ZETA),
        (vr::A_E, a_e),
        (vr::SLOSH_X0, X0),
    ];
    for (r, v) in reals.iter().chain(more) {
        set_real(&mut tld, Phase::InitializationMode, *r, *v);
    }
    tld
}

pub(super) fn set_real(tld: &mut Tld, phase: Phase, r: u32, v: f64) {
    let set = tld.set(
        &context(phase),
        &[r],
        &[v],
        VarType::Real,
        "fmi2SetReal",
        |v| v,
    );
    assert_eq!(set.map_err(|e| e.message), Ok(Status::Ok), "{r} = {v}");
}

pub(super) fn real(tld: &Tld, phase: Phase, r: u32) -> f64 {
    let mut out = [f64::NAN];
    let got = tld.get(
        &context(phase),
        &[r],
        &mut out,
        VarType::Real,
        "fmi2GetReal",
        |v| v,
    );
    assert_eq!(got.map_err(|e| e.message), Ok(Status::Ok), "{r}");
    out[0]
}

/// Out of initialisation mode, as fmi2ExitInitializationMode does.
pub(super) fn initialised(mut tld: Tld) -> Tld {
    let warnings = tld.initialise(&context(Phase::InitializationMode));
    assert!(warnings.is_ok(), "{:?}", warnings.err().map(|e| e.message));
    tld
}

pub(super) fn ct() -> Context {
    context(Phase::ContinuousTimeMode)
}

/// Eq 2.1's fundamental mode of all the tanks: (m_1, omega_1).
pub(super) fn mode_one() -> (f64, f64) {
    let pi = std::f64::consts::PI;
    let r = H / A;
    let t = (pi * r).tanh();
    let mass = TANKS * 1000.0 * A * B * H * 8.0 * t / (pi * pi * pi * r);
    (mass, (9.81 * pi * t / A).sqrt())
}

pub(super) fn close(got: f64, want: f64, rel: f64, what: &str) {
    assert!(
        (got - want).abs() <= rel * want.abs().max(1e-300),
        "{what}: {got} vs {want}"
    );
}

pub(super) fn states(tld: &Tld) -> Vec<f64> {
    let mut x = vec![f64::NAN; ALL_STATES];
    assert_eq!(tld.states(&mut x).map_err(|e| e.message), Ok(Status::Ok));
    x
}

pub(super) fn derivatives(tld: &Tld) -> Vec<f64> {
    let mut dx = vec![f64::NAN; ALL_STATES];
    let got = tld.derivatives(&ct(), &mut dx);
    assert_eq!(got.map_err(|e| e.message), Ok(Status::Ok));
    dx
}

fn refused<T: std::fmt::Debug>(reply: Result<T, Refusal>, status: Status, says: &[&str]) {
    let why = reply.expect_err("refused");
    assert_eq!(why.status, status, "{}", why.message);
    for s in says {
        assert!(why.message.contains(s), "{:?} lacks {s:?}", why.message);
    }
}

/// Linear with one mode: the states in the model description's order (slosh.x0 and its energy
/// counted as input, all else 0), the derivatives Eq 2.1's oscillator under base.a and its
/// energies' rates (0 for every state Linear with one mode does not move), the same read as
/// variables; states set are read back and taken by the outputs.
#[test]
fn linear_states_and_derivatives_are_eq_2_1s_in_the_descriptions_order() {
    let (m, w) = mode_one();
    let mut tld = initialised(instance(LINEAR, FIXED, 0.005, &[]));
    let x = states(&tld);
    let e0 = 0.5 * m * w * w * X0 * X0;
    close(x[0], X0, 1e-15, "slosh.x");
    close(x[2], e0, 1e-12, "energy.input");
    for (k, v) in x.iter().enumerate() {
        if k != 0 && k != 2 {
            assert_eq!(*v, 0.0, "state {k}");
        }
    }
    let (xs, vs, a) = (-0.021, 0.047, 0.7);
    let mut s = vec![0.0; ALL_STATES];
    s[..4].copy_from_slice(&[xs, vs, e0 + 0.2, 0.05]);
    assert_eq!(
        tld.set_states(&ct(), &s).map_err(|e| e.message),
        Ok(Status::Ok)
    );
    assert_eq!(states(&tld), s);
    set_real(&mut tld, Phase::ContinuousTimeMode, vr::BASE_A, a);
    let dx = derivatives(&tld);
    let want = [
        vs,
        -a - 2.0 * ZETA * w * vs - w * w * xs,
        -m * a * vs,
        m * 2.0 * ZETA * w * vs * vs,
    ];
    for (k, want) in want.into_iter().enumerate() {
        close(dx[k], want, 1e-12, &format!("derivative {k}"));
    }
    assert!(dx[4..].iter().all(|v| *v == 0.0), "{dx:?}");
    let names = [
        vr::DER_SLOSH_X_,
        vr::DER_SLOSH_V_,
        vr::DER_ENERGY_INPUT_,
        vr::DER_ENERGY_DISSIPATED_,
    ];
    for (k, r) in names.into_iter().enumerate() {
        assert_eq!(real(&tld, Phase::ContinuousTimeMode, r), dx[k], "{r}");
    }
    let p = Phase::ContinuousTimeMode;
    assert_eq!(real(&tld, p, vr::SLOSH_X), xs);
    assert_eq!(real(&tld, p, vr::SLOSH_V), vs);
    close(
        real(&tld, p, vr::FORCE),
        m * (2.0 * ZETA * w * vs + w * w * xs),
        1e-12,
        "force",
    );
    // Linear's event indicators never cross, and an event iteration changes nothing.
    let mut z = [f64::NAN; 2];
    assert_eq!(tld.event_indicators(&ct(), &mut z).ok(), Some(Status::Ok));
    assert_eq!(z, [1.0, 1.0]);
    let update = tld.event_update(&context(Phase::EventMode));
    assert!(!update.expect("an event iteration").states_changed);
    assert_eq!(states(&tld), s);
    assert_eq!(tld.completed_step(&ct()).ok(), Some(false));
}

/// Before fmi2ExitInitializationMode a host reads the initial unknowns: the derivatives and
/// the states that are no outputs come from the simulation the parameters set so far start
/// (slosh.x0 at rest under base.a: v' = -a - w^2 x0), the estimator's (here none) are 0.
#[test]
fn initial_derivatives_are_read_in_initialisation_mode() {
    let (_, w) = mode_one();
    let mut tld = instance(LINEAR, FIXED, 0.005, &[]);
    let p = Phase::InitializationMode;
    set_real(&mut tld, p, vr::BASE_A, 0.3);
    close(
        real(&tld, p, vr::DER_SLOSH_V_),
        -0.3 - w * w * X0,
        1e-12,
        "der(slosh.v)",
    );
    assert_eq!(real(&tld, p, vr::DER_SLOSH_X_), 0.0);
    assert_eq!(real(&tld, p, vr::IMPACT_V), 0.0);
    assert_eq!(real(&tld, p, named("der(impact.z)")), 0.0);
    for k in 0..TRACKER_CONTINUOUS {
        assert_eq!(real(&tld, p, tracker_vr(k, false)), 0.0, "tracker {k}");
        assert_eq!(real(&tld, p, tracker_vr(k, true)), 0.0, "der tracker {k}");
    }
    // impact.v is no output: read from the state (S^2 resting nowhere: 0; Linear: 0), and
    // slosh.x's derivative is slosh.v.
    let mut tld = initialised(tld);
    let mut s = states(&tld);
    s[1] = -0.08;
    assert!(tld.set_states(&ct(), &s).is_ok());
    let p = Phase::ContinuousTimeMode;
    assert_eq!(real(&tld, p, vr::DER_SLOSH_X_), -0.08);
    assert_eq!(real(&tld, p, vr::IMPACT_V), 0.0);
}

/// J d in closed form for Linear with one mode: x' = v, v' = -a - 2 zeta w v - w^2 x,
/// energy.input' = -m a v, energy.dissipated' = 2 m zeta w v^2, force = m (2 zeta w v + w^2 x);
/// base.v and base.x enter no equation with a fixed amplitude, nor the estimator's states; a
/// known named twice adds its changes; the derivatives of states Linear does not move (and the
/// estimator's) are 0.
#[test]
fn directional_derivatives_are_the_closed_forms_partials() {
    let (m, w) = mode_one();
    let mut tld = initialised(instance(LINEAR, FIXED, 0.005, &[]));
    let (xs, vs, a) = (0.013, -0.06, 0.45);
    let mut s = states(&tld);
    (s[0], s[1]) = (xs, vs);
    assert!(tld.set_states(&ct(), &s).is_ok());
    set_real(&mut tld, Phase::ContinuousTimeMode, vr::BASE_A, a);
    let unknowns = [
        vr::DER_SLOSH_X_,
        vr::DER_SLOSH_V_,
        vr::DER_ENERGY_INPUT_,
        vr::DER_ENERGY_DISSIPATED_,
        vr::FORCE,
        vr::DER_IMPACT_Z_,
        tracker_vr(3, true),
        named("der(mode[2].v)"),
    ];
    let (dx, dv, da) = (0.7, -1.3, 0.9);
    let want = [
        dv,
        -da - 2.0 * ZETA * w * dv - w * w * dx,
        -m * (da * vs + a * dv),
        4.0 * m * ZETA * w * vs * dv,
        m * (2.0 * ZETA * w * dv + w * w * dx),
        0.0,
        0.0,
        0.0,
    ];
    // slosh.x twice (its changes add), base.v, base.x and an estimator state (no effect).
    let knowns = [
        vr::SLOSH_X,
        vr::SLOSH_V,
        vr::BASE_A,
        vr::BASE_V,
        vr::BASE_X,
        tracker_vr(0, false),
        vr::SLOSH_X,
    ];
    let seeds = [0.25 * dx, dv, da, 3.0, -2.0, 5.0, 0.75 * dx];
    let mut out = [f64::NAN; 8];
    let got = tld.directional_derivative(&ct(), &unknowns, &knowns, &seeds, &mut out);
    assert_eq!(got.map_err(|e| e.message), Ok(Status::Ok));
    for k in 0..want.len() {
        close(out[k], want[k], 1e-12, &format!("unknown {k}"));
    }
}

/// What is neither a state nor an input as a known, and neither a state derivative nor a Real
/// output as an unknown, is refused with the reason, the host's array untouched.
#[test]
fn directional_derivatives_refuse_what_is_no_state_input_or_output() {
    let tld = initialised(instance(LINEAR, FIXED, 0.005, &[]));
    let mut out = [f64::NAN];
    for known in [vr::ZETA, vr::FORCE, tracker_vr(0, true), vr::DER_SLOSH_X_] {
        let reply =
            tld.directional_derivative(&ct(), &[vr::DER_SLOSH_V_], &[known], &[1.0], &mut out);
        refused(
            reply,
            Status::Error,
            &["neither a continuous state", &known.to_string()],
        );
        assert!(out[0].is_nan());
    }
    for unknown in [
        vr::IMPACTS,
        vr::BASE_A,
        vr::ZETA,
        vr::SLOSH_X0,
        tracker_vr(0, false),
    ] {
        let reply = tld.directional_derivative(&ct(), &[unknown], &[vr::SLOSH_X], &[1.0], &mut out);
        refused(
            reply,
            Status::Error,
            &["neither a state derivative", &unknown.to_string()],
        );
        assert!(out[0].is_nan());
    }
}

/// Numbers too large for a double are refused, not handed over: base.a = 1e308 with the mass
/// moving makes energy.input's rate -m a v overflow; fmi2GetDerivatives and J d say which
/// entry, the host's arrays untouched.
#[test]
fn derivatives_that_overflow_are_refused() {
    let mut tld = initialised(instance(LINEAR, FIXED, 0.005, &[]));
    let mut s = states(&tld);
    s[1] = 1.0;
    assert!(tld.set_states(&ct(), &s).is_ok());
    set_real(&mut tld, Phase::ContinuousTimeMode, vr::BASE_A, 1e308);
    let mut dx = vec![f64::NAN; ALL_STATES];
    let reply = tld.derivatives(&ct(), &mut dx);
    refused(
        reply,
        Status::Error,
        &["fmi2GetDerivatives", "derivative 2 is not finite"],
    );
    assert!(dx.iter().all(|v| v.is_nan()));
    let mut out = [f64::NAN; 2];
    let unknowns = [vr::DER_SLOSH_X_, vr::DER_ENERGY_INPUT_];
    let reply = tld.directional_derivative(&ct(), &unknowns, &[vr::SLOSH_V], &[1.0], &mut out);
    refused(reply, Status::Error, &["entry 1 is not finite"]);
    assert!(out.iter().all(|v| v.is_nan()));
    // A direction of base.a alone at this state stays finite (-m v da): answered.
    let reply = tld.directional_derivative(&ct(), &unknowns, &[vr::BASE_A], &[1.0], &mut out);
    assert_eq!(reply.map_err(|e| e.message), Ok(Status::Ok));
    assert_eq!(out[0], 0.0);
}

/// The nominals are the states' scales: half a tank length, the velocity of that motion at
/// w_1 and its energy, for the bank's modes too; where a model's scale is not a finite number
/// above 0 (the estimator's with A_e = 0, whose squares underflow) the FMI default 1.
#[test]
fn nominals_are_the_scales_and_one_where_a_scale_vanishes() {
    let (m, w) = mode_one();
    let tld = initialised(instance(LINEAR, FIXED, 0.0, &[]));
    let mut n = vec![f64::NAN; ALL_STATES];
    assert_eq!(tld.nominals(&mut n).ok(), Some(Status::Ok));
    let (x, v) = (0.5 * A, 0.5 * A * w);
    let e = 0.5 * m * v * v;
    for (k, want) in [(0, x), (1, v), (2, e), (3, e), (4, x), (5, v)] {
        close(n[k], want, 1e-12, &format!("nominal {k}"));
    }
    for (k, got) in n.iter().enumerate().take(STATES).skip(BANK) {
        let want = if (k - BANK).is_multiple_of(2) { x } else { v };
        close(*got, want, 1e-12, &format!("nominal {k}"));
    }
    let sim = tld.sim.as_ref().expect("initialised");
    let mut scales = [f64::NAN; TRACKER_CONTINUOUS];
    sim.tracker_nominals(&mut scales);
    assert!(
        scales.iter().any(|s| *s <= 0.0),
        "the test needs a scale of 0: {scales:?}"
    );
    for (k, scale) in scales.iter().enumerate() {
        let want = if scale.is_finite() && *scale > 0.0 {
            *scale
        } else {
            1.0
        };
        assert_eq!(n[T0 + k], want, "the estimator's nominal {k}");
    }
}

/// S^2: the event indicators are the gaps to the walls (d/2 -+ z, the wall moved away from a
/// clearance further); an impact is an event that changes the states (the impact mass
/// rebounds), after which the mass moves away and the next iteration changes nothing.
#[test]
fn s2s_indicators_are_the_gaps_and_an_impact_changes_the_states() {
    let d = 0.1;
    let more = [(vr::SLAMMING_CLEARANCE, d), (vr::SLAMMING_OMEGA, 0.9)];
    let mut tld = initialised(instance(SLAMMING, FIXED, 0.005, &more));
    let p = Phase::ContinuousTimeMode;
    set_real(&mut tld, p, vr::BASE_A, 1.0);
    let mut s = states(&tld);
    (s[4], s[5]) = (0.03, -0.2);
    assert!(tld.set_states(&ct(), &s).is_ok());
    let mut z = [f64::NAN; 2];
    assert_eq!(tld.event_indicators(&ct(), &mut z).ok(), Some(Status::Ok));
    close(z[0], 0.5 * d - 0.03 + d, 1e-15, "wall +d/2");
    close(z[1], 0.5 * d + 0.03, 1e-15, "wall -d/2");
    let update = tld.event_update(&context(Phase::EventMode)).expect("event");
    assert!(!update.states_changed);
    // At the wall -d/2, moving into it.
    (s[4], s[5]) = (-0.5 * d, -0.2);
    assert!(tld.set_states(&ct(), &s).is_ok());
    let update = tld.event_update(&context(Phase::EventMode)).expect("event");
    assert!(update.states_changed);
    let after = states(&tld);
    assert!(after[5] > 0.0, "rebounds: {after:?}");
    assert_eq!(real(&tld, p, vr::IMPACT_V), after[5]);
    let update = tld.event_update(&context(Phase::EventMode)).expect("event");
    assert!(!update.states_changed);
}

/// base.v.jump is the host's total of the structure's velocity jumps (FMU.md): each event
/// applies what is new since the last one, once. The impact mass in flight takes the jump in
/// its relative velocity: 0.1, then nothing while the total stands, then the 0.2 more.
#[test]
fn base_velocity_jumps_are_taken_once_each() {
    let more = [(vr::SLAMMING_CLEARANCE, 0.1), (vr::SLAMMING_OMEGA, 0.9)];
    let mut tld = initialised(instance(SLAMMING, FIXED, 0.005, &more));
    let mut s = states(&tld);
    (s[4], s[5]) = (0.03, -0.2);
    assert!(tld.set_states(&ct(), &s).is_ok());
    let mut jumped = |total: f64| {
        let before = states(&tld)[5];
        set_real(&mut tld, Phase::EventMode, vr::BASE_V_JUMP, total);
        assert!(tld.event_update(&context(Phase::EventMode)).is_ok());
        states(&tld)[5] - before
    };
    let first = jumped(0.1);
    close(first.abs(), 0.1, 1e-12, "the first jump");
    assert_eq!(jumped(0.1), 0.0, "the same total again");
    close(jumped(0.3), 2.0 * first, 1e-12, "what is new of the total");
}

/// Every Model Exchange function refuses before initialisation ("no simulation") and for a
/// model ME does not offer (ShallowWater in a Co-Simulation instance, which may ask once
/// terminated), saying why; states refused by the model (a runaway slosh.x) are an error that
/// leaves the states as they were.
#[test]
fn me_functions_refuse_without_a_simulation_they_can_integrate() {
    let mut fresh = instance(LINEAR, FIXED, 0.005, &[]);
    assert_eq!(
        fresh.offers_model_exchange(),
        Err("no simulation".to_string())
    );
    let mut sw = initialised(instance(SHALLOW_WATER, FIXED, 0.005, &[]));
    let why = sw.offers_model_exchange().expect_err("not offered");
    for tld in [&mut fresh, &mut sw] {
        let says = if tld.sim.is_some() {
            why.as_str()
        } else {
            "no simulation"
        };
        let mut x = vec![f64::NAN; ALL_STATES];
        refused(
            tld.states(&mut x),
            Status::Error,
            &["fmi2GetContinuousStates", says],
        );
        refused(
            tld.nominals(&mut x),
            Status::Error,
            &["fmi2GetNominalsOfContinuousStates", says],
        );
        refused(
            tld.derivatives(&ct(), &mut x),
            Status::Error,
            &["fmi2GetDerivatives", says],
        );
        assert!(x.iter().all(|v| v.is_nan()));
        let mut z = [f64::NAN; 2];
        refused(
            tld.event_indicators(&ct(), &mut z),
            Status::Error,
            &["fmi2GetEventIndicators", says],
        );
        refused(
            tld.completed_step(&ct()),
            Status::Error,
            &["fmi2CompletedIntegratorStep", says],
        );
        let mut out = [f64::NAN];
        let reply = tld.directional_derivative(
            &ct(),
            &[vr::DER_SLOSH_V_],
            &[vr::SLOSH_X],
            &[1.0],
            &mut out,
        );
        refused(
            reply,
            Status::Error,
            &["fmi2GetDirectionalDerivative", says],
        );
        let s = vec![0.0; ALL_STATES];
        refused(
            tld.set_states(&ct(), &s),
            Status::Error,
            &["fmi2SetContinuousStates", says],
        );
    }
    refused(
        fresh.event_update(&context(Phase::EventMode)),
        Status::Error,
        &["fmi2NewDiscreteStates", "no simulation"],
    );
    let mut tld = initialised(instance(LINEAR, FIXED, 0.005, &[]));
    assert_eq!(tld.offers_model_exchange(), Ok(()));
    let before = states(&tld);
    let mut s = before.clone();
    s[0] = 101.0 * A;
    s[1] = 0.3;
    refused(
        tld.set_states(&ct(), &s),
        Status::Error,
        &[
            "fmi2SetContinuousStates",
            "slosh.x",
            "the states are left as they were",
        ],
    );
    assert_eq!(states(&tld), before);
}

/// A host learns the number of continuous states from the model description, one der(...)
/// variable per state: ALL_STATES (and so the arrays of every ME call) must be that number.
#[test]
fn the_state_count_is_the_model_descriptions() {
    let derivatives = VARIABLES
        .iter()
        .filter(|v| v.name.starts_with("der("))
        .count();
    assert_eq!(ALL_STATES, derivatives);
}
