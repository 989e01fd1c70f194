use super::*;
use crate::analysis::design::wind_force;
use crate::description::{AmplitudeModeItem, DampingLawItem, ModelKindItem, vr};
use crate::model::StartValues;
use crate::physics::laws::DampingLaw;
use crate::physics::screens::RANDOM_SCREENS;

fn item(i: impl Into<i64>) -> f64 {
    i.into() as f64
}

/// The lab tank (Table 2.1: a = 0.25 m, h = 0.021 m), one tank, from rest, amplitude Fixed.
fn lab(model: ModelKindItem) -> StartValues {
    StartValues::default()
        .with(vr::MODEL, item(model as i64))
        .with(vr::AMPLITUDE, item(AmplitudeModeItem::Fixed as i64))
        .with(vr::TANKS, 1.0)
        .with(vr::SLOSH_X0, 0.0)
        .with(vr::SLOSH_V0, 0.0)
}

/// Tait's pair at 0.4 a and 0.6 a of solidity `s`, damping = Screens with no boundary layers
/// (liquid.viscosity 0): the screens alone, in the law and in the shallow-water model.
fn screens(p: StartValues, s: f64) -> StartValues {
    p.with(vr::DAMPING, item(DampingLawItem::Screens as i64))
        .with(vr::SCREENS_COUNT, 2.0)
        .with(vr::SCREENS_SOLIDITY, s)
        .with(vr::SCREENS_SPACING, 0.05)
        .with(vr::LIQUID_VISCOSITY, 0.0)
}

/// zeta_BL and K of the Screens law `p` configures.
fn law(p: &StartValues) -> (f64, f64) {
    match Common::read(p).expect("parameters").0.damping {
        DampingLaw::Screens {
            boundary,
            per_response,
            ..
        } => (boundary, per_response),
        other => panic!("not the Screens law: {other:?}"),
    }
}

const H: f64 = 0.01;
const SEED: u64 = 28;

/// Band-limited white noise over 0.5-1.5 omega_f for `seconds`, of the two-sided density s0
/// that gives the random Screens law's linear oscillator the rms response `sigma` (module
/// `random_screens_sigma` inverted: s0 = 2 zeta omega^3 sigma^2 / pi).
fn record(omega: f64, zeta: f64, sigma: f64, seconds: f64) -> (f64, Vec<f64>) {
    let s0 = 2.0 * zeta * omega.powi(3) * sigma * sigma / std::f64::consts::PI;
    let n = (seconds / H) as usize;
    (s0, wind_force(s0, (0.5 * omega, 1.5 * omega), H, n, SEED))
}

/// One comparison at solidity `s`: the shallow-water model `swe` under the record sized for
/// the rms response `sigma` (`seconds` long, the first `skip` steps not measured), the Linear
/// model with the random law at the model's sigma_X on the same record, and the law's
/// closed-form sigma_X from the record's density.
struct Comparison {
    swe: Stationary,
    linear: Stationary,
    predicted: f64,
}

fn compare(swe: &StartValues, s: f64, sigma: f64, seconds: f64, skip: usize) -> Comparison {
    let (_, k) = law(swe);
    let omega = Common::read(swe).unwrap().0.tank.fundamental().omega;
    let (s0, accel) = record(omega, RANDOM_SCREENS * k * sigma, sigma, seconds);
    let r = stationary_response(swe, &accel, H, skip).expect("shallow water");
    let linear = screens(lab(ModelKindItem::Linear), s)
        .with(vr::MODES, 1.0)
        .with(vr::SCREENS_RESPONSE, 2.0)
        .with(vr::A_E, r.sigma_x);
    Comparison {
        swe: r,
        linear: stationary_response(&linear, &accel, H, skip).expect("linear"),
        predicted: random_screens_sigma(0.0, k, omega, s0),
    }
}

/// The estimator on the linear oscillator (model = Linear, one mode, damping Constant 0.05):
/// its dissipation is c v^2 exactly, so zeta_eq is the zeta set (to the record's rounding), and
/// its variance is the white-noise one, pi s0/(2 zeta omega^3), within the record's sampling
/// error (a 600 s record: about 4 % for zeta omega_f = 0.28/s) and the band's cut (the
/// response spectrum outside 0.5-1.5 omega_f holds under 1 %).
#[test]
fn the_estimator_is_exact_on_the_linear_oscillator() {
    let p = lab(ModelKindItem::Linear)
        .with(vr::MODES, 1.0)
        .with(vr::DAMPING, item(DampingLawItem::Constant as i64))
        .with(vr::ZETA, 0.05);
    let omega = Common::read(&p).unwrap().0.tank.fundamental().omega;
    let (s0, accel) = record(omega, 0.05, 0.002, 600.0);
    let r = stationary_response(&p, &accel, H, 5000).expect("run");
    let want = (std::f64::consts::PI * s0 / (2.0 * 0.05 * omega.powi(3))).sqrt();
    eprintln!(
        "linear: zeta_eq {:.6}, sigma_x {:.4e} vs {want:.4e}",
        r.zeta_eq, r.sigma_x
    );
    assert!((r.zeta_eq / 0.05 - 1.0).abs() < 1e-3, "{}", r.zeta_eq);
    assert!(
        (r.sigma_x / want - 1.0).abs() < 0.1,
        "{} vs {want}",
        r.sigma_x
    );
}

/// The random form of the Screens law (screens.response = Random) against the shallow-water
/// model with the same screens (Tait's pair, S = 0.5, 32 cells, no boundary layers) under
/// band-limited white-noise base acceleration (0.5-1.5 omega_f, 400 s, the first 50 s skipped)
/// at two response levels, sigma_X/a = 0.004 and 0.02 (zeta 0.025 and 0.12):
/// - the model's energy-equivalent damping against 1.880 K sigma_X at its own sigma_X (+4 % and
///   -5 % of the law: allowed 8 %), and not against a sinusoid of the same rms,
///   K sqrt(2) sigma_X, 21-28 % below it (required more than 15 % off: the test tells the two
///   forms apart);
/// - the Linear model with the random law at A_e = that sigma_X, driven by the same record:
///   its sigma_X within 6 % of the model's (measured +1 % and -4 %);
/// - the closed-form prediction from the excitation alone, the root of
///   sigma^2 = pi s0/(2 (1.880 K sigma) omega^3), within 6 % (measured +2 % and +3 %).
///
/// About 10 s of CPU in a debug build; docs/SCREENS-SWEEP.md has 150 cells, S = 0.5 and 0.7 and
/// more levels (scripts/screens-report).
#[test]
fn random_screens_law_matches_the_shallow_water_model() {
    let swe = screens(lab(ModelKindItem::ShallowWater), 0.5).with(vr::SWE_CELLS, 32.0);
    let (boundary, k) = law(&swe);
    assert_eq!(boundary, 0.0);
    for sigma in [0.001, 0.005] {
        let Comparison {
            swe: r,
            linear: l,
            predicted,
        } = compare(&swe, 0.5, sigma, 400.0, 5000);
        let random = RANDOM_SCREENS * k * r.sigma_x;
        let sine = k * r.sigma_x * 2f64.sqrt();
        eprintln!(
            "sigma {sigma}: SWE sigma_x {:.4e} (predicted {predicted:.4e}), zeta_eq {:.4}; law \
             1.880 K sigma {random:.4}, sinusoid of the same rms {sine:.4}; Linear sigma_x {:.4e}",
            r.sigma_x, r.zeta_eq, l.sigma_x
        );
        assert!(
            (r.zeta_eq / random - 1.0).abs() < 0.08,
            "{} vs {random}",
            r.zeta_eq
        );
        assert!(
            (r.zeta_eq / sine - 1.0).abs() > 0.15,
            "{} vs {sine}",
            r.zeta_eq
        );
        assert!(
            (l.sigma_x / r.sigma_x - 1.0).abs() < 0.06,
            "{} vs {}",
            l.sigma_x,
            r.sigma_x
        );
        assert!(
            (predicted / r.sigma_x - 1.0).abs() < 0.06,
            "{predicted} vs {}",
            r.sigma_x
        );
    }
}

/// The report behind the random half of docs/SCREENS-SWEEP.md (scripts/screens-report runs it
/// in a release build): the lab tank with Tait's pair (S = 0.5 and 0.7, no boundary layers) as
/// model = ShallowWater at 150 cells under band-limited white noise (0.5-1.5 omega_f, 1200 s,
/// the first 100 s skipped) sized for sigma_X/a = 0.001 to 0.04 by the random law (levels whose
/// law zeta would pass 0.6 left out); its sigma_X and energy-equivalent damping against the
/// random law at that sigma_X, the Linear model with screens.response = Random (A_e = the
/// model's sigma_X) on the same record, and the law's closed-form sigma_X from the excitation.
/// Prints a Markdown table; asserts only that every run finished.
#[test]
#[ignore = "a report (scripts/screens-report), about a minute in a release build"]
fn random_screens_law_report() {
    println!(
        "| S | sigma_X/a sized for | SWE sigma_X/a | SWE zeta_eq | law 1.880 K sigma_X | \
         SWE / law | Linear+Random sigma_X/a | SWE / Linear | law's sigma_X from S_0, /a | SWE / that |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for s in [0.5, 0.7] {
        let swe = screens(lab(ModelKindItem::ShallowWater), s).with(vr::SWE_CELLS, 150.0);
        let (_, k) = law(&swe);
        for level in [0.001, 0.002, 0.005, 0.01, 0.02, 0.04] {
            let sigma = level * 0.25;
            if RANDOM_SCREENS * k * sigma > 0.6 {
                continue;
            }
            let Comparison {
                swe: r,
                linear: l,
                predicted,
            } = compare(&swe, s, sigma, 1200.0, 10_000);
            let at = RANDOM_SCREENS * k * r.sigma_x;
            println!(
                "| {s} | {level} | {:.5} | {:.4} | {at:.4} | {:.3} | {:.5} | {:.3} | {:.5} | {:.3} |",
                r.sigma_x / 0.25,
                r.zeta_eq,
                r.zeta_eq / at,
                l.sigma_x / 0.25,
                r.sigma_x / l.sigma_x,
                predicted / 0.25,
                r.sigma_x / predicted
            );
        }
    }
}
