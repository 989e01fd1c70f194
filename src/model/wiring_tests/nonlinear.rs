//! Model = Nonlinear and model = Auto against a tiny-step RK4 of Eq 2.11 with the power law of
//! Eq 2.13, written here, whose own error a Richardson check (the same run at twice the
//! substeps) bounds.

use super::*;

/// Eq 2.11 per unit sloshing mass: x'' = -a_b - c x' - Phi(x), Phi(x) = w^2 x (1 + phi |2x/a|^(2
/// eta - 2)), and the work of the base and the dissipation along.
#[derive(Clone, Copy, Debug)]
struct Law {
    w: f64,
    phi: f64,
    eta: f64,
}

impl Law {
    fn hardening(&self, x: f64) -> f64 {
        self.phi * (2.0 * x / A).abs().powf(2.0 * self.eta - 2.0)
    }

    fn phi_of(&self, x: f64) -> f64 {
        self.w * self.w * x * (1.0 + self.hardening(x))
    }

    fn slope(&self, x: f64) -> f64 {
        self.w * self.w * (1.0 + (2.0 * self.eta - 1.0) * self.hardening(x))
    }

    fn potential(&self, x: f64) -> f64 {
        0.5 * self.w * self.w * x * x * (1.0 + self.hardening(x) / self.eta)
    }

    /// [x, v, work, dissipated]' at s into a step with input a0 + a1 s + a2 s^2/2.
    fn rhs(&self, c: f64, a: [f64; 3], s: f64, y: [f64; 4]) -> [f64; 4] {
        let ab = a[0] + s * a[1] + 0.5 * s * s * a[2];
        let v = y[1];
        [v, -ab - c * v - self.phi_of(y[0]), -ab * v, c * v * v]
    }

    /// `y` advanced by `h` in `n` classical RK4 steps.
    fn rk4(&self, c: f64, a: [f64; 3], h: f64, n: u32, mut y: [f64; 4]) -> [f64; 4] {
        let dt = h / f64::from(n);
        let add = |y: [f64; 4], k: [f64; 4], f: f64| std::array::from_fn(|i| y[i] + f * k[i]);
        for i in 0..n {
            let s = f64::from(i) * dt;
            let k1 = self.rhs(c, a, s, y);
            let k2 = self.rhs(c, a, s + 0.5 * dt, add(y, k1, 0.5 * dt));
            let k3 = self.rhs(c, a, s + 0.5 * dt, add(y, k2, 0.5 * dt));
            let k4 = self.rhs(c, a, s + dt, add(y, k3, dt));
            y = std::array::from_fn(|j| y[j] + dt / 6.0 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]));
        }
        y
    }
}

/// The run's steps: (length, input a, its first and second derivatives).
type Steps = Vec<(f64, [f64; 3])>;

/// The reference states after each step, from (x0, v0), at `n` RK4 substeps per step; checked
/// against the same at 2n: the difference (15 times the finer run's error) must be below
/// `tol` / 10 of the largest |x|.
fn reference(law: Law, c: f64, x0: f64, v0: f64, steps: &Steps, n: u32, tol: f64) -> Vec<[f64; 4]> {
    let run = |n| {
        let mut y = [x0, v0, 0.0, 0.0];
        steps
            .iter()
            .map(|(h, a)| {
                y = law.rk4(c, *a, *h, n, y);
                y
            })
            .collect::<Vec<_>>()
    };
    let (coarse, fine) = (run(n), run(2 * n));
    let largest = fine.iter().map(|y| y[0].abs()).fold(0.0, f64::max);
    let diff = coarse
        .iter()
        .zip(&fine)
        .map(|(c, f)| (c[0] - f[0]).abs())
        .fold(0.0, f64::max);
    assert!(
        diff < 0.1 * tol * largest,
        "reference not converged: {diff:e}"
    );
    fine
}

/// Harmonic base motion near resonance, its derivatives given, in steps of 0.02 s; then held.
fn harmonic_steps(w: f64, amplitude: f64, count: u32) -> Steps {
    let h = 0.02;
    (0..count)
        .map(|k| {
            let t = f64::from(k) * h;
            let (s, c) = (w * t).sin_cos();
            let w2 = w * w;
            (
                h,
                [
                    -amplitude * w2 * s,
                    -amplitude * w2 * w * c,
                    amplitude * w2 * w2 * s,
                ],
            )
        })
        .collect()
}

/// The input a0 + a1 s + a2 s^2/2 over a step.
fn polynomial(a: &[f64; 3]) -> Inputs {
    Inputs {
        a: a[0],
        a_derivatives: [a[1], a[2]],
        ..Inputs::default()
    }
}

/// Run `p` over `steps` and compare every output and rate with the reference of `law`.
fn compare_run(p: &StartValues, law: Law, tanks: f64, a_e: f64, steps: &Steps, what: &str) {
    let mut sim = damper(p);
    let (x0, v0) = (0.03, 0.05);
    let zeta = nsd_zeta(a_e);
    let c = 2.0 * zeta * law.w;
    let mass = natural(1).0 * tanks;
    let inactive = liquid() * tanks - mass;
    let initial = mass * (0.5 * v0 * v0 + law.potential(x0));
    let refs = reference(law, c, x0, v0, steps, 40, 1e-8);
    let surface = surface_per_x();
    // Every output and rate at the state [x, v, work, dissipated], with the mean force of the
    // last step, read under the input `read`.
    let expected = |y: [f64; 4], mean: f64, read: &Inputs| {
        let [x, v, work, dissipated] = y;
        let force = mass * (c * v + law.phi_of(x));
        let mut e = Expected::default();
        for (which, value) in [
            (Output::Force, force),
            (Output::X, x),
            (Output::V, v),
            (Output::ForceMean, mean),
            (Output::BaseShear, force - inactive * read.a),
            (Output::EnergyInput, initial + mass * work),
            (Output::EnergyDissipated, mass * dissipated),
            (
                Output::EnergyStored,
                mass * (0.5 * v * v + law.potential(x)),
            ),
            (Output::Amplitude, a_e),
            (Output::Zeta, zeta),
            (Output::SurfaceLeft, surface * x),
            (Output::SurfaceRight, -surface * x),
        ] {
            e.set(which, value);
        }
        let acc = -read.a - c * v - law.phi_of(x);
        let rate_force = mass * (c * acc + law.slope(x) * v);
        let mut rates = [0.0; 14];
        for (which, value) in [
            (Output::Force, rate_force),
            (Output::X, v),
            (Output::V, acc),
            (
                Output::BaseShear,
                rate_force - inactive * read.a_derivatives[0],
            ),
            (Output::EnergyInput, -mass * read.a * v),
            (Output::EnergyDissipated, mass * c * v * v),
            (Output::EnergyStored, mass * v * (acc + law.phi_of(x))),
            (Output::SurfaceLeft, surface * v),
            (Output::SurfaceRight, -surface * v),
        ] {
            rates[index(which)] = value;
        }
        e.rates = Some(rates);
        e
    };
    let mut history = History::new(what);
    // Before any step: the initial state, the force as the mean force.
    let read = Inputs {
        a: 0.3,
        a_derivatives: [-1.3, 0.0],
        ..Inputs::default()
    };
    let force0 = mass * (c * v0 + law.phi_of(x0));
    history.compare(&sim, &read, &expected([x0, v0, 0.0, 0.0], force0, &read));
    let mut t = 0.0;
    let mut v_before = v0;
    for (k, ((h, a), y)) in steps.iter().zip(&refs).enumerate() {
        let inputs = polynomial(a);
        sim.step(t, *h, &inputs).expect("step");
        t += h;
        let v = y[1];
        let integral = h * (a[0] + h * (0.5 * a[1] + h * a[2] / 6.0));
        let impulse = mass * (-(v - v_before) - integral);
        v_before = v;
        let read = Inputs {
            a: 0.3 - a[0],
            a_derivatives: [-1.3, 0.0],
            ..Inputs::default()
        };
        let e = expected(*y, impulse / h, &read);
        history.compare(&sim, &read, &e);
        if k == steps.len() / 2 {
            sim = reloaded(&sim, p);
            history.compare(&sim, &read, &e);
        }
    }
    history.assert(1e-8);
}

fn nonlinear_parameters(model: f64, eta: f64, tanks: f64, a_e: f64) -> StartValues {
    StartValues::default()
        .with(vr::MODEL, model)
        .with(vr::ETA, eta)
        .with(vr::PHI, 1.0)
        .with(vr::TANKS, tanks)
        .with(vr::AMPLITUDE, FIXED)
        .with(vr::A_E, a_e)
        .with(vr::SOLVER, DOP853)
        .with(vr::SOLVER_TOLERANCE, 1e-12)
        .with(vr::SLOSH_X0, 0.03)
        .with(vr::SLOSH_V0, 0.05)
}

/// Model = Nonlinear, integer and real exponents, several tanks: every output and rate.
#[test]
fn nonlinear_outputs_are_the_reference_integration() {
    let w = natural(1).1;
    for (eta, tanks) in [(2.0, 2.0), (1.7, 1.0)] {
        let a_e = 0.001;
        let p = nonlinear_parameters(NONLINEAR, eta, tanks, a_e);
        let law = Law { w, phi: 1.0, eta };
        let steps = harmonic_steps(1.05 * w, 0.004, 400);
        compare_run(&p, law, tanks, a_e, &steps, &format!("Nonlinear eta {eta}"));
    }
}

/// Model = Auto with a threshold the exact linear step can meet: on the same run it is the
/// nonlinear model (its shortcut must be refused wherever the hardening matters).
#[test]
fn auto_outputs_are_the_reference_integration() {
    let w = natural(1).1;
    let a_e = 0.001;
    let law = Law {
        w,
        phi: 1.0,
        eta: 2.0,
    };
    let steps = harmonic_steps(1.05 * w, 0.004, 400);
    // 0: the solver's tolerance.
    for threshold in [1e-9, 0.0] {
        let p = nonlinear_parameters(AUTO, 2.0, 1.0, a_e).with(vr::AUTO_THRESHOLD, threshold);
        compare_run(&p, law, 1.0, a_e, &steps, &format!("Auto {threshold}"));
    }
}

/// Model = Auto's exact linear step: taken (no evaluation of the equation) where the hardening
/// stays far below the threshold over the step, and refused wherever it reaches the threshold
/// (over the reference trajectory, sampled at its 400 substeps): from rest under a held input,
/// a ramp, a parabola, or an input whose terms cancel at the step's end; through the centre
/// fast; with a free oscillation and an input whose deflections cancel; a step of 2/omega_f
/// (the static deflection 2/omega^2 equal to h/omega); and a small input just above the
/// threshold; a 10 s step under a slow parabola; a free amplitude of 1 m. The state after every
/// step is the nonlinear one: x, v, force.
#[test]
fn auto_takes_the_linear_step_only_where_the_hardening_is_small() {
    let w = natural(1).1;
    let a_e = 0.001;
    let threshold = 1e-6;
    let p = nonlinear_parameters(AUTO, 2.0, 1.0, a_e).with(vr::AUTO_THRESHOLD, threshold);
    let law = Law {
        w,
        phi: 1.0,
        eta: 2.0,
    };
    let c = 2.0 * nsd_zeta(a_e) * w;
    let mass = natural(1).0;
    // (x0, v0, step, input): the hardening phi (2|x|/a)^2 reaches 1e-6 at |x| = 1.25e-4 m.
    let cases: [(f64, f64, f64, [f64; 3]); 15] = [
        (1e-5, 0.0, 0.05, [1e-4, 0.0, 0.0]),
        (0.0, 1e-5 * w, 0.05, [0.0, 0.0, 0.0]),
        (-1e-5, 0.0, 0.05, [0.0, 1e-3, 0.0]),
        (0.0, 0.0, 0.4, [1.0, 0.0, 0.0]),
        (0.0, 0.0, 0.4, [0.0, 5.0, 0.0]),
        (0.0, 0.0, 0.4, [0.0, 0.0, 40.0]),
        (0.0, 0.0, 0.4, [1.0, -2.5, 0.0]),
        (0.0, 0.0, 0.4, [0.0, 2.0, -10.0]),
        (0.0, 0.1, 0.1, [0.0, 0.0, 0.0]),
        (0.02, 0.02 * w, 0.05, [0.0, 0.0, 0.0]),
        (0.03, 0.0, 0.1, [-0.373, 0.0, 0.0]),
        (0.0, 0.0, 2.0 / w, [1.0, 0.0, 0.0]),
        (0.0, 0.0, 0.4, [0.0039, 0.0, 0.0]),
        // A 10 s step under a slow parabola: the input's bound must grow as h^2.
        (0.0, 0.0, 10.0, [0.0, 0.0, 1.1e-4]),
        // A free amplitude just above 1 m (v0 a hair above w_f): refused. (v0 % w_f for
        // v0 / w_f would read it as 1e-9 m.)
        (0.0, w * (1.0 + 1e-9), 0.05, [0.0, 0.0, 0.0]),
    ];
    for (x0, v0, h, a) in cases {
        let q = p.clone().with(vr::SLOSH_X0, x0).with(vr::SLOSH_V0, v0);
        let mut sim = damper(&q);
        let inputs = polynomial(&a);
        let report = sim.step(0.0, h, &inputs).expect("step");
        // The largest hardening over the step, from the reference trajectory.
        let n = 400;
        let mut y = [x0, v0, 0.0, 0.0];
        let mut largest = law.hardening(x0);
        for k in 0..n {
            let s = h * f64::from(k) / f64::from(n);
            let shifted = [a[0] + s * (a[1] + 0.5 * s * a[2]), a[1] + s * a[2], a[2]];
            // RK4 steps of at most 1 ms.
            let m = (h / f64::from(n) / 1e-3).ceil().max(4.0) as u32;
            y = law.rk4(c, shifted, h / f64::from(n), m, y);
            largest = largest.max(law.hardening(y[0]));
        }
        let what =
            format!("x0 {x0} v0 {v0} h {h} a {a:?}: hardening up to {largest:e}, {report:?}");
        let linear = report.stats.evaluations == 0;
        if linear {
            assert_eq!(
                (report.stats.accepted, report.stats.rejected),
                (1, 0),
                "{what}"
            );
            assert!(largest < 0.1 * threshold, "{what}: linear step taken");
        } else {
            assert!(largest > threshold, "{what}: linear step refused");
        }
        // The linear step is exact for the linear equation; the hardening it leaves out is
        // below 1e-7 there, so its error is that small a fraction.
        let tol = if linear { 1e-6 } else { 1e-8 };
        let [x, v, ..] = y;
        let out = |o| sim.output(o, &inputs);
        let xs = x.abs().max(1e-5);
        assert!((out(Output::X) - x).abs() <= tol * xs, "{what}: x {x}");
        assert!((out(Output::V) - v).abs() <= tol * xs * w, "{what}: v {v}");
        let force = mass * (c * v + law.phi_of(x));
        let fs = mass * w * w * xs;
        assert!(
            (out(Output::Force) - force).abs() <= tol * fs,
            "{what}: force {force}"
        );
    }
}

/// Model = Nonlinear's error control: the adaptive solver holds its error to solver.tolerance
/// times the scale half a tank length (docs/MODEL.md: the error norm rtol (a/2 + |x|)), so at a
/// moderate tolerance its error over a whole run of free sloshing (steps of 1 s, many solver
/// steps each) against the tiny-step RK4 must be a small multiple of rtol (a/2 + |x|max), and
/// not far below it (the test would then not see the scale).
#[test]
fn nonlinear_error_is_a_small_multiple_of_the_tolerance_at_half_the_tank() {
    let w = natural(1).1;
    let (a_e, rtol) = (0.001, 1e-6);
    let law = Law {
        w,
        phi: 1.0,
        eta: 2.0,
    };
    let c = 2.0 * nsd_zeta(a_e) * w;
    let (x0, v0) = (0.05, 0.0);
    // Free sloshing in steps of 1 s (about one period): the solver takes many steps in each.
    let steps: Steps = vec![(1.0, [0.0; 3]); 8];
    let refs = reference(law, c, x0, v0, &steps, 2000, 1e-6);
    let p = nonlinear_parameters(NONLINEAR, 2.0, 1.0, a_e)
        .with(vr::SOLVER_TOLERANCE, rtol)
        .with(vr::SLOSH_X0, x0)
        .with(vr::SLOSH_V0, v0);
    let mut sim = damper(&p);
    let (mut t, mut err, mut largest) = (0.0, 0.0_f64, x0.abs());
    for ((h, a), y) in steps.iter().zip(&refs) {
        let inputs = polynomial(a);
        sim.step(t, *h, &inputs).expect("step");
        t += h;
        err = err.max((sim.output(Output::X, &inputs) - y[0]).abs());
        largest = largest.max(y[0].abs());
    }
    let scale = rtol * (0.5 * A + largest);
    // Measured: 0.92 rtol (a/2 + |x|max); with the scale a/2 made 2 m (16 times looser), 8.1.
    assert!(
        err <= 2.0 * scale,
        "error {err:e} for rtol (a/2 + |x|) = {scale:e}"
    );
    assert!(
        err >= 0.05 * scale,
        "error {err:e}: the run does not exercise the error control"
    );
}

/// Model = Auto in a long tank (a = 10 m, h = 1 m: omega_f 0.97 rad/s, where the bound's
/// static-deflection term 2/omega_f^2 is larger than h/omega_f's step terms): near-resonant
/// forcing grows the slosh through the threshold's amplitude (hardening 1e-6 at |x| = 5 mm),
/// so Auto takes the exact linear step early and the integrator late; every step is the
/// Nonlinear model's (DOP853 at 1e-12) to a small multiple of the threshold (1.3e-9 of the
/// 1.6e-7 allowed seen; 53 steps of 300 linear).
#[test]
fn auto_in_a_long_tank_is_the_nonlinear_model() {
    let (a, depth, threshold) = (10.0, 1.0, 1e-6);
    let w = (G * PI * (PI * depth / a).tanh() / a).sqrt();
    let long = |model| {
        nonlinear_parameters(model, 2.0, 1.0, 0.0)
            .with(vr::TANK_LENGTH, a)
            .with(vr::TANK_BREADTH, 1.0)
            .with(vr::TANK_DEPTH, depth)
            .with(vr::DAMPING, CONSTANT)
            .with(vr::ZETA, 0.02)
            .with(vr::AUTO_THRESHOLD, threshold)
            .with(vr::SLOSH_X0, 0.001)
            .with(vr::SLOSH_V0, 0.0)
    };
    let (mut auto, mut nonlinear) = (damper(&long(AUTO)), damper(&long(NONLINEAR)));
    let (h, d) = (0.1, 1.5e-3);
    let (mut t, mut linear, mut refused) = (0.0, 0, 0);
    let (mut err, mut largest) = (0.0_f64, 0.0_f64);
    for _ in 0..300 {
        let (s, c) = (w * t).sin_cos();
        let w2 = w * w;
        let inputs = Inputs {
            a: -d * w2 * s,
            a_derivatives: [-d * w2 * w * c, d * w2 * w2 * s],
            ..Inputs::default()
        };
        let before = nonlinear.output(Output::X, &inputs);
        let report = auto.step(t, h, &inputs).expect("Auto");
        nonlinear.step(t, h, &inputs).expect("Nonlinear");
        t += h;
        let x = nonlinear.output(Output::X, &inputs);
        if report.stats.evaluations == 0 {
            linear += 1;
            // The hardening phi (2x/a)^2 at both ends of a linear step below the threshold.
            let hardening = (2.0 * before.abs().max(x.abs()) / a).powi(2);
            assert!(hardening < threshold, "linear step at t {t}: {hardening:e}");
        } else {
            refused += 1;
        }
        err = err.max((auto.output(Output::X, &inputs) - x).abs());
        largest = largest.max(x.abs());
    }
    assert!(
        linear > 10 && refused > 10,
        "{linear} linear, {refused} not"
    );
    assert!(
        largest > 0.01,
        "the slosh {largest:e} m stays below the threshold's"
    );
    assert!(
        err <= 10.0 * threshold * largest,
        "x off by {err:e} of {largest:e}"
    );
}
