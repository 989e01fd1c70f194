//! The parameter checks at their bounds (the words of the checks: "must not exceed",
//! "exceeds"), and S^2's impact mass under a jump of the tank's velocity in flight and at rest
//! on a wall (MODEL.md's S^2 model: at rest the mass moves with the tank).

use super::*;
use crate::model::continuous::{ENERGY_INPUT, IMPACT_V, IMPACT_Z};
use crate::model::slamming::Event;

fn configured(p: &StartValues) -> Result<Vec<String>, String> {
    Damper::configure(p).map(|(_, warnings)| warnings)
}

/// lambda.min may equal lambda.max (Lambda then fixed there: NSD's zeta = c Lambda^p at that
/// value whatever A_e), not exceed it.
#[test]
fn lambda_min_may_equal_lambda_max() {
    let lambda = 0.05;
    let p = StartValues::default()
        .with(vr::AMPLITUDE, FIXED)
        .with(vr::LAMBDA_MIN, lambda)
        .with(vr::LAMBDA_MAX, lambda);
    let sim = damper(&p);
    let zeta = sim.output(Output::Zeta, &held(0.0));
    let want = 0.5 * lambda.powf(0.35);
    assert!((zeta - want).abs() < 1e-15, "{zeta} for {want}");
    let refused = configured(&p.with(vr::LAMBDA_MIN, lambda.next_up()));
    let why = refused.expect_err("refused");
    assert!(why.contains("must not exceed lambda.max"), "{why}");
}

/// slosh.x0 may be a whole tank length either way, not more.
#[test]
fn slosh_x0_may_be_a_tank_length() {
    for x0 in [A, -A] {
        let p = StartValues::default().with(vr::SLOSH_X0, x0);
        let sim = damper(&p);
        assert_eq!(sim.output(Output::X, &held(0.0)), x0);
        let why = configured(&p.with(vr::SLOSH_X0, x0 * 1f64.next_up()));
        let why = why.expect_err("refused");
        assert!(why.contains("exceeds the tank length"), "{why}");
    }
}

/// The shallow-water validity warning is for depth ratios above 0.15, not at it.
#[test]
fn the_depth_warning_is_above_h_over_a_of_0_15() {
    let p = StartValues::default()
        .with(vr::TANK_LENGTH, 1.0)
        .with(vr::TANK_DEPTH, 0.15);
    assert_eq!(configured(&p), Ok(vec![]));
    let warnings = configured(&p.with(vr::TANK_DEPTH, 0.15f64.next_up()));
    let warnings = warnings.expect("a warning, no refusal");
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("exceeds 0.15"), "{warnings:?}");
}

/// A jump dv of the tank's velocity: the flying impact mass keeps its absolute velocity, so
/// impact.v drops by dv as slosh.v does; the mass at rest on a wall moves with the tank, so
/// its velocity stays 0 and it stays there. Nothing else moves but energy.input.
#[test]
fn a_velocity_jump_moves_the_flying_impact_mass_only() {
    let d = 0.1;
    let p = StartValues::default()
        .with(vr::MODEL, SLAMMING)
        .with(vr::AMPLITUDE, FIXED)
        .with(vr::SLAMMING_CLEARANCE, d)
        .with(vr::SLOSH_V0, 0.02);
    let dv = 0.03;
    for rest in [false, true] {
        let mut sim = damper(&p);
        let mut s = sim.continuous_states();
        (s[IMPACT_Z], s[IMPACT_V]) = if rest { (0.5 * d, 0.0) } else { (0.01, 0.1) };
        assert!(sim.set_continuous_states(&s).is_ok());
        if rest {
            // Pressed onto +d/2 (the base accelerating towards -x): it rests there.
            let event = sim.event(&held(-30.0));
            assert!(
                matches!(event, Event::Impact { rests: true, .. }),
                "{event:?}"
            );
        }
        let before = sim.continuous_states();
        assert_eq!(sim.base_velocity_jump(dv), Ok(true), "rest {rest}");
        let after = sim.continuous_states();
        for (k, (b, a)) in before.iter().zip(&after).enumerate() {
            let moved = match k {
                1 => -dv,
                IMPACT_V if !rest => -dv,
                ENERGY_INPUT => a - b,
                _ => 0.0,
            };
            assert!(
                (a - b - moved).abs() < 1e-15,
                "rest {rest}, state {k}: {b} to {a}"
            );
        }
        if rest {
            assert_eq!(after[IMPACT_V], 0.0);
            assert_eq!(after[IMPACT_Z], 0.5 * d);
        }
    }
}

/// ShallowWater's wall heights are cut at the bottom (the wall depth 1.5 H_0 - 0.5 H_1 at most
/// 0 when the first cell is nearly dry): there surface.left = -h, and its rate is 0 (the
/// difference quotient of the output over a short step, as long as the wall stays dry), not
/// the extrapolation's rate.
#[test]
fn a_dry_walls_height_does_not_move() {
    let p = StartValues::default()
        .with(vr::MODEL, 5.0)
        .with(vr::SWE_CELLS, 40.0)
        .with(vr::DAMPING, CONSTANT)
        .with(vr::ZETA, 0.05)
        .with(vr::AMPLITUDE, FIXED);
    let mut sim = damper(&p);
    // The tank accelerating at 3 m/s^2 towards -x tilts the surface by 0.3: 0.04 m at the
    // walls, twice the depth, so the liquid leaves the left wall.
    let inputs = held(-3.0);
    let mut dry = 0;
    for k in 0..100 {
        let left = sim.output(Output::SurfaceLeft, &inputs);
        if left == -H {
            dry += 1;
            let rate = sim.output_derivative(Output::SurfaceLeft, &inputs);
            let mut next = sim.clone();
            next.step(0.0, 1e-6, &inputs).expect("step");
            let quotient = (next.output(Output::SurfaceLeft, &inputs) - left) / 1e-6;
            if next.output(Output::SurfaceLeft, &inputs) == -H {
                assert_eq!((rate, quotient), (0.0, 0.0), "step {k}");
            }
        }
        sim.step(k as f64 * 0.005, 0.005, &inputs).expect("step");
    }
    assert!(dry > 0, "the left wall never ran dry");
}
