//! amplitude = Tracked in Model Exchange through TLD.fmu's C entry points: the estimator's
//! filters and velocity rebuild are continuous states, so the estimate (and the damping ratio
//! the NSD law makes of it) follow the host's solution, not its steps. Checked against an
//! independent high-accuracy solution of the estimator's ODEs written here from MODEL.md
//! section 2, against Co-Simulation converging to it as its step shrinks (its held-sample
//! filter is first order in the step), and the switch to a measured base.v as an event.

mod common;

use common::*;
use tld_fmu::fmi::vars::vr;

const N: usize = tld_fmu::model::continuous::ALL_STATES;
/// The estimator's states follow the 24 of the oscillators, the impact mass and the modes.
const T0: usize = tld_fmu::model::continuous::STATES;
const NONLINEAR: i32 = 2;
const NSD: i32 = 2;
/// Base motion A sin(w t) near the default tank's resonance (5.64 rad/s).
const W: f64 = 5.5;
const A: f64 = 0.004;
const T_END: f64 = 8.0;
const OUT: f64 = 0.01;

fn accel(t: f64) -> f64 {
    -W * W * A * (W * t).sin()
}

fn set_up(inst: &Instance) {
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.set_integer(vr::MODEL, NONLINEAR), OK);
    assert_eq!(inst.set_integer(vr::DAMPING, NSD), OK);
    assert_eq!(inst.set_integer(vr::AMPLITUDE, 2), OK);
    assert_eq!(inst.set_real(vr::AMPLITUDE_TAU, 1.0), OK);
}

fn running(name: &str) -> Instance {
    let inst = Instance::model_exchange(name);
    set_up(&inst);
    inst.start_continuous_time();
    inst
}

/// A_e.estimate, zeta.effective and slosh.x every OUT over T_END.
type History = [Vec<f64>; 3];

fn record(inst: &Instance, h: &mut History) {
    for (k, r) in [vr::A_E_ESTIMATE, vr::ZETA_EFFECTIVE, vr::SLOSH_X]
        .into_iter()
        .enumerate()
    {
        h[k].push(inst.real(r));
    }
}

/// The host's RK4 at step `dt` with the input continuous in time.
fn model_exchange(dt: f64) -> History {
    let inst = running("tracked-me");
    let mut h = History::default();
    let per = (OUT / dt).round() as usize;
    let outputs = (T_END / OUT).round() as usize;
    for k in 0..=outputs {
        let t = k as f64 * OUT;
        assert_eq!(inst.set_real(vr::BASE_A, accel(t)), OK);
        record(&inst, &mut h);
        if k < outputs {
            inst.rk4(N, t, t + OUT, per, |i, t| {
                assert_eq!(i.set_real(vr::BASE_A, accel(t)), OK);
            });
        }
    }
    h
}

/// Co-Simulation at step `dt`, base.a sampled at each step's start (held), recorded every OUT.
fn co_simulation(dt: f64) -> History {
    let mut inst = Instance::new("tracked-cs");
    set_up(&inst);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.exit(), OK);
    let mut h = History::default();
    let per = (OUT / dt).round() as usize;
    let steps = (T_END / dt).round() as usize;
    for i in 0..=steps {
        let t = i as f64 * dt;
        assert_eq!(inst.set_real(vr::BASE_A, accel(t)), OK);
        if i % per == 0 {
            record(&inst, &mut h);
        }
        if i < steps {
            assert_eq!(inst.do_step(dt), OK);
        }
    }
    h
}

/// The estimator of MODEL.md section 2 as ODEs, solved here by RK4 at 0.1 ms (its error far
/// below the comparisons'): the velocity rebuilt from the acceleration by v' = a - w_c v
/// (w_c = omega_f/20), two cascaded low-pass filters (time constant tau) of v^2, of a^2 and of
/// 1, and A_e = sqrt(2) <a^2>^(1/2) / (<a^2>/<v^2> - w_c^2) with <.> the second filters
/// divided by the weight's, each with the prior's share (docs/MODEL_EXCHANGE.md): 1e-6 of the
/// mean squares of the prior's motion (A_e at omega_f, the velocity through the leak's gain)
/// added to the filter, 1e-6 to the weight.
fn reference_estimate(omega_f: f64, tau: f64) -> Vec<f64> {
    let wc = 0.05 * omega_f;
    let (share, prior) = (1e-6, 0.005);
    let a0 = 0.5 * (prior * omega_f * omega_f).powi(2);
    let v0 = a0 / (omega_f * omega_f + wc * wc);
    let rates = |t: f64, y: &[f64; 7]| {
        let a = accel(t);
        let v = y[0];
        [
            a - wc * v,
            (v * v - y[1]) / tau,
            (y[1] - y[2]) / tau,
            (a * a - y[3]) / tau,
            (y[3] - y[4]) / tau,
            (1.0 - y[5]) / tau,
            (y[5] - y[6]) / tau,
        ]
    };
    let estimate = |y: &[f64; 7]| {
        let w = y[6] + share;
        let (v2, a2) = ((y[2] + share * v0) / w, (y[4] + share * a0) / w);
        std::f64::consts::SQRT_2 * a2.sqrt() / (a2 / v2 - wc * wc)
    };
    let dt = 1e-4;
    let per = (OUT / dt).round() as usize;
    let mut y = [0.0; 7];
    let mut out = vec![f64::NAN];
    let add = |y: &[f64; 7], k: &[f64; 7], c: f64| std::array::from_fn(|j| y[j] + c * k[j]);
    for i in 0..(T_END / dt).round() as usize {
        let t = i as f64 * dt;
        let k1 = rates(t, &y);
        let k2 = rates(t + dt / 2.0, &add(&y, &k1, dt / 2.0));
        let k3 = rates(t + dt / 2.0, &add(&y, &k2, dt / 2.0));
        let k4 = rates(t + dt, &add(&y, &k3, dt));
        for j in 0..7 {
            y[j] += dt / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
        }
        if (i + 1) % per == 0 {
            out.push(estimate(&y));
        }
    }
    out
}

/// Largest |a - b| after `skip` samples, as a fraction of b's largest magnitude there.
fn error(a: &[f64], b: &[f64], skip: usize) -> f64 {
    let peak = b[skip..].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    a[skip..]
        .iter()
        .zip(&b[skip..])
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
        / peak
}

#[test]
fn tracked_amplitude_follows_its_odes_and_co_simulation_converges_to_it() {
    let omega_f = running("tracked-w").real(vr::OMEGA_F);
    let me = model_exchange(2e-3);
    let me_fine = model_exchange(1e-3);
    // The estimate is the prior until the rebuilt velocity has moved: from 0.5 s on.
    let skip = 50;
    let reference = reference_estimate(omega_f, 1.0);
    let e_ref = error(&me_fine[0], &reference, skip);
    let e_me = (0..3)
        .map(|k| error(&me[k], &me_fine[k], skip))
        .fold(0.0, f64::max);
    let cs: Vec<History> = [2e-3, 1e-3, 5e-4].map(co_simulation).into();
    let e_cs: Vec<[f64; 3]> = cs
        .iter()
        .map(|c| std::array::from_fn(|k| error(&c[k], &me_fine[k], skip)))
        .collect();
    let table: Vec<String> = e_cs
        .iter()
        .map(|e| format!("[{:.1e}, {:.1e}, {:.1e}]", e[0], e[1], e[2]))
        .collect();
    println!(
        "Tracked in ME (RK4 1 ms): A_e.estimate vs the ODEs' RK4 at 0.1 ms {e_ref:.1e}; ME 2 ms \
         vs 1 ms {e_me:.1e}; CS at 2, 1, 0.5 ms vs ME [A_e.estimate, zeta.effective, slosh.x]: \
         {}; A_e.estimate at the end {:.5} m (A = {A})",
        table.join(" "),
        me_fine[0].last().unwrap_or(&f64::NAN)
    );
    assert!(e_ref < 1e-8, "{e_ref}");
    assert!(e_me < 1e-7, "{e_me}");
    // Co-Simulation's held-sample filter is first order in its step: its difference from ME
    // halves with the step (ratio 2 +- 0.3; seen 2.00 for each output), and at 0.5 ms is
    // below 0.2 % (seen 1.1e-3, 6.4e-4, 1.4e-3).
    for k in 0..3 {
        for pair in e_cs.windows(2) {
            let ratio = pair[0][k] / pair[1][k];
            assert!((1.7..2.3).contains(&ratio), "output {k}: {e_cs:?}");
        }
        assert!(e_cs[2][k] < 2e-3, "{e_cs:?}");
    }
}

/// A base.v other than 0 switches the estimator to the measured velocity: the next
/// fmi2CompletedIntegratorStep asks for event mode, fmi2NewDiscreteStates restarts the
/// statistics (the continuous states changed), and the estimator's states are 0 again.
#[test]
fn a_measured_base_velocity_is_an_event() {
    let inst = running("tracked-event");
    inst.rk4(N, 0.0, 1.0, 500, |i, t| {
        assert_eq!(i.set_real(vr::BASE_A, accel(t)), OK);
    });
    let (_, x) = inst.states(N);
    assert!(x[T0 + 1..T0 + 7].iter().all(|v| *v > 0.0), "{x:?}");
    assert_eq!(inst.set_real(vr::BASE_V, 0.02), OK);
    let (s, (event, terminate)) = inst.completed_integrator_step();
    assert_eq!((s, event, terminate), (OK, 1, 0));
    assert_eq!(inst.enter_event_mode(), OK);
    let (s, info) = inst.new_discrete_states();
    assert_eq!((s, info.valuesOfContinuousStatesChanged), (OK, 1));
    let (_, y) = inst.states(N);
    assert!(y[T0 + 1..T0 + 7].iter().all(|v| *v == 0.0), "{y:?}");
    assert_eq!(y[T0], x[T0]);
    // Once switched, no further event; the rates now read base.v.
    let (_, info) = inst.new_discrete_states();
    assert_eq!(info.valuesOfContinuousStatesChanged, 0);
    assert_eq!(inst.enter_continuous_time_mode(), OK);
    let (_, d) = inst.derivatives(N);
    assert!(
        (d[T0 + 1] - 0.02 * 0.02 / 1.0).abs() < 1e-15,
        "{}",
        d[T0 + 1]
    );
    assert_eq!(inst.completed_integrator_step().1, (0, 0));
}

/// The filters start at 0 and a host solver's trial step may put a mean square or the weight
/// slightly below 0 (fmpy's CVode did at t = 0.011 s, fmusim's at 1e-10 s): such a state is a
/// host's trial, taken, with finite derivatives and outputs; only a non-finite one is refused.
#[test]
fn a_trial_state_with_a_mean_square_below_zero_is_taken() {
    let inst = running("tracked-trial");
    assert_eq!(inst.set_real(vr::BASE_A, accel(0.3)), OK);
    let (_, x) = inst.states(N);
    for k in T0 + 1..T0 + 7 {
        let mut trial = x.clone();
        trial[k] = -1e-9;
        assert_eq!(inst.set_states(&trial), OK, "state {k}: {:?}", inst.logs());
        assert_eq!(inst.states(N).1[k], -1e-9);
        let (s, d) = inst.derivatives(N);
        assert_eq!(s, OK);
        assert!(d.iter().all(|v| v.is_finite()), "state {k}: {d:?}");
        for r in [vr::A_E_ESTIMATE, vr::ZETA_EFFECTIVE, vr::FORCE] {
            assert!(inst.real(r).is_finite(), "state {k}, vr {r}");
        }
        assert_eq!(inst.completed_integrator_step().0, OK);
    }
    let mut bad = x.clone();
    bad[T0 + 3] = f64::NAN;
    assert_ne!(inst.set_states(&bad), OK);
    assert_eq!(inst.states(N).1[T0 + 3], x[T0 + 3]);
}
