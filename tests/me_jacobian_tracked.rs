//! TLD.fmu's directional derivatives in Model Exchange with amplitude = Tracked (the default),
//! through its C entry points: the estimator's states move the estimate and, through the
//! damping law, the damping of every oscillator. Every column of J (all 31 continuous states,
//! base.a, base.v, base.x) for every state derivative and Real output, against central
//! differences of fmi2GetDerivatives and fmi2GetReal, for every model offered in Model Exchange
//! (Linear with 3 modes, Nonlinear, Auto, SloshingSlamming with its impact mass in flight),
//! under the NSD and Screens laws, with the velocity rebuilt from base.a and measured (base.v
//! set, the switch an event).

mod common;

use common::*;
use tld_fmu::fmi::vars::vr;

const STATES: usize = tld_fmu::model::continuous::ALL_STATES;
const NSD: i32 = 2;
const SCREENS: i32 = 4;
/// The continuous states' names in state order: S^2's six, the modes' bank, the estimator's
/// (the rebuilt velocity, then each filter pair of v^2, a^2 and 1).
fn state_names() -> Vec<String> {
    let mut names: Vec<String> = S2_NAMES.map(String::from).into();
    for n in 2..=10 {
        names.push(format!("mode[{n}].x"));
        names.push(format!("mode[{n}].v"));
    }
    names.push("A_e.tracker.v".into());
    for lane in ["v2", "a2", "weight"] {
        names.extend((1..=2).map(|k| format!("A_e.tracker.{lane}[{k}]")));
    }
    assert_eq!(names.len(), STATES);
    names
}

/// The knowns: the states, then base.a, base.v, base.x.
fn knowns() -> Vec<u32> {
    let mut k: Vec<u32> = state_names().iter().map(|n| vr_of(n)).collect();
    k.extend([vr::BASE_A, vr::BASE_V, vr::BASE_X]);
    k
}

/// The unknowns: the state derivatives, then the Real outputs.
fn unknowns() -> Vec<u32> {
    let mut u: Vec<u32> = state_names()
        .iter()
        .map(|n| vr_of(&format!("der({n})")))
        .collect();
    u.extend(real_outputs());
    u
}

/// An ME instance of `model` (`modes` modes) under the damping law `law`, amplitude Tracked
/// (tau 0.7 s), in continuous-time mode; `measured`: base.v set, the estimator switched to it
/// at the event that asks for.
fn running(model: i32, modes: i32, law: i32, measured: bool) -> Instance {
    let inst = Instance::model_exchange(&format!("jac-tracked-{model}-{law}-{measured}"));
    assert_eq!(inst.setup(), OK);
    let integers = [
        (vr::MODEL, model),
        (vr::MODES, modes),
        (vr::DAMPING, law),
        (vr::SCREENS_COUNT, 2),
        (vr::AMPLITUDE, 2),
    ];
    for (r, value) in integers {
        assert_eq!(inst.set_integer(r, value), OK, "{r}");
    }
    assert_eq!(inst.set_real(vr::AMPLITUDE_TAU, 0.7), OK);
    inst.start_continuous_time();
    if measured {
        assert_eq!(inst.set_real(vr::BASE_V, 0.03), OK);
        assert_eq!(inst.completed_integrator_step().1, (1, 0));
        assert_eq!(inst.enter_event_mode(), OK);
        assert_eq!(
            inst.new_discrete_states().1.valuesOfContinuousStatesChanged,
            1
        );
        assert_eq!(inst.enter_continuous_time_mode(), OK);
    }
    inst
}

/// The point: states (those the model has not read back as 0 and are left so), then base.a,
/// base.v, base.x. The estimator's filters mid-way (of base motion about 3 mm at 5 rad/s).
fn point(model: i32, measured: bool) -> Vec<f64> {
    let mut p = vec![0.0; STATES + 3];
    p[..6].copy_from_slice(&[0.02, -0.05, 0.4, 0.1, 0.0, 0.0]);
    if model == 3 {
        // S^2's impact mass in flight inside the clearance (0.1 m by default).
        (p[4], p[5]) = (0.01, 0.2);
    }
    if model == 1 {
        p[6..10].copy_from_slice(&[0.004, -0.03, -0.002, 0.02]);
    }
    let t = STATES - 7;
    p[t..STATES].copy_from_slice(&[0.011, 6e-5, 4e-5, 1.6e-3, 9e-4, 0.55, 0.3]);
    let v = if measured { 0.03 } else { 0.0 };
    p[STATES..].copy_from_slice(&[-0.6, v, 0.002]);
    p
}

fn put(inst: &Instance, p: &[f64]) {
    assert_eq!(inst.set_states(&p[..STATES]), OK, "{:?}", inst.logs());
    for (k, r) in [vr::BASE_A, vr::BASE_V, vr::BASE_X].into_iter().enumerate() {
        assert_eq!(inst.set_real(r, p[STATES + k]), OK);
    }
}

/// The unknowns' values at the point set.
fn values(inst: &Instance) -> Vec<f64> {
    let (s, mut out) = inst.derivatives(STATES);
    assert_eq!(s, OK, "{:?}", inst.logs());
    out.extend(real_outputs().into_iter().map(|r| inst.real(r)));
    out
}

/// Every column at `p` against central differences; the largest error relative to the
/// tolerance (<= 1 passes).
fn check(inst: &Instance, what: &str, p: &[f64]) -> f64 {
    let (knowns, unknowns) = (knowns(), unknowns());
    let mut worst: f64 = 0.0;
    for (k, &known) in knowns.iter().enumerate() {
        put(inst, p);
        let j = jacobian_column(inst, &unknowns, known);
        // Relative steps (the estimator's states are small numbers); 1e-6 where 0.
        let h = if p[k] != 0.0 { 1e-4 * p[k].abs() } else { 1e-6 };
        let (up, down) = values_either_side(p, k, h, |q| put(inst, q), || values(inst));
        worst = worst.max(against_differences(&j, &up, &down, h, |i| {
            format!("{what}: d[{}]/d[{known}]", unknowns[i])
        }));
    }
    put(inst, p);
    worst
}

#[test]
fn tracked_directional_derivatives_match_central_differences() {
    let mut worst: f64 = 0.0;
    let mut moved = 0;
    for (model, modes) in [(1, 3), (2, 1), (4, 1), (3, 1)] {
        for law in [NSD, SCREENS] {
            for measured in [false, true] {
                let what = format!("model {model}, law {law}, measured {measured}");
                let inst = running(model, modes, law, measured);
                let p = point(model, measured);
                worst = worst.max(check(&inst, &what, &p));
                // The damping does move with the estimator's states: zeta.effective's entry by
                // the second velocity filter is not 0, nor der(slosh.v)'s.
                put(&inst, &p);
                let j = jacobian_column(
                    &inst,
                    &[vr::ZETA_EFFECTIVE, vr::DER_SLOSH_V_],
                    vr_of("A_e.tracker.v2[2]"),
                );
                assert!(j.iter().all(|v| v.abs() > 1e-6), "{what}: {j:?}");
                moved += 1;
            }
        }
    }
    assert_eq!(moved, 16);
    println!("largest error / tolerance: {worst:.3e}");
}
