//! TLD's Model Exchange functions with amplitude = Tracked (the estimator's states, rates,
//! event and nominals), against the estimator's ODEs and harmonic motion at the prior; the
//! helpers and the other references are me_tests.rs's.

use super::me_tests::{
    LINEAR, T0, TRACKED, close, context, ct, derivatives, initialised, instance, mode_one, real,
    set_real, states, tracker_vr,
};
use super::vars::vr;
use crate::model::continuous::ALL_STATES;
use crate::physics::amplitude::TRACKER_CONTINUOUS;
use crate::physics::amplitude_tests::estimator_odes;
use fmi2_slave::calls::Phase;
use fmi2_slave::{Continuous, Status};

/// amplitude = Tracked: the estimator's states follow the others, are read back as set and as
/// the variables A_e.tracker.*; their derivatives are the estimator's ODEs (tau given, w_c =
/// w_1/20, the rebuilt velocity feeding <v^2>); a base.v other than 0 asks for an event at the
/// end of the integrator's step, the event switches the estimator (states changed) once, and
/// then the measured velocity feeds <v^2>.
#[test]
fn the_estimators_states_and_rates_are_its_odes() {
    let (_, w) = mode_one();
    let (tau, leak) = (1.5, 0.05 * w);
    let odes = |s: &[f64], a: f64, v: f64| estimator_odes(s, a, v, tau, leak);
    let more = [(vr::AMPLITUDE_TAU, tau)];
    let mut tld = initialised(instance(LINEAR, TRACKED, 0.004, &more));
    let mut s = states(&tld);
    let t = [0.37, 0.011, 0.0093, 0.41, 0.33, 0.64, 0.45];
    s[T0..T0 + TRACKER_CONTINUOUS].copy_from_slice(&t);
    assert!(tld.set_states(&ct(), &s).is_ok());
    assert_eq!(states(&tld), s);
    let a = -0.73;
    set_real(&mut tld, Phase::ContinuousTimeMode, vr::BASE_A, a);
    let dx = derivatives(&tld);
    let want = odes(&t, a, t[0]);
    let p = Phase::ContinuousTimeMode;
    for k in 0..TRACKER_CONTINUOUS {
        close(dx[T0 + k], want[k], 1e-14, &format!("rate {k}"));
        assert_eq!(real(&tld, p, tracker_vr(k, false)), t[k], "state {k}");
        assert_eq!(real(&tld, p, tracker_vr(k, true)), dx[T0 + k], "der {k}");
    }
    assert_eq!(dx[0], s[1], "der(slosh.x)");
    assert_eq!(tld.completed_step(&ct()).ok(), Some(false));
    let update = tld.event_update(&context(Phase::EventMode)).expect("event");
    assert!(!update.states_changed);
    // The host drives base.v: an event at the end of the step, which switches the estimator.
    set_real(&mut tld, p, vr::BASE_V, 0.29);
    assert_eq!(tld.completed_step(&ct()).ok(), Some(true));
    let update = tld.event_update(&context(Phase::EventMode)).expect("event");
    assert!(update.states_changed);
    assert_eq!(tld.completed_step(&ct()).ok(), Some(false));
    let update = tld.event_update(&context(Phase::EventMode)).expect("event");
    assert!(!update.states_changed, "the switch is once");
    let s = states(&tld);
    let dx = derivatives(&tld);
    let want = odes(&s[T0..], a, 0.29);
    for k in 0..TRACKER_CONTINUOUS {
        close(dx[T0 + k], want[k], 1e-14, &format!("measured: rate {k}"));
    }
}

/// amplitude = Tracked: the estimator's nominals are those of harmonic base motion of the
/// prior amplitude A_e at w_1 (the squares of its velocity A_e w_1 and acceleration A_e w_1^2,
/// the weights 1), and the rebuilt velocity's is slosh.v's.
#[test]
fn the_estimators_nominals_are_harmonic_motion_at_the_prior() {
    let (_, w) = mode_one();
    let a_e = 0.004;
    let tld = initialised(instance(LINEAR, TRACKED, a_e, &[(vr::AMPLITUDE_TAU, 1.5)]));
    let mut n = vec![f64::NAN; ALL_STATES];
    assert_eq!(tld.nominals(&mut n).ok(), Some(Status::Ok));
    let (v, a) = (a_e * w, a_e * w * w);
    // The rebuilt velocity is scaled as slosh.v (state 1): at the prior's it made CVode's steps
    // some 5 times shorter than the motion needs.
    let want = [n[1], v * v, v * v, a * a, a * a, 1.0, 1.0];
    for (k, want) in want.into_iter().enumerate() {
        close(
            n[T0 + k],
            want,
            1e-12,
            &format!("the estimator's nominal {k}"),
        );
    }
}
