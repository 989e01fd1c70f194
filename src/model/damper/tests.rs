use super::*;
use crate::description::{Causality, VARIABLES, VarType};
use crate::model::StartValues;
use crate::solver::SolveError;

mod screens;

/// Items of the enumerations (modelDescription.xml) the tests select.
const LINEAR: f64 = 1.0;
const NONLINEAR: f64 = 2.0;
const SLAMMING: f64 = 3.0;
const AUTO: f64 = 4.0;
const SHALLOW_WATER: f64 = 5.0;
const CONSTANT: f64 = 1.0;
const BOUNDARY_LAYER: f64 = 3.0;
const SCREENS: f64 = 4.0;
const TRACKED: f64 = 2.0;
/// Solver items: DormandPrince45, RK4, SDIRK4, Auto, DormandPrince853, RK5, RK8, ExpRK4.
const SOLVERS: [f64; 8] = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0];
const RK4: f64 = 2.0;
const EXP_RK4: f64 = 8.0;

/// The model description's defaults: Nonlinear, the Table 2.1 tank, NSD damping at a fixed
/// 5 mm, Dormand-Prince 5(4) at 1e-10.
fn defaults() -> StartValues {
    StartValues::default()
}

fn damper(p: &StartValues) -> Damper {
    Damper::configure(p).expect("configuration").0
}

/// The S^2 model the tests run: Omega 0.9, a 0.1 m clearance.
fn slamming(p: StartValues) -> StartValues {
    p.with(vr::MODEL, SLAMMING)
        .with(vr::SLAMMING_OMEGA, 0.9)
        .with(vr::SLAMMING_RESTITUTION, 0.4)
        .with(vr::SLAMMING_CLEARANCE, 0.1)
        .with(vr::SLAMMING_MASS_RATIO, 0.01)
}

fn tracked(p: StartValues) -> StartValues {
    p.with(vr::AMPLITUDE, TRACKED)
        .with(vr::AMPLITUDE_TAU, 0.0)
        .with(vr::A_E, 0.005)
}

fn held(a: f64) -> Inputs {
    Inputs {
        a,
        ..Inputs::default()
    }
}

/// Free decay of the linear limit against the closed-form damped oscillation.
#[test]
fn linear_free_decay_matches_closed_form() {
    let p = defaults()
        .with(vr::ETA, 1.0)
        .with(vr::PHI, 0.0)
        .with(vr::DAMPING, CONSTANT)
        .with(vr::ZETA, 0.02)
        .with(vr::SLOSH_X0, 0.01);
    let mut sim = damper(&p);
    let w = sim.derived().omega_f;
    let wd = w * (1.0 - 0.02f64 * 0.02).sqrt();
    let h = 0.01;
    let mut worst: f64 = 0.0;
    for k in 0..2000 {
        sim.step(k as f64 * h, h, &Inputs::default()).expect("step");
        let t = (k + 1) as f64 * h;
        let exact =
            0.01 * (-0.02 * w * t).exp() * ((wd * t).cos() + 0.02 * w / wd * (wd * t).sin());
        worst = worst.max((sim.output(Output::X, &Inputs::default()) - exact).abs());
    }
    assert!(worst < 1e-8 * 0.01, "worst error {worst}");
}

/// energy.input = energy.stored + energy.dissipated, and dissipation never decreases.
#[test]
fn energy_balance_under_harmonic_forcing() {
    let mut sim = damper(&defaults().with(vr::SLOSH_X0, 0.02));
    let w = 1.1 * sim.derived().omega_f;
    let mut last_dissipated = 0.0;
    let h = 0.005;
    for k in 0..4000 {
        let t = k as f64 * h;
        let inputs = held(-w * w * 0.005 * (w * t).sin());
        sim.step(t, h, &inputs).expect("step");
        let e = |w| sim.output(w, &inputs);
        let (input, stored, dissipated) = (
            e(Output::EnergyInput),
            e(Output::EnergyStored),
            e(Output::EnergyDissipated),
        );
        let residual = (input - stored - dissipated).abs();
        assert!(
            residual < 1e-8 * input.abs().max(1e-6),
            "step {k}: residual {residual}"
        );
        assert!(dissipated >= last_dissipated);
        last_dissipated = dissipated;
    }
    assert!(last_dissipated > 0.0);
}

#[test]
fn a_refused_step_changes_nothing() {
    let p = defaults()
        .with(vr::SOLVER_MAX_SUBSTEPS, 3.0)
        .with(vr::SLOSH_X0, 0.05);
    let mut sim = damper(&p);
    let before = sim.clone();
    let r = sim.step(0.0, 50.0, &held(1.0));
    assert!(
        matches!(r, Err(StepError::Solver(SolveError::TooManySteps { .. }))),
        "{r:?}"
    );
    assert_eq!(sim, before);
}

/// A step whose displacement leaves every physical range is refused after a successful
/// integration, or the exact linear step of model = Auto; the state and the integrator's carried
/// step size stay as they were.
#[test]
fn a_runaway_step_changes_nothing() {
    for solver in SOLVERS {
        // With phi = 0 the Auto model never leaves its exact linear step.
        for model in [NONLINEAR, AUTO] {
            // Linear (phi = 0), so that a huge input is integrated without trouble.
            let p = defaults()
                .with(vr::MODEL, model)
                .with(vr::PHI, 0.0)
                .with(vr::SOLVER, solver)
                .with(vr::SOLVER_TOLERANCE, 1e-8)
                .with(vr::SOLVER_FIXED_STEP, 0.01);
            let mut sim = damper(&p);
            sim.step(0.0, 0.013, &held(0.3)).expect("an ordinary step");
            let before = sim.clone();
            let r = sim.step(0.013, 0.1, &held(-1e9));
            assert!(
                matches!(r, Err(StepError::Runaway { .. })),
                "model {model} solver {solver}: {r:?}"
            );
            assert_eq!(sim, before, "model {model} solver {solver}");
            sim.step(0.013, 0.01, &held(0.3)).expect("usable after");
        }
    }
}

/// The force kept with the state is the state's force, bit for bit: from the start, after every
/// step (the damping moving with a tracked amplitude), a refused step and a restore, for every
/// model, kind of exponent and path through the step.
#[test]
fn the_force_kept_with_the_state_is_the_states_force() {
    let mut cases = vec![];
    for eta in [1.0, 1.5, 2.0, 2.5, 3.0, 5.0] {
        cases.push(defaults().with(vr::ETA, eta));
    }
    for solver in [RK4, EXP_RK4] {
        cases.push(
            defaults()
                .with(vr::SOLVER, solver)
                .with(vr::SOLVER_FIXED_STEP, 0.004),
        );
    }
    // Below the threshold (the exact linear step) while the motion is small, above it later.
    let auto = defaults()
        .with(vr::MODEL, AUTO)
        .with(vr::AUTO_THRESHOLD, 0.1);
    cases.push(auto.clone());
    cases.push(defaults().with(vr::MODEL, LINEAR).with(vr::MODES, 3.0));
    cases.push(slamming(defaults()));
    cases.push(
        defaults()
            .with(vr::MODEL, SHALLOW_WATER)
            .with(vr::SWE_CELLS, 20.0),
    );
    for case in cases {
        let p = tracked(case).with(vr::SLOSH_X0, 0.02);
        let same = |sim: &Damper, when: &str| {
            let kept = sim.output(Output::Force, &Inputs::default());
            let state = sim.model.force();
            assert_eq!(
                kept.to_bits(),
                state.to_bits(),
                "{p:?}, {when}: {kept} vs {state}"
            );
            assert_ne!(kept, 0.0, "{p:?}: a state with a force");
            // x and v: the (first) sloshing mode's, first in the snapshot of the mechanical
            // models (the shallow-water model's x and v are moments of its cells).
            let snapshot = sim.snapshot();
            let (x, v) = sim.model.sloshing();
            assert_eq!(sim.per_step[1..3], [x, v], "{p:?}, {when}");
            let mechanical = !matches!(sim.model, AnyModel::ShallowWater(_));
            for (which, k) in [(Output::X, 0), (Output::V, 1)]
                .into_iter()
                .filter(|_| mechanical)
            {
                let got = sim.output(which, &Inputs::default());
                assert_eq!(got.to_bits(), snapshot[k].to_bits(), "{p:?} {which:?}");
            }
        };
        let mut sim = damper(&p);
        same(&sim, "start");
        let mut zetas = vec![];
        let mut linear_steps = 0;
        for k in 0..300 {
            let t = f64::from(k) * 0.01;
            let inputs = Inputs {
                a: 0.3 * (5.6 * t).sin(),
                v: -0.3 / 5.6 * (5.6 * t).cos(),
                ..Inputs::default()
            };
            let stats = sim.step(t, 0.01, &inputs).expect("step").stats;
            same(&sim, &format!("step {k}"));
            zetas.push(sim.zeta);
            // The exact linear step of model = Auto evaluates nothing.
            linear_steps += usize::from(stats.evaluations == 0);
        }
        if p == tracked(auto.clone()).with(vr::SLOSH_X0, 0.02) {
            assert!(
                linear_steps > 0 && linear_steps < 300,
                "Auto: both kinds of step ({linear_steps} linear)"
            );
        }
        assert_ne!(zetas[299], zetas[298], "{p:?}: the damping moves");
        let refused = sim.step(3.0, 0.1, &held(-1e300));
        assert!(refused.is_err(), "{p:?}: {refused:?}");
        same(&sim, "a refused step");
        let restored = Damper::restore(&p, &sim.snapshot()).expect("restore");
        same(&restored, "restored");
        assert_eq!(restored.force().to_bits(), sim.force().to_bits());
    }
}

/// The shortest step there is (h = 5e-324, 1/h = inf) is taken, every output stays finite, and
/// the damper goes on; for every model.
#[test]
fn a_subnormal_step_gives_finite_outputs() {
    for case in [
        defaults(),
        defaults()
            .with(vr::SOLVER, RK4)
            .with(vr::SOLVER_FIXED_STEP, 0.01),
        defaults().with(vr::MODEL, AUTO),
        defaults().with(vr::MODEL, LINEAR).with(vr::MODES, 2.0),
        slamming(defaults()),
        defaults().with(vr::MODEL, SHALLOW_WATER),
    ] {
        let p = case.with(vr::SLOSH_X0, 0.02).with(vr::SLOSH_V0, 0.1);
        let mut sim = damper(&p);
        let inputs = held(0.3);
        sim.step(0.0, 5e-324, &inputs).expect("a subnormal step");
        for which in crate::model::wiring_tests::OUTPUTS {
            let value = sim.output(which, &inputs);
            assert!(value.is_finite(), "{p:?} {which:?}: {value}");
        }
        sim.step(5e-324, 0.01, &inputs)
            .expect("an ordinary step after");
    }
}

/// force.mean: the force before the first step (the state's flag 0), the step's impulse over
/// its length after one, the force after a step too short for a mean; the same bits restored.
#[test]
fn the_mean_force_is_formed_when_read_and_kept_with_the_state() {
    for case in [defaults(), defaults().with(vr::MODEL, SHALLOW_WATER)] {
        let p = case.with(vr::SLOSH_X0, 0.02);
        let mut sim = damper(&p);
        let flag = sim.model.state_len() + 1;
        let mean = |sim: &Damper| sim.output(Output::ForceMean, &held(0.3)).to_bits();
        assert_eq!(sim.snapshot()[flag..flag + 2], [0.0, 0.0], "{p:?}");
        assert_eq!(mean(&sim), sim.force().to_bits(), "{p:?}: no step yet");
        let x0 = sim.model.sloshing().0;
        sim.step(0.0, 0.01, &held(0.3)).expect("step");
        assert_ne!(
            mean(&sim),
            sim.force().to_bits(),
            "{p:?}: a mean, not the end's force"
        );
        let (x1, f1) = (sim.model.sloshing().0, f64::from_bits(mean(&sim)));
        // The mean force moves the sloshing mass the way the force does (opposite in sign).
        assert!(f1 * (x1 - x0) < 0.0, "{p:?}: {f1} {x0} {x1}");
        let restored = Damper::restore(&p, &sim.snapshot()).expect("restore");
        assert_eq!(sim.snapshot()[flag..flag + 2], [1.0, f1], "{p:?}");
        assert_eq!(mean(&restored), mean(&sim), "{p:?}: restored");
        sim.step(0.01, 5e-324, &held(0.3))
            .expect("a subnormal step");
        assert_eq!(
            mean(&sim),
            sim.force().to_bits(),
            "{p:?}: too short for a mean"
        );
    }
}

#[test]
fn a_restored_state_has_the_damping_of_its_last_step() {
    // Tracked amplitude: the damping moves with every step, and the output derivatives read it
    // from the model; a restored damper must give the same ones as the original.
    for case in [
        defaults(),
        defaults().with(vr::MODEL, LINEAR).with(vr::MODES, 2.0),
        slamming(defaults()),
        defaults()
            .with(vr::MODEL, SHALLOW_WATER)
            .with(vr::SWE_CELLS, 20.0),
    ] {
        let p = tracked(case);
        let mut sim = damper(&p);
        let zeta0 = sim.zeta;
        for k in 0..400 {
            let t = f64::from(k) * 0.01;
            let inputs = Inputs {
                a: 0.5 * (5.6 * t).sin(),
                v: -0.5 / 5.6 * (5.6 * t).cos(),
                ..Inputs::default()
            };
            sim.step(t, 0.01, &inputs).expect("step");
        }
        assert!(
            (sim.zeta - zeta0).abs() > 1e-4 * zeta0,
            "{p:?}: the damping moved"
        );
        let restored = Damper::restore(&p, &sim.snapshot()).expect("restore");
        for which in [Output::Force, Output::BaseShear] {
            assert_eq!(
                restored.output_derivative(which, &held(0.3)),
                sim.output_derivative(which, &held(0.3)),
                "{p:?} {which:?}"
            );
        }
    }
}

#[test]
fn tracked_amplitude_settles_within_five_percent() {
    for rebuild in [false, true] {
        for ratio in [0.5, 1.0, 2.0] {
            let p = tracked(defaults()).with(vr::A_E, 0.001);
            let mut sim = damper(&p);
            let w = ratio * sim.derived().omega_f;
            let amp = 0.005;
            let h = 0.01;
            for k in 0..6000 {
                let t = k as f64 * h;
                let v = if rebuild {
                    0.0
                } else {
                    w * amp * (w * t).cos()
                };
                let inputs = Inputs {
                    a: -w * w * amp * (w * t).sin(),
                    v,
                    ..Inputs::default()
                };
                sim.step(t, h, &inputs).expect("step");
                if k > 4000 {
                    let est = sim.output(Output::Amplitude, &inputs);
                    assert!(
                        (est / amp - 1.0).abs() < 0.05,
                        "w/wf {ratio} rebuild {rebuild}: {est}"
                    );
                }
            }
        }
    }
}

/// Under a damping law that ignores the amplitude, the tracker only takes in each step's input
/// and its estimate is formed when read. Read late (only at the end, after 3000 steps with the
/// communication step changing and the host starting to drive base.v halfway), A_e.estimate and
/// the saved tracker state are those of a reference tracker that computes everything afresh
/// every step (a new tracker from the saved state, so no coefficient kept from one step to the
/// next), bit for bit, and those of the same run under the NSD law, which reads the estimate
/// every step; a restored damper continues the same. Guards the lazy path against drifting from
/// the eager one (a stale coefficient, a skipped update, an update on a refused step).
#[test]
fn tracked_amplitude_read_late_is_exact() {
    let lazy_p = tracked(defaults())
        .with(vr::DAMPING, CONSTANT)
        .with(vr::ZETA, 0.02);
    let eager_p = tracked(defaults());
    let (mut lazy, mut eager) = (damper(&lazy_p), damper(&eager_p));
    assert!(!lazy.estimates_first && eager.estimates_first);
    let wf = lazy.derived().omega_f;
    let (tau, prior) = (2.0 * std::f64::consts::TAU / wf, 0.005);
    let mut reference = AmplitudeTracker::new(tau, 0.05 * wf, prior, wf);
    let mut t = 0.0;
    for k in 0..3000 {
        let h = [0.01, 0.004, 0.01, 0.0125][(k / 400) % 4];
        let w = 1.05 * wf;
        let inputs = Inputs {
            a: -w * w * 0.003 * (w * t).sin(),
            v: if k >= 1500 {
                w * 0.003 * (w * t).cos()
            } else {
                0.0
            },
            ..Inputs::default()
        };
        lazy.step(t, h, &inputs).expect("step");
        eager.step(t, h, &inputs).expect("step");
        let mut fresh = AmplitudeTracker::new(tau, 0.05 * wf, prior, wf);
        fresh.set_state(&reference.state()).expect("a saved state");
        fresh.update(h, inputs.a, inputs.v);
        reference = fresh;
        t += h;
    }
    let late = lazy.output(Output::Amplitude, &held(0.0));
    assert_eq!(late.to_bits(), reference.estimate().to_bits());
    assert_eq!(late, eager.output(Output::Amplitude, &held(0.0)));
    assert!(
        (late / 0.003 - 1.0).abs() < 0.05,
        "the estimate follows: {late}"
    );
    // The saved frame: the amplitude, then the tracker's state, as the eager run saves them.
    let (saved, saved_eager) = (lazy.snapshot(), eager.snapshot());
    let frame = |s: &[f64]| s[s.len() - FRAME..].to_vec();
    assert_eq!(frame(&saved)[0].to_bits(), late.to_bits());
    assert_eq!(frame(&saved)[3..], reference.state());
    assert_eq!(frame(&saved)[3..], frame(&saved_eager)[3..]);
    // A refused step takes nothing in.
    assert!(lazy.step(t, 0.1, &held(-1e300)).is_err());
    assert_eq!(lazy.snapshot(), saved);
    let mut restored = Damper::restore(&lazy_p, &saved).expect("restore");
    assert_eq!(restored.output(Output::Amplitude, &held(0.0)), late);
    restored.step(t, 0.01, &held(0.2)).expect("step");
    reference.update(0.01, 0.2, 0.0);
    assert_eq!(
        restored.output(Output::Amplitude, &held(0.0)),
        reference.estimate()
    );
}

#[test]
fn inconsistent_configurations_are_refused() {
    let bad = defaults()
        .with(vr::LAMBDA_MIN, 0.2)
        .with(vr::LAMBDA_MAX, 0.1);
    assert!(Damper::configure(&bad).is_err());
    assert!(Damper::configure(&defaults().with(vr::TANK_DEPTH, 0.3)).is_err());
    let (_, warnings) =
        Damper::configure(&defaults().with(vr::TANK_DEPTH, 0.05)).expect("valid but deep");
    assert_eq!(warnings.len(), 1);
    let wide = slamming(defaults()).with(vr::SLAMMING_CLEARANCE, 0.3);
    assert!(Damper::configure(&wide).is_err());
    let greedy = slamming(defaults()).with(vr::SLAMMING_MASS_RATIO, 10.0);
    assert!(Damper::configure(&greedy).is_err());
    assert!(Damper::configure(&defaults().with(vr::SLOSH_X0, 0.3)).is_err());
}

/// Every model the model description offers is registered, and nothing else is.
#[test]
fn the_registry_holds_the_model_descriptions_models() {
    let model = VARIABLES
        .iter()
        .find(|v| v.vr == vr::MODEL)
        .expect("a model parameter");
    let mut declared: Vec<i64> = model.items.iter().map(|(_, v)| *v).collect();
    let mut registered: Vec<i64> = AnyModel::ITEMS.iter().map(|m| m.value()).collect();
    declared.sort();
    registered.sort();
    assert_eq!(declared, registered);
}

/// A value of the parameter `var` other than `start`, inside its declared range.
fn perturbed(var: &crate::description::Variable, start: f64) -> f64 {
    if !var.items.is_empty() {
        return var
            .items
            .iter()
            .map(|(_, v)| *v as f64)
            .find(|v| *v != start)
            .unwrap_or(start);
    }
    let (lo, hi) = (var.min.unwrap_or(f64::MIN), var.max.unwrap_or(f64::MAX));
    let step = if var.ty == VarType::Integer {
        1.0
    } else {
        0.01
    };
    let candidates = [start * 1.1, start * 0.9, start + step, start - step];
    let pick = candidates
        .into_iter()
        .map(|c| {
            if var.ty == VarType::Integer {
                c.round()
            } else {
                c
            }
        })
        .find(|c| *c != start && (lo..=hi).contains(c));
    pick.unwrap_or(start)
}

/// Every declared parameter is read by the model configuration: changing it changes the
/// configured damper for some choice of model, damping law, amplitude source and solver. A
/// parameter declared in the XML but never read fails here.
#[test]
fn every_declared_parameter_is_read() {
    let mut contexts = vec![];
    for model in [LINEAR, NONLINEAR, SLAMMING, AUTO, SHALLOW_WATER] {
        for damping in [CONSTANT, 2.0, BOUNDARY_LAYER, SCREENS] {
            for amplitude in [1.0, TRACKED] {
                for solver in SOLVERS {
                    contexts.push(
                        defaults()
                            .with(vr::MODEL, model)
                            .with(vr::DAMPING, damping)
                            .with(vr::AMPLITUDE, amplitude)
                            .with(vr::SOLVER, solver),
                    );
                }
            }
        }
    }
    let mut unread = vec![];
    for var in VARIABLES
        .iter()
        .filter(|v| v.causality == Causality::Parameter)
    {
        let changes = contexts.iter().any(|context| {
            let start = context.value(var.vr);
            let value = perturbed(var, start);
            assert_ne!(value, start, "'{}' has no other value to try", var.name);
            let changed = context.clone().with(var.vr, value);
            match (Damper::configure(context), Damper::configure(&changed)) {
                // By their printed form, which is exact for f64 and equal for NaN (a propagator's
                // empty cache) where == is not.
                (Ok((a, _)), Ok((b, _))) => format!("{a:?}") != format!("{b:?}"),
                _ => false,
            }
        });
        if !changes {
            unread.push(var.name);
        }
    }
    // The Integer aliases of the enumerations are the FMI layer's to resolve (fmi::params).
    unread.retain(|name| !name.ends_with("_id"));
    assert!(unread.is_empty(), "declared but never read: {unread:?}");
}

/// Likely unit mistakes are noticed once per run: base.a in mm/s^2 (the sloshing then goes far
/// beyond the walls), base.a absurdly large, and tank lengths in centimetres (a configuration
/// warning). An ordinary run near resonance, up to the walls, is not.
#[test]
fn unit_mistakes_are_noticed_once() {
    let w = 5.6;
    let run = |p: &StartValues, scale: f64| {
        let mut sim = damper(p);
        let mut notices = vec![];
        for k in 0..3000 {
            let t = f64::from(k) * 0.01;
            let inputs = held(-scale * w * w * 0.005 * (w * t).sin());
            match sim.step(t, 0.01, &inputs) {
                Ok(report) if report.implausible => notices.extend(sim.notice(inputs.a)),
                Ok(_) => {}
                Err(_) => break,
            }
        }
        notices
    };
    // 5 mm of base motion at resonance: the sloshing reaches the walls, and that is physics.
    let ordinary = run(&defaults(), 1.0);
    assert!(ordinary.is_empty(), "{ordinary:?}");
    // The same in mm/s^2: 1000 times the acceleration.
    let millimetres = run(&defaults(), 1000.0);
    assert_eq!(millimetres.len(), 1, "{millimetres:?}");
    assert!(millimetres[0].contains("mm/s^2"), "{}", millimetres[0]);
    // Linear, so that nothing bounds the sloshing but the runaway check.
    let linear = defaults().with(vr::MODEL, LINEAR);
    let beyond = run(&linear, 30.0);
    assert_eq!(beyond.len(), 1, "{beyond:?}");
    assert!(beyond[0].contains("beyond the walls"), "{}", beyond[0]);
    let (_, warnings) =
        Damper::configure(&defaults().with(vr::TANK_LENGTH, 25.0)).expect("simulable");
    assert!(
        warnings.iter().any(|w| w.contains("metres")),
        "a 25 m tank 21 mm deep: {warnings:?}"
    );
    let (_, warnings) = Damper::configure(&defaults()).expect("defaults");
    assert!(warnings.is_empty(), "{warnings:?}");
}
