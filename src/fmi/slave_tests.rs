//! TLD's slave (slave.rs, access.rs, snapshot.rs) through the shared layer's contract
//! ([`Slave`]), as the layer calls it once it has checked the phase and the lengths: against
//! references written here: the free decay of Eq 2.1's fundamental mode in closed form (its
//! mass and frequency from the tank, MODEL.md), the calculated parameters' formulas (the model
//! description: mass.liquid = rho a b h tanks, mass.inactive = mass.liquid - mass.slosh), the
//! ranges the model description declares, and the FMI 2.0 rules (a refused call changes
//! nothing; input derivatives hold for one step; a saved state restores the same instance).

// The test's tank (me_tests.rs): 0.6 x 0.25 x 0.07 m, two tanks, zeta 0.04, x0 = 0.015 m.
use super::super::me_tests::{
    A, B, FIXED, H, LINEAR, SLAMMING, TANKS, X0, ZETA, close, context, initialised, instance,
    mode_one, named, real, set_real,
};
use super::*;
use crate::model::Output;
use crate::solver::SolveError;
use fmi2_slave::calls::Phase;
use fmi2_slave::frame::{Common, Experiment, decode, encode};
use fmi2_slave::{Continuous, Status};
use vars::VarType;

/// Free decay of a damped oscillator from (x0, 0): (x, v) at t, in closed form.
fn free_decay(t: f64) -> (f64, f64) {
    let w = mode_one().1;
    let s = ZETA * w;
    let wd = w * (1.0 - ZETA * ZETA).sqrt();
    let e = (-s * t).exp();
    let x = e * X0 * ((wd * t).cos() + s / wd * (wd * t).sin());
    let v = -e * X0 * w * w / wd * (wd * t).sin();
    (x, v)
}

fn step(tld: &mut Tld, t: f64, h: f64) -> Result<bool, Refusal> {
    tld.step(&context(Phase::StepComplete), t, h)
}

fn get(tld: &Tld, phase: Phase, r: u32, ty: VarType) -> Result<f64, Refusal> {
    let mut out = [f64::NAN];
    tld.get(&context(phase), &[r], &mut out, ty, "fmi2GetReal", |v| v)?;
    Ok(out[0])
}

/// The value of `r` read as its own type (impacts is an Integer).
fn read(tld: &Tld, phase: Phase, r: u32) -> f64 {
    let ty = index_of(r).map_or(VarType::Real, |i| VARIABLES[i].ty);
    let got = get(tld, phase, r, ty).map_err(|e| e.message);
    got.unwrap_or_else(|e| panic!("{r}: {e}"))
}

fn refused<T: std::fmt::Debug>(reply: Result<T, Refusal>, says: &[&str]) {
    let why = reply.expect_err("refused");
    assert_eq!(why.status, Status::Error, "{}", why.message);
    for s in says {
        assert!(why.message.contains(s), "{:?} lacks {s:?}", why.message);
    }
}

/// Every output variable of the model description and the simulation output it shows (the
/// model description's descriptions, FMU.md's table).
const OUTPUTS: [(&str, Output); 15] = [
    ("force", Output::Force),
    ("force.mean", Output::ForceMean),
    ("base_shear", Output::BaseShear),
    ("slosh.x", Output::X),
    ("slosh.v", Output::V),
    ("energy.input", Output::EnergyInput),
    ("energy.dissipated", Output::EnergyDissipated),
    ("energy.stored", Output::EnergyStored),
    ("A_e.estimate", Output::Amplitude),
    ("zeta.effective", Output::Zeta),
    ("impact.z", Output::ImpactZ),
    ("impacts", Output::Impacts),
    ("impact.impulse", Output::ImpactImpulse),
    ("surface.left", Output::SurfaceLeft),
    ("surface.right", Output::SurfaceRight),
];

/// A step of Linear's free decay: Ok(false) (plausible), and slosh.x, slosh.v, energy.stored
/// read by name are the closed form's; every output reads as the simulation output its name
/// says after a step under base.a (S^2's and ShallowWater's outputs included: a Linear
/// run reports them too).
#[test]
fn a_step_is_the_free_decay_and_every_output_reads_by_its_name() {
    let mut tld = initialised(instance(LINEAR, FIXED, 0.005, &[]));
    let p = Phase::StepComplete;
    let (m, w) = mode_one();
    assert_eq!(real(&tld, p, vr::SLOSH_X), X0);
    close(
        real(&tld, p, vr::ENERGY_STORED),
        0.5 * m * w * w * X0 * X0,
        1e-12,
        "energy.stored at t = 0",
    );
    for (t, h) in [(0.0, 0.3), (0.3, 0.45)] {
        assert_eq!(step(&mut tld, t, h).map_err(|e| e.message), Ok(false));
        let (x, v) = free_decay(t + h);
        close(real(&tld, p, vr::SLOSH_X), x, 1e-9, "slosh.x");
        close(real(&tld, p, vr::SLOSH_V), v, 1e-9, "slosh.v");
        let stored = 0.5 * m * (w * w * x * x + v * v);
        close(real(&tld, p, vr::ENERGY_STORED), stored, 1e-9, "energy");
        // The outputs a master reads after every step take the quick path (Tld::quick_reals:
        // loads, no call out of line), with the same value.
        for r in [vr::FORCE, vr::SLOSH_X, vr::SLOSH_V] {
            assert_eq!(quick(&tld, r), Some(real(&tld, p, r)), "{r}");
        }
    }
    set_real(&mut tld, p, vr::BASE_A, 0.7);
    assert_eq!(step(&mut tld, 0.75, 0.2).map_err(|e| e.message), Ok(false));
    let sim = tld.sim.as_ref().expect("initialised");
    let inputs = tld.values.inputs([0.0; 2]);
    for (name, which) in OUTPUTS {
        let r = named(name);
        let want = sim.output(which, &inputs);
        assert_eq!(read(&tld, p, r).to_bits(), want.to_bits(), "{name}");
    }
}

/// fmi2GetRealOutputDerivatives (order 1, exact) of every output: Eq 2.1's oscillator's
/// rates for Linear (slosh.x' = v, slosh.v' = -a - 2 zeta w v - w^2 x, the base's power
/// energy.input' = -m a v, the damping's energy.dissipated' = 2 zeta w m v^2, force' =
/// m (2 zeta w v' + w^2 v), impact.z' = 0: no impact mass), the others the simulation's own
/// rates; none before initialisation, and order 2 refused.
#[test]
fn output_derivatives_are_the_oscillators_rates() {
    let p = Phase::StepComplete;
    let (m, w) = mode_one();
    let fresh = instance(LINEAR, FIXED, 0.005, &[]);
    let c = context(p);
    let none = fresh.output_derivatives(&c, &[vr::FORCE], &[1], |_, _| {});
    refused(none, &["not initialised"]);
    let mut tld = initialised(fresh);
    let a = 0.7;
    set_real(&mut tld, p, vr::BASE_A, a);
    assert!(step(&mut tld, 0.0, 0.3).is_ok());
    let vrs: Vec<u32> = OUTPUTS.iter().map(|(name, _)| named(name)).collect();
    let mut got = vec![f64::NAN; vrs.len()];
    let reply = tld.output_derivatives(&c, &vrs, &vec![1; vrs.len()], |k, v| got[k] = v);
    assert_eq!(reply.map_err(|e| e.message), Ok(Status::Ok));
    let (x, v) = (real(&tld, p, vr::SLOSH_X), real(&tld, p, vr::SLOSH_V));
    let dv = -a - 2.0 * ZETA * w * v - w * w * x;
    let sim = tld.sim.as_ref().expect("initialised");
    let inputs = tld.values.inputs([0.0; 2]);
    for (k, (name, which)) in OUTPUTS.into_iter().enumerate() {
        let want = match name {
            "slosh.x" => v,
            "slosh.v" => dv,
            "energy.input" => -m * a * v,
            "energy.dissipated" => 2.0 * ZETA * w * m * v * v,
            "force" => m * (2.0 * ZETA * w * dv + w * w * v),
            "impact.z" => 0.0,
            _ => sim.output_derivative(which, &inputs),
        };
        close(got[k], want, 1e-12, name);
    }
    let order_2 = tld.output_derivatives(&c, &[vr::SLOSH_X], &[2], |_, _| {});
    refused(order_2, &["order 2 of 'slosh.x'"]);
}

/// The calculated parameters, and the outputs before initialisation (from the simulation the
/// parameters set so far would start), read by name: Eq 2.1's and Eq 2.2's numbers.
#[test]
fn calculated_parameters_and_early_outputs_are_the_tanks() {
    let tld = instance(LINEAR, FIXED, 0.005, &[]);
    let p = Phase::InitializationMode;
    let (m, w) = mode_one();
    let liquid = TANKS * 1000.0 * A * B * H;
    close(real(&tld, p, named("omega_f")), w, 1e-12, "omega_f");
    close(real(&tld, p, named("mass.liquid")), liquid, 1e-12, "liquid");
    close(real(&tld, p, named("mass.slosh")), m, 1e-12, "slosh");
    close(
        real(&tld, p, named("mass.inactive")),
        liquid - m,
        1e-12,
        "inactive",
    );
    assert_eq!(real(&tld, p, named("slosh.x")), X0);
    close(
        real(&tld, p, named("energy.stored")),
        0.5 * m * w * w * X0 * X0,
        1e-12,
        "energy.stored",
    );
    close(real(&tld, p, named("zeta.effective")), ZETA, 1e-15, "zeta");
}

/// What no variable holds, or holds as another type, or holds no value for, is refused with
/// the reason; a parameter set so far that makes no simulation refuses what depends on it.
#[test]
fn reads_without_a_value_are_refused_with_the_reason() {
    let mut tld = instance(LINEAR, FIXED, 0.005, &[]);
    let p = Phase::InitializationMode;
    refused(
        get(&tld, p, 9999, VarType::Real),
        &["unknown value reference 9999"],
    );
    refused(
        get(&tld, p, vr::TANK_LENGTH, VarType::Integer),
        &["'tank.length'", "of type Real"],
    );
    // The tank deeper than long: no simulation, so no omega_f and no slosh.x yet.
    set_real(&mut tld, p, vr::TANK_DEPTH, 0.9);
    refused(
        get(&tld, p, vr::OMEGA_F, VarType::Real),
        &["inconsistent", "tank.depth"],
    );
    refused(get(&tld, p, vr::SLOSH_X, VarType::Real), &["inconsistent"]);
}

/// Sets: one and several at once, each checked against the model description's range before
/// any is taken; the per-step inputs through the quick path (finite values only); the flag of
/// a solver.tolerance the user set, and of nothing else.
#[test]
fn sets_are_checked_first_and_the_user_tolerance_is_flagged() {
    let mut tld = Tld::new();
    let p = Phase::InitializationMode;
    let c = context(p);
    let set = |tld: &mut Tld, vrs: &[u32], values: &[f64]| {
        tld.set(&c, vrs, values, VarType::Real, "fmi2SetReal", |v| v)
    };
    assert!(!tld.flag());
    assert_eq!(
        set(&mut tld, &[vr::TANK_LENGTH], &[0.5]).ok(),
        Some(Status::Ok)
    );
    assert_eq!(set(&mut tld, &[vr::BASE_A], &[0.5]).ok(), Some(Status::Ok));
    assert!(!tld.flag(), "no tolerance set");
    let two = set(&mut tld, &[vr::TANK_BREADTH, vr::TANK_DEPTH], &[0.4, 0.03]);
    assert_eq!(two.ok(), Some(Status::Ok));
    assert_eq!(real(&tld, p, vr::TANK_LENGTH), 0.5);
    assert_eq!(real(&tld, p, vr::TANK_BREADTH), 0.4);
    assert_eq!(real(&tld, p, vr::TANK_DEPTH), 0.03);
    // The depth's min is 0 (exclusive or not): -1 is refused, and neither value is taken.
    let before = format!("{:?}", tld.values); // NaN where no value: compared as text
    refused(set(&mut tld, &[vr::TANK_DEPTH], &[-1.0]), &["tank.depth"]);
    refused(
        set(&mut tld, &[vr::TANK_BREADTH, vr::TANK_DEPTH], &[0.3, -1.0]),
        &["tank.depth"],
    );
    refused(set(&mut tld, &[vr::BASE_A], &[f64::NAN]), &["base.a"]);
    assert_eq!(format!("{:?}", tld.values), before);
    // The quick path: base.a, base.v, base.x take any finite value; nothing else goes there.
    assert!(tld.set_quietly(vr::BASE_A, -2.5, VarType::Real));
    assert!(tld.set_quietly(vr::BASE_X, 1e-3, VarType::Real));
    assert!(!tld.set_quietly(vr::BASE_V, f64::INFINITY, VarType::Real));
    assert!(!tld.set_quietly(vr::TANK_LENGTH, 0.7, VarType::Real));
    assert_eq!(quick(&tld, vr::BASE_A), Some(-2.5));
    assert_eq!(quick(&tld, vr::BASE_X), Some(1e-3));
    assert_eq!(quick(&tld, vr::BASE_V), Some(0.0));
    assert_eq!(quick(&tld, vr::TANK_LENGTH), Some(0.5));
    // A calculated parameter and an output before initialisation are no load.
    assert_eq!(quick(&tld, vr::OMEGA_F), None);
    assert_eq!(quick(&tld, vr::SLOSH_X), None);
    assert!(!tld.flag());
    assert_eq!(
        set(&mut tld, &[vr::SOLVER_TOLERANCE], &[1e-7]).ok(),
        Some(Status::Ok)
    );
    assert!(tld.flag());
}

/// fmi2SetRealInputDerivatives: base.a's first and second derivatives are kept for the next
/// step (base.v's and base.x's accepted and not used), a refused list keeps nothing, and a
/// step uses them (Linear's exact step under a ramp: x(h) of x'' + 2 zeta w x' + w^2 x = -r t
/// from rest, in closed form) and then forgets them.
#[test]
fn input_derivatives_hold_for_one_step() {
    let mut tld = initialised(instance(LINEAR, FIXED, 0.005, &[(vr::SLOSH_X0, 0.0)]));
    let d = |tld: &mut Tld, vrs: &[u32], orders: &[i32], values: &[f64]| {
        tld.set_input_derivatives(vrs, orders, values)
    };
    let all = [vr::BASE_A, vr::BASE_A, vr::BASE_V, vr::BASE_X];
    let got = d(&mut tld, &all, &[1, 2, 1, 2], &[0.4, 3.0, 5.0, 7.0]);
    assert_eq!(got.map_err(|e| e.message), Ok(Status::Ok));
    assert_eq!(tld.a_derivatives, [0.4, 3.0]);
    refused(
        d(&mut tld, &[vr::BASE_A, vr::BASE_A], &[1, 3], &[1.0, 1.0]),
        &["order"],
    );
    assert_eq!(tld.a_derivatives, [0.4, 3.0]);
    assert_eq!(
        d(&mut tld, &[vr::BASE_A], &[2], &[0.0]).ok(),
        Some(Status::Ok)
    );
    assert_eq!(tld.a_derivatives, [0.4, 0.0]);
    // From rest under base.a = r t: x = alpha t + beta + e^(-s t) (c1 cos wd t + c2 sin wd t),
    // alpha = -r/w^2, beta = 2 zeta r/w^3 (the particular solution), x(0) = x'(0) = 0.
    let (_, w) = mode_one();
    let (r, h) = (0.4, 0.25);
    let s = ZETA * w;
    let wd = w * (1.0 - ZETA * ZETA).sqrt();
    let (alpha, beta) = (-r / (w * w), 2.0 * ZETA * r / (w * w * w));
    let c1 = -beta;
    let c2 = (s * c1 - alpha) / wd;
    let want = alpha * h + beta + (-s * h).exp() * (c1 * (wd * h).cos() + c2 * (wd * h).sin());
    assert_eq!(step(&mut tld, 0.0, h).map_err(|e| e.message), Ok(false));
    close(
        real(&tld, Phase::StepComplete, vr::SLOSH_X),
        want,
        1e-9,
        "x under a ramp",
    );
    assert_eq!(tld.a_derivatives, [0.0; 2]);
    // Both derivatives set (neither 0): forgotten after the step all the same.
    let both = d(&mut tld, &[vr::BASE_A, vr::BASE_A], &[1, 2], &[0.4, 3.0]);
    assert_eq!(both.ok(), Some(Status::Ok));
    assert_eq!(step(&mut tld, h, h).map_err(|e| e.message), Ok(false));
    assert_eq!(tld.a_derivatives, [0.0; 2]);
}

/// The experiment's tolerance is kept within solver.tolerance's declared range [1e-14, 0.1].
#[test]
fn the_experiments_tolerance_is_kept_in_the_declared_range() {
    assert_eq!(Tld::tolerance(1e-20), 1e-14);
    assert_eq!(Tld::tolerance(0.5), 0.1);
    assert_eq!(Tld::tolerance(3e-7), 3e-7);
}

/// Initialisation builds the simulation and passes its warnings on; uninitialising drops it,
/// after which a step is refused.
#[test]
fn initialisation_warns_and_uninitialisation_forgets() {
    let p = Phase::InitializationMode;
    let mut tld = instance(LINEAR, FIXED, 0.005, &[]);
    assert_eq!(
        tld.initialise(&context(p)).map_err(|e| e.message),
        Ok(vec![])
    );
    // h/a = 0.2: beyond the shallow-water validity, a warning.
    let mut deep = instance(LINEAR, FIXED, 0.005, &[(vr::TANK_DEPTH, 0.12)]);
    let warnings = deep.initialise(&context(p)).map_err(|e| e.message);
    let warnings = warnings.expect("initialised");
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].contains("h/a = 0.200 exceeds 0.15"),
        "{warnings:?}"
    );
    assert!(step(&mut tld, 0.0, 0.1).is_ok());
    tld.uninitialise();
    assert!(tld.sim.is_none());
    refused(step(&mut tld, 0.1, 0.1), &["not initialised"]);
}

/// A step whose motion leaves the tank far behind says so (Ok(true)), and the notice, once,
/// names the step's end and the displacement; a plausible run has none.
#[test]
fn implausible_motion_is_noticed_once_with_the_numbers() {
    let mut calm = initialised(instance(LINEAR, FIXED, 0.005, &[]));
    assert_eq!(step(&mut calm, 0.0, 1.0).map_err(|e| e.message), Ok(false));
    let mut tld = initialised(instance(LINEAR, FIXED, 0.005, &[]));
    // 5 g (below the notice's 10 g): |x| ~ 2 a / w^2 = 5.5 m in a 0.6 m tank.
    set_real(&mut tld, Phase::StepComplete, vr::BASE_A, 49.0);
    assert_eq!(step(&mut tld, 0.0, 1.0).map_err(|e| e.message), Ok(true));
    let mut c = context(Phase::StepComplete);
    c.time = 1.0;
    let notice = tld.notice(&c).expect("a notice");
    let x = real(&tld, Phase::StepComplete, vr::SLOSH_X);
    assert!(x.abs() > A, "{x}");
    for s in [
        "fmi2DoStep to t = 1: slosh.x = ",
        &format!("{x:.3} m"),
        "0.6 m long",
    ] {
        assert!(notice.contains(s), "{notice:?} lacks {s:?}");
    }
    assert_eq!(tld.notice(&c), None, "once");
}

/// A step the solver gives up on is fmi2Discard with the hint to retry smaller; any other
/// failure is fmi2Error, and both say where the step started and how long it was.
#[test]
fn failed_steps_say_whether_a_smaller_step_may_do() {
    let limit = 7;
    let e = StepError::Solver(SolveError::TooManySteps { limit, t: 1.5 });
    let r = step_failed(2.0, 0.5, e);
    assert_eq!(r.status, Status::Discard);
    assert!(
        r.message.starts_with("fmi2DoStep from t = 2 by 0.5: "),
        "{}",
        r.message
    );
    assert!(
        r.message
            .ends_with("retry with a smaller communication step."),
        "{}",
        r.message
    );
    let r = step_failed(
        2.0,
        0.5,
        StepError::Runaway {
            x: 70.0,
            limit: 60.0,
        },
    );
    assert_eq!(r.status, Status::Error);
    assert!(r.message.contains("ran away"), "{}", r.message);
    assert!(
        r.message.ends_with("left at the start of the step."),
        "{}",
        r.message
    );
}

/// The saved part and back through the shared layer's frame.
fn round_trip(tld: &Tld, phase: Phase) -> Result<Tld, String> {
    let common = Common {
        phase,
        experiment: Experiment::default(),
        time: 0.0,
        flag: tld.flag(),
    };
    let bytes = encode(b"TLDs", 1, "g", &common, |out| tld.save(out));
    let (common, mut reader) = decode(&bytes, b"TLDs", 1, "g", "TLD")?;
    let back = Tld::load(&context(common.phase), common.flag, &mut reader)?;
    reader.finish()?;
    Ok(back)
}

/// A saved state restores the same slave (values, input derivatives, flag, simulation),
/// which continues as the original does; one with non-finite input derivatives, or with a
/// simulation in a phase before initialisation, is refused.
#[test]
fn a_saved_slave_restores_and_continues_alike() {
    let p = Phase::StepComplete;
    let mut tld = initialised(instance(
        LINEAR,
        FIXED,
        0.005,
        &[(vr::SOLVER_TOLERANCE, 1e-8)],
    ));
    assert!(step(&mut tld, 0.0, 0.3).is_ok());
    set_real(&mut tld, p, vr::BASE_A, 0.3);
    assert!(
        tld.set_input_derivatives(&[vr::BASE_A], &[1], &[0.2])
            .is_ok()
    );
    let mut back = round_trip(&tld, p).expect("restored");
    assert_eq!(format!("{:?}", back.values), format!("{:?}", tld.values));
    assert_eq!(back.a_derivatives, [0.2, 0.0]);
    assert!(back.flag());
    let snapshot = |t: &Tld| t.sim.as_ref().map(Damper::snapshot);
    assert_eq!(snapshot(&back), snapshot(&tld));
    assert!(step(&mut tld, 0.3, 0.2).is_ok());
    assert!(step(&mut back, 0.3, 0.2).is_ok());
    for (name, _) in OUTPUTS {
        let r = named(name);
        assert_eq!(
            read(&back, p, r).to_bits(),
            read(&tld, p, r).to_bits(),
            "{name}"
        );
    }
    // Before initialisation: no simulation saved, none restored.
    let fresh = instance(LINEAR, FIXED, 0.005, &[]);
    let early = round_trip(&fresh, Phase::InitializationMode).expect("restored");
    assert!(early.sim.is_none());
    assert_eq!(format!("{:?}", early.values), format!("{:?}", fresh.values));
    let refusal = round_trip(&tld, Phase::InitializationMode)
        .err()
        .unwrap_or_default();
    assert!(refusal.contains("before initialisation"), "{refusal}");
    tld.a_derivatives[1] = f64::NAN;
    let refusal = round_trip(&tld, p).err().unwrap_or_default();
    assert!(
        refusal.contains("non-finite input derivatives"),
        "{refusal}"
    );
}

/// S^2's impulse handed to the structure so far rides in the saved state (impact.impulse's
/// slot) and comes back; without an impact the slot keeps its start.
#[test]
fn s2s_impulse_rides_in_the_saved_state() {
    let d = 0.1;
    let more = [(vr::SLAMMING_CLEARANCE, d), (vr::SLAMMING_OMEGA, 0.9)];
    let mut tld = initialised(instance(SLAMMING, FIXED, 0.005, &more));
    let (ct, ev) = (Phase::ContinuousTimeMode, Phase::EventMode);
    let calm = round_trip(&tld, ev).expect("restored");
    assert_eq!(real(&calm, ev, vr::IMPACT_IMPULSE), 0.0);
    // The impact mass at the wall -d/2, moving into it: an impact at the next event.
    set_real(&mut tld, ct, vr::BASE_A, 1.0);
    let mut s = vec![f64::NAN; crate::model::continuous::ALL_STATES];
    assert!(tld.states(&mut s).is_ok());
    (s[4], s[5]) = (-0.5 * d, -0.2);
    assert!(tld.set_states(&context(ct), &s).is_ok());
    let update = tld.event_update(&context(ev)).expect("event");
    assert!(update.states_changed);
    let impulse = real(&tld, ev, vr::IMPACT_IMPULSE);
    assert!(impulse != 0.0);
    let back = round_trip(&tld, ev).expect("restored");
    assert_eq!(real(&back, ev, vr::IMPACT_IMPULSE), impulse);
    assert_eq!(read(&back, ev, vr::IMPACTS), 1.0);
}

/// The quick path reads several values in one call, in the host's order, and answers false
/// (the full path decides) as soon as one of them is no load or not finite: an unknown value
/// reference, an output it does not keep, a calculated parameter, finite values whose sum
/// overflows (the full path then hands them out).
#[test]
fn the_quick_path_reads_all_or_leaves_them_to_the_full_path() {
    let p = Phase::StepComplete;
    let mut tld = initialised(instance(LINEAR, FIXED, 0.005, &[]));
    set_real(&mut tld, p, vr::BASE_A, 0.25);
    assert_eq!(step(&mut tld, 0.0, 0.1).map_err(|e| e.message), Ok(false));
    let vrs = [
        vr::SLOSH_V,
        vr::BASE_A,
        vr::FORCE,
        vr::SLOSH_X,
        vr::TANK_LENGTH,
    ];
    let mut out = [0.0; 5];
    assert!(tld.get_quietly(&vrs, &mut out, VarType::Real, |x| x));
    let want = vrs.map(|r| real(&tld, p, r));
    assert_eq!(out.map(f64::to_bits), want.map(f64::to_bits));
    assert_eq!(out[1], 0.25);
    let unknown = (0..u32::MAX).find(|&r| vars::index_of(r).is_none());
    let unknown = unknown.expect("an unknown value reference");
    for other in [vr::FORCE_MEAN, vr::OMEGA_F, unknown, u32::MAX] {
        let vrs = [vr::SLOSH_X, other, vr::SLOSH_V];
        let mut out = [0.0; 3];
        assert!(
            !tld.get_quietly(&vrs, &mut out, VarType::Real, |x| x),
            "{other}"
        );
    }
    // Finite, their sum not: the full path hands them out.
    set_real(&mut tld, p, vr::BASE_A, f64::MAX);
    set_real(&mut tld, p, vr::BASE_X, f64::MAX);
    let vrs = [vr::BASE_A, vr::BASE_X];
    assert!(!tld.get_quietly(&vrs, &mut [0.0; 2], VarType::Real, |x| x));
    assert_eq!(vrs.map(|r| real(&tld, p, r)), [f64::MAX; 2]);
}

/// [`Slave::get_quietly`] of one Real: its value, or None (the full path).
fn quick(tld: &Tld, r: u32) -> Option<f64> {
    let mut out = [0.0];
    tld.get_quietly(&[r], &mut out, VarType::Real, |x| x)
        .then_some(out[0])
}
