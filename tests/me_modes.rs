//! model = Linear with more than one mode in Model Exchange through TLD.fmu's C entry points:
//! the modes above the fundamental are the bank of states mode[n].x, mode[n].v (n = 2..10). A
//! host integrates them by RK4 under a held harmonic input and every mode, the total force and
//! the energies follow the exact solution (Co-Simulation's Linear model is each mode's exact
//! held-input propagator; tests/python/test_me_modes.py checks against the closed form). More
//! modes than the bank holds are refused with the reason.

mod common;

use common::*;
use tld_fmu::fmi::vars::{VARIABLES, vr};

/// All continuous states (the amplitude estimator's and the ShallowWater cells after these, 0 here).
const N: usize = tld_fmu::model::continuous::ALL_STATES;
const DT: f64 = 0.01;

fn linear(name: &str, me: bool, modes: i32) -> Instance {
    let integers = [
        (vr::MODEL, 1),
        (vr::MODES, modes),
        (vr::DAMPING, 1),
        (vr::AMPLITUDE, 1),
    ];
    configured(
        name,
        me,
        &integers,
        &[(vr::ZETA, 0.02), (vr::SLOSH_X0, 0.01)],
    )
}

/// Ten modes under held base motion near the fundamental's resonance for 5 s: RK4 at 0.1 ms
/// (omega_10 h = 0.005) against the exact propagator, at every sample.
#[test]
fn a_host_integrates_ten_modes_to_the_exact_solution() {
    let modes = 10;
    let me = linear("me-modes", true, modes);
    assert_eq!(me.exit(), OK, "{:?}", me.logs());
    assert_eq!(me.new_discrete_states().0, OK);
    assert_eq!(me.enter_continuous_time_mode(), OK);
    let mut cs = linear("cs-modes", false, modes);
    assert_eq!(cs.exit(), OK);
    let w = me.real(vr::OMEGA_F);
    let watched: Vec<u32> = [
        "slosh.x",
        "force",
        "energy.input",
        "energy.dissipated",
        "mode[2].x",
        "mode[2].v",
        "mode[5].x",
        "mode[10].x",
        "mode[10].v",
    ]
    .iter()
    .map(|n| vr_of(n))
    .collect();
    let mut worst = vec![0.0f64; watched.len()];
    let mut peak = vec![0.0f64; watched.len()];
    for k in 0..500 {
        let t = k as f64 * DT;
        let a = -w * w * 0.004 * (w * t).sin();
        assert_eq!(cs.set_real(vr::BASE_A, a), OK);
        assert_eq!(cs.do_step(DT), OK);
        me.rk4(N, t, t + DT, 100, |i, _| {
            assert_eq!(i.set_real(vr::BASE_A, a), OK);
        });
        for (j, &r) in watched.iter().enumerate() {
            let (got, want) = (me.real(r), cs.real(r));
            worst[j] = worst[j].max((got - want).abs());
            peak[j] = peak[j].max(want.abs());
        }
    }
    for (j, &r) in watched.iter().enumerate() {
        let name = VARIABLES.iter().find(|v| v.vr == r).map_or("?", |v| v.name);
        println!(
            "{name}: error {:.1e} of its peak {:.2e}",
            worst[j] / peak[j],
            peak[j]
        );
        assert!(peak[j] > 0.0, "{name} never moved");
        assert!(
            worst[j] < 1e-9 * peak[j],
            "{name}: {} of {}",
            worst[j],
            peak[j]
        );
    }
    // The bank beyond the model's modes: none here; all modes are moving.
    let (_, x) = me.states(N);
    let modes = tld_fmu::model::continuous::STATES;
    assert!(x[6..modes].iter().all(|v| *v != 0.0), "{x:?}");
}

/// Fewer modes: the bank's pairs beyond them stay 0 with derivative 0; more than ten modes are
/// refused at fmi2ExitInitializationMode with the reason, and fewer can be chosen then.
#[test]
fn the_bank_beyond_the_modes_stays_zero_and_more_modes_are_refused() {
    let me = linear("me-modes-3", true, 3);
    assert_eq!(me.exit(), OK, "{:?}", me.logs());
    assert_eq!(me.new_discrete_states().0, OK);
    assert_eq!(me.enter_continuous_time_mode(), OK);
    me.rk4(N, 0.0, 0.5, 500, |i, t| {
        assert_eq!(i.set_real(vr::BASE_A, (6.0 * t).sin()), OK);
    });
    let (_, x) = me.states(N);
    let (_, d) = me.derivatives(N);
    assert!(
        x[6..10].iter().all(|v| *v != 0.0),
        "modes 2 and 3 move: {x:?}"
    );
    assert!(
        x[10..].iter().chain(&d[10..]).all(|v| *v == 0.0),
        "{x:?} {d:?}"
    );

    let too_many = linear("me-modes-11", true, 11);
    assert_eq!(too_many.exit(), ERROR);
    assert!(
        too_many.logs().join("\n").contains("at most 10 modes"),
        "{:?}",
        too_many.logs()
    );
    assert_eq!(too_many.set_integer(vr::MODES, 10), OK);
    assert_eq!(too_many.exit(), OK);
}
