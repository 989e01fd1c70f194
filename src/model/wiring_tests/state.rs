//! What the models carry besides their outputs: the integrator each `solver` item names (its
//! evaluations per step, its accuracy), the statistics of the exact steps, a saved state that
//! continues bit for bit (integrator memory and amplitude tracker included), and the messages
//! of a refused step.

use super::*;
use crate::model::StepError;
use crate::solver::SolveError;

/// Solver items (modelDescription.xml): DormandPrince45, RK4, SDIRK4, Auto, DormandPrince853,
/// RK5, RK8, ExpRK4.
const SOLVERS: [f64; 8] = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0];

fn harmonic(t: f64, w: f64) -> Inputs {
    let (s, c) = (w * t).sin_cos();
    let amplitude = 0.004;
    Inputs {
        a: -amplitude * w * w * s,
        v: amplitude * w * c,
        a_derivatives: [-amplitude * w * w * w * c, amplitude * w.powi(4) * s],
    }
}

/// The fixed-step items: h = 0.01 in internal steps of at most 0.004 is three steps of 4 (RK4,
/// ExpRK4), 6 (RK5) or 12 (RK8) evaluations; the exact steps (Linear, S^2) one step and none.
#[test]
fn every_solver_item_takes_the_steps_it_names() {
    for (solver, evaluations) in [(2.0, 4), (6.0, 6), (7.0, 12), (8.0, 4)] {
        let p = StartValues::default()
            .with(vr::SOLVER, solver)
            .with(vr::SOLVER_FIXED_STEP, 0.004)
            .with(vr::SLOSH_X0, 0.02);
        let mut sim = damper(&p);
        let r = sim.step(0.0, 0.01, &Inputs::default()).expect("step");
        assert_eq!(
            (r.stats.accepted, r.stats.rejected, r.stats.evaluations),
            (3, 0, 3 * evaluations),
            "solver {solver}"
        );
    }
    for model in [LINEAR, SLAMMING] {
        let mut sim = damper(&StartValues::default().with(vr::MODEL, model));
        let r = sim.step(
            0.0,
            0.3,
            &Inputs {
                a: 0.2,
                ..Inputs::default()
            },
        );
        let stats = r.expect("step").stats;
        assert_eq!(
            (stats.accepted, stats.rejected, stats.evaluations),
            (1, 0, 0)
        );
    }
}

/// ExpRK4 advances the linear oscillator by its exact flow: with no hardening (phi = 0) and no
/// damping it is exact where RK4 in steps of 0.05 s (omega h = 0.28) is not, against the
/// closed form cos(omega t).
#[test]
fn exponential_rk4_is_exact_on_the_linear_oscillator_and_rk4_is_not() {
    let w = natural(1).1;
    let error = |solver: f64| {
        let p = StartValues::default()
            .with(vr::SOLVER, solver)
            .with(vr::PHI, 0.0)
            .with(vr::DAMPING, CONSTANT)
            .with(vr::ZETA, 0.0)
            .with(vr::SOLVER_FIXED_STEP, 0.05)
            .with(vr::SLOSH_X0, 0.01);
        let mut sim = damper(&p);
        let mut worst: f64 = 0.0;
        for k in 0..40 {
            sim.step(f64::from(k) * 0.05, 0.05, &Inputs::default())
                .expect("step");
            let exact = 0.01 * (w * f64::from(k + 1) * 0.05).cos();
            worst = worst.max((sim.output(Output::X, &Inputs::default()) - exact).abs());
        }
        worst
    };
    let (exp, rk4) = (error(8.0), error(2.0));
    assert!(exp < 1e-13, "ExpRK4 off by {exp:e}");
    assert!(rk4 > 1e-8, "RK4 off by {rk4:e} only");
}

/// A state saved and restored continues exactly as the run it came from, every output equal to
/// the last bit: every model, every solver (the adaptive ones carry their step sizes), the
/// amplitude tracked (its filters carried too).
#[test]
fn a_restored_state_continues_bit_for_bit() {
    let mut cases: Vec<StartValues> = SOLVERS
        .iter()
        .flat_map(|&s| {
            [NONLINEAR, AUTO].map(|m| {
                StartValues::default()
                    .with(vr::MODEL, m)
                    .with(vr::SOLVER, s)
                    .with(vr::SOLVER_TOLERANCE, 1e-7)
                    .with(vr::AUTO_THRESHOLD, 1e-4)
            })
        })
        .collect();
    cases.push(
        StartValues::default()
            .with(vr::MODEL, LINEAR)
            .with(vr::MODES, 2.0),
    );
    cases.push(
        StartValues::default()
            .with(vr::MODEL, SLAMMING)
            .with(vr::SLAMMING_OMEGA, 0.9),
    );
    cases.push(
        StartValues::default()
            .with(vr::MODEL, 5.0)
            .with(vr::SWE_CELLS, 20.0),
    );
    let w = natural(1).1;
    for p in cases {
        let p = p.with(vr::SLOSH_X0, 0.01);
        let mut sim = damper(&p);
        let h = 0.05;
        for k in 0..30 {
            sim.step(f64::from(k) * h, h, &harmonic(f64::from(k) * h, w))
                .expect("step");
        }
        let mut copy = reloaded(&sim, &p);
        for k in 30..60 {
            let t = f64::from(k) * h;
            let inputs = harmonic(t, w);
            let r = sim.step(t, h, &inputs).expect("step");
            let rc = copy.step(t, h, &inputs).expect("step");
            assert_eq!(r.stats, rc.stats, "{p:?} step {k}");
            for which in OUTPUTS {
                let (a, b) = (sim.output(which, &inputs), copy.output(which, &inputs));
                assert_eq!(
                    a.to_bits(),
                    b.to_bits(),
                    "{p:?} step {k}: {which:?} {a} {b}"
                );
            }
        }
    }
}

/// A refused step says why, with its numbers.
#[test]
fn refused_steps_say_why() {
    let runaway = StepError::Runaway {
        x: 31.5,
        limit: 25.0,
    }
    .to_string();
    assert!(
        runaway.contains("3.15e1") && runaway.contains("25 m"),
        "{runaway}"
    );
    let solver = StepError::Solver(SolveError::TooManySteps { limit: 7, t: 0.5 }).to_string();
    assert_eq!(
        solver,
        SolveError::TooManySteps { limit: 7, t: 0.5 }.to_string()
    );
    assert!(!solver.is_empty());
    let chattering = StepError::Chattering("impacts without end".into()).to_string();
    assert_eq!(chattering, "impacts without end");
}
