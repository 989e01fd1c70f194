use super::*;
use crate::analysis::harmonic::HarmonicBalance;
use crate::description::{AmplitudeModeItem, DampingLawItem, ModelKindItem, vr};
use crate::model::StartValues;
use crate::physics::geometry::Tank;
use crate::physics::power::PowerLaw;

fn item(i: impl Into<i64>) -> f64 {
    i.into() as f64
}

/// The Table 2.1 tank (a = 0.25 m, h = 0.021 m: omega_f = 5.6389 rad/s), one tank, constant
/// damping `zeta`, from rest.
fn table21(model: ModelKindItem, zeta: f64) -> StartValues {
    StartValues::default()
        .with(vr::MODEL, item(model as i64))
        .with(vr::DAMPING, item(DampingLawItem::Constant as i64))
        .with(vr::ZETA, zeta)
        .with(vr::AMPLITUDE, item(AmplitudeModeItem::Fixed as i64))
        .with(vr::TANKS, 1.0)
        .with(vr::SLOSH_X0, 0.0)
        .with(vr::SLOSH_V0, 0.0)
}

fn tank() -> Tank {
    Tank {
        length: 0.25,
        breadth: 0.32,
        depth: 0.021,
        density: 1000.0,
        g: 9.81,
    }
}

/// A linear oscillator's steady state is the closed form
/// X = w^2 A / sqrt((w_f^2 - w^2)^2 + (2 zeta w_f w)^2) with the phase lag
/// atan2(2 zeta r, 1 - r^2), and the energy-equivalent damping of a harmonic response is its
/// zeta: across resonance, from rest.
#[test]
fn linear_steady_state_and_damping_are_the_closed_form() {
    let zeta = 0.02;
    let a = 1e-3;
    let p = table21(ModelKindItem::Linear, zeta).with(vr::MODES, 1.0);
    let mut sweeper = Sweeper::new(&p, a, Settling::default()).expect("sweeper");
    let wf = tank().fundamental().omega;
    assert!((sweeper.omega_f() - wf).abs() < 1e-12 * wf);
    for r in sweeper.sweep(&[0.9, 1.0, 1.1]).expect("sweep") {
        let w = r.ratio * wf;
        let exact = w * w * a / ((wf * wf - w * w).powi(2) + (2.0 * zeta * wf * w).powi(2)).sqrt();
        assert!(r.settled, "{r:?}");
        assert!((r.x / exact - 1.0).abs() < 2e-3, "{r:?} vs {exact}");
        assert!((r.x_peak / exact - 1.0).abs() < 2e-3, "{r:?} vs {exact}");
        assert!((r.zeta_eq / zeta - 1.0).abs() < 2e-3, "{r:?}");
        let lag = (2.0 * zeta * r.ratio).atan2(1.0 - r.ratio * r.ratio);
        assert!((r.phase - lag).abs() < 2e-3, "{r:?} vs {lag}");
    }
}

/// VERIFY.md item 4: the Nonlinear model (eta = 2, phi = 1, zeta = 0.02, A_e = 3 mm) swept slowly
/// up falls off its upper branch between w/w_f = 1.17 and 1.19, within 1 % of harmonic
/// balance's peak (1.171, X = 0.0878 m: one harmonic is that accurate for eta = 2), its largest
/// amplitude within 1.5 % of the peak's; swept down it jumps up across the fold of harmonic
/// balance's high-frequency branch (1.07..1.09).
#[test]
fn nonlinear_sweeps_jump_where_harmonic_balance_folds() {
    let (zeta, a) = (0.02, 3e-3);
    let p = table21(ModelKindItem::Nonlinear, zeta)
        .with(vr::ETA, 2.0)
        .with(vr::PHI, 1.0);
    let settling = Settling {
        steps_per_cycle: 64,
        tolerance: 2e-3,
        ..Settling::default()
    };
    let wf = tank().fundamental().omega;
    let hb = HarmonicBalance {
        law: PowerLaw::new(wf, 1.0, 2.0, 0.25),
        damping: 2.0 * zeta * wf,
        base_amplitude: a,
    };
    let hb_peak = hb.peak(0.75).expect("a peak");
    let hb_fold = hb.fold(0.75).expect("a fold");
    let lambda = a / 0.25;
    let plan = Plan {
        from: 0.95,
        to: 1.4,
        step: 0.01,
        settling,
    };
    let c = characterise(&p, lambda, &plan).expect("sweeps");
    assert_eq!(c.lambda, lambda);
    let (before, after) = c.jump_down.expect("an up-sweep jump");
    let kappa = hb_peak.w / wf;
    assert!(
        before.ratio >= 1.17 && after.ratio <= 1.19 && (before.ratio - kappa).abs() <= 0.011,
        "up: {before:?} {after:?} vs harmonic balance {kappa}"
    );
    assert_eq!(c.peak.ratio, before.ratio);
    // Quadrature at the top of the upper branch: within the frequency step of the peak.
    let (k, z) = c.quadrature.expect("quadrature");
    assert!(
        (k - kappa).abs() <= 0.011,
        "{k} vs harmonic balance {kappa}"
    );
    assert!((z / zeta - 1.0).abs() < 0.01, "{z}");
    assert!(
        (c.peak.x / hb_peak.x - 1.0).abs() < 0.015,
        "{:?} vs {hb_peak:?}",
        c.peak
    );
    // Constant damping: the energy-equivalent zeta is the model's, within the share of the
    // higher harmonics in the velocity.
    assert!((c.peak.zeta_eq / zeta - 1.0).abs() < 0.01, "{:?}", c.peak);
    // The up-sweep stopped on the lower branch, three frequencies below half the peak.
    assert!(c.up.len() < 30 && c.up.iter().rev().take(3).all(|r| r.x < 0.5 * c.peak.x));
    assert!(
        c.up.iter()
            .rev()
            .take(3)
            .all(|r| r.phase > 0.75 * std::f64::consts::PI)
    );
    assert_eq!(
        c.down.first().map(|r| r.ratio),
        c.up.last().map(|r| r.ratio)
    );
    let (before, after) = c.jump_up.expect("a down-sweep jump");
    let fold = hb_fold.w / wf;
    assert!(
        after.ratio < fold && fold < before.ratio,
        "down: {before:?} {after:?} vs harmonic balance {fold}"
    );
}

#[test]
fn jumps_and_peaks_are_found_in_the_direction_asked() {
    let at = |ratio: f64, x: f64| Response {
        ratio,
        x,
        phase: ratio,
        x_peak: x,
        energy_per_cycle: 0.0,
        zeta_eq: 0.0,
        cycles: 1,
        settled: true,
    };
    let rs = [at(1.0, 1.0), at(1.1, 3.0), at(1.2, 0.5), at(1.3, 0.45)];
    let (b, a) = jump(&rs, true, 1.5).expect("a drop");
    assert_eq!((b.ratio, a.ratio), (1.1, 1.2));
    let (b, a) = jump(&rs, false, 1.5).expect("a rise");
    assert_eq!((b.ratio, a.ratio), (1.0, 1.1));
    assert!(jump(&rs, true, 7.0).is_none());
    assert_eq!(peak(&rs).map(|r| r.ratio), Some(1.1));
    assert_eq!(ratios(1.0, 2.0, 3), vec![1.0, 1.5, 2.0]);
    // phase = ratio here: pi/2 is passed between 1.5 and 1.6, at 1.5708.
    let rs = [at(1.4, 1.0), at(1.5, 1.0), at(1.6, 1.0), at(1.7, 1.0)];
    let (k, _) = quadrature(&rs).expect("crossed");
    assert!((k - 0.5 * std::f64::consts::PI).abs() < 1e-12);
    assert!(quadrature(&rs[..2]).is_none());
}

#[test]
fn bad_sweeps_are_refused() {
    let p = table21(ModelKindItem::Linear, 0.02);
    assert!(Sweeper::new(&p, 0.0, Settling::default()).is_err());
    assert!(Sweeper::new(&p, f64::NAN, Settling::default()).is_err());
    let coarse = Settling {
        steps_per_cycle: 4,
        ..Settling::default()
    };
    assert!(Sweeper::new(&p, 1e-3, coarse).is_err());
    let unmeasured = Settling {
        measure_cycles: 0,
        ..Settling::default()
    };
    assert!(Sweeper::new(&p, 1e-3, unmeasured).is_err());
    // Fewer than 8 cycles to settle in leaves no window of 4 (it was a panic in the clamp).
    let hasty = Settling {
        max_cycles: 7,
        ..Settling::default()
    };
    assert!(Sweeper::new(&p, 1e-3, hasty).is_err());
    let settling = Settling {
        max_cycles: 8,
        ..Settling::default()
    };
    assert!(Sweeper::new(&p, 1e-3, settling).is_ok());
    // Each condition of a plan on its own. The message says which check refused it: a plan
    // let through would fail later, differently, or run (a zero step, without end).
    let refused = |from: f64, to: f64, step: f64| {
        let plan = Plan {
            from,
            to,
            step,
            settling: Settling::default(),
        };
        match characterise(&p, 0.004, &plan) {
            Err(e) => e.starts_with("a sweep from"),
            Ok(_) => false,
        }
    };
    assert!(refused(0.9, 1.0, -0.1), "a negative step");
    assert!(refused(0.0, 1.0, 0.1), "from 0");
    assert!(refused(1.0, 1.0, 0.1), "to = from");
    assert!(refused(1.0, 0.9, 0.1), "downwards");
    assert!(refused(0.9, 1.0, 0.0), "a zero step");
}

/// The rules of the sweeps at their boundaries, on made-up responses (the physics tests
/// above cannot reach exact ties).
#[test]
fn the_rules_hold_at_their_boundaries() {
    use std::f64::consts::PI;
    let at = |ratio: f64, x: f64, phase: f64, zeta_eq: f64| Response {
        ratio,
        x,
        phase,
        x_peak: x,
        energy_per_cycle: 0.0,
        zeta_eq,
        cycles: 1,
        settled: true,
    };
    // A change of exactly the factor is no jump.
    let rs = [at(1.0, 3.0, 1.0, 0.0), at(1.1, 2.0, 1.0, 0.0)];
    assert!(jump(&rs, true, 1.5).is_none());
    assert!(jump(&rs, true, 1.49).is_some());
    // Quadrature: the zeta interpolated with the ratio (pi/2 at 57.08 % of the way).
    let rs = [at(1.0, 1.0, 1.0, 0.1), at(2.0, 1.0, 2.0, 0.3)];
    let (k, z) = quadrature(&rs).expect("crossed");
    let t = (0.5 * PI - 1.0) / (2.0 - 1.0);
    assert!((k - (1.0 + t)).abs() < 1e-15, "{k}");
    assert!((z - (0.1 + 0.2 * t)).abs() < 1e-15, "{z}");
    // A response exactly at pi/2 is the quadrature, rising or falling through it.
    let rs = [at(1.0, 1.0, 1.0, 0.1), at(1.1, 1.0, 0.5 * PI, 0.2)];
    assert_eq!(quadrature(&rs), Some((1.1, 0.2)));
    let rs = [at(1.0, 1.0, 2.0, 0.1), at(1.1, 1.0, 0.5 * PI, 0.2)];
    assert_eq!(quadrature(&rs), Some((1.1, 0.2)));
    // Past the peak: below half of it, or lagging beyond 3 pi/4; exactly there is not past.
    assert!(past_peak(&at(1.0, 0.49, 1.0, 0.0), 1.0));
    assert!(!past_peak(&at(1.0, 0.5, 1.0, 0.0), 1.0));
    assert!(!past_peak(&at(1.0, 0.9, 1.0, 0.0), 1.0));
    assert!(past_peak(&at(1.0, 0.9, 2.5, 0.0), 1.0));
    assert!(!past_peak(&at(1.0, 0.9, 0.75 * PI, 0.0), 1.0));
    // The settling window: an e-fold (1/(2 pi zeta) cycles: 7.96 at 0.02, 31.8 at 0.005) or
    // 1.5 beats (1.5/abs(1 - r): 12 at r = 0.875, 3 at 0.5, 150 -> 40 at 0.99), rounded up; at
    // least 4, at most half the cycles allowed.
    assert_eq!(settling_window(0.02, 0.875, 300), 12);
    assert_eq!(settling_window(0.02, 0.5, 300), 8);
    assert_eq!(settling_window(0.005, 0.5, 300), 32);
    assert_eq!(settling_window(0.5, 0.5, 300), 4);
    assert_eq!(settling_window(0.5, 0.99, 300), 40);
    assert_eq!(settling_window(0.005, 1.2, 300), 32);
    assert_eq!(settling_window(1e-4, 0.5, 300), 150);
    assert_eq!(settling_window(1e-4, 0.5, 9), 4);
}

/// A plan's frequencies: an up-sweep that never passes its peak runs to `to` (and the down
/// sweep back from there); one that does stops three frequencies past it. For a linear
/// oscillator with zeta = 0.3 the relative motion never falls to half its peak (it tends to
/// the base amplitude), and the lag atan2(2 zeta r, 1 - r^2) passes 3 pi/4 at r = 1.344: the
/// up-sweep stops at the third ratio past that.
#[test]
fn sweeps_run_their_plan_and_stop_past_the_peak() {
    use std::f64::consts::PI;
    let settling = Settling {
        steps_per_cycle: 32,
        ..Settling::default()
    };
    let near = |a: &[f64], b: &[f64]| {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12)
    };
    let ratios_of = |rs: &[Response]| rs.iter().map(|r| r.ratio).collect::<Vec<_>>();
    let p = table21(ModelKindItem::Linear, 0.02).with(vr::MODES, 1.0);
    let plan = Plan {
        from: 0.5,
        to: 0.6,
        step: 0.05,
        settling,
    };
    let c = characterise(&p, 0.004, &plan).expect("sweeps");
    assert!(
        near(&ratios_of(&c.up), &[0.5, 0.55, 0.6]),
        "{:?}",
        ratios_of(&c.up)
    );
    assert!(
        near(&ratios_of(&c.down), &[0.6, 0.55, 0.5]),
        "{:?}",
        ratios_of(&c.down)
    );
    let zeta = 0.3;
    let p = table21(ModelKindItem::Linear, zeta).with(vr::MODES, 1.0);
    let plan = Plan {
        from: 1.2,
        to: 2.0,
        step: 0.1,
        settling,
    };
    let c = characterise(&p, 0.004, &plan).expect("sweeps");
    let grid: Vec<f64> = (0..=8).map(|k| 1.2 + 0.1 * f64::from(k)).collect();
    let lag = |r: f64| (2.0 * zeta * r).atan2(1.0 - r * r);
    let first = grid
        .iter()
        .position(|&r| lag(r) > 0.75 * PI)
        .expect("past 3 pi/4");
    assert!(
        near(&ratios_of(&c.up), &grid[..=first + 2]),
        "{:?}",
        ratios_of(&c.up)
    );
    assert!(c.up.iter().all(|r| r.x > 0.5 * c.peak.x));
}

/// The excitation's derivatives go with it into each step: at 16 steps per cycle the steady
/// state of a linear oscillator is the closed form within 5e-3 in amplitude (relative) and
/// phase (rad). Measured: 6.9e-4 and 2.5e-3 with the sine's second-order Taylor polynomial
/// over each step; without its second derivative 2.5e-2 in amplitude, without the first 0.19
/// rad in phase.
#[test]
fn input_derivatives_follow_the_sine_within_a_step() {
    let (zeta, a) = (0.05, 1e-3);
    let p = table21(ModelKindItem::Linear, zeta).with(vr::MODES, 1.0);
    let settling = Settling {
        steps_per_cycle: 16,
        ..Settling::default()
    };
    let mut sweeper = Sweeper::new(&p, a, settling).expect("sweeper");
    let wf = sweeper.omega_f();
    let mut worst: f64 = 0.0;
    for r in sweeper.sweep(&[0.8, 1.0, 1.25]).expect("sweep") {
        let w = r.ratio * wf;
        let exact = w * w * a / ((wf * wf - w * w).powi(2) + (2.0 * zeta * wf * w).powi(2)).sqrt();
        let lag = (2.0 * zeta * r.ratio).atan2(1.0 - r.ratio * r.ratio);
        eprintln!(
            "16 steps per cycle, r = {}: x {:e}, phase {:e}",
            r.ratio,
            r.x / exact - 1.0,
            r.phase - lag
        );
        worst = worst
            .max((r.x / exact - 1.0).abs())
            .max((r.phase - lag).abs());
    }
    assert!(worst < 5e-3, "{worst:e}");
}

/// The sweeper's clock: the cycles it ran, whole periods of the excitation.
#[test]
fn the_sweep_clock_counts_whole_cycles() {
    let p = table21(ModelKindItem::Linear, 0.05).with(vr::MODES, 1.0);
    let settling = Settling {
        steps_per_cycle: 32,
        ..Settling::default()
    };
    let mut sweeper = Sweeper::new(&p, 1e-3, settling).expect("sweeper");
    let mut cycles = 0.0;
    for ratio in [0.8, 1.25] {
        let r = sweeper.respond(ratio).expect("response");
        let period = 2.0 * std::f64::consts::PI / (ratio * sweeper.omega_f());
        cycles += (f64::from(r.cycles) + f64::from(settling.measure_cycles)) * period;
        assert!(
            (sweeper.time() / cycles - 1.0).abs() < 1e-12,
            "{} vs {cycles}",
            sweeper.time()
        );
    }
}

/// VERIFY.md, the shallow-water model against the mechanical models at moderate amplitude (a
/// coarse 24-cell lab tank, 32 steps per cycle, frequency steps of 0.02 w_f: about 4 s of CPU in
/// a debug build). It hardens as the Nonlinear model with the FMU's defaults (phi = 1, eta = 2,
/// NSD zeta) does by harmonic balance: its quadrature frequency within 0.005 w_f of the
/// Nonlinear model's jump frequency at Lambda = 0.003 (both within 0.6 % of w_f), and at
/// Lambda = 0.03 its hardening kappa - 1 within a quarter of the Nonlinear model's (measured:
/// 0.041 against 0.038) -- the two are independent (no parameter of one is fitted to the
/// other). Its equivalent damping exceeds the boundary layer's alone (bores) and grows with the
/// amplitude as the NSD law's does (measured 0.046 to 0.132; NSD 0.065 to 0.146).
#[test]
fn shallow_water_hardens_and_dissipates_as_the_mechanical_models() {
    let zeta_bl = 0.0151;
    let p = table21(ModelKindItem::ShallowWater, 0.0)
        .with(vr::DAMPING, item(DampingLawItem::BoundaryLayer as i64))
        .with(vr::SWE_CELLS, 24.0);
    let plan = Plan {
        from: 0.9,
        to: 1.5,
        step: 0.02,
        settling: Settling {
            steps_per_cycle: 32,
            tolerance: 3e-3,
            ..Settling::default()
        },
    };
    let wf = tank().fundamental().omega;
    let nonlinear = |lambda: f64| {
        let zeta = 0.5 * lambda.powf(0.35);
        crate::analysis::calibration::kappa_model(wf, 0.25, 1.0, 2.0, lambda, zeta).expect("a jump")
    };
    let (k_small, z_small) = characterise(&p, 0.003, &plan)
        .expect("sweep")
        .quadrature
        .expect("quadrature");
    let (k_large, z_large) = characterise(&p, 0.03, &plan)
        .expect("sweep")
        .quadrature
        .expect("quadrature");
    assert!(
        (k_small - nonlinear(0.003)).abs() < 0.005,
        "{k_small} vs {}",
        nonlinear(0.003)
    );
    let hardening = (k_large - 1.0) / (nonlinear(0.03) - 1.0);
    eprintln!(
        "shallow water: kappa {k_small} (Nonlinear {}), {k_large} (Nonlinear {}); zeta {z_small}, \
         {z_large}",
        nonlinear(0.003),
        nonlinear(0.03)
    );
    assert!(
        (0.75..1.33).contains(&hardening),
        "{k_large} vs {}",
        nonlinear(0.03)
    );
    assert!(k_large > k_small + 0.02, "{k_small} {k_large}");
    assert!(z_small > 2.0 * zeta_bl, "{z_small}");
    assert!(z_large > 2.0 * z_small, "{z_small} {z_large}");
}

/// `p` with damping = Screens and Tait's pair of screens of solidity `s` at 0.4 a and 0.6 a of
/// the lab tank.
fn tait_pair(p: StartValues, s: f64) -> StartValues {
    p.with(vr::DAMPING, item(DampingLawItem::Screens as i64))
        .with(vr::SCREENS_COUNT, 2.0)
        .with(vr::SCREENS_SOLIDITY, s)
        .with(vr::SCREENS_SPACING, 0.05)
}

/// The Screens law `p` configures: the shared parameters, zeta_BL and K (zeta_s = K X).
fn screens_law(p: &StartValues) -> (crate::model::Common, f64, f64) {
    let (common, _) = crate::model::Common::read(p).expect("parameters");
    let crate::physics::laws::DampingLaw::Screens {
        boundary,
        per_response,
        ..
    } = common.damping
    else {
        panic!("not the Screens law")
    };
    (common, boundary, per_response)
}

/// The `Screens` damping law against the shallow-water model with the same screens (Tait's
/// pair at 0.4 a and 0.6 a, S = 0.5, in the lab tank; model = ShallowWater with damping =
/// Screens takes the boundary layers' drag and resolves the screens), swept up through
/// resonance at small base amplitudes: the model's energy-equivalent damping at quadrature
/// against the law's zeta_BL + K X at the model's own response X, and against the law as the
/// mechanical models use it, at the resonant response to A_e. Coarse (32 cells, 32 steps per
/// cycle, about 16 s in a debug build): the figures over Lambda 0.001-0.1 at 150 cells are
/// docs/SCREENS.md's (scripts/screens-report).
#[test]
fn screens_law_matches_the_shallow_water_model_at_small_amplitude() {
    let p = tait_pair(table21(ModelKindItem::ShallowWater, 0.0), 0.5).with(vr::SWE_CELLS, 32.0);
    let plan = Plan {
        from: 0.9,
        to: 1.3,
        step: 0.02,
        settling: Settling {
            steps_per_cycle: 32,
            tolerance: 3e-3,
            ..Settling::default()
        },
    };
    let (common, boundary, per_response) = screens_law(&p);
    for lambda in [0.001, 0.005] {
        let c = characterise(&p, lambda, &plan).expect("sweep");
        let (kappa, zeta) = c.quadrature.expect("quadrature");
        let x = c.peak.x;
        let at_response = boundary + per_response * x;
        let law = common.zeta(lambda * 0.25);
        eprintln!(
            "screens: Lambda {lambda}: shallow water zeta {zeta:.4} at kappa {kappa:.3}, X {x:.4e} \
             m; law at that X {at_response:.4}, law at A_e {law:.4}"
        );
        // Measured at 32 cells: +9 % and +8 % against the law at X, +5 % and +4 % against
        // the law at A_e (the coarse grid's own damping is in the model's figure).
        assert!(
            (zeta / at_response - 1.0).abs() < 0.15,
            "{zeta} vs {at_response}"
        );
        assert!((zeta / law - 1.0).abs() < 0.1, "{zeta} vs {law}");
        assert!(zeta > 3.0 * boundary, "{zeta}: the screens should dominate");
        assert!((kappa - 1.0).abs() < 0.02, "{kappa}");
        // The Linear model with the law, amplitude Fixed at A_e: its resonant response is the
        // law's A_e/(2 zeta), and the shallow-water model's within 10 % of it (measured -5 %
        // and -4 % at 32 cells, -3 % at 150: docs/SCREENS-SWEEP.md).
        let linear = tait_pair(table21(ModelKindItem::Linear, 0.0), 0.5)
            .with(vr::A_E, lambda * 0.25)
            .with(vr::MODES, 1.0);
        let l = characterise(&linear, lambda, &plan).expect("sweep");
        let resonant = lambda * 0.25 / (2.0 * law);
        eprintln!(
            "screens: Lambda {lambda}: Linear + Screens X {:.4e} m (A_e/(2 zeta) {resonant:.4e})",
            l.peak.x
        );
        assert!(
            (l.peak.x / resonant - 1.0).abs() < 0.01,
            "{} vs {resonant}",
            l.peak.x
        );
        assert!((x / l.peak.x - 1.0).abs() < 0.1, "{x} vs {}", l.peak.x);
    }
}

/// The report behind docs/SCREENS-SWEEP.md (scripts/screens-report runs it in a release build:
/// `cargo test --release --lib -- --ignored screens_law_report --nocapture`): the shallow-water
/// model with Tait's pair (S = 0.5 and 0.7) at `swe.cells` = 150, 64 steps per cycle, swept
/// up through resonance at Lambda 0.001 to 0.1; the model's equivalent damping and response at
/// quadrature against the Screens law, and the Linear model with damping = Screens (amplitude
/// Fixed at A_e) swept the same way. Prints a Markdown table; asserts only that every sweep
/// passed quadrature.
#[test]
#[ignore = "a report (scripts/screens-report), about a minute in a release build"]
fn screens_law_report() {
    // Up to 2 omega_f: at S = 0.7, Lambda = 0.1 the hardened tank's quadrature and peak lie
    // beyond 1.5 omega_f (under MUSCL-Hancock; SSPRK(10,4) found it at 1.471).
    let plan = Plan {
        from: 0.9,
        to: 2.0,
        step: 0.02,
        settling: Settling {
            steps_per_cycle: 64,
            tolerance: 2e-3,
            ..Settling::default()
        },
    };
    println!(
        "| S | Lambda | SWE kappa | SWE zeta_eq | SWE X/a | law at SWE X | law at A_e | \
         Linear+Screens X/a | SWE X / Linear X |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for s in [0.5, 0.7] {
        let screens = |p: StartValues| tait_pair(p, s);
        let swe = screens(table21(ModelKindItem::ShallowWater, 0.0)).with(vr::SWE_CELLS, 150.0);
        let (common, boundary, per_response) = screens_law(&swe);
        for lambda in [0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1] {
            let c = characterise(&swe, lambda, &plan).expect("sweep");
            let (kappa, zeta) = c.quadrature.expect("quadrature");
            let x = c.peak.x;
            let linear = screens(table21(ModelKindItem::Linear, 0.0))
                .with(vr::A_E, lambda * 0.25)
                .with(vr::MODES, 1.0);
            let l = characterise(&linear, lambda, &plan).expect("sweep");
            println!(
                "| {s} | {lambda} | {kappa:.3} | {zeta:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.3} |",
                x / 0.25,
                boundary + per_response * x,
                common.zeta(lambda * 0.25),
                l.peak.x / 0.25,
                x / l.peak.x
            );
        }
    }
}
