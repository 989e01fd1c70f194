//! The damper in Model Exchange (`continuous.rs`, `events.rs`) against references written here
//! from MODEL.md: Eq 2.1's fundamental mode (its mass and frequency from the tank's geometry),
//! its oscillator's rates and energies, the runaway limit of 100 tank lengths, the S^2 contact
//! functions (the gaps to the walls), and every output's J d against central differences of the
//! outputs themselves.

use super::*;
use crate::model::continuous::{BANK, Direction, IMPACT_V, IMPACT_Z, STATES};
use crate::model::slamming::Event;
use crate::model::wiring_tests::OUTPUTS;
use crate::model::{StartValues, Unknown};

const LINEAR: f64 = 1.0;
const NONLINEAR: f64 = 2.0;
const SLAMMING: f64 = 3.0;
const CONSTANT: f64 = 1.0;
const FIXED: f64 = 1.0;
const TRACKED: f64 = 2.0;
/// A tank that is not the defaults' (so that no product of its numbers is 1), three of them.
const A: f64 = 0.4;
const B: f64 = 0.3;
const H: f64 = 0.05;
const TANKS: f64 = 3.0;
const ZETA: f64 = 0.03;
const X0: f64 = 0.012;

fn params(model: f64) -> StartValues {
    StartValues::default()
        .with(vr::MODEL, model)
        .with(vr::MODES, 1.0)
        .with(vr::TANK_LENGTH, A)
        .with(vr::TANK_BREADTH, B)
        .with(vr::TANK_DEPTH, H)
        .with(vr::TANKS, TANKS)
        .with(vr::ETA, 1.0)
        .with(vr::PHI, 0.0)
        .with(vr::DAMPING, CONSTANT)
        .with(vr::ZETA, ZETA)
        .with(vr::AMPLITUDE, FIXED)
        .with(vr::A_E, 0.005)
        .with(vr::SLOSH_X0, X0)
}

fn damper(p: &StartValues) -> Damper {
    Damper::configure(p).expect("configuration").0
}

fn held(a: f64) -> Inputs {
    Inputs {
        a,
        ..Inputs::default()
    }
}

/// Eq 2.1's fundamental mode of all the tanks: (m_1, omega_1).
/// S^2's impact mass pressed onto the wall +d/2 (the base accelerating towards -x), at rest
/// there (an event that says so): the damper's states then, from `s` otherwise.
fn rest_on_the_wall(d: &mut Damper, mut s: [f64; STATES]) -> [f64; STATES] {
    (s[IMPACT_Z], s[IMPACT_V]) = (0.05, 0.0);
    d.set_continuous_states(&s).expect("takes them");
    assert!(matches!(
        d.event(&held(-30.0)),
        Event::Impact { rests: true, .. }
    ));
    d.continuous_states()
}

fn fundamental() -> (f64, f64) {
    let (g, rho, r) = (9.81, 1000.0, H / A);
    let pi = std::f64::consts::PI;
    let liquid = TANKS * rho * A * B * H;
    let m1 = liquid * 8.0 * (pi * r).tanh() / (pi.powi(3) * r);
    (m1, (g * pi * (pi * r).tanh() / A).sqrt())
}

fn close(got: f64, want: f64, rel: f64, what: &str) {
    assert!(
        (got - want).abs() <= rel * want.abs().max(1e-300),
        "{what}: {got} vs {want}"
    );
}

/// Linear with one mode: the states start at slosh.x0 with its stored energy counted as input
/// (0.5 m_1 w_1^2 x0^2), the nominals are half a tank length and that motion's velocity and
/// energy, the derivatives Eq 2.1's oscillator and its energies' rates, and states set are
/// the outputs read.
#[test]
fn the_dampers_states_nominals_and_rates_are_eq_2_1s() {
    let (m1, w) = fundamental();
    let mut d = damper(&params(LINEAR));
    assert!(d.offers_model_exchange().is_ok());
    let e0 = 0.5 * m1 * w * w * X0 * X0;
    let s = d.continuous_states();
    close(s[0], X0, 1e-15, "slosh.x");
    close(s[2], e0, 1e-12, "energy.input at the start");
    for (k, v) in s.iter().enumerate() {
        if k != 0 && k != 2 {
            assert_eq!(*v, 0.0, "state {k}");
        }
    }
    let n = d.continuous_nominals();
    let (x, v) = (0.5 * A, w * 0.5 * A);
    let e = 0.5 * m1 * v * v;
    for (k, want) in [(0, x), (1, v), (2, e), (3, e), (IMPACT_Z, x), (IMPACT_V, v)] {
        close(n[k], want, 1e-12, &format!("nominal {k}"));
    }
    for (k, got) in n.iter().enumerate().skip(BANK) {
        let want = if (k - BANK).is_multiple_of(2) { x } else { v };
        close(*got, want, 1e-12, &format!("nominal {k}"));
    }
    let mut s = [0.0; STATES];
    s[..4].copy_from_slice(&[0.02, -0.05, e0 + 0.3, 0.1]);
    d.set_continuous_states(&s).expect("takes them");
    let back = d.continuous_states();
    for k in 0..STATES {
        close(back[k], s[k], 1e-14, &format!("state {k} read back"));
    }
    let now = held(0.0);
    close(d.output(Output::X, &now), 0.02, 1e-15, "slosh.x");
    close(d.output(Output::V, &now), -0.05, 1e-15, "slosh.v");
    let force = m1 * (2.0 * ZETA * w * -0.05 + w * w * 0.02);
    close(d.output(Output::Force, &now), force, 1e-12, "force");
    close(
        d.output(Output::EnergyInput, &now),
        e0 + 0.3,
        1e-14,
        "energy.input",
    );
    close(
        d.output(Output::EnergyDissipated, &now),
        0.1,
        1e-14,
        "dissipated",
    );
    let a = 0.7;
    let der = d.continuous_derivatives(&held(a));
    let want = [
        -0.05,
        -a - 2.0 * ZETA * w * -0.05 - w * w * 0.02,
        -m1 * a * -0.05,
        m1 * 2.0 * ZETA * w * 0.05 * 0.05,
    ];
    for (k, want) in want.into_iter().enumerate() {
        close(der[k], want, 1e-12, &format!("der {k}"));
    }
    assert!(der[4..].iter().all(|v| *v == 0.0), "{der:?}");
}

/// States up to 100 tank lengths are taken (the limit itself included); beyond, slosh.x or
/// impact.z is refused with the reason and the damper is unchanged.
#[test]
fn states_beyond_a_hundred_tank_lengths_are_refused_and_change_nothing() {
    let mut d = damper(&params(SLAMMING).with(vr::SLAMMING_CLEARANCE, 0.1));
    let limit = 100.0 * A;
    for k in [0, IMPACT_Z] {
        for sign in [1.0, -1.0] {
            let mut s = d.continuous_states();
            s[k] = sign * limit;
            d.set_continuous_states(&s).expect("the limit is taken");
            assert_eq!(d.continuous_states()[k], sign * limit);
        }
    }
    let mut s = d.continuous_states();
    s[0] = 0.01;
    s[IMPACT_Z] = 0.02;
    d.set_continuous_states(&s).expect("takes them");
    // (Debug, not PartialEq: a cache of the model holds NaN until first used.)
    let before = format!("{d:?}");
    for (k, name) in [(0, "slosh.x"), (IMPACT_Z, "impact.z")] {
        for beyond in [limit * (1.0 + 1e-12), -1.001 * limit, 1.1 * limit] {
            let mut t = s;
            t[k] = beyond;
            let why = d.set_continuous_states(&t).expect_err("beyond the limit");
            assert!(
                why.contains(name) && why.contains("100 tank lengths"),
                "{why}"
            );
            assert_eq!(
                format!("{d:?}"),
                before,
                "a refused state changed the damper"
            );
        }
    }
}

/// amplitude = Tracked: J d carries the change of the estimator's states through the estimate
/// and the damping law into the damping. Every column (the 24 states, the estimator's 7,
/// base.a, base.v) of every output, state derivative and estimator derivative against central
/// differences of the outputs and derivatives themselves, for Linear (3 modes), Nonlinear and
/// S^2 with its impact mass in flight and resting on a wall, under NSD (Lambda inside its
/// clamp) and Screens, with the velocity rebuilt and measured (base.v then enters the
/// estimator's rates). The filters are set mid-way (the estimate neither the prior nor
/// settled).
#[test]
fn a_tracked_amplitudes_tangent_is_its_change() {
    use crate::model::shallow_water::continuous::CELL_STATES;
    use crate::physics::amplitude::TRACKER_CONTINUOUS;
    const NSD: f64 = 2.0;
    const SCREENS: f64 = 4.0;
    let mut cases = 0;
    let models = [
        (LINEAR, 3.0, false),
        (NONLINEAR, 1.0, false),
        (SLAMMING, 1.0, false),
        (SLAMMING, 1.0, true),
    ];
    for (model, modes, rest) in models {
        for law in [NSD, SCREENS] {
            for measured in [false, true] {
                let p = params(model)
                    .with(vr::MODES, modes)
                    .with(vr::AMPLITUDE, TRACKED)
                    .with(vr::AMPLITUDE_TAU, 0.7)
                    .with(vr::DAMPING, law)
                    .with(vr::SCREENS_COUNT, 2.0)
                    .with(vr::SLAMMING_CLEARANCE, 0.1);
                let mut d = damper(&p);
                let inputs = Inputs {
                    a: -0.6,
                    v: if measured { 0.03 } else { 0.0 },
                    ..Inputs::default()
                };
                assert_eq!(d.tracker_event(&inputs), measured);
                let mut s = d.continuous_states();
                s[..6].copy_from_slice(&[0.02, -0.05, 0.4, 0.1, 0.03, 0.2]);
                for (k, v) in s[BANK..BANK + 4].iter_mut().enumerate() {
                    *v = 0.004 * (k as f64 - 1.5);
                }
                if rest {
                    s = rest_on_the_wall(&mut d, s);
                }
                // Mid-way filters of base motion about 3 mm at 5 rad/s (the mean squares of
                // its velocity and acceleration, 1.1e-4 and 2.8e-3 when settled).
                let tracker = [0.011, 6e-5, 4e-5, 1.6e-3, 9e-4, 0.55, 0.3];
                let cells = [0.0; CELL_STATES];
                d.set_all_continuous_states(&s, &tracker, &cells)
                    .expect("takes them");
                let mut dir = Direction::default();
                for (k, v) in dir.states.iter_mut().enumerate() {
                    *v = 0.1 + 0.05 * k as f64;
                }
                for (k, v) in dir.tracker.iter_mut().enumerate() {
                    *v = tracker[k] * (0.3 + 0.1 * k as f64);
                }
                (dir.a, dir.v) = (0.7, 0.02);
                let h = 1e-4;
                let at = |sign: f64| {
                    let mut m = d.clone();
                    let mut t = s;
                    for (v, dv) in t.iter_mut().zip(dir.states) {
                        *v += sign * h * dv;
                    }
                    let tr: [f64; TRACKER_CONTINUOUS] =
                        std::array::from_fn(|k| tracker[k] + sign * h * dir.tracker[k]);
                    m.set_all_continuous_states(&t, &tr, &cells).expect("near");
                    let i = Inputs {
                        a: inputs.a + sign * h * dir.a,
                        v: inputs.v + sign * h * dir.v,
                        ..inputs
                    };
                    (m, i)
                };
                let ((plus, ip), (minus, im)) = (at(1.0), at(-1.0));
                let mut unknowns: Vec<Unknown> =
                    OUTPUTS.iter().map(|&o| Unknown::Output(o)).collect();
                unknowns.extend((0..STATES).map(Unknown::Derivative));
                unknowns.extend((0..TRACKER_CONTINUOUS).map(Unknown::Tracker));
                let mut out = vec![0.0; unknowns.len()];
                d.directional_derivatives(&inputs, &dir, &unknowns, &mut out)
                    .expect("offered");
                let rates = |m: &Damper, i: &Inputs| {
                    let mut r = [0.0; TRACKER_CONTINUOUS];
                    m.tracker_derivatives(i, &mut r);
                    (m.continuous_derivatives(i), r)
                };
                let ((dp, rp), (dm, rm)) = (rates(&plus, &ip), rates(&minus, &im));
                let case = format!("model {model} (rest {rest}), law {law}, measured {measured}");
                for (u, got) in unknowns.iter().zip(&out) {
                    let fd = match *u {
                        Unknown::Output(o) => {
                            (plus.output(o, &ip) - minus.output(o, &im)) / (2.0 * h)
                        }
                        Unknown::Derivative(k) => (dp[k] - dm[k]) / (2.0 * h),
                        Unknown::Tracker(k) => (rp[k] - rm[k]) / (2.0 * h),
                        Unknown::Frozen => unreachable!("not among the unknowns"),
                    };
                    // The estimate's and the laws' curvature: the differences' error is
                    // O(h^2) of their second derivatives (seen below 1e-8 relative).
                    assert!(
                        (got - fd).abs() <= 1e-6 * (1e-6 + fd.abs()),
                        "{case}: {u:?}: {got} vs {fd}"
                    );
                }
                // The damping moves: zeta.effective's and A_e.estimate's entries are not 0.
                for o in [Output::Zeta, Output::Amplitude] {
                    let k = OUTPUTS.iter().position(|&x| x == o).expect("an output");
                    assert!(out[k].abs() > 1e-6, "{case}: {o:?} {}", out[k]);
                }
                cases += 1;
            }
        }
    }
    assert_eq!(cases, 16);
}

/// J d of every output and every derivative against central differences of the outputs and
/// derivatives themselves (each at most quadratic in the states and the input, so the central
/// difference is exact to rounding), for Linear, Nonlinear at eta = 1 and S^2 with the impact
/// mass flying and resting on a wall (whose mass then moves with the tank: base_shear reads
/// it). An unknown out of range is refused, the output untouched.
#[test]
fn every_outputs_tangent_is_its_change() {
    let slamming = params(SLAMMING)
        .with(vr::SLAMMING_CLEARANCE, 0.1)
        .with(vr::SLAMMING_MASS_RATIO, 0.2)
        .with(vr::SLAMMING_OMEGA, 0.9);
    for (case, p, rest) in [
        ("Linear", params(LINEAR), false),
        ("Nonlinear", params(NONLINEAR), false),
        ("S^2 flying", slamming.clone(), false),
        ("S^2 resting", slamming, true),
    ] {
        let mut d = damper(&p);
        let mut s = d.continuous_states();
        s[..6].copy_from_slice(&[0.02, -0.05, 0.4, 0.1, 0.03, 0.2]);
        if rest {
            s = rest_on_the_wall(&mut d, s);
        }
        d.set_continuous_states(&s).expect("takes them");
        let a = -0.6;
        let mut dir = Direction::default();
        for (k, v) in dir.states.iter_mut().enumerate() {
            *v = 0.1 + 0.05 * k as f64;
        }
        dir.a = 0.7;
        let h = 1e-4;
        let at = |sign: f64| {
            let mut m = d.clone();
            let mut t = s;
            for (v, dv) in t.iter_mut().zip(dir.states) {
                *v += sign * h * dv;
            }
            m.set_continuous_states(&t).expect("near");
            (m, held(a + sign * h * dir.a))
        };
        let ((plus, ip), (minus, im)) = (at(1.0), at(-1.0));
        let mut unknowns: Vec<Unknown> = OUTPUTS.iter().map(|&o| Unknown::Output(o)).collect();
        unknowns.extend((0..STATES).map(Unknown::Derivative));
        let mut out = vec![0.0; unknowns.len()];
        d.directional_derivatives(&held(a), &dir, &unknowns, &mut out)
            .expect("offered");
        let (dp, dm) = (
            plus.continuous_derivatives(&ip),
            minus.continuous_derivatives(&im),
        );
        for (u, got) in unknowns.iter().zip(&out) {
            let fd = match *u {
                Unknown::Output(o) => (plus.output(o, &ip) - minus.output(o, &im)) / (2.0 * h),
                Unknown::Derivative(k) => (dp[k] - dm[k]) / (2.0 * h),
                // Not asked for here: the bank's frozen states have no differences to compare;
                // the estimator's are frozen (amplitude = Fixed).
                Unknown::Frozen | Unknown::Tracker(_) => unreachable!("not among the unknowns"),
            };
            assert!(
                (got - fd).abs() <= 1e-7 * (1.0 + fd.abs()),
                "{case}: {u:?}: {got} vs {fd}"
            );
        }
        let mut kept = [3.0];
        let why = d
            .directional_derivatives(&held(a), &dir, &[Unknown::Derivative(STATES)], &mut kept)
            .expect_err("out of range");
        assert!(why.contains(&format!("not {}", STATES + 1)), "{why}");
        assert_eq!(kept, [3.0]);
    }
}

/// The damper's event indicators are S^2's contact functions under the inputs now (the gaps
/// d/2 -+ z to the walls, plus d for the wall the mass moves away from), constant 1 for the
/// models without events; its event hands the input's acceleration to the impact law.
#[test]
fn the_dampers_events_are_s2s_under_the_inputs() {
    let clearance = 0.1;
    let mut d = damper(
        &params(SLAMMING)
            .with(vr::SLAMMING_CLEARANCE, clearance)
            .with(vr::SLAMMING_OMEGA, 0.9),
    );
    let mut s = d.continuous_states();
    (s[IMPACT_Z], s[IMPACT_V]) = (0.03, -0.2);
    d.set_continuous_states(&s).expect("takes them");
    let g = d.event_indicators(&held(1.0));
    close(g[0], 0.5 * clearance - 0.03 + clearance, 1e-15, "wall +d/2");
    close(g[1], 0.5 * clearance + 0.03, 1e-15, "wall -d/2");
    assert_eq!(d.event(&held(1.0)), Event::None);
    // At the wall -d/2 with speed 0, pressed onto it by the base (its relative acceleration
    // is -a: a > 0 presses it onto -d/2): it rests there, its indicator the pressing
    // acceleration until the base pulls it away.
    (s[IMPACT_Z], s[IMPACT_V]) = (-0.5 * clearance, 0.0);
    d.set_continuous_states(&s).expect("takes them");
    assert!(matches!(
        d.event(&held(3.0)),
        Event::Impact {
            wall: -1,
            rests: true,
            ..
        }
    ));
    assert_eq!(d.event_indicators(&held(3.0)), [clearance, 3.0]);
    assert_eq!(d.event_indicators(&held(-2.0)), [clearance, -2.0]);
    assert_eq!(d.event(&held(-2.0)), Event::Release { wall: -1 });
    let linear = damper(&params(LINEAR));
    assert_eq!(linear.event_indicators(&held(1.0)), [1.0, 1.0]);
}
