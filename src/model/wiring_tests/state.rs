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
    // One step of 0.3 s under a held 0.2 m/s^2.
    let stats_of = |p: &StartValues| damper(p).step(0.0, 0.3, &held(0.2)).expect("step").stats;
    for model in [LINEAR, SLAMMING] {
        let stats = stats_of(&StartValues::default().with(vr::MODEL, model));
        assert_eq!(
            (stats.accepted, stats.rejected, stats.evaluations),
            (1, 0, 0)
        );
    }
    // The shallow-water substeps: MUSCL-Hancock, one flux evaluation each, taken or not.
    let p = StartValues::default()
        .with(vr::MODEL, 5.0)
        .with(vr::SWE_CELLS, 20.0);
    let stats = stats_of(&p);
    assert!(stats.accepted > 1, "{stats:?}");
    assert_eq!(stats.evaluations, stats.accepted + stats.rejected);
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
/// amplitude tracked (its filters carried too). At a tolerance of 1e-11 the adaptive solvers
/// take several steps per interval, so that the step size carried matters.
#[test]
fn a_restored_state_continues_bit_for_bit() {
    let mut cases: Vec<StartValues> = SOLVERS
        .iter()
        .flat_map(|&s| {
            [NONLINEAR, AUTO].map(|m| {
                StartValues::default()
                    .with(vr::MODEL, m)
                    .with(vr::SOLVER, s)
                    .with(vr::SOLVER_TOLERANCE, 1e-11)
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

/// The models' own limits, at and just past them: the modes the linear model carries (1 to
/// the declared maximum), the S^2 clearance (up to the tank length), the shallow-water cells
/// (2 or more, below the declared 4) and depth (h/a up to 0.3), and the shallow-water start
/// (a fundamental-mode surface at the walls below the depth).
#[test]
fn the_models_limits_hold_at_their_ends() {
    let ok = |p: &StartValues| Damper::configure(p).is_ok();
    let linear = StartValues::default().with(vr::MODEL, LINEAR);
    let most = f64::from(crate::description::limits::MODES_MAX);
    assert!(ok(&linear.clone().with(vr::MODES, 1.0)));
    assert!(ok(&linear.clone().with(vr::MODES, most)));
    assert!(!ok(&linear.clone().with(vr::MODES, 0.0)));
    assert!(!ok(&linear.clone().with(vr::MODES, most + 1.0)));
    let s2 = StartValues::default()
        .with(vr::MODEL, SLAMMING)
        .with(vr::SLAMMING_OMEGA, 0.9);
    assert!(ok(&s2.clone().with(vr::SLAMMING_CLEARANCE, A)));
    assert!(!ok(&s2
        .clone()
        .with(vr::SLAMMING_CLEARANCE, A * (1.0 + 1e-12))));
    let swe = StartValues::default().with(vr::MODEL, 5.0);
    assert!(ok(&swe.clone().with(vr::SWE_CELLS, 2.0)));
    assert!(!ok(&swe.clone().with(vr::SWE_CELLS, 1.0)));
    // h/a = 0.3 exactly (a = 0.25 m, h = 0.075 m) and just above.
    assert!(ok(&swe.clone().with(vr::TANK_DEPTH, 0.075)));
    assert!(!ok(&swe.clone().with(vr::TANK_DEPTH, 0.0751)));
    // The wall height pi^2 m_1 x0 / (2 rho b a^2) of the start against the depth.
    let reach = -surface_per_x();
    assert!(ok(&swe.clone().with(vr::SLOSH_X0, 0.99 * H / reach)));
    assert!(!ok(&swe.clone().with(vr::SLOSH_X0, 1.01 * H / reach)));
    assert!(!ok(&swe.clone().with(vr::SLOSH_X0, -1.01 * H / reach)));
}

/// A saved shallow-water state is taken only if it holds this tank's liquid: no negative depth,
/// the still volume to 1e-9.
#[test]
fn shallow_water_states_of_other_liquid_are_refused() {
    let p = StartValues::default()
        .with(vr::MODEL, 5.0)
        .with(vr::SWE_CELLS, 10.0);
    let sim = damper(&p);
    let good = sim.snapshot();
    // Depths first: move liquid from cell 0 to cell 1 (the volume kept), or add some.
    let moved = |dh: f64, extra: f64| {
        let mut s = good.clone();
        s[0] -= dh;
        s[1] += dh + extra;
        Damper::restore(&p, &s)
    };
    assert!(moved(0.5 * H, 0.0).is_ok());
    let restored = moved(H, 0.0).expect("a dry cell");
    assert!(restored.output(Output::SurfaceLeft, &Inputs::default()) < 0.0);
    assert!(moved(1.0001 * H, 0.0).is_err(), "a negative depth");
    assert!(moved(0.0, 1e-6 * H).is_err(), "more liquid");
    assert!(moved(0.0, -1e-6 * H).is_err(), "less liquid");
    assert!(moved(0.0, 1e-12 * H).is_ok(), "round-off");
}

/// A step is refused as a runaway beyond 100 tank lengths (25 m here), not before: the linear
/// model driven by a static deflection of 35 m (or 20 m) for a quarter period.
#[test]
fn a_runaway_is_a_hundred_tank_lengths() {
    let w = natural(1).1;
    let p = StartValues::default()
        .with(vr::MODEL, LINEAR)
        .with(vr::DAMPING, CONSTANT)
        .with(vr::ZETA, 0.01);
    let quarter = 0.5 * PI / w;
    let mut sim = damper(&p);
    let r = sim.step(
        0.0,
        quarter,
        &Inputs {
            a: -35.0 * w * w,
            ..Inputs::default()
        },
    );
    match r {
        Err(StepError::Runaway { x, limit }) => {
            assert_eq!(limit, 100.0 * A);
            assert!(x > 30.0 && x < 35.0, "{x}");
        }
        other => panic!("{other:?}"),
    }
    let r = sim.step(
        0.0,
        quarter,
        &Inputs {
            a: -20.0 * w * w,
            ..Inputs::default()
        },
    );
    assert!(r.expect("20 m is no runaway").implausible);
}

/// The notice of implausible motion names the numbers: above 10 g of base acceleration the
/// acceleration in g, up to 10 g (5 g, exactly 10 g) the displacement against the walls; once
/// per run. A runaway check at exactly its limit passes.
#[test]
fn notices_name_the_numbers() {
    let w = natural(1).1;
    let p = StartValues::default().with(vr::MODEL, LINEAR);
    let quarter = 0.5 * PI / w;
    let driven = || {
        let mut sim = damper(&p);
        let inputs = Inputs {
            a: -20.0 * w * w,
            ..Inputs::default()
        };
        assert!(sim.step(0.0, quarter, &inputs).expect("step").implausible);
        sim
    };
    let mut sim = driven();
    let said = sim.notice(20.0 * 9.81).expect("a notice");
    assert!(said.contains("is 20 g"), "{said}");
    assert_eq!(sim.notice(20.0 * 9.81), None);
    for a in [50.0, 10.0 * 9.81] {
        let mut sim = driven();
        let x = sim.output(Output::X, &Inputs::default());
        let said = sim.notice(a).expect("a notice");
        let expected = format!("slosh.x = {x:.3} m in a tank 0.25 m long (walls at +-0.125 m)");
        assert!(said.starts_with(&expected), "{said}");
    }
    assert!(crate::model::check_runaway(25.0, 25.0).is_ok());
    assert!(crate::model::check_runaway(-25.0, 25.0).is_ok());
    assert!(crate::model::check_runaway(25.000000000000004, 25.0).is_err());
    assert!(crate::model::check_runaway(f64::NAN, 25.0).is_err());
}

/// A shallow-water step refused (more substeps than allowed) leaves the damper as it was.
#[test]
fn a_refused_shallow_water_step_changes_nothing() {
    let p = StartValues::default()
        .with(vr::MODEL, 5.0)
        .with(vr::SWE_CELLS, 20.0)
        .with(vr::SOLVER_MAX_SUBSTEPS, 2.0)
        .with(vr::SLOSH_X0, 0.001);
    let mut sim = damper(&p);
    sim.step(0.0, 0.001, &Inputs::default())
        .expect("a short step");
    let before = sim.clone();
    assert_eq!(sim, before);
    let r = sim.step(
        0.001,
        1.0,
        &Inputs {
            a: 0.1,
            ..Inputs::default()
        },
    );
    assert!(
        matches!(r, Err(StepError::Solver(SolveError::TooManySteps { .. }))),
        "{r:?}"
    );
    assert_eq!(sim, before);
}

/// S^2's impact mass may take all the liquid the sloshing mode leaves, not more: a mass ratio
/// for which (1 + ratio) m_1 is the liquid mass to the last bit is accepted, the next one up
/// refused.
#[test]
fn slamming_mass_ratio_may_take_all_the_liquid() {
    let (m1, _) = natural(1);
    let p = StartValues::default()
        .with(vr::MODEL, SLAMMING)
        .with(vr::SLAMMING_OMEGA, 0.9);
    // The ratio near M_l/m_1 - 1 whose sloshing mass equals the liquid's exactly.
    let start = liquid() / m1 - 1.0;
    let exact = (-50..=50)
        .map(|k| f64::from_bits((start.to_bits() as i64 + k) as u64))
        .find(|r| liquid() - (m1 + r * m1) == 0.0)
        .expect("a ratio that takes all the liquid");
    let ok = |r: f64| Damper::configure(&p.clone().with(vr::SLAMMING_MASS_RATIO, r)).is_ok();
    assert!(ok(exact), "{exact}");
    assert!(!ok(exact * (1.0 + 1e-12)));
}

/// A violent impulse between steps (base.a from 0.2 to 20 m/s^2, 2 g) makes the shallow-water
/// waves faster within a substep than the CFL step taken from the speeds before it allowed:
/// substeps are taken again, and each attempt, rejected or not, costs the scheme's flux
/// evaluation.
#[test]
fn rejected_shallow_water_substeps_are_counted_and_cost_their_evaluations() {
    let p = StartValues::default()
        .with(vr::MODEL, 5.0)
        .with(vr::SWE_CELLS, 20.0);
    let mut sim = damper(&p);
    let calm = sim.step(0.0, 0.1, &held(0.2)).expect("step").stats;
    assert_eq!(calm.rejected, 0, "{calm:?}");
    let stats = sim.step(0.1, 0.1, &held(20.0)).expect("step").stats;
    assert!(stats.rejected > 0 && stats.accepted > 1, "{stats:?}");
    assert_eq!(stats.evaluations, stats.accepted + stats.rejected);
}

/// The number saved beside the pinned state layout (S^2's impact impulse): a model without
/// impacts carries 0 and refuses any other (a snapshot of another model, or corrupted), and
/// S^2 takes any finite impulse back and refuses a non-finite one.
#[test]
fn only_the_slamming_model_takes_an_impact_impulse_back() {
    // 5: ShallowWater.
    for model in [LINEAR, NONLINEAR, AUTO, 5.0] {
        let mut sim = damper(&StartValues::default().with(vr::MODEL, model));
        assert_eq!(sim.extra(), 0.0, "model {model}");
        assert_eq!(sim.load_extra(0.0), Ok(()), "model {model}");
        let refused = sim.load_extra(1e-3).expect_err("an impulse refused");
        assert!(
            refused.contains("impact impulse"),
            "model {model}: {refused}"
        );
    }
    let mut sim = damper(&StartValues::default().with(vr::MODEL, SLAMMING));
    assert_eq!(sim.load_extra(1e-3), Ok(()));
    assert_eq!(sim.extra(), 1e-3);
    assert!(sim.load_extra(f64::NAN).is_err());
}

/// A jump dv of the tank's velocity (Model Exchange's impulse from the host): the liquid keeps
/// its absolute velocity, so every velocity relative to the tank (slosh.v and the linear
/// modes' mode[n].v) drops by dv, nothing else moves, and energy.input takes the change of the
/// stored energy, which is sum_n m_n ((v_n - dv)^2 - v_n^2)/2 with Eq 2.1's modal masses.
#[test]
fn a_base_velocity_jump_shifts_every_relative_velocity() {
    use crate::model::continuous::{BANK, ENERGY_INPUT};
    let (x0, v0, dv) = (0.01, 0.02, 0.05);
    for (model, modes) in [(LINEAR, 3u32), (NONLINEAR, 1)] {
        let p = StartValues::default()
            .with(vr::MODEL, model)
            .with(vr::MODES, f64::from(modes))
            .with(vr::SLOSH_X0, x0)
            .with(vr::SLOSH_V0, v0);
        let mut sim = damper(&p);
        let none = Inputs::default();
        let (before, stored) = (
            sim.continuous_states(),
            sim.output(Output::EnergyStored, &none),
        );
        assert_eq!(sim.base_velocity_jump(dv), Ok(true));
        let after = sim.continuous_states();
        let mut velocities = vec![1];
        velocities.extend((1..modes as usize).map(|k| BANK + 2 * k - 1));
        let mut want = 0.5 * natural(1).0 * ((v0 - dv).powi(2) - v0 * v0);
        for n in 2..=modes {
            want += 0.5 * natural(n).0 * dv * dv;
        }
        let gained = sim.output(Output::EnergyStored, &none) - stored;
        assert!(
            (gained - want).abs() < 1e-9 * want.abs(),
            "model {model}: {gained} for {want}"
        );
        for (k, (b, a)) in before.iter().zip(&after).enumerate() {
            let moved = if velocities.contains(&k) {
                -dv
            } else if k == ENERGY_INPUT {
                want
            } else {
                0.0
            };
            assert!(
                (a - b - moved).abs() < 1e-12,
                "model {model}, state {k}: {b} to {a}"
            );
        }
    }
}

/// An enumeration's value that is no item of it is refused with the variable's name
/// (FMU.md's: model, solver).
#[test]
fn an_enumeration_out_of_range_is_named() {
    for (vr, name) in [(vr::MODEL, "model"), (vr::SOLVER, "solver")] {
        let p = StartValues::default().with(vr, 99.0);
        let refused = Damper::configure(&p).map(|_| ()).expect_err("99 refused");
        assert!(
            refused.contains(&format!("99 is no item of '{name}'")),
            "{refused}"
        );
    }
}
