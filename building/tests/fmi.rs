//! Building.fmu through its C entry points: the call sequence, bad input (refused with a logged
//! reason, the instance unchanged and usable), state round trips, output derivatives, and the
//! exact step against closed forms.

mod host;

use host::*;

const ONE_STOREY: [(u32, f64); 3] = [
    (vr::STOREYS, 1.0),
    (vr::STOREY_1__MASS, 168.0),
    (vr::STOREY_1__STIFFNESS, 5342.0),
];

fn three_storeys() -> Vec<(u32, f64)> {
    vec![
        (vr::STOREYS, 3.0),
        (vr::STOREY_1__MASS, 60.0),
        (vr::STOREY_1__MASS + 1, 60.0),
        (vr::STOREY_1__MASS + 2, 50.0),
        (vr::STOREY_1__STIFFNESS, 9600.0),
        (vr::STOREY_1__STIFFNESS + 1, 8230.0),
        (vr::STOREY_1__STIFFNESS + 2, 6860.0),
        (vr::DAMPING_ZETA, 0.02),
        (vr::TLD_MASS, 0.35),
    ]
}

#[test]
fn calls_out_of_order_are_refused_with_the_way_out() {
    let mut inst = Instance::new("order");
    assert_eq!(inst.do_step(0.01), ERROR);
    assert!(
        inst.logs()
            .iter()
            .any(|m| m.contains("fmi2DoStep is not allowed"))
    );
    inst.initialise(&ONE_STOREY);
    assert_eq!(inst.do_step(0.01), OK);
    assert_eq!(inst.setup(), ERROR);
    assert_eq!(unsafe { inst.lib.fmi2Terminate(inst.c) }, OK);
    assert_eq!(inst.do_step(0.01), ERROR);
    assert_eq!(unsafe { inst.lib.fmi2Reset(inst.c) }, OK);
    inst.time = 0.0;
    inst.initialise(&ONE_STOREY);
    assert_eq!(inst.do_step(0.01), OK);
    // Model Exchange functions refuse on a Co-Simulation instance, naming the way to one.
    assert_eq!(unsafe { inst.lib.fmi2SetTime(inst.c, 0.0) }, ERROR);
    let said = inst.logs();
    assert!(
        said.iter().any(|m| m.contains("fmuType fmi2ModelExchange")),
        "{said:?}"
    );
}

/// Every bad value is refused with a message, and the instance is byte for byte as before.
#[test]
fn bad_input_is_refused_and_changes_nothing() {
    let mut inst = Instance::new("bad");
    inst.initialise(&three_storeys());
    assert_eq!(inst.set_real(vr::GROUND_A, 0.3), OK);
    assert_eq!(inst.do_step(0.01), OK);
    let before = inst.serialised();
    let refused = [
        inst.set_real(vr::GROUND_A, f64::NAN),
        inst.set_real(vr::TLD_FORCE, f64::INFINITY),
        inst.set_real(vr::STOREY_1__MASS, 1.0), // fixed after initialisation
        inst.set_real(vr::TLD_A, 1.0),          // an output
        inst.set_real(9999, 1.0),
        inst.derivative(vr::GROUND_A, 3, 1.0),
        inst.derivative(vr::TLD_A, 1, 1.0),
        inst.do_step(-0.01),
        inst.do_step(0.0),
        unsafe { inst.lib.fmi2DoStep(inst.c, inst.time + 1.0, 0.01, 1) },
    ];
    assert!(refused.iter().all(|&s| s == ERROR), "{refused:?}");
    assert_eq!(inst.serialised(), before);
    assert!(inst.logs().len() >= refused.len(), "{:?}", inst.logs());
    assert_eq!(inst.do_step(0.01), OK, "still usable");
}

/// A step too long for the exact propagator (coverage-guided fuzzing: steps near 1e300 s made
/// the matrix exponential take about a thousand squarings each, over a second a step for 20
/// storeys, to end in NaN) is refused before the exponential is formed, saying why; the
/// instance is as before and steps on.
#[test]
fn a_step_too_long_to_form_is_refused_before_the_exponential() {
    let mut inst = Instance::new("long-step");
    inst.initialise(&three_storeys());
    assert_eq!(inst.set_real(vr::GROUND_A, 0.3), OK);
    assert_eq!(inst.do_step(0.01), OK);
    let before = inst.serialised();
    for h in [1e300, 1e20] {
        assert_eq!(inst.do_step(h), ERROR, "{h}");
        let logs = inst.logs().join("\n");
        assert!(
            logs.contains("beyond what the exact propagator can form"),
            "{h}: {logs}"
        );
        assert_eq!(inst.serialised(), before);
    }
    // A long but formable step (the structure at rest long after the input): taken.
    assert_eq!(inst.do_step(1e6), OK, "{:?}", inst.logs());
}

/// Inconsistent parameters are refused at fmi2ExitInitializationMode with the reason; fixed,
/// the same instance initialises.
#[test]
fn inconsistent_parameters_say_why() {
    let inst = Instance::new("params");
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.set_integer(vr::STOREYS, 0), ERROR);
    assert_eq!(inst.set_integer(vr::STOREYS, 3), OK);
    assert_eq!(inst.set_integer(vr::TLD_FLOOR, 5), OK);
    assert_eq!(inst.exit(), ERROR);
    assert!(
        inst.logs().iter().any(|m| m.contains("tld.floor = 5")),
        "{:?}",
        inst.logs()
    );
    assert_eq!(inst.set_integer(vr::TLD_FLOOR, 2), OK);
    // Mode 2's ratio far above mode 1's would need a negative mass coefficient.
    assert_eq!(inst.set_real(vr::DAMPING_ZETA1, 0.01), OK);
    assert_eq!(inst.set_real(vr::DAMPING_ZETA2, 0.5), OK);
    assert_eq!(inst.exit(), ERROR);
    assert!(
        inst.logs()
            .iter()
            .any(|m| m.contains("negative coefficient"))
    );
    assert_eq!(inst.set_real(vr::DAMPING_ZETA1, -0.5), OK);
    assert_eq!(inst.set_real(vr::DAMPING_ZETA2, 0.02), OK);
    assert_eq!(inst.exit(), ERROR);
    assert_eq!(inst.set_real(vr::DAMPING_ZETA1, -1.0), OK);
    assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
}

/// A state saved mid-run continues bit for bit in another instance, and a corrupted one is
/// refused.
#[test]
fn serialised_states_continue_bit_for_bit_elsewhere() {
    let drive = |inst: &mut Instance, steps: usize| {
        for _ in 0..steps {
            let t = inst.time;
            assert_eq!(inst.set_real(vr::GROUND_A, (5.0 * t).sin()), OK);
            assert_eq!(inst.set_real(vr::TLD_FORCE, 2.0 * (3.0 * t).cos()), OK);
            assert_eq!(inst.derivative(vr::GROUND_A, 1, 5.0 * (5.0 * t).cos()), OK);
            assert_eq!(inst.do_step(0.01), OK);
        }
    };
    let mut a = Instance::new("a");
    a.initialise(&three_storeys());
    drive(&mut a, 50);
    let bytes = a.serialised();
    let mut b = Instance::new("b");
    assert_eq!(b.restore(&bytes), OK, "{:?}", b.logs());
    b.time = a.time;
    drive(&mut a, 50);
    drive(&mut b, 50);
    for r in [vr::TLD_A, vr::TLD_X, vr::ROOF_X, vr::BASE_SHEAR] {
        assert_eq!(a.real(r).to_bits(), b.real(r).to_bits());
    }
    let mut bad = bytes.clone();
    bad[bytes.len() / 2] ^= 1;
    let c = Instance::new("c");
    assert_eq!(c.restore(&bad), ERROR);
    assert!(
        c.logs().iter().any(|m| m.contains("checksum")),
        "{:?}",
        c.logs()
    );
}

/// Output derivatives agree with central differences of the outputs over a ramped input, on
/// top of the built-in ground motion.
#[test]
fn output_derivatives_are_the_outputs_slopes() {
    let mut inst = Instance::new("rates");
    let mut params = three_storeys();
    params.extend([(vr::GROUND_AMPLITUDE, 0.01), (vr::GROUND_OMEGA, 6.0)]);
    inst.initialise(&params);
    for _ in 0..40 {
        let t = inst.time;
        inst.set_real(vr::GROUND_A, 0.8 * (4.0 * t).sin());
        inst.do_step(0.01);
    }
    let (slope, force_rate, dt) = (0.3, 40.0, 1e-5);
    // Every output: the damper's floor (3) and the floors below it too.
    let outputs = [
        vr::TLD_A,
        vr::TLD_V,
        vr::TLD_X,
        vr::ROOF_X,
        vr::BASE_SHEAR,
        vr::FLOOR_1__X,
        vr::FLOOR_1__X + 1,
        vr::FLOOR_1__X + 2,
        vr::FLOOR_1__A,
        vr::FLOOR_1__A + 1,
        vr::FLOOR_1__A + 2,
    ];
    let sample = |inst: &mut Instance, k: f64| {
        inst.set_real(vr::GROUND_A, slope * k * dt);
        inst.set_real(vr::TLD_FORCE, force_rate * k * dt);
        outputs.map(|r| inst.real(r))
    };
    let y0 = sample(&mut inst, 0.0);
    assert_eq!(inst.derivative(vr::GROUND_A, 1, slope), OK);
    assert_eq!(inst.derivative(vr::TLD_FORCE, 1, force_rate), OK);
    let rates = outputs.map(|r| inst.rate(r));
    assert_eq!(inst.do_step(dt), OK);
    let y1 = sample(&mut inst, 1.0);
    for k in 0..outputs.len() {
        let fd = (y1[k] - y0[k]) / dt;
        let tol = 1e-3 * rates[k].abs().max(1e-6) + 1e-3 * dt * y0[k].abs().max(1.0);
        assert!(
            (fd - rates[k]).abs() < tol.max(1e-4 * (fd.abs() + rates[k].abs())),
            "output {}: rate {} vs slope {fd}",
            outputs[k],
            rates[k]
        );
    }
    // Floor 4 of three storeys: no floor, standing still (docs/MODEL_EXCHANGE.md: the storeys
    // above `storeys` stay 0), and so are the last of the twenty.
    for r in [
        vr::FLOOR_1__X + 3,
        vr::FLOOR_1__A + 3,
        vr::FLOOR_1__X + 19,
        vr::FLOOR_1__A + 19,
    ] {
        assert_eq!((inst.real(r), inst.rate(r)), (0.0, 0.0), "output {r}");
    }
}

/// A floor's external force acts where the damper's force acts when the damper stands on that
/// floor: floor[k].force alone and tld.force alone with tld.floor = k move the building alike,
/// for each floor k of three storeys.
#[test]
fn a_floors_force_acts_on_that_floor() {
    let (f0, h) = (30.0, 0.02);
    let run = |params: &[(u32, f64)], force: u32, name: &str| {
        let mut inst = Instance::new(name);
        inst.initialise(params);
        assert_eq!(inst.set_real(force, f0), OK);
        for _ in 0..25 {
            assert_eq!(inst.do_step(h), OK);
        }
        [
            vr::FLOOR_1__X,
            vr::FLOOR_1__X + 1,
            vr::FLOOR_1__X + 2,
            vr::FLOOR_1__A + 1,
        ]
        .map(|r| inst.real(r))
    };
    for k in 1..=3 {
        let mut on_floor = three_storeys();
        on_floor.push((vr::TLD_FLOOR, f64::from(k)));
        let by_damper = run(&on_floor, vr::TLD_FORCE, &format!("damper{k}"));
        let by_floor = run(&on_floor, vr::FLOOR_1__FORCE + k - 1, &format!("floor{k}"));
        assert!(
            by_damper[0].abs() > 1e-6,
            "the run must move: {by_damper:?}"
        );
        for (d, f) in by_damper.iter().zip(&by_floor) {
            assert!(
                (d - f).abs() <= 1e-12 * d.abs().max(1e-9),
                "floor {k}: {by_damper:?} vs {by_floor:?}"
            );
        }
    }
}

/// One storey, free vibration from an initial push: the exact solution of the damped
/// oscillator, whatever the step.
#[test]
fn one_storey_free_vibration_is_the_closed_form() {
    let (m, k, zeta, f0, tp) = (168.0_f64, 5342.0_f64, 0.02, 100.0, 0.05);
    let mut inst = Instance::new("free");
    let mut params = ONE_STOREY.to_vec();
    params.push((vr::DAMPING_ZETA, zeta));
    inst.initialise(&params);
    // A constant force for tp, then nothing: response = step response minus delayed one.
    assert_eq!(inst.set_real(vr::TLD_FORCE, f0), OK);
    assert_eq!(inst.do_step(tp), OK);
    assert_eq!(inst.set_real(vr::TLD_FORCE, 0.0), OK);
    let w = (k / m).sqrt();
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let step = |t: f64| {
        if t <= 0.0 {
            return 0.0;
        }
        let e = (-zeta * w * t).exp();
        f0 / k * (1.0 - e * ((wd * t).cos() + zeta * w / wd * (wd * t).sin()))
    };
    let mut worst = 0.0_f64;
    for (n, h) in [(37, 0.013), (5, 0.21), (100, 0.001)] {
        for _ in 0..n {
            assert_eq!(inst.do_step(h), OK);
            let t = inst.time;
            let want = step(t) - step(t - tp);
            worst = worst.max((inst.real(vr::FLOOR_1__X) - want).abs());
        }
    }
    assert!(worst < 1e-13, "largest error {worst:e} m");
}

/// Exact within a step: a quadratic input over 2h in one step (value, first and second
/// derivatives) ends where two steps of h end, the second started from the polynomial's value
/// and derivatives at h; a held input likewise. Any integration error would differ between the
/// two; the exponential's rounding does not reach 1e-12.
#[test]
fn one_long_step_equals_two_short_ones_for_polynomial_inputs() {
    let (h, a0, a1, a2, f0, f1) = (0.37, 0.3, -1.1, 2.4, 5.0, -7.0);
    let outputs = [
        vr::FLOOR_1__X,
        vr::ROOF_X,
        vr::TLD_V,
        vr::TLD_X,
        vr::BASE_SHEAR,
    ];
    let run = |split: bool| {
        let mut inst = Instance::new(if split { "split" } else { "whole" });
        inst.initialise(&three_storeys());
        let drive = |inst: &mut Instance, s: f64, h: f64| {
            // ground.a = a0 + a1 t + a2 t^2/2, tld.force = f0 + f1 t, from time s
            let a = a0 + a1 * s + a2 * s * s / 2.0;
            assert_eq!(inst.set_real(vr::GROUND_A, a), OK);
            assert_eq!(inst.set_real(vr::TLD_FORCE, f0 + f1 * s), OK);
            assert_eq!(inst.derivative(vr::GROUND_A, 1, a1 + a2 * s), OK);
            assert_eq!(inst.derivative(vr::GROUND_A, 2, a2), OK);
            assert_eq!(inst.derivative(vr::TLD_FORCE, 1, f1), OK);
            assert_eq!(inst.do_step(h), OK);
        };
        if split {
            drive(&mut inst, 0.0, h);
            drive(&mut inst, h, h);
        } else {
            drive(&mut inst, 0.0, 2.0 * h);
        }
        outputs.map(|r| inst.real(r))
    };
    let (whole, split) = (run(false), run(true));
    for k in 0..outputs.len() {
        let scale = whole[k].abs().max(1e-9);
        assert!(
            (whole[k] - split[k]).abs() < 1e-12 * scale.max(1.0),
            "output {}: {} vs {}",
            outputs[k],
            whole[k],
            split[k]
        );
        assert!(whole[k].abs() > 1e-6, "the run must move: {}", whole[k]);
    }
}

/// One storey under the built-in ground motion x_g = A sin(w t) alone: the whole response from
/// rest relative to the ground (transient and steady state), in closed form, whatever the
/// step. m u'' + c u' + k u = m A w^2 sin(w t), u(0) = u'(0) = 0; the absolute outputs add the
/// ground's motion (tld.x = x_g + u, tld.v = A w cos(w t) + u') and floor[1].a = -(c u' + k u)/m.
#[test]
fn one_storey_built_in_ground_motion_is_the_closed_form() {
    let (m, k, zeta, amp, w) = (168.0_f64, 5342.0_f64, 0.02, 1e-3, 5.0);
    let mut inst = Instance::new("harmonic");
    let mut params = ONE_STOREY.to_vec();
    params.extend([
        (vr::DAMPING_ZETA, zeta),
        (vr::GROUND_AMPLITUDE, amp),
        (vr::GROUND_OMEGA, w),
    ]);
    inst.initialise(&params);
    let wn = (k / m).sqrt();
    let c = 2.0 * zeta * wn * m;
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    // particular P sin + Q cos, then the free motion that starts u, u' at 0
    let (f, d) = (m * amp * w * w, (k - m * w * w).powi(2) + (c * w).powi(2));
    let (p, q) = (f * (k - m * w * w) / d, -f * c * w / d);
    let (c1, s) = (-q, zeta * wn);
    let c2 = (s * c1 - p * w) / wd;
    let exact = |t: f64| {
        let e = (-s * t).exp();
        let (cd, sd) = ((wd * t).cos(), (wd * t).sin());
        let u = p * (w * t).sin() + q * (w * t).cos() + e * (c1 * cd + c2 * sd);
        let v = p * w * (w * t).cos() - q * w * (w * t).sin()
            + e * ((c2 * wd - s * c1) * cd - (c1 * wd + s * c2) * sd);
        [
            u,
            amp * (w * t).sin() + u,
            amp * w * (w * t).cos() + v,
            -(c * v + k * u) / m,
        ]
    };
    let outputs = [vr::FLOOR_1__X, vr::TLD_X, vr::TLD_V, vr::FLOOR_1__A];
    let mut worst = [0.0_f64; 4];
    let mut peak = [0.0_f64; 4];
    // at t = 0 the ground moves, the building stands
    let start = outputs.map(|r| inst.real(r));
    assert_eq!(start, [0.0, 0.0, amp * w, 0.0]);
    for (n, h) in [(370, 0.013), (40, 0.21), (1000, 0.001), (300, 0.05)] {
        for _ in 0..n {
            assert_eq!(inst.do_step(h), OK);
            let want = exact(inst.time);
            for (j, &r) in outputs.iter().enumerate() {
                worst[j] = worst[j].max((inst.real(r) - want[j]).abs());
                peak[j] = peak[j].max(want[j].abs());
            }
        }
    }
    for j in 0..4 {
        let rel = worst[j] / peak[j];
        eprintln!(
            "output {}: {rel:.1e} of its peak {:.4e}",
            outputs[j], peak[j]
        );
        assert!(rel < 1e-11, "output {}: {rel:e} of its peak", outputs[j]);
    }
}

/// The calculated parameters against their definitions: two equal storeys (mass m, stiffness
/// k) have omega^2 = (3 -/+ sqrt 5)/2 k/m, and the Rayleigh coefficients give each of the
/// first two modes its own ratio, zeta_i = alpha/(2 omega_i) + beta omega_i/2; one storey has
/// one mode (reported for both) damped half by the mass, half by the stiffness.
#[test]
fn calculated_parameters_are_the_modes_and_their_damping() {
    let (m, k, z1, z2) = (80.0_f64, 9000.0_f64, 0.02, 0.05);
    let calculated = |params: &[(u32, f64)], name: &str| {
        let inst = Instance::new(name);
        inst.initialise(params);
        [
            vr::MODE_1__OMEGA,
            vr::MODE_2__OMEGA,
            vr::DAMPING_ALPHA,
            vr::DAMPING_BETA,
        ]
        .map(|r| inst.real(r))
    };
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
    let [w1, w2, alpha, beta] = calculated(
        &[
            (vr::STOREYS, 2.0),
            (vr::STOREY_1__MASS, m),
            (vr::STOREY_1__MASS + 1, m),
            (vr::STOREY_1__STIFFNESS, k),
            (vr::STOREY_1__STIFFNESS + 1, k),
            (vr::DAMPING_ZETA1, z1),
            (vr::DAMPING_ZETA2, z2),
        ],
        "calculated2",
    );
    let root5 = 5.0_f64.sqrt();
    assert!(close(w1, ((3.0 - root5) / 2.0 * k / m).sqrt()), "{w1}");
    assert!(close(w2, ((3.0 + root5) / 2.0 * k / m).sqrt()), "{w2}");
    assert!(
        close(alpha / (2.0 * w1) + beta * w1 / 2.0, z1),
        "{alpha} {beta}"
    );
    assert!(
        close(alpha / (2.0 * w2) + beta * w2 / 2.0, z2),
        "{alpha} {beta}"
    );

    let (m, k, zeta) = (168.0_f64, 5342.0_f64, 0.03);
    let mut params = ONE_STOREY.to_vec();
    params.push((vr::DAMPING_ZETA, zeta));
    let [w1, w2, alpha, beta] = calculated(&params, "calculated1");
    let w = (k / m).sqrt();
    assert!(close(w1, w) && w2 == w1, "{w1} {w2}");
    assert!(close(alpha / (2.0 * w), zeta / 2.0) && close(beta * w / 2.0, zeta / 2.0));
}

/// Output derivatives of anything but an output are refused, naming it: an input, a parameter,
/// a Model Exchange local (floor[1].v, whose value reference lies above the outputs').
#[test]
fn output_derivatives_of_non_outputs_are_refused() {
    let inst = Instance::new("not-outputs");
    inst.initialise(&ONE_STOREY);
    for (r, name) in [
        (vr::GROUND_A, "ground.a"),
        (vr::STOREY_1__MASS, "storey[1].mass"),
        (vr::FLOOR_1__V, "floor[1].v"),
    ] {
        let (mut v, order) = (f64::NAN, 1);
        // SAFETY: our live instance, one value reference, order and value each.
        let s = unsafe {
            inst.lib
                .fmi2GetRealOutputDerivatives(inst.c, &r, 1, &order, &mut v)
        };
        assert_eq!(s, ERROR, "{name}");
        let said = inst.logs();
        assert_eq!(
            said.last().map(String::as_str),
            Some(format!("fmi2GetRealOutputDerivatives: '{name}' is not an output").as_str())
        );
    }
}
