//! S^2's impacts in a Model Exchange coupling, through TLD.fmu's C entry points: an impact's
//! momentum leaves as the discrete output impact.impulse (its change at the event is the
//! impact mass times its velocity before less after), and a jump of the tank's velocity comes
//! back as the discrete input base.v.jump (set in event mode: the liquid keeps its absolute
//! velocity, so slosh.v and the flying impact.v drop by the change, and the energy balance
//! still closes); refused in continuous-time mode, as FMI 2.0 asks of discrete inputs.

mod common;

use common::*;
use tld_fmu::fmi::vars::vr;

const N: usize = tld_fmu::model::continuous::ALL_STATES;
const D: f64 = 0.1;
const E: f64 = 0.4;
const OMEGA: f64 = 0.8;
const RATIO: f64 = 0.01;

fn s2_in_model_exchange() -> Instance {
    let integers = [(vr::MODEL, 3), (vr::DAMPING, 1), (vr::AMPLITUDE, 1)];
    let reals = [
        (vr::ZETA, 0.02),
        (vr::SLAMMING_OMEGA, OMEGA),
        (vr::SLAMMING_CLEARANCE, D),
        (vr::SLAMMING_RESTITUTION, E),
        (vr::SLAMMING_MASS_RATIO, RATIO),
    ];
    let inst = configured("me-impulse", true, &integers, &reals);
    assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
    let (s, info) = inst.new_discrete_states();
    assert_eq!((s, info.newDiscreteStatesNeeded), (OK, 0));
    assert_eq!(inst.enter_continuous_time_mode(), OK);
    inst
}

fn balance(inst: &Instance) -> f64 {
    inst.real(vr::ENERGY_INPUT) - inst.real(vr::ENERGY_STORED) - inst.real(vr::ENERGY_DISSIPATED)
}

#[test]
fn an_impact_hands_its_momentum_out_and_a_base_velocity_jump_shifts_the_liquid() {
    let inst = s2_in_model_exchange();
    let impact_mass = inst.real(vr::MASS_SLOSH) / (1.0 + RATIO) * (RATIO + 1.0 - OMEGA);
    assert_eq!(inst.real(vr::IMPACT_IMPULSE), 0.0);
    // The impact mass at the wall +d/2 moving into it at 0.3 m/s, the sloshing mode moving.
    let (_, mut x) = inst.states(N);
    x[..6].copy_from_slice(&[0.01, 0.2, 0.0, 0.0, 0.5 * D, 0.3]);
    assert_eq!(inst.set_states(&x), OK);
    let start_balance = balance(&inst);
    assert_eq!(inst.set_real(vr::BASE_V_JUMP, 0.01), ERROR);
    assert_eq!(inst.enter_event_mode(), OK);
    let (s, info) = inst.new_discrete_states();
    assert_eq!((s, info.valuesOfContinuousStatesChanged), (OK, 1));
    let p = inst.real(vr::IMPACT_IMPULSE);
    let expected = impact_mass * (1.0 + E) * 0.3;
    assert!((p - expected).abs() < 1e-15, "{p} vs {expected}");
    // The host's structure took it: the tank's velocity jumps by 0.02 m/s.
    assert_eq!(inst.set_real(vr::BASE_V_JUMP, 0.02), OK);
    let (s, info) = inst.new_discrete_states();
    assert_eq!((s, info.valuesOfContinuousStatesChanged), (OK, 1));
    let (_, after) = inst.states(N);
    assert!((after[1] - (0.2 - 0.02)).abs() < 1e-15);
    assert!((after[5] - (-E * 0.3 - 0.02)).abs() < 1e-15);
    assert_eq!(after[0], 0.01);
    assert_eq!(after[4], 0.5 * D);
    // energy.input took the kinetic energy the jump changed: the balance still closes.
    assert!((balance(&inst) - start_balance).abs() < 1e-15);
    // Nothing new: no change, no impact (the mass now leaves the wall).
    let (_, info) = inst.new_discrete_states();
    assert_eq!(info.valuesOfContinuousStatesChanged, 0);
    assert_eq!(inst.real(vr::IMPACT_IMPULSE), p);
    assert_eq!(inst.enter_continuous_time_mode(), OK);
}
