//! The amplitude estimator's continuous-time side (Model Exchange's states) through its public
//! API only, against references written here from the module's own definitions (MODEL.md
//! section 2): the ODEs v' = a - w_c v, f1' = (s - f1)/tau, f2' = (f1 - f2)/tau of the velocity
//! rebuild and the three filter pairs (<v^2>, <a^2>, the weight), solved here by RK4 in small
//! steps and compared with the discrete update (their exact solution for held inputs); the
//! continuous state's layout against a scalar recursion of its own; the switch to a measured
//! velocity; equality of trackers.

use super::amplitude::{AmplitudeTracker, TRACKER_CONTINUOUS, TRACKER_STATE};

const TAU: f64 = 1.3;
const LEAK: f64 = 0.27;
const PRIOR: f64 = 0.002;
/// The prior's frequency (harmonic motion at PRIOR) [rad/s].
const PRIOR_OMEGA: f64 = 5.6;

/// The estimator's ODEs written out from their definitions: the state [rebuilt v, <v^2> first,
/// second, <a^2> first, second, weight first, second], the velocity `v` that feeds <v^2>, time
/// constant `tau`, leak `leak` (also the reference of the FMI layer's tests).
pub(crate) fn estimator_odes(
    s: &[f64],
    a: f64,
    v: f64,
    tau: f64,
    leak: f64,
) -> [f64; TRACKER_CONTINUOUS] {
    [
        a - leak * s[0],
        (v * v - s[1]) / tau,
        (s[1] - s[2]) / tau,
        (a * a - s[3]) / tau,
        (s[3] - s[4]) / tau,
        (1.0 - s[5]) / tau,
        (s[5] - s[6]) / tau,
    ]
}

fn odes(s: &[f64; TRACKER_CONTINUOUS], a: f64, v: f64) -> [f64; TRACKER_CONTINUOUS] {
    estimator_odes(s, a, v, TAU, LEAK)
}

/// RK4 of [`odes`] over `h` in `n` steps, base.a = `a` held; the velocity that feeds <v^2> is
/// `measured` if given, else the rebuilt one held at its value at the start (as the discrete
/// update samples it).
fn rk4(
    s: [f64; TRACKER_CONTINUOUS],
    h: f64,
    n: usize,
    a: f64,
    measured: Option<f64>,
) -> [f64; TRACKER_CONTINUOUS] {
    let v = measured.unwrap_or(s[0]);
    let f = |s: &[f64; TRACKER_CONTINUOUS]| odes(s, a, v);
    let dt = h / n as f64;
    let mut s = s;
    for _ in 0..n {
        let add = |s: &[f64; 7], k: &[f64; 7], c: f64| std::array::from_fn(|i| s[i] + c * k[i]);
        let k1 = f(&s);
        let k2 = f(&add(&s, &k1, 0.5 * dt));
        let k3 = f(&add(&s, &k2, 0.5 * dt));
        let k4 = f(&add(&s, &k3, dt));
        s = std::array::from_fn(|i| s[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    s
}

/// A state with every entry different and none 0, 1 or 2 (so that no `*` reads as `+`).
const STATE: [f64; TRACKER_CONTINUOUS] = [0.37, 0.011, 0.0093, 0.41, 0.33, 0.64, 0.45];

/// The rates are the ODEs, with the rebuilt velocity feeding <v^2> until base.v is seen and the
/// measured one after (whatever velocity is passed before).
#[test]
fn continuous_rates_are_the_estimators_odes() {
    let mut tracker = AmplitudeTracker::new(TAU, LEAK, PRIOR, PRIOR_OMEGA);
    tracker.set_continuous_state(&STATE).expect("finite");
    let (a, v) = (-0.73, 0.29);
    // base.v not yet seen: <v^2> is fed by the rebuilt velocity, base.v ignored.
    for velocity in [0.0, v] {
        let got = tracker.continuous_rates(a, velocity);
        let want = odes(&STATE, a, STATE[0]);
        for k in 0..TRACKER_CONTINUOUS {
            assert!(
                (got[k] - want[k]).abs() <= 1e-15 * want[k].abs().max(1e-3),
                "rebuilt, base.v = {velocity}: rate {k}: {got:?} vs {want:?}"
            );
        }
    }
    assert!(tracker.sees_velocity(v));
    tracker.set_continuous_state(&STATE).expect("finite");
    let got = tracker.continuous_rates(a, v);
    let want = odes(&STATE, a, v);
    for k in 0..TRACKER_CONTINUOUS {
        assert!(
            (got[k] - want[k]).abs() <= 1e-15 * want[k].abs().max(1e-3),
            "measured: rate {k}: {got:?} vs {want:?}"
        );
    }
}

/// The discrete update over an interval h with base.a (and base.v) held against the ODEs solved
/// by RK4 in 2000 substeps (error ~ (h/tau)^4/n^4, far below 1e-12), for intervals short and
/// long against tau and the leak, from a state of every entry its own, the velocity rebuilt and
/// measured. The rebuilt velocity and each filter's first stage are the exact solution. The
/// second stages are not: the update feeds each the first stage's value at the interval's end,
/// held, where the ODE feeds the first stage's exponential, which differs by
/// (f1(0) - s) e^(-h/tau) (1 - e^(-h/tau) - h/tau), s the sample (worked out by hand from
/// the two solutions in closed form), at most |f1(0) - s| (h/tau)^2/2: the reference there is
/// the ODE's solution plus that. (Second order in h: Model Exchange's estimator and
/// Co-Simulation's agree as h -> 0.) (Rebuilt, the update samples <v^2> with
/// the velocity at the interval's start, as the reference does.)
#[test]
fn an_update_solves_the_rates_with_each_second_stage_fed_the_first_held() {
    for h in [0.01, 0.37, 2.9] {
        for measured in [None, Some(-0.19)] {
            let mut tracker = AmplitudeTracker::new(TAU, LEAK, PRIOR, PRIOR_OMEGA);
            if let Some(v) = measured {
                assert!(tracker.sees_velocity(v));
            }
            tracker.set_continuous_state(&STATE).expect("finite");
            let a = 0.61;
            tracker.update(h, a, measured.unwrap_or(0.0));
            let got = tracker.continuous_state();
            let want = rk4(STATE, h, 2000, a, measured);
            let v = measured.unwrap_or(STATE[0]);
            let e = (-h / TAU).exp();
            for k in 0..TRACKER_CONTINUOUS {
                // A second stage: the ODE's solution + (f1(0) - s) e (1 - e - h/tau).
                let offset = match k {
                    2 => STATE[1] - v * v,
                    4 => STATE[3] - a * a,
                    6 => STATE[5] - 1.0,
                    _ => 0.0,
                } * e
                    * (1.0 - e - h / TAU);
                assert!(
                    (got[k] - want[k] - offset).abs() <= 1e-12 * want[k].abs().max(1e-2),
                    "h = {h}, base.v {measured:?}: state {k}: {got:?} vs {want:?}"
                );
            }
        }
    }
}

/// The continuous state is the saved state without its flag, in the documented order; set back
/// (any finite values, below 0 too: a solver's trial state), it is read back as set and the
/// velocity source stays; a non-finite value anywhere is refused and nothing taken.
#[test]
fn the_continuous_state_is_the_saved_state_without_its_flag() {
    for measured in [false, true] {
        let mut tracker = AmplitudeTracker::new(TAU, LEAK, PRIOR, PRIOR_OMEGA);
        if measured {
            assert!(tracker.sees_velocity(0.2));
        }
        for k in 0..5 {
            let v = if measured { 0.2 - 0.03 * k as f64 } else { 0.0 };
            tracker.update(0.05, -0.8 + 0.1 * k as f64, v);
        }
        let saved = tracker.state();
        assert_eq!(saved.len(), TRACKER_STATE);
        assert_eq!(saved[1], if measured { 1.0 } else { 0.0 });
        let c = tracker.continuous_state();
        let want = [
            saved[0], saved[2], saved[3], saved[4], saved[5], saved[6], saved[7],
        ];
        assert_eq!(c, want);
        assert!(c.iter().all(|v| *v != 0.0), "{c:?}");

        let trial = [-0.1, -1e-9, 0.02, 0.3, -2e-12, 0.7, 0.5];
        tracker.set_continuous_state(&trial).expect("finite");
        assert_eq!(tracker.continuous_state(), trial);
        let s = tracker.state();
        // The velocity source stays; the flag's 2 says the estimate is now the continuous one
        // (Model Exchange's, from the first state a host sets).
        assert_eq!(s[1], saved[1] + 2.0, "the velocity source stays");
        assert_eq!(
            [s[0], s[2], s[3], s[4], s[5], s[6], s[7]],
            trial,
            "the saved state"
        );
        for k in 0..TRACKER_CONTINUOUS {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let mut t = STATE;
                t[k] = bad;
                assert!(tracker.set_continuous_state(&t).is_err(), "{k}: {bad}");
                assert_eq!(tracker.continuous_state(), trial, "refused, yet taken");
            }
        }
    }
}

/// The switch to a measured base velocity: any base.v other than 0 switches, once; the switch
/// restarts the statistics (the filters and the weight to 0, the estimate the prior) and keeps
/// the rebuilt velocity; base.v = 0 never switches.
#[test]
fn a_measured_velocity_switches_the_estimator_once() {
    let mut tracker = AmplitudeTracker::new(TAU, LEAK, PRIOR, PRIOR_OMEGA);
    for k in 0..20 {
        tracker.update(0.05, 0.5 * (0.3 * k as f64).sin() + 0.2, 0.0);
    }
    assert!(tracker.estimate() != PRIOR);
    let before = tracker.state();
    assert!(!tracker.would_see_velocity(0.0));
    assert!(!tracker.sees_velocity(0.0));
    assert_eq!(tracker.state(), before, "base.v = 0 changed the estimator");
    assert!(tracker.would_see_velocity(-0.1));
    assert!(tracker.would_see_velocity(0.1));
    assert_eq!(tracker.state(), before, "asking changed the estimator");
    assert!(tracker.sees_velocity(-0.1));
    let after = tracker.state();
    assert_eq!(after[0], before[0], "the rebuilt velocity stays");
    assert_eq!(after[1], 1.0);
    assert_eq!(after[2..], [0.0; TRACKER_STATE - 2]);
    assert_eq!(tracker.estimate(), PRIOR);
    for v in [0.1, -0.1, 0.0] {
        assert!(!tracker.would_see_velocity(v));
        assert!(!tracker.sees_velocity(v));
    }
    assert_eq!(tracker.state(), after);
    // The same through an update: the first base.v other than 0 restarts the statistics.
    let mut updated = AmplitudeTracker::new(TAU, LEAK, PRIOR, PRIOR_OMEGA);
    updated.update(0.05, 0.4, 0.0);
    updated.update(0.05, 0.4, 0.0);
    let mut switched = updated.clone();
    assert!(switched.sees_velocity(0.3));
    updated.update(0.05, 0.4, 0.3);
    switched.update(0.05, 0.4, 0.3);
    assert_eq!(updated.state(), switched.state());
    assert_eq!(updated.state()[1], 1.0);
}

/// Trackers are equal when their settings and states are, whatever interval they last saw; a
/// difference in any one setting or in the state alone makes them differ.
#[test]
fn trackers_are_equal_by_settings_and_state() {
    let fresh = AmplitudeTracker::new(TAU, LEAK, PRIOR, PRIOR_OMEGA);
    assert_eq!(fresh, AmplitudeTracker::new(TAU, LEAK, PRIOR, PRIOR_OMEGA));
    for other in [
        AmplitudeTracker::new(1.1 * TAU, LEAK, PRIOR, PRIOR_OMEGA),
        AmplitudeTracker::new(TAU, LEAK, PRIOR, 1.1 * PRIOR_OMEGA),
        AmplitudeTracker::new(TAU, 1.1 * LEAK, PRIOR, PRIOR_OMEGA),
        AmplitudeTracker::new(TAU, LEAK, 1.1 * PRIOR, PRIOR_OMEGA),
    ] {
        assert_ne!(fresh, other);
    }
    // Same state, another interval seen last: equal.
    let mut stepped = AmplitudeTracker::new(TAU, LEAK, PRIOR, PRIOR_OMEGA);
    stepped.update(0.5, 0.3, 0.0);
    assert_ne!(fresh, stepped, "the state alone differs");
    stepped.set_state(&fresh.state()).expect("a fresh state");
    assert_eq!(fresh, stepped);
    // Each part of the state alone.
    for k in 0..TRACKER_STATE {
        let mut s = fresh.state();
        s[k] = 1.0;
        let mut t = fresh.clone();
        t.set_state(&s).expect("in range");
        assert_ne!(fresh, t, "state[{k}] differs");
    }
}
