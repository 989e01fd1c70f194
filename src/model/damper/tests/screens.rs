//! The damper's tests of the Screens law's wiring (the amplitude it reads, screens.response).

use super::*;

/// The Screens law reads the amplitude: with amplitude = Tracked its damping follows the
/// excitation (zeta.effective is the law at A_e.estimate after every step), as NSD's does.
/// Guards the law's `reads_amplitude` (false held the damping at the prior's for the whole run).
#[test]
fn screens_law_follows_a_tracked_amplitude() {
    let p = tracked(defaults())
        .with(vr::MODEL, LINEAR)
        .with(vr::DAMPING, SCREENS)
        .with(vr::SCREENS_COUNT, 2.0)
        .with(vr::A_E, 0.0005);
    let mut sim = damper(&p);
    let (common, _) = Common::read(&p).expect("parameters");
    let w = sim.derived().omega_f;
    let start = sim.output(Output::Zeta, &Inputs::default());
    for k in 0..3000 {
        let t = f64::from(k) * 0.01;
        let inputs = held(-w * w * 0.005 * (w * t).sin());
        sim.step(t, 0.01, &inputs).expect("step");
        let (zeta, a_e) = (
            sim.output(Output::Zeta, &inputs),
            sim.output(Output::Amplitude, &inputs),
        );
        assert_eq!(zeta, common.zeta(a_e), "step {k}");
    }
    let end = sim.output(Output::Zeta, &Inputs::default());
    // The estimate settles near the 5 mm driven, ten times the prior: zeta grows about 3-fold.
    assert!(end > 2.0 * start, "{start} -> {end}");
}

/// screens.response: Sinusoidal (the default) is the law as it was, bit for bit; Random takes
/// A_e as the rms response, zeta_BL + 1.880 K A_e, in every mechanical model, and is refused with
/// a tracked amplitude (which estimates a harmonic base amplitude) except by ShallowWater,
/// which resolves the screens and reads no law (the Integer alias: fmi::params' alias test).
#[test]
fn screens_response_random_takes_a_e_as_the_rms_response() {
    use crate::physics::laws::DampingLaw;
    use crate::physics::screens::{RANDOM_SCREENS, random_zeta, resonant_zeta};
    let base = defaults()
        .with(vr::DAMPING, SCREENS)
        .with(vr::SCREENS_COUNT, 2.0)
        .with(vr::A_E, 0.002)
        .with(vr::AMPLITUDE, 1.0);
    let law = |p: &StartValues| Common::read(p).expect("parameters").0.damping;
    let DampingLaw::Screens {
        boundary,
        per_response,
        random: false,
    } = law(&base)
    else {
        panic!("the default is Sinusoidal")
    };
    let random = base.clone().with(vr::SCREENS_RESPONSE, 2.0);
    for model in [LINEAR, NONLINEAR, SLAMMING, AUTO] {
        let sine = damper(&base.clone().with(vr::MODEL, model));
        let want = resonant_zeta(boundary, per_response, 0.002);
        assert_eq!(sine.output(Output::Zeta, &Inputs::default()), want);
        let d = damper(&random.clone().with(vr::MODEL, model));
        let zeta = d.output(Output::Zeta, &Inputs::default());
        assert_eq!(zeta, random_zeta(boundary, per_response, 0.002));
        assert!((zeta - (boundary + RANDOM_SCREENS * per_response * 0.002)).abs() < 1e-15);
        let err = Damper::configure(
            &random
                .clone()
                .with(vr::MODEL, model)
                .with(vr::AMPLITUDE, TRACKED),
        )
        .expect_err("Random with a tracked amplitude is refused");
        assert!(err.contains("amplitude = Fixed"), "{err}");
    }
    assert!(
        Damper::configure(
            &random
                .clone()
                .with(vr::MODEL, SHALLOW_WATER)
                .with(vr::AMPLITUDE, TRACKED)
        )
        .is_ok()
    );
    // The factor is 1.880 K sigma against the resonant law's root: at this A_e and these screens
    // the two differ (a test of which one is applied).
    assert!(
        (random_zeta(boundary, per_response, 0.002) / resonant_zeta(boundary, per_response, 0.002)
            - 1.0)
            .abs()
            > 0.1
    );
}

/// The Screens law's K (zeta_s = K X, MODEL.md 9) as the damper reads it from the parameters:
/// K = (2/3) C_l (m_1/M_l) sum_j |sin(pi x_j/a)|^3 / a, with the loss coefficient C_l given, two
/// screens evenly spaced (x_j = a/3, 2a/3: sum 2 (sqrt(3)/2)^3) and Eq 2.1's mass ratio
/// m_1/M_l = 8 tanh(pi r)/(pi^3 r), r = h/a, in a tank that is not the defaults' (three of them:
/// the ratio is per tank and total alike). Guards the mass ratio's `/` (m_1 M_l for m_1/M_l).
#[test]
fn screens_k_is_model_9s_with_eq_2_1s_mass_ratio() {
    use crate::physics::laws::DampingLaw;
    let (a, h, loss) = (0.7, 0.09, 2.6);
    let p = defaults()
        .with(vr::MODEL, LINEAR)
        .with(vr::DAMPING, SCREENS)
        .with(vr::SCREENS_COUNT, 2.0)
        .with(vr::SCREENS_LOSS, loss)
        .with(vr::TANK_LENGTH, a)
        .with(vr::TANK_BREADTH, 0.35)
        .with(vr::TANK_DEPTH, h)
        .with(vr::TANKS, 3.0);
    let DampingLaw::Screens { per_response, .. } = Common::read(&p).expect("parameters").0.damping
    else {
        panic!("the Screens law")
    };
    let pi = std::f64::consts::PI;
    let r = h / a;
    let ratio = 8.0 * (pi * r).tanh() / (pi.powi(3) * r);
    let cubes = 2.0 * (0.75f64.sqrt()).powi(3);
    let want = 2.0 / 3.0 * loss * ratio * cubes / a;
    assert!(
        (per_response / want - 1.0).abs() < 1e-12,
        "{per_response} vs {want}"
    );
}
