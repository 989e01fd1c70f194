use super::*;

/// The mean relative error of the estimate over t in [40, 60) s (ripple averaged out) for
/// base motion A sin(w t) sampled every h and held, from base.a alone or with base.v too;
/// the tracker as the simulation sets it up (tau = 2 periods of w_f, leak w_f/20).
fn mean_error(ratio: f64, with_velocity: bool, reference: impl Fn(f64, f64, f64) -> f64) -> f64 {
    let wf = 5.6389f64;
    let (w, leak) = (ratio * wf, 0.05 * wf);
    let tau = 2.0 * std::f64::consts::TAU / wf;
    let mut tracker = AmplitudeTracker::new(tau, leak, 0.001, wf);
    let (amp, h) = (0.005, 0.01);
    let want = reference(amp, w, h);
    let (mut sum, mut n) = (0.0, 0.0);
    for k in 0..6000 {
        let t = k as f64 * h;
        let v = if with_velocity {
            w * amp * (w * t).cos()
        } else {
            0.0
        };
        tracker.update(h, -w * w * amp * (w * t).sin(), v);
        if k >= 4000 {
            sum += tracker.estimate() / want - 1.0;
            n += 1.0;
        }
    }
    sum / n
}

/// The ripple at 2w passes the two cascaded filters as 1/(1 + (2 w tau)^2), 1/160 at the
/// slowest w here; its first order averages out of the mean, its square (~4e-5) does not.
const MEAN_TOL: f64 = 2e-4;

/// From base.a alone the velocity is rebuilt by the leaky integrator v' = a - w_c v,
/// advanced exactly with a held over each step: a discrete filter whose gain at w is
/// |H|^2 = ((1 - E)/w_c)^2 / ((1 - E)^2 + 4 E sin^2(w h/2)), E = e^(-w_c h). The estimate
/// then settles on w^2 A / (1/|H|^2 - w_c^2) (A up to (w h)^2), which the mean must
/// match. Guards the leak correction (- w_c^2): without it the mean is 1 % low at w_f/2
/// and 0.2 % low at w_f, while the worst single error stays inside any 5 % band.
#[test]
fn rebuilt_velocity_estimate_is_unbiased() {
    let discrete = |amp: f64, w: f64, h: f64| {
        let leak = 0.05 * 5.6389;
        let e = (-leak * h).exp();
        let gain2 = ((1.0 - e) / leak).powi(2)
            / ((1.0 - e).powi(2) + 4.0 * e * (0.5 * w * h).sin().powi(2));
        w * w * amp / (1.0 / gain2 - leak * leak)
    };
    for ratio in [0.5, 1.0, 2.0] {
        let err = mean_error(ratio, false, discrete);
        assert!(err.abs() < MEAN_TOL, "w/wf {ratio}: mean error {err:e}");
    }
}

/// With the measured base velocity the estimate sqrt(2) <v^2>/sqrt(<a^2>) is A itself.
#[test]
fn measured_velocity_estimate_is_unbiased() {
    for ratio in [0.5, 1.0, 2.0] {
        let err = mean_error(ratio, true, |amp, _, _| amp);
        assert!(err.abs() < MEAN_TOL, "w/wf {ratio}: mean error {err:e}");
    }
}

/// Guards the normalisation by the filters' response to a constant (the `/ w` of both mean
/// squares): with a constant acceleration and velocity the normalised means are exactly
/// a^2 and v^2 from the first update on, so the estimate is sqrt(2) v^2/|a| to rounding,
/// while the filters themselves hold only 1 - e^(-t/tau) of it (and the square of that).
#[test]
fn estimate_is_normalised_from_the_first_update() {
    let mut tracker = AmplitudeTracker::new(2.0, 0.3, 0.001, 6.0);
    let (a, v) = (-0.8, 0.05);
    let want = std::f64::consts::SQRT_2 * v * v / 0.8;
    for k in 1..=20 {
        tracker.update(0.05, a, v);
        let got = tracker.estimate();
        assert!(
            (got / want - 1.0).abs() < 1e-14,
            "update {k}: {got} vs {want}"
        );
    }
}

/// From base.a alone the rebuilt velocity starts at rest, so after the first update only
/// the acceleration has a mean square: no amplitude follows from that (the estimate stays
/// the prior, not 0). Guards the v2 > 0 half of the guard (>= or || would answer 0).
#[test]
fn no_estimate_before_the_rebuilt_velocity_moves() {
    let mut tracker = AmplitudeTracker::new(2.0, 0.3, 0.001, 6.0);
    tracker.update(0.05, -0.8, 0.0);
    assert_eq!(tracker.estimate(), 0.001);
    tracker.update(0.05, -0.8, 0.0);
    assert!(tracker.estimate() != 0.001 && tracker.estimate() > 0.0);
}

/// The tracker's state after each update, bit for bit, against the recursion written out
/// signal by signal (the filters of each signal on their own, the coefficients computed
/// afresh each time): the packed lanes and the kept coefficients change no bit. Over
/// intervals of changing length, base.v first absent (+0 and -0) then driven: the update's
/// one check for both (in integer bits) misses neither.
#[test]
fn packed_updates_are_the_scalar_recursion_to_the_bit() {
    let (tau, leak) = (1.3, 0.27);
    let mut tracker = AmplitudeTracker::new(tau, leak, 0.002, 5.4);
    let (mut rebuilt, mut seen) = (0.0f64, false);
    let mut filters = [[0.0f64; 2]; 3];
    for k in 0..400 {
        let h = if k % 97 < 50 { 0.01 } else { 0.0125 };
        let t = k as f64 * 0.01;
        let a = -0.7 * (2.1 * t).sin() + 0.01 * (k % 7) as f64;
        // Before the host drives base.v, +0 and -0 alternate: neither switches to it.
        let v = if k < 150 {
            [0.0, -0.0][k % 2]
        } else {
            0.33 * (2.1 * t).cos()
        };
        tracker.update(h, a, v);

        let alpha = -(-h / tau).exp_m1();
        if v != 0.0 && !seen {
            seen = true;
            filters = [[0.0; 2]; 3];
        }
        let vv = if seen { v } else { rebuilt };
        for (f, sample) in filters.iter_mut().zip([vv * vv, a * a, 1.0]) {
            f[0] += alpha * (sample - f[0]);
            f[1] += alpha * (f[0] - f[1]);
        }
        rebuilt = rebuilt * (-leak * h).exp() - a * (-leak * h).exp_m1() / leak;

        let want = [
            rebuilt,
            f64::from(u8::from(seen)),
            filters[0][0],
            filters[0][1],
            filters[1][0],
            filters[1][1],
            filters[2][0],
            filters[2][1],
        ];
        assert_eq!(
            tracker.state().map(f64::to_bits),
            want.map(f64::to_bits),
            "{k}"
        );
    }
}

/// Guards the checks of a restored state: a fresh tracker's (zero) state is accepted, and
/// each bad value alone (not finite, a negative mean square, a flag not 0 or 1) refused.
#[test]
fn restored_state_is_checked_value_by_value() {
    let mut tracker = AmplitudeTracker::new(2.0, 0.3, 0.001, 6.0);
    let fresh = tracker.state();
    assert!(tracker.set_state(&fresh).is_ok());
    tracker.update(0.05, -0.8, 0.05);
    let good = tracker.state();
    assert!(tracker.set_state(&good).is_ok());
    assert_eq!(tracker.state(), good);
    for (i, bad) in [(0, f64::NAN), (3, f64::INFINITY), (4, -1e-12), (1, 0.5)] {
        let mut s = good;
        s[i] = bad;
        assert!(tracker.set_state(&s).is_err(), "state[{i}] = {bad}");
    }
}
/// The estimator as ODEs (Model Exchange): from all filters 0 its estimate is the prior,
/// and states a solver's noise away from there (1e-18, of either sign, against the prior's
/// share 1e-6 of mean squares of order 1e-5 and 1e-3) move it by no more than their size
/// relative to that share: continuous, where Co-Simulation's formula of the same tiny
/// numbers jumps (to 1 m from the prior's 1 mm here). The flag that says so is saved
/// (2 at position 1) and restored; Co-Simulation's saved states never carry it.
#[test]
fn the_continuous_estimate_starts_at_the_prior_and_leaves_it_smoothly() {
    let (prior, omega) = (0.001, 6.0);
    let mut tracker = AmplitudeTracker::new(2.0, 0.3, prior, omega);
    assert_eq!(tracker.state()[1], 0.0);
    tracker
        .set_continuous_state(&[0.0; TRACKER_CONTINUOUS])
        .expect("finite");
    assert_eq!(tracker.state()[1], 2.0);
    let start = tracker.estimate();
    assert!((start / prior - 1.0).abs() < 1e-14, "{start}");
    tracker
        .set_continuous_state(&[0.0, 1e-18, -1e-18, 1e-18, 1e-18, 1e-18, -1e-18])
        .expect("finite");
    assert!((tracker.estimate() / prior - 1.0).abs() < 1e-6);
    let noisy = [0.0, 1e-18, 1e-18, 1e-18, 2e-18, 1e-18, 1e-18];
    tracker.set_continuous_state(&noisy).expect("finite");
    let moved = tracker.estimate();
    assert!((moved / prior - 1.0).abs() < 1e-6, "{moved}");
    let mut cs = AmplitudeTracker::new(2.0, 0.3, prior, omega);
    let mut saved = tracker.state();
    saved[1] = 0.0;
    cs.set_state(&saved).expect("in range");
    assert!(cs.estimate() > 100.0 * prior, "{}", cs.estimate());
    let mut restored = AmplitudeTracker::new(2.0, 0.3, prior, omega);
    restored.set_state(&tracker.state()).expect("in range");
    assert_eq!(restored, tracker);
    assert_eq!(restored.estimate(), moved);
}

/// The gradient of the continuous estimate against central differences of it, with the
/// velocity rebuilt and measured, filters mid-way.
#[test]
fn the_continuous_estimates_gradient_is_its_change() {
    for measured in [false, true] {
        let mut tracker = AmplitudeTracker::new(1.5, 0.3, 0.004, 6.0);
        if measured {
            tracker.sees_velocity(0.1);
        }
        let s = [0.02, 8e-5, 5e-5, 2e-3, 1.2e-3, 0.6, 0.35];
        tracker.set_continuous_state(&s).expect("finite");
        let (_, gradient) = tracker.continuous_estimate();
        for k in 0..TRACKER_CONTINUOUS {
            let h = 1e-5 * s[k];
            let at = |x: f64| {
                let mut t = tracker.clone();
                let mut p = s;
                p[k] = x;
                t.set_continuous_state(&p).expect("finite");
                t.estimate()
            };
            let fd = (at(s[k] + h) - at(s[k] - h)) / (2.0 * h);
            assert!(
                (gradient[k] - fd).abs() <= 1e-7 * fd.abs().max(1e-9),
                "measured {measured}, {k}: {} vs {fd}",
                gradient[k]
            );
        }
    }
}

/// The weight counted (`take_in`) is the weight updated (`update`), to the bit, whenever it is
/// read: the estimate, the saved state and equality read at irregular times (one step, many
/// steps, or none apart), over interval lengths that change (the counted updates applied with
/// the old gain first), base.v first absent then driven (the count restarts), a restored state,
/// and a run long enough for the weight to reach its fixed point (where the read stops
/// applying), with a gain small enough that it takes tens of thousands of updates.
#[test]
fn the_counted_weight_is_the_updated_one_to_the_bit() {
    let (tau, leak, prior, w) = (2.2, 0.28, 0.005, 5.9);
    let mut eager = AmplitudeTracker::new(tau, leak, prior, w);
    let mut lazy = eager.clone();
    let (mut t, mut reads) = (0.0, 0);
    for k in 0..150_000usize {
        let h = match k {
            0..30_000 => 1e-3,
            30_000..30_500 => 2.5e-3,
            _ => 1e-3,
        };
        let accel = -w * w * 0.003 * (w * t).sin();
        let velocity = if (40_000..60_000).contains(&k) || k >= 80_000 {
            w * 0.003 * (w * t).cos()
        } else {
            0.0
        };
        eager.update(h, accel, velocity);
        lazy.take_in(h, accel, velocity);
        if k == 70_000 {
            let saved = eager.state();
            eager.set_state(&saved).expect("a saved state");
            lazy.set_state(&saved).expect("a saved state");
        }
        // Reads: every step for a while, then at growing gaps, and none over the 30,000 steps
        // before the first change of interval length.
        let read = (100..200).contains(&k) || (k > 30_000 && k.is_power_of_two()) || k % 7919 == 0;
        if read {
            reads += 1;
            assert_eq!(
                lazy.estimate().to_bits(),
                eager.estimate().to_bits(),
                "step {k}"
            );
            assert_eq!(
                lazy.state().map(f64::to_bits),
                eager.state().map(f64::to_bits),
                "step {k}"
            );
            assert_eq!(lazy, eager, "step {k}");
        }
        t += h;
    }
    assert!(reads > 100, "{reads}");
    assert_eq!(
        lazy.state().map(f64::to_bits),
        eager.state().map(f64::to_bits)
    );
    // The weight's filters have reached their fixed point (so the reads stopped early).
    let before = eager.state();
    eager.update(1e-3, 0.0, 0.01);
    assert_eq!(eager.state()[6..].to_vec(), before[6..].to_vec());
}
