use super::*;
use crate::description::{ModelKindItem, vr};
use crate::model::continuous::{Direction, IMPACT_V, IMPACT_Z, STATES};
use crate::model::{AnyModel, Common, Start, StartValues};

const D: f64 = 0.1;
const E: f64 = 0.4;

fn s2(omega: f64) -> AnyModel {
    let p = StartValues::default()
        .with(vr::SLAMMING_OMEGA, omega)
        .with(vr::SLAMMING_CLEARANCE, D)
        .with(vr::SLAMMING_RESTITUTION, E);
    let (common, _) = Common::read(&p).expect("start values are consistent");
    let start = Start {
        zeta: 0.02,
        amplitude: 0.005,
    };
    AnyModel::configure(ModelKindItem::SloshingSlamming, &p, &common, start).expect("configures")
}

fn slam(m: &mut AnyModel) -> &mut SloshingSlamming {
    match m {
        AnyModel::SloshingSlamming(s) => s,
        _ => panic!("not S^2"),
    }
}

/// In flight the contact functions are the gaps; at the wall moving into it the event applies
/// Eq 2.5 (v -> -e v, the impulse (1 + e) m v to the tank, (1 - e^2) m v^2 / 2 dissipated);
/// moving away, or short of the wall, nothing happens.
#[test]
fn an_impact_reverses_the_velocity_with_restitution() {
    let mut m = s2(0.8);
    let s = slam(&mut m);
    let mass = s.impact_mass;
    s.state.z = 0.02;
    s.state.v = 0.3;
    // Moving towards +d/2: its gap; away from -d/2: its gap plus d.
    assert_eq!(
        s.contact_functions(-1.0),
        [0.5 * D - 0.02, 0.5 * D + 0.02 + D]
    );
    assert_eq!(s.event(-1.0), Event::None, "short of the wall");
    s.state.z = 0.5 * D;
    let before = s.state;
    match s.event(2.0) {
        Event::Impact {
            wall: 1,
            impulse,
            rests: false,
        } => assert!((impulse - (1.0 + E) * 0.3 * mass).abs() < 1e-15 * mass),
        other => panic!("{other:?}"),
    }
    assert_eq!((s.state.z, s.state.v), (0.5 * D, -E * 0.3));
    assert_eq!(s.state.impacts, before.impacts + 1);
    let lost = s.state.dissipated - before.dissipated;
    assert!((lost - 0.5 * (1.0 - E * E) * 0.09).abs() < 1e-16, "{lost}");
    // Now moving away from the wall it touches: no second impact.
    assert_eq!(s.event(2.0), Event::None);
    // The left wall, reached within the host's tolerance (REACH), moving into it.
    s.state.z = -0.5 * D * (1.0 - 0.5 * REACH);
    s.state.v = -0.1;
    assert!(matches!(s.event(0.0), Event::Impact { wall: -1, .. }));
    assert_eq!(s.state.z, -0.5 * D);
}

/// Pressed onto a wall by a constant base acceleration, the mass's bounces (each an event of
/// a host that integrates the flights exactly) shrink by e each; the rebound falls below the
/// rest speed after a finite number of events and the mass rests on the wall: its contact
/// function becomes the pressing acceleration, its rates 0. When the base acceleration turns
/// the contact function crosses 0 and the event releases it.
#[test]
fn chattering_ends_at_rest_after_finitely_many_events_and_releases() {
    let mut m = s2(0.8);
    let s = slam(&mut m);
    let a = -2.0; // presses the mass onto +d/2 (its relative acceleration is +2)
    s.state.z = 0.5 * D;
    s.state.v = 0.3;
    let mut events = 0;
    let mut v = 0.3;
    loop {
        // The flight from the wall and back takes 2 v / |a|; it arrives with the speed it left.
        s.state.v = v;
        match s.event(a) {
            Event::Impact { rests: true, .. } => break,
            Event::Impact { .. } => {}
            other => panic!("{other:?}"),
        }
        events += 1;
        assert!(events < 100, "chattering did not end");
        v = -s.state.v;
        let (dz, dv) = s.impact_rates(a);
        assert_eq!((dz, dv), (s.state.v, -a));
    }
    // The number of rebounds above the rest speed: e^n 0.3 >= rest_speed.
    let want = ((s.impact.rest_speed / 0.3).ln() / E.ln()).ceil() as i32 - 1;
    assert!(
        (events - want).abs() <= 1,
        "{events} events, {want} expected"
    );
    assert_eq!(s.state.contact, 1);
    assert_eq!(s.impact_rates(a), (0.0, 0.0));
    assert_eq!(s.contact_functions(a), [2.0, D]);
    assert_eq!(s.event(a), Event::None, "still pressed");
    assert_eq!(s.contact_functions(0.5), [-0.5, D]);
    assert_eq!(s.event(0.5), Event::Release { wall: 1 });
    assert_eq!(s.impact_rates(0.5), (0.0, -0.5));
    // Leaving the wall: not 0 (a host restarting here sees no event), d for each.
    assert_eq!(s.contact_functions(0.5), [D, D + D]);
}

/// The continuous states round-trip through the model (the energy totals split between the
/// sloshing mode and the impact mass's own share), and the derivatives are the mode's Eq 2.11
/// and the free flight of the impact mass, whose power enters der(energy.input).
#[test]
fn states_round_trip_and_rates_are_the_flight() {
    let mut m = s2(0.7);
    slam(&mut m).state.work_in = 0.25;
    slam(&mut m).state.dissipated = 0.125;
    let mut s = [0.0; STATES];
    s[..6].copy_from_slice(&[0.01, -0.02, 0.5, 0.3, 0.049, 0.2]);
    m.set_continuous_states(&s, 0.1).expect("takes them");
    let back = m.continuous_states(0.1);
    for k in 0..STATES {
        assert!((back[k] - s[k]).abs() < 1e-15, "{k}: {back:?}");
    }
    let a = 0.7;
    let d = m.continuous_derivatives(a);
    let (o, mi) = (slam(&mut m).oscillator(), slam(&mut m).impact_mass);
    assert_eq!(d[0], s[1]);
    assert_eq!(d[1], -a - o.c * s[1] - o.restoring);
    let power = -o.mass * a * s[1] - mi * a * s[5];
    assert!((d[2] - power).abs() < 1e-15 * power.abs());
    assert_eq!((d[IMPACT_Z], d[IMPACT_V]), (s[5], -a));
}

/// J d against central differences of the derivatives (exact for this system, linear in the
/// states and the input), in flight and at rest; the impact columns of the other models are 0.
#[test]
fn the_tangent_is_the_derivatives_change() {
    for rest in [false, true] {
        let mut m = s2(0.7);
        let mut s = [0.0; STATES];
        s[..6].copy_from_slice(&[0.01, -0.02, 0.5, 0.3, 0.03, 0.2]);
        m.set_continuous_states(&s, 0.0).expect("takes them");
        if rest {
            let sl = slam(&mut m);
            sl.state.z = 0.5 * D;
            sl.state.v = 0.0;
            sl.state.contact = 1;
        }
        let s = m.continuous_states(0.0);
        let a = -0.4;
        for k in 0..STATES + 1 {
            let mut dir = Direction::default();
            let h = 1e-3;
            let (mut plus, mut minus) = (m.clone(), m.clone());
            let (ap, am) = if k == STATES {
                dir.a = 1.0;
                (a + h, a - h)
            } else {
                dir.states[k] = 1.0;
                let (mut sp, mut sm) = (s, s);
                sp[k] += h;
                sm[k] -= h;
                plus.set_continuous_states(&sp, 0.0).expect("plus");
                minus.set_continuous_states(&sm, 0.0).expect("minus");
                (a, a)
            };
            let t = m.continuous_tangent(a, &dir).expect("offered");
            let (dp, dm) = (
                plus.continuous_derivatives(ap),
                minus.continuous_derivatives(am),
            );
            for j in 0..STATES {
                let fd = (dp[j] - dm[j]) / (2.0 * h);
                assert!(
                    (t.derivatives[j] - fd).abs() < 1e-9 * (1.0 + fd.abs()),
                    "rest {rest}: d der({j}) / d {k}: {} vs {fd}",
                    t.derivatives[j]
                );
            }
            let stored = |m: &AnyModel| m.observe(crate::model::Observable::Stored);
            let fd = (stored(&plus) - stored(&minus)) / (2.0 * h);
            assert!(
                (t.stored - fd).abs() < 1e-9 * (1.0 + fd.abs()),
                "stored by {k}"
            );
            let want_z = if k == IMPACT_Z { 1.0 } else { 0.0 };
            assert_eq!(t.impact_z, want_z);
        }
        let _ = IMPACT_V;
    }
}

/// At a wall, only a mass moving into it, or at speed 0 pressed onto it by the base, hits it:
/// at speed 0 with the base pulling it away it leaves, and moving away it leaves even while
/// the base presses it back (the rebound of the last impact): no event, nothing changed.
#[test]
fn at_a_wall_only_a_mass_moving_into_it_or_pressed_at_rest_hits_it() {
    let mut m = s2(0.8);
    let s = slam(&mut m);
    // (z, v, a): at +d/2 the base presses the mass there when a <= 0 (relative acceleration
    // -a), at -d/2 when a >= 0.
    for (z, v, a) in [
        (0.5 * D, 0.0, 0.5),
        (-0.5 * D, 0.0, -0.5),
        (0.5 * D, -0.2, -2.0),
        (-0.5 * D, 0.2, 2.0),
        (0.5 * D, -0.2, 0.0),
    ] {
        s.state.z = z;
        s.state.v = v;
        let before = s.state;
        assert_eq!(s.event(a), Event::None, "z {z}, v {v}, a {a}");
        assert_eq!(s.state, before, "z {z}, v {v}, a {a}");
    }
    // Pressed at speed 0 (a = 0 counts as pressing): it rests.
    for (z, a) in [(0.5 * D, 0.0), (-0.5 * D, 0.0), (0.5 * D, -1.0)] {
        s.state.z = z;
        s.state.v = 0.0;
        s.state.contact = 0;
        assert!(
            matches!(s.event(a), Event::Impact { rests: true, .. }),
            "z {z}, a {a}"
        );
        s.state.contact = 0;
    }
}

/// The contact functions of a fast flight (speeds above 1 m/s, as in a large tank): the gap
/// to the wall it moves towards, the gap plus d to the other.
#[test]
fn fast_flights_have_the_gap_towards_the_wall_they_move_to() {
    let mut m = s2(0.8);
    let s = slam(&mut m);
    s.state.z = 0.01;
    for v in [-1.5, -40.0, 1.5, 40.0] {
        s.state.v = v;
        let want = if v > 0.0 {
            [0.5 * D - 0.01, 0.5 * D + 0.01 + D]
        } else {
            [0.5 * D - 0.01 + D, 0.5 * D + 0.01]
        };
        let got = s.contact_functions(0.3);
        for k in 0..2 {
            assert!(
                (got[k] - want[k]).abs() < 1e-15,
                "v {v}: {got:?} vs {want:?}"
            );
        }
    }
}

/// At rest on a wall a host's trial state may carry a velocity; the stored energy reads it
/// (m v^2/2), and so does its tangent, while the rates stay 0.
#[test]
fn at_rest_the_stored_energys_tangent_reads_the_velocity() {
    let mut m = s2(0.8);
    let s = slam(&mut m);
    s.state.z = 0.5 * D;
    s.state.contact = 1;
    s.state.v = 0.2;
    let mass = s.impact_mass;
    let t = s.impact_tangent(-1.0, 0.5, 0.3);
    assert!((t.kinetic - mass * 0.2 * 0.5).abs() < 1e-15 * mass, "{t:?}");
    assert_eq!((t.z_rate, t.v_rate, t.power), (0.0, 0.0, 0.0));
    let stored = |v: f64, m: &mut AnyModel| {
        slam(m).state.v = v;
        m.observe(crate::model::Observable::Stored)
    };
    let h = 1e-4;
    // d(stored)/dv times the direction's 0.5.
    let fd = 0.5 * (stored(0.2 + h, &mut m) - stored(0.2 - h, &mut m)) / (2.0 * h);
    assert!((fd - mass * 0.2 * 0.5).abs() < 1e-9 * mass, "{fd}");
}
