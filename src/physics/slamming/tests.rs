use super::*;

fn slam(e: f64) -> Slamming {
    Slamming {
        clearance: 0.1,
        restitution: e,
        rest_speed: 1e-6,
    }
}

/// No base motion: the mass crosses the tank at constant speed; the impact times and
/// rebound speeds are known exactly.
#[test]
fn free_bounces_are_located_exactly() {
    let m = slam(0.5);
    let mut st = SlamState {
        z: 0.0,
        v: 0.2,
        ..Default::default()
    };
    // First impact after 0.05 / 0.2 = 0.25 s at +d/2, then 0.1 / 0.1 = 1 s to the other wall.
    let imp = m
        .advance(&mut st, 0.3, &BaseAcceleration::held(0.0))
        .expect("step");
    assert_eq!(st.impacts, 1);
    assert!((imp - 1.5 * 0.2).abs() < 1e-15, "impulse {imp}");
    assert!(
        (st.v + 0.1).abs() < 1e-15 && (st.z - (0.05 - 0.1 * 0.05)).abs() < 1e-15,
        "{st:?}"
    );
    m.advance(&mut st, 0.95 - 1e-9, &BaseAcceleration::held(0.0))
        .expect("step");
    assert_eq!(st.impacts, 1, "not yet at the other wall: {st:?}");
    m.advance(&mut st, 2e-9, &BaseAcceleration::held(0.0))
        .expect("step");
    assert_eq!(st.impacts, 2, "{st:?}");
    assert!((st.v - 0.05).abs() < 1e-15);
}

/// Constant base acceleration: the impact time solves a quadratic; energy and momentum
/// balance exactly.
#[test]
fn impact_time_under_constant_acceleration_and_balances() {
    let m = slam(0.4);
    let a = -3.0; // the tank accelerates towards -x: the water moves towards +x
    let mut st = SlamState {
        z: -0.02,
        v: 0.05,
        ..Default::default()
    };
    let e0 = 0.5 * st.v * st.v;
    // z(t) = -0.02 + 0.05 t + 1.5 t^2 = 0.05  ->  t = (-0.05 + sqrt(0.0025 + 4 * 1.5 * 0.07)) / 3
    let t_hit = (-0.05 + (0.0025f64 + 6.0 * 0.07).sqrt()) / 3.0;
    let v_hit = 0.05 + 3.0 * t_hit;
    let imp = m
        .advance(&mut st, t_hit + 1e-6, &BaseAcceleration::held(a))
        .expect("step");
    assert_eq!(st.impacts, 1);
    assert!(
        (imp - 1.4 * v_hit).abs() < 1e-12,
        "{imp} vs {}",
        1.4 * v_hit
    );
    let stored = 0.5 * st.v * st.v;
    assert!((st.work_in - st.dissipated - (stored - e0)).abs() < 1e-15);
    assert!((st.dissipated - 0.5 * (1.0 - 0.16) * v_hit * v_hit).abs() < 1e-12);
}

/// Pressed onto a wall the bounces shrink geometrically; chattering must end with the mass
/// resting there, pushing on the tank with the base's acceleration, and leave when it turns.
#[test]
fn chattering_ends_at_rest_and_releases() {
    let m = slam(0.5);
    let mut st = SlamState {
        z: 0.04,
        v: 0.3,
        ..Default::default()
    };
    let a = -9.81;
    let imp = m
        .advance(&mut st, 1.0, &BaseAcceleration::held(a))
        .expect("ends");
    assert_eq!(st.contact, 1, "{st:?}");
    assert!(st.impacts > 5 && st.impacts < 100, "{}", st.impacts);
    // Momentum: everything the water had plus what the base pushed in went to the tank.
    // Relative frame: impulse on the tank = v0 - v_end - int a = 0.3 - 0 + 9.81.
    assert!((imp - (0.3 + 9.81)).abs() < 1e-9, "{imp}");
    // Energy: all kinetic energy and all work ends dissipated.
    assert!(
        (st.work_in - st.dissipated + 0.5 * 0.09).abs() < 1e-12,
        "{st:?}"
    );
    // The acceleration turns: the mass leaves the wall and flies back.
    m.advance(&mut st, 0.05, &BaseAcceleration::held(2.0))
        .expect("release");
    assert_eq!(st.contact, 0);
    assert!(st.v < 0.0 && st.z < 0.05, "{st:?}");
}

/// z(t) of free flight from (z0, v0) at t = 0 under a_b = a0 + a1 t + a2 t^2/2, written out
/// as its own polynomial (the reference for the stepped flight).
fn quartic(a: [f64; 3], z0: f64, v0: f64, t: f64) -> (f64, f64) {
    let z = z0 + v0 * t - a[0] * t * t / 2.0 - a[1] * t * t * t / 6.0 - a[2] * t.powi(4) / 24.0;
    let v = v0 - a[0] * t - a[1] * t * t / 2.0 - a[2] * t * t * t / 6.0;
    (z, v)
}

/// Polynomials in z of magnitude ~0.1 with O(1) coefficients round to ~1e-17; every
/// comparison with the closed form below allows 1e-14, a thousand times that, and still
/// sees any wrong coefficient (the mutants change z by 1e-3 or more).
const TOL: f64 = 1e-14;

/// Guards p2 (a[1]/6, a[2]/24) and the flight from a mid-step start: a changing base
/// acceleration (nonzero first and second derivative), one step with no impact, and one in
/// which the mass hits the wall and flies on; both against the closed-form quartic, the
/// impact time against a Newton root of that quartic.
#[test]
fn flight_under_a_changing_input_follows_the_quartic() {
    let m = Slamming {
        clearance: 1.0,
        restitution: 0.5,
        rest_speed: 1e-6,
    };
    let a = [0.7, -2.3, 5.1];
    let base = BaseAcceleration { t0: 0.0, a };
    let mut st = SlamState {
        z: 0.1,
        v: -0.2,
        ..Default::default()
    };
    let h = 0.6;
    m.advance(&mut st, h, &base).expect("step");
    let (z, v) = quartic(a, 0.1, -0.2, h);
    assert_eq!(st.impacts, 0, "{st:?}");
    assert!(
        (st.z - z).abs() < TOL && (st.v - v).abs() < TOL,
        "{st:?} vs {z} {v}"
    );

    // From rest at the centre the input -a pushes the mass to the +wall (z = 0.5) at t1.
    let a = [-4.0, -3.0, 2.0];
    let base = BaseAcceleration { t0: 0.0, a };
    let mut t1 = 0.4;
    for _ in 0..50 {
        let (z, v) = quartic(a, 0.0, 0.0, t1);
        t1 -= (z - 0.5) / v;
    }
    let mut st = SlamState::default();
    let h = 0.55;
    let impulse = m.advance(&mut st, h, &base).expect("step");
    assert_eq!(st.impacts, 1, "{st:?}");
    let (_, v_hit) = quartic(a, 0.0, 0.0, t1);
    // After the impact: from (0.5, -e v_hit) at t1 under the same input, i.e. the quartic
    // with the input re-expanded about t1.
    let shifted = [
        a[0] + a[1] * t1 + a[2] * t1 * t1 / 2.0,
        a[1] + a[2] * t1,
        a[2],
    ];
    let (z, v) = quartic(shifted, 0.5, -0.5 * v_hit, h - t1);
    assert!(
        (st.z - z).abs() < TOL && (st.v - v).abs() < TOL,
        "{st:?} vs {z} {v}"
    );
    assert!(
        (impulse - 1.5 * v_hit).abs() < TOL,
        "{impulse} vs {}",
        1.5 * v_hit
    );
}

/// A mass resting on `wall` under a ramp a_b = a0 + a1 s that stops pressing it there at
/// s* = -a0/a1 inside the step, with |a_b| < 1 m/s^2 throughout: it must stay until s*
/// (pushing on the tank with -a_b), then fly off from rest. Guards the release test's sign
/// (a_b wall > 0; a_b + wall > 0 releases at once from the +1 wall and never from the -1
/// wall) and where the release lands.
#[test]
fn ramped_input_turning_on_a_wall_releases_at_its_root() {
    let m = slam(0.5);
    for wall in [1i8, -1] {
        let w = f64::from(wall);
        let a = [-0.5 * w, 1.6 * w, 0.0];
        let base = BaseAcceleration { t0: 0.0, a };
        let s_star = 0.5 / 1.6;
        let h = 0.5;
        let mut st = SlamState {
            z: 0.05 * w,
            contact: wall,
            ..Default::default()
        };
        let impulse = m.advance(&mut st, h, &base).expect("step");
        assert_eq!(st.contact, 0, "wall {wall}: {st:?}");
        assert_eq!(st.impacts, 0, "wall {wall}: {st:?}");
        // While resting: impulse -int a; the input has a root at s*, so it is the input's
        // integral up to there.
        let rest = -(a[0] * s_star + a[1] * s_star * s_star / 2.0);
        assert!(
            (impulse - rest).abs() < TOL,
            "wall {wall}: {impulse} vs {rest}"
        );
        let shifted = [0.0, a[1], 0.0];
        let (z, v) = quartic(shifted, 0.05 * w, 0.0, h - s_star);
        assert!(
            (st.z - z).abs() < TOL && (st.v - v).abs() < TOL,
            "wall {wall}: {st:?} vs {z} {v}"
        );
    }
}

/// Weak held accelerations (0.3 m/s^2) on each wall: pressing keeps the mass there for the
/// whole step, pulling releases it at once, and no acceleration at all leaves it resting
/// (it has not turned). Guards the release sign for |a_b| < 1, where a_b + wall has the
/// sign of the wall, not of a_b wall, and the strict a_b wall > 0.
#[test]
fn weak_inputs_press_or_release_on_each_wall() {
    let m = slam(0.5);
    for wall in [1i8, -1] {
        let w = f64::from(wall);
        for (a, stays) in [(-0.3 * w, true), (0.0, true), (0.3 * w, false)] {
            let mut st = SlamState {
                z: 0.05 * w,
                contact: wall,
                ..Default::default()
            };
            let h = 0.2;
            let impulse = m
                .advance(&mut st, h, &BaseAcceleration::held(a))
                .expect("step");
            if stays {
                assert_eq!((st.contact, st.z, st.v), (wall, 0.05 * w, 0.0), "{st:?}");
                assert!((impulse + a * h).abs() < TOL, "{impulse}");
            } else {
                assert_eq!(st.contact, 0, "wall {wall} a {a}: {st:?}");
                assert_eq!(impulse, 0.0);
                assert!((st.v + a * h).abs() < TOL, "{st:?}");
                assert!((st.z - (0.05 * w - a * h * h / 2.0)).abs() < TOL, "{st:?}");
            }
        }
    }
}

/// The release time alone, against the root of the quadratic input by the quadratic
/// formula. The bisection ends within an ulp of the place where the computed a_b changes
/// sign, which lies within rounding of a_b (~1e-16) over its slope (~1) of the true root:
/// 1e-14 allows a hundred times that; a search stopped at the 1/64 grid is 1e-3 off.
/// Also guards the grid staying inside the interval.
#[test]
fn release_time_is_the_root_of_the_input() {
    let a = [-0.8, 0.9, 1.7];
    let base = BaseAcceleration { t0: 0.0, a };
    // a0 + a1 s + a2 s^2 / 2 = 0, the positive root.
    let (qa, qb, qc) = (a[2] / 2.0, a[1], a[0]);
    let root = (-qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
    let (s0, s1) = (0.1, 0.9);
    assert!(root > s0 && root < s1);
    let got = Slamming::release(&base, 1, s0, s1).expect("releases");
    assert!((got - root).abs() < TOL, "{got} vs {root}");
    // Beyond the root the input presses the -1 wall throughout and pulls from the +1 wall
    // at once; before it, the reverse.
    assert_eq!(Slamming::release(&base, -1, root + 1e-3, s1), None);
    assert_eq!(Slamming::release(&base, -1, s0, s1), Some(s0));
    // A root just after the interval is not in it (the search must stay inside (s0, s1]).
    assert_eq!(Slamming::release(&base, 1, s0, root - 1e-3), None);
    assert_eq!(
        Slamming::release(&base, 1, root + 1e-3, s1),
        Some(root + 1e-3)
    );
}

/// Chattering may take up to MAX_IMPACTS_PER_STEP impacts in one step, not one fewer:
/// elastic bounces at 1 m/s across d = 0.1 hit a wall at 0.05 + 0.1 k s, so a step of
/// 10000 s holds exactly 100000 impacts (the next one 0.05 s later), and one of 10000.1 s
/// one more. Guards the comparison against the limit (> not >=).
#[test]
fn impact_limit_is_exact() {
    let m = Slamming {
        clearance: 0.1,
        restitution: 1.0,
        rest_speed: 1e-6,
    };
    let start = SlamState {
        v: 1.0,
        ..Default::default()
    };
    let mut st = start;
    m.advance(&mut st, 10_000.0, &BaseAcceleration::held(0.0))
        .expect("exactly at the limit");
    assert_eq!(st.impacts, MAX_IMPACTS_PER_STEP);
    let mut st = start;
    assert!(
        m.advance(&mut st, 10_000.1, &BaseAcceleration::held(0.0))
            .is_err()
    );
}

/// Guards the sampling density of the impact search (amax, vmax, resolution, n): the
/// search promises to see any crossing of the wall that lasts longer than one sample
/// interval, at most r = 0.01 d / vmax. Here the mass is thrown at the +wall against a held
/// a_b = 2 m/s^2 so that it passes the wall by only delta = a (0.525 r)^2 / 2 and is
/// beyond it for 1.05 r, just more than the promise. Over 40 step lengths (the grid's
/// phase against the graze moves) every graze must be an impact at the root of the
/// parabola; a grid 1.3 times as coarse (r = 0.01 d vmax here) misses some.
#[test]
fn grazes_of_the_wall_are_not_stepped_over() {
    let m = slam(0.5);
    let accel = 2.0;
    for i in 0..40 {
        let h = 0.3 + 0.005 * f64::from(i);
        let v_nominal = (2.0 * accel * 0.05f64).sqrt();
        let r = 0.01 * 0.1 / (v_nominal + accel * h);
        let delta = accel * (0.525 * r).powi(2) / 2.0;
        let v0 = (2.0 * accel * (0.05 + delta)).sqrt();
        let mut st = SlamState {
            v: v0,
            ..Default::default()
        };
        m.advance(&mut st, h, &BaseAcceleration::held(accel))
            .expect("step");
        assert_eq!(
            st.impacts, 1,
            "h {h}: the graze by {delta:e} m was missed: {st:?}"
        );
        // Reaches the wall with v^2 = v0^2 - 2 a d/2 = 2 a delta, rebounds with e.
        let v_hit = (2.0 * accel * delta).sqrt();
        let t_hit = (v0 - v_hit) / accel;
        let (z, v) = quartic([accel, 0.0, 0.0], 0.05, -0.5 * v_hit, h - t_hit);
        // A graze is crossed at the slow v_hit: the rounding of z (< 1e-16 here) moves the
        // root by 1e-16 / v_hit, and the state after it by (|v| + a) times that <= 3x.
        let tol = 3e-16 / v_hit;
        assert!(
            (st.z - z).abs() < tol && (st.v - v).abs() < tol,
            "h {h}: {st:?} vs {z} {v}"
        );
    }
}

/// Guards the search's upper end after a mid-step impact: elastic bounces at 0.2 m/s
/// across d = 0.1 hit at 0.25 s and 0.75 s; a step of 0.6 s holds the first only (a grid
/// reaching past s1 from s0 = 0.25 would take the second early).
#[test]
fn an_impact_after_the_step_is_not_taken_early() {
    let m = Slamming {
        clearance: 0.1,
        restitution: 1.0,
        rest_speed: 1e-6,
    };
    let mut st = SlamState {
        v: 0.2,
        ..Default::default()
    };
    m.advance(&mut st, 0.6, &BaseAcceleration::held(0.0))
        .expect("step");
    assert_eq!(st.impacts, 1, "{st:?}");
    assert!(
        (st.z - (0.05 - 0.2 * 0.35)).abs() < TOL && st.v == -0.2,
        "{st:?}"
    );
}

/// As `grazes_of_the_wall_are_not_stepped_over`, under a ramp a_b = 0.5 + 4 s and under
/// 0.5 + 2 s + 8 s^2/2: the search's bound on the acceleration must count the input's
/// derivatives (|a1| h + |a2| h^2 of 2.1 and 2.1 m/s^2 here), or its samples are too sparse. The mass peaks at t_p = 0.2 s beyond the wall by
/// delta = a(t_p) (0.525 r)^2 / 2, which it is beyond for 1.05 r (to 0.2 %: the cubic
/// term bends the parabola by a1 r / a(t_p)); the impact time is bisected on the quartic.
#[test]
fn grazes_under_a_ramp_are_not_stepped_over() {
    for a in [[0.5, 4.0, 0.0], [0.5, 2.0, 8.0]] {
        graze_under(0.1, a, 0.2, 0.3);
    }
    // Steps of 2.5-4.1 s in a tank of 40 m, where h |a1| exceeds h + |a1|: a bound that
    // added where it should multiply would be too small only there.
    graze_under(40.0, [0.5, 4.0, 0.0], 2.0, 2.5);
    // And under a2 = 8 in a tank of 400 m (the mass falls 80 m after the graze): h |a2|
    // exceeds h + |a2| from h = 8/7 on.
    graze_under(400.0, [0.5, 2.0, 8.0], 2.0, 2.5);
}

/// Guards the impact search of a flight that starts late in a long step (s0 of 2.9 s, steps
/// of 6.2-8.8 s): its samples must cover s1 - s0, not s1 / s0 (shorter there). Under a held
/// a_b = 0.1 m/s^2 in a tank of d = 0.45 m with e = 0.9, the mass thrown up from the centre
/// hits the +wall, falls onto the -wall at t2 and rebounds with u = sqrt(2 a (d + delta)), so
/// that it passes the +wall by delta, for 1.05 r, r = 0.01 d / (u + a (h - t2)) the promise
/// of that search (as in `grazes_of_the_wall_are_not_stepped_over`). Every flight is a
/// parabola: the impact times and the state at the step's end are closed forms.
#[test]
fn grazes_after_impacts_late_in_long_steps_are_not_stepped_over() {
    let (accel, d, e) = (0.1, 0.45, 0.9);
    let m = Slamming {
        clearance: d,
        restitution: e,
        rest_speed: 1e-6,
    };
    let half = d / 2.0;
    // Nominal times (delta = 0), for r only.
    let u_nominal = (2.0 * accel * d).sqrt();
    let t2_nominal = {
        let w = u_nominal / e;
        let ev = (w * w - 2.0 * accel * d).sqrt();
        let v = ev / e;
        ((v * v + accel * d).sqrt() - v + w - ev) / accel
    };
    for i in 0..40 {
        let h = 6.2 + 0.065 * f64::from(i);
        let r = 0.01 * d / (u_nominal + accel * (h - t2_nominal));
        let delta = accel * (0.525 * r).powi(2) / 2.0;
        // Backwards from the rebound at the -wall: it hit at w, after falling from the
        // +wall, which it left at e v, having hit it at v on the way up from the centre.
        let u = (2.0 * accel * (d + delta)).sqrt();
        let w = u / e;
        let ev = (w * w - 2.0 * accel * d).sqrt();
        let v = ev / e;
        let v_start = (v * v + accel * d).sqrt();
        let t2 = (v_start - v + w - ev) / accel;
        // Up from the -wall: half + delta - a (t - t_peak)^2 / 2 = half at the graze.
        let v_graze = (2.0 * accel * delta).sqrt();
        let t_graze = t2 + (u - v_graze) / accel;
        assert!(t_graze < h && h - t_graze < (2.0 * d / accel).sqrt());
        let mut st = SlamState {
            v: v_start,
            ..Default::default()
        };
        m.advance(&mut st, h, &BaseAcceleration::held(accel))
            .expect("step");
        assert_eq!(
            st.impacts, 3,
            "h {h}: the graze by {delta:e} m was missed: {st:?}"
        );
        let (z, v) = quartic([accel, 0.0, 0.0], half, -e * v_graze, h - t_graze);
        // The rebound u carries the rounding of three flights and two impacts, in the model
        // and in the closed forms (where w^2 - 2 a d cancels to a fifth): up to ~5 ulps, so
        // the peak moves by u du / a = 2 d du / u ~ 1.1e-15 d, the graze's time by that over
        // v_graze, and the state at the end by up to (|v| + a) ~ 0.5 times that:
        // 1e-15 d / v_graze allows twice the estimate.
        let tol = 1e-15 * d / v_graze;
        assert!(
            (st.z - z).abs() < tol && (st.v - v).abs() < tol,
            "h {h}: {st:?} vs {z} {v}, {tol:e}"
        );
    }
}

/// One case of `grazes_under_a_ramp_are_not_stepped_over`: clearance d, input a, peak at
/// t_p, 40 step lengths from h0 on.
fn graze_under(d: f64, a: [f64; 3], t_p: f64, h0: f64) {
    let m = Slamming {
        clearance: d,
        restitution: 0.5,
        rest_speed: 1e-6,
    };
    let half = d / 2.0;
    let base = BaseAcceleration { t0: 0.0, a };
    let v0 = a[0] * t_p + a[1] * t_p * t_p / 2.0 + a[2] * t_p.powi(3) / 6.0;
    let at = |t: f64| [a[0] + a[1] * t + a[2] * t * t / 2.0, a[1] + a[2] * t, a[2]];
    let curvature = at(t_p)[0];
    for i in 0..40 {
        let h = h0 + h0 / 60.0 * f64::from(i);
        let amax = a[0] + h * (a[1] + h * a[2]);
        let r = 0.01 * d / (v0 + amax * h);
        let delta = curvature * (0.525 * r).powi(2) / 2.0;
        let (rise, _) = quartic(a, 0.0, v0, t_p);
        let z0 = half + delta - rise;
        assert!(z0.abs() < half);
        let mut st = SlamState {
            z: z0,
            v: v0,
            ..Default::default()
        };
        m.advance(&mut st, h, &base).expect("step");
        assert_eq!(
            st.impacts, 1,
            "{a:?} h {h}: graze by {delta:e} m missed: {st:?}"
        );
        let (mut lo, mut hi) = (t_p - r, t_p);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if quartic(a, z0, v0, mid).0 < half {
                lo = mid
            } else {
                hi = mid
            }
        }
        let (_, v_hit) = quartic(a, z0, v0, hi);
        let (z, v) = quartic(at(hi), half, -0.5 * v_hit, h - hi);
        // As in the held case: the root is known to the rounding of z over v_hit, here
        // z up to d/2 and the state after it moving at up to |v| + a.
        let tol = 3e-16 * d / 0.1 * (1.0 + v.abs()) / v_hit;
        assert!(
            (st.z - z).abs() < tol && (st.v - v).abs() < tol,
            "{a:?} h {h}: {st:?} vs {z} {v}"
        );
    }
}

/// Chattering under weak and strong pressing on each wall (|a_b| = 0.5 and 1.5 m/s^2) must
/// end with the mass at rest there, and by momentum the tank has taken v0 + |a_b| t.
/// Guards the test of a pressing input at an impact (a_b wall <= 0): with a_b + wall <= 0
/// a weak press on +1 (or a strong one on -1) never lets the mass rest, and the bounces
/// shrink towards infinitely many.
#[test]
fn chattering_under_weak_and_strong_pressing_ends_at_rest() {
    let m = slam(0.5);
    for wall in [1i8, -1] {
        let w = f64::from(wall);
        for press in [0.5, 1.5] {
            let mut st = SlamState {
                z: 0.04 * w,
                v: 0.3 * w,
                ..Default::default()
            };
            let impulse = m
                .advance(&mut st, 2.0, &BaseAcceleration::held(-press * w))
                .expect("chattering ends");
            assert_eq!(st.contact, wall, "wall {wall} press {press}: {st:?}");
            let want = w * (0.3 + press * 2.0);
            // Momentum is exact at each impact and while resting: a few dozen impacts
            // round to ~1e-14.
            assert!(
                (impulse - want).abs() < 1e-12,
                "wall {wall} press {press}: {impulse} vs {want}"
            );
        }
    }
}

/// The impact search's bound of abs(a_b) holds over any interval of the step, also one that
/// starts after an impact, where the polynomial about the step's start has grown (a_b = 4 s^2
/// searched over [3, 3.5]: at most 49, which the interval's length alone, 0.5, would put at 2).
#[test]
fn the_acceleration_bound_holds_anywhere_in_the_step() {
    let cases = [
        ([0.0, 0.0, 8.0], 3.0, 3.5),
        ([1.0, -2.0, 0.5], 0.0, 2.0),
        ([-0.3, 5.0, -7.0], 1.25, 1.5),
        ([2.0, 0.0, 0.0], 4.0, 9.0),
    ];
    for (a, s0, s1) in cases {
        let b = BaseAcceleration { t0: 0.0, a };
        let bound = acceleration_bound(&b, s0, s1);
        let largest = (0..=1000)
            .map(|k| b.at(s0 + (s1 - s0) * f64::from(k) / 1000.0).abs())
            .fold(0.0f64, f64::max);
        assert!(
            largest <= bound,
            "{a:?} on [{s0}, {s1}]: {largest} > {bound}"
        );
        // Not looser than the terms' own sizes at the far end.
        let far = s1.abs().max(s0.abs());
        assert!(bound <= a[0].abs() + far * (a[1].abs() + far * a[2].abs()) + 1e-12);
    }
}
