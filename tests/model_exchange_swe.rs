//! model = ShallowWater in Model Exchange through TLD.fmu's C entry points: a host's RK4 of
//! the semi-discrete equations (the cells as states) against the linear mode's closed form in
//! the small-amplitude limit, against Co-Simulation (the fully discrete scheme) under resonant
//! forcing with and without screens, with the mass conserved and the states the FMU computes
//! from the cells (slosh.v, energy.dissipated) matching those the host integrates; the cells'
//! stencil (what the model description's dependencies declare); the refusals (a negative
//! depth: fmi2Discard; swe.cells above the bank).

mod common;

use common::*;
use tld_fmu::fmi::vars::vr;
use tld_fmu::model::shallow_water::continuous::{CELL_STATES, ME_CELLS};

const N: usize = tld_fmu::model::continuous::ALL_STATES;
const SHALLOW_WATER: i32 = 5;
/// The bank's first depth and discharge in the state vector (after the four and the
/// amplitude estimator's seven).
const H0: usize = N - CELL_STATES;
const Q0: usize = H0 + ME_CELLS;

struct Case {
    cells: f64,
    zeta: f64,
    x0: f64,
    v0: f64,
    screens: i32,
}

const FREE: Case = Case {
    cells: 150.0,
    zeta: 0.03,
    x0: 0.0005,
    v0: 0.002,
    screens: 0,
};

fn set_up(inst: &Instance, c: &Case) {
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.set_integer(vr::MODEL, SHALLOW_WATER), OK);
    assert_eq!(inst.set_integer(vr::DAMPING, 1), OK);
    assert_eq!(inst.set_real(vr::ZETA, c.zeta), OK);
    assert_eq!(inst.set_integer(vr::AMPLITUDE, 1), OK);
    assert_eq!(inst.set_real(vr::SLOSH_X0, c.x0), OK);
    assert_eq!(inst.set_real(vr::SLOSH_V0, c.v0), OK);
    assert_eq!(inst.set_integer(vr::SWE_CELLS, c.cells as i32), OK);
    assert_eq!(inst.set_integer(vr::SCREENS_COUNT, c.screens), OK);
}

/// An ME instance of the case in continuous-time mode.
fn running(name: &str, c: &Case) -> Instance {
    let inst = Instance::model_exchange(name);
    set_up(&inst, c);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
    assert_eq!(inst.new_discrete_states().0, OK);
    assert_eq!(inst.enter_continuous_time_mode(), OK);
    inst
}

/// What a host run records at each output point: time, slosh.x, slosh.v, force, and the
/// host's own integrals of der(slosh.v) and der(energy.dissipated).
#[derive(Default)]
struct Record {
    t: Vec<f64>,
    x: Vec<f64>,
    v: Vec<f64>,
    force: Vec<f64>,
    host_v: Vec<f64>,
    host_dissipated: Vec<f64>,
    dissipated: Vec<f64>,
    volume: Vec<f64>,
}

/// Classical RK4 of all states by the host over [0, t1] in steps of `h` under base.a =
/// a(t0, t) (t0 the step's start: a held input is a(t0)), recording every `every` steps.
fn rk4(inst: &Instance, t1: f64, h: f64, every: usize, a: impl Fn(f64, f64) -> f64) -> Record {
    let steps = (t1 / h).round() as usize;
    let (s, mut x) = inst.states(N);
    assert_eq!(s, OK);
    let f = |t0: f64, t: f64, x: &[f64]| {
        assert_eq!(inst.set_time(t), OK);
        assert_eq!(inst.set_real(vr::BASE_A, a(t0, t)), OK);
        assert_eq!(inst.set_states(x), OK, "{:?}", inst.logs());
        let (s, d) = inst.derivatives(N);
        assert_eq!(s, OK, "{:?}", inst.logs());
        d
    };
    let axpy = |x: &[f64], k: &[f64], c: f64| -> Vec<f64> {
        x.iter().zip(k).map(|(x, k)| x + c * k).collect()
    };
    let mut r = Record::default();
    for i in 0..=steps {
        let t = i as f64 * h;
        if i % every == 0 {
            assert_eq!(inst.set_real(vr::BASE_A, a(t, t)), OK);
            r.t.push(t);
            r.x.push(inst.real(vr::SLOSH_X));
            r.v.push(inst.real(vr::SLOSH_V));
            r.force.push(inst.real(vr::FORCE));
            r.dissipated.push(inst.real(vr::ENERGY_DISSIPATED));
            r.host_v.push(x[1]);
            r.host_dissipated.push(x[3]);
            r.volume.push(x[H0..Q0].iter().sum());
        }
        if i == steps {
            break;
        }
        let k1 = f(t, t, &x);
        let k2 = f(t, t + h / 2.0, &axpy(&x, &k1, h / 2.0));
        let k3 = f(t, t + h / 2.0, &axpy(&x, &k2, h / 2.0));
        let k4 = f(t, t + h, &axpy(&x, &k3, h));
        for j in 0..N {
            x[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
        }
        assert_eq!(inst.set_time(t + h), OK);
        assert_eq!(inst.set_states(&x), OK, "{:?}", inst.logs());
        let (s, (event, _)) = inst.completed_integrator_step();
        assert_eq!((s, event), (OK, 0));
    }
    r
}

/// Largest |a - b| over the history, as a fraction of b's largest magnitude.
fn error(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let peak = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
        / peak
}

/// The same case in Co-Simulation at communication steps of `h` (the scheme's own CFL
/// substeps inside), base.a held over each step from its start, recorded every step.
fn co_simulation(c: &Case, t1: f64, h: f64, a: impl Fn(f64) -> f64) -> Record {
    let mut inst = Instance::new("swe-cs");
    set_up(&inst, c);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
    let mut r = Record::default();
    let steps = (t1 / h).round() as usize;
    for i in 0..=steps {
        let t = i as f64 * h;
        assert_eq!(inst.set_real(vr::BASE_A, a(t)), OK);
        r.t.push(t);
        r.x.push(inst.real(vr::SLOSH_X));
        r.v.push(inst.real(vr::SLOSH_V));
        r.force.push(inst.real(vr::FORCE));
        if i < steps {
            assert_eq!(inst.do_step(h), OK, "{:?}", inst.logs());
        }
    }
    r
}

/// A small fundamental-mode slosh's free decay, integrated by the host, is the linear mode
/// of Eqs 2.1, 2.2 in closed form (the Co-Simulation test's case and tolerance: 1 % of the
/// peak, the scheme's dispersion and the waves' nonlinearity); the volume stays the tank's to
/// round-off, and the states the FMU reads from the cells stay those the host integrates.
#[test]
fn a_small_slosh_decays_as_the_linear_mode() {
    let inst = running("swe-me-free", &FREE);
    let w = inst.real(vr::OMEGA_F);
    let r = rk4(&inst, 3.0, 1e-3, 10, |_, _| 0.0);
    let (zeta, x0, v0) = (FREE.zeta, FREE.x0, FREE.v0);
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let mode = |t: f64| {
        let (c, s, e) = ((wd * t).cos(), (wd * t).sin(), (-zeta * w * t).exp());
        let b = (v0 + zeta * w * x0) / wd;
        let x = e * (x0 * c + b * s);
        let v = e * ((-zeta * w) * (x0 * c + b * s) + wd * (-x0 * s + b * c));
        (x, v)
    };
    let (x, v): (Vec<f64>, Vec<f64>) = r.t.iter().map(|&t| mode(t)).unzip();
    let (ex, ev) = (error(&r.x, &x), error(&r.v, &v));
    println!(
        "ShallowWater ME, linear limit, 150 cells, RK4 1 ms: slosh.x {ex:.2e}, slosh.v {ev:.2e}"
    );
    // 1.7e-3 seen (Co-Simulation's test allows 1 %).
    assert!(ex < 5e-3 && ev < 5e-3, "{ex} {ev}");
    let volume = r.volume[0];
    let drift = r
        .volume
        .iter()
        .fold(0.0f64, |m, v| m.max((v - volume).abs()))
        / volume;
    println!("  volume drift {drift:.1e}");
    assert!(drift < 1e-13, "{drift}");
    // The FMU's slosh.v and energy.dissipated (from the cells) against the host's integrals of
    // their derivatives: equal up to the host's RK4 error.
    let (e_v, e_d) = (
        error(&r.host_v, &r.v),
        error(&r.host_dissipated, &r.dissipated),
    );
    println!("  host-integrated slosh.v {e_v:.1e}, energy.dissipated {e_d:.1e}");
    assert!(e_v < 1e-9 && e_d < 1e-6, "{e_v} {e_d}");
    assert!(r.dissipated.last().is_some_and(|d| *d > 0.0));
}

/// Resonant forcing (base 2 mm at omega_f: the waves steepen into bores): the host's RK4 of
/// the semi-discrete equations at 1 ms and 0.5 ms agree (the ME solution converged, to the
/// limiter's reduced order), and Co-Simulation's fully discrete scheme (SSPRK(10,4) at its CFL
/// substeps) at 10 ms communication steps differs from it by its own time-stepping error (its
/// 5 ms run shows that the communication step is not it: the CFL substeps are), the input held
/// over each 10 ms in both. Over 3 s, errors as fractions of the peaks: [ME 1 ms vs 0.5 ms,
/// slosh.x ME vs CS, force ME vs CS, CS 5 ms vs 10 ms].
fn against_co_simulation(c: &Case, name: &str) -> [f64; 4] {
    let hold = 0.01;
    let w = running("swe-me-w", c).real(vr::OMEGA_F);
    let amplitude = 0.002;
    let sample = |t: f64| -w * w * amplitude * (w * t).sin();
    let held = |t0: f64| sample((t0 / hold + 1e-9).floor() * hold);
    let t1 = 3.0;
    let me = |h: f64| {
        let inst = running(name, c);
        rk4(&inst, t1, h, (hold / h).round() as usize, |t0, _| held(t0))
    };
    let (fine, finer) = (me(1e-3), me(5e-4));
    let cs = co_simulation(c, t1, hold, held);
    let e_me = error(&fine.x, &finer.x).max(error(&fine.force, &finer.force));
    let e_x = error(&finer.x, &cs.x);
    let e_force = error(&finer.force, &cs.force);
    // Co-Simulation at 5 ms with the same held input, sampled every 10 ms: its own step error.
    let cs5 = co_simulation(c, t1, hold / 2.0, held);
    let every = |r: &[f64]| r.iter().step_by(2).copied().collect::<Vec<_>>();
    let e_cs = error(&every(&cs5.x), &cs.x).max(error(&every(&cs5.force), &cs.force));
    let peak = finer.x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    println!(
        "{name}: ME RK4 1 ms vs 0.5 ms {e_me:.1e}; ME vs CS 10 ms: slosh.x {e_x:.1e}, force \
         {e_force:.1e}; CS 5 ms vs 10 ms {e_cs:.1e}; peak slosh.x {peak:.3e} m"
    );
    let volume = finer.volume[0];
    let drift = finer
        .volume
        .iter()
        .fold(0.0f64, |m, v| m.max((v - volume).abs()))
        / volume;
    assert!(drift < 1e-13, "{drift}");
    [e_me, e_x, e_force, e_cs]
}

/// Without screens and with two (S = 0.5), each with its bounds: [ME 1 ms vs 0.5 ms, slosh.x
/// ME vs CS, force ME vs CS]. Seen without screens: 1.0e-5 (the force's bores); 3.7e-6,
/// 7.6e-5 (9.1e-5, 6.0e-6, 8.9e-4 over 4 s). With screens: 7.2e-7; 4.2e-3, 5.6e-3 (over 4 s
/// 2.5e-5, 4.9e-3, 6.9e-3): Co-Simulation splits the screens' loss from the fluxes at its CFL
/// substeps (l |u| dt near 1 in the screens' cells), ME does not; the split's error is
/// Co-Simulation's, and no shorter communication step reduces it (CS 5 ms vs 10 ms: 5.1e-6).
#[test]
fn resonant_forcing_matches_co_simulation() {
    for (screens, bounds) in [(0, [3e-4, 5e-5, 3e-3]), (2, [1e-4, 1e-2, 1.5e-2])] {
        let c = Case {
            x0: 0.0,
            v0: 0.0,
            zeta: 0.01,
            screens,
            ..FREE
        };
        let name = format!("ShallowWater ME, {screens} screens");
        let [e_me, e_x, e_force, _] = against_co_simulation(&c, &name);
        for (got, bound) in [e_me, e_x, e_force].into_iter().zip(bounds) {
            assert!(got < bound, "{name}: {e_me} {e_x} {e_force}");
        }
    }
}

/// The cells beyond swe.cells are frozen (0, derivative 0, the host's values ignored); each
/// cell's derivatives read only the cells i - 2 .. i + 2 (the dependencies the model
/// description declares); a negative depth is fmi2Discard with the reason, the states
/// unchanged; a perturbed volume is taken (difference quotients); swe.cells above the bank is
/// refused at fmi2ExitInitializationMode.
#[test]
fn cells_frozen_stencil_and_refusals() {
    let c = Case {
        cells: 20.0,
        x0: 0.003,
        v0: 0.01,
        ..FREE
    };
    let inst = running("swe-me-refusals", &c);
    assert_eq!(inst.set_real(vr::BASE_A, 0.3), OK);
    let (s, x) = inst.states(N);
    assert_eq!(s, OK);
    let (s, d) = inst.derivatives(N);
    assert_eq!(s, OK);
    let n = 20;
    let frozen: Vec<usize> = (H0 + n..Q0)
        .chain(Q0 + n..N)
        .filter(|&k| x[k] != 0.0)
        .collect();
    assert!(frozen.is_empty(), "{frozen:?} {:?}", &x[..H0]);
    assert!(d[H0 + n..Q0].iter().chain(&d[Q0 + n..]).all(|v| *v == 0.0));
    assert!(x[H0..H0 + n].iter().all(|h| *h > 0.0));
    assert!(d[Q0..Q0 + n].iter().any(|v| *v != 0.0));
    let mut y = x.clone();
    y[H0 + n] = 5.0;
    y[Q0 + ME_CELLS - 1] = -7.0;
    assert_eq!(inst.set_states(&y), OK);
    assert_eq!(inst.derivatives(N).1, d, "a frozen cell's value was read");
    // Stencil: a change of cell j's depth and discharge changes the rates of i - 2 .. i + 2.
    for j in [0, 1, 7, n - 2, n - 1] {
        let mut y = x.clone();
        y[H0 + j] += 1e-5;
        y[H0 + (j + 5) % n] -= 1e-5; // the same volume
        y[Q0 + j] += 1e-4;
        assert_eq!(inst.set_states(&y), OK, "{:?}", inst.logs());
        let (_, e) = inst.derivatives(N);
        for i in 0..n {
            let far = i.abs_diff(j) > 2 && i.abs_diff((j + 5) % n) > 2;
            if far {
                assert_eq!(e[H0 + i], d[H0 + i], "cell {i} reads cell {j}");
                assert_eq!(e[Q0 + i], d[Q0 + i], "cell {i} reads cell {j}");
            }
        }
    }
    assert_eq!(inst.set_states(&x), OK);
    // A negative depth: the host's step was too long; a shorter one may do.
    let mut y = x.clone();
    y[H0 + 2] = -1e-6;
    y[H0 + 3] += 1e-6;
    assert_eq!(inst.set_states(&y), DISCARD);
    let said = inst.logs().join("\n");
    assert!(
        said.contains("swe.h[3]") && said.contains("below 0"),
        "{said}"
    );
    assert_eq!(inst.states(N).1, x);
    // A state with more liquid (a host's difference quotient perturbs one cell) is taken, and
    // its rates are those of the perturbed state.
    let mut y = x.clone();
    y[H0 + 2] *= 1.0 + 1e-8;
    assert_eq!(inst.set_states(&y), OK);
    // (slosh.x and energy.dissipated are the cells', not the host's.)
    assert_eq!(inst.states(N).1[H0..], y[H0..]);
    assert_ne!(inst.derivatives(N).1, d);
    assert_eq!(inst.set_states(&x), OK);
    assert_eq!(inst.derivatives(N).1, d);

    let big = Instance::model_exchange("swe-me-big");
    set_up(
        &big,
        &Case {
            cells: (ME_CELLS + 1) as f64,
            ..FREE
        },
    );
    assert_eq!(big.enter(), OK);
    assert_eq!(big.exit(), ERROR);
    let said = big.logs().join("\n");
    assert!(
        said.contains("swe.cells = 201") && said.contains("Co-Simulation"),
        "{said}"
    );
}

/// An FMU state saved in continuous-time mode (serialised) restores into a new ME instance to
/// the same cells and the same continuation, bit for bit; ME instances of ShallowWater in
/// threads give the serial runs' numbers.
#[test]
fn shallow_water_states_save_restore_and_threads() {
    let c = Case {
        cells: 30.0,
        ..FREE
    };
    fn a(_: f64, t: f64) -> f64 {
        0.3 * (5.0 * t).sin()
    }
    let inst = running("swe-save", &c);
    rk4(&inst, 0.2, 1e-3, 200, a);
    let bytes = inst.serialised();
    let (_, saved) = inst.states(N);
    let end = rk4(&inst, 0.2, 1e-3, 200, a);
    let other = running("swe-restored", &Case { x0: 0.0, ..c });
    let mut s = restore(&other, &bytes);
    assert_eq!(other.states(N), (OK, saved));
    let again = rk4(&other, 0.2, 1e-3, 200, a);
    assert_eq!((again.x, again.force), (end.x, end.force));
    assert_eq!(unsafe { other.lib.fmi2FreeFMUstate(other.c, &mut s) }, OK);

    assert_threads_match_serial(&[0.001, -0.002, 0.003], move |name, x0| {
        let c = Case {
            cells: 30.0,
            x0,
            ..FREE
        };
        let inst = running(&name, &c);
        rk4(&inst, 0.1, 1e-3, 100, a);
        let (_, x) = inst.states(N);
        x.iter().fold(0u64, |h, v| h.rotate_left(7) ^ v.to_bits())
    });
}
