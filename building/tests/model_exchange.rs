//! Building.fmu in Model Exchange through its C entry points: the padded state vector, its
//! derivatives against the exact Co-Simulation step, and the directional derivatives of its
//! linear system (exact) against differences of fmi2GetDerivatives and the outputs.

mod host;

use host::*;

/// Declared continuous states: floor[i].x, floor[i].v for 20 storeys, ground.x, ground.v,
/// ground.motion.x, ground.motion.v.
const N: usize = 44;

const THREE_STOREYS: [(u32, f64); 5] = [
    (vr::STOREYS, 3.0),
    (vr::TLD_MASS, 0.35),
    (vr::STOREY_1__STIFFNESS + 2, 4000.0),
    (vr::GROUND_AMPLITUDE, 0.004),
    (vr::GROUND_OMEGA, 6.5),
];

fn running(name: &str) -> Instance {
    let inst = Instance::model_exchange(name);
    inst.initialise(&THREE_STOREYS);
    let (s, info) = inst.new_discrete_states();
    assert_eq!((s, info.newDiscreteStatesNeeded), (OK, 0));
    assert_eq!(inst.enter_continuous_time_mode(), OK);
    inst
}

/// A state with every floor of the three-storey building and the ground moving; the padding
/// (storeys 4 to 20) at 0.
fn some_state() -> Vec<f64> {
    let mut x = vec![0.0; N];
    for (k, v) in [0.01, -0.02, 0.015].iter().enumerate() {
        x[k] = *v;
        x[20 + k] = 3.0 * v + 0.1;
    }
    x[40..].copy_from_slice(&[0.002, -0.03, 0.001, 0.02]);
    x
}

/// The ground starts with the built-in motion's velocity A w, the building at rest; the padded
/// states of storeys above the building's stay 0 and have derivative 0.
#[test]
fn states_start_at_rest_and_the_padding_stays_zero() {
    // The states and derivatives are initial unknowns: readable in initialisation mode (FMI
    // Library hosts such as libcosim read them there).
    let init = Instance::model_exchange("me-init");
    assert_eq!(init.setup(), OK);
    assert_eq!(init.enter(), OK);
    assert_eq!(init.set_real(vr::GROUND_AMPLITUDE, 0.004), OK);
    assert_eq!(init.get_real(vr::DER_GROUND_X_), (OK, 0.004 * 5.6389));
    let inst = running("me-start");
    let (s, x) = inst.states(N);
    assert_eq!(s, OK);
    let v0 = 0.004 * 6.5;
    assert_eq!(x[41], v0);
    assert_eq!(x[43], v0);
    assert!(x[..40].iter().all(|v| *v == 0.0));
    assert_eq!(inst.set_states(&some_state()), OK);
    let (_, d) = inst.derivatives(N);
    assert!(d[3..20].iter().chain(&d[23..40]).all(|v| *v == 0.0));
    // x' = v for the floors and the ground, and the built-in motion is free: h'' = -w^2 h.
    let x = some_state();
    assert_eq!(d[..3], x[20..23]);
    assert_eq!(d[40], x[41]);
    assert!((d[43] + 6.5 * 6.5 * x[42]).abs() < 1e-15);
    // The derivative variables read the same.
    assert_eq!(inst.real(vr::DER_FLOOR_1__V_), d[20]);
    assert_eq!(inst.real(vr::FLOOR_1__V + 1), x[21]);
}

/// J d for unit directions d: exactly the difference of fmi2GetDerivatives (and of the
/// outputs) between the state (input) plus d and the state, the system being linear; and two
/// entries written out: roof.x by floor[3].x is 1, tld.a by tld.force is 1/(floor mass +
/// tld.mass).
#[test]
fn directional_derivatives_are_the_linear_system_s() {
    let inst = running("me-jacobian");
    let x = some_state();
    assert_eq!(inst.set_states(&x), OK);
    assert_eq!(inst.set_real(vr::TLD_FORCE, 2.0), OK);
    let (_, d0) = inst.derivatives(N);
    let der = |k: usize| -> u32 {
        match k {
            0..20 => vr::DER_FLOOR_1__X_ + k as u32,
            20..40 => vr::DER_FLOOR_1__V_ + (k - 20) as u32,
            _ => vr::DER_GROUND_X_ + (k - 40) as u32,
        }
    };
    let state = |k: usize| -> u32 {
        match k {
            0..20 => vr::FLOOR_1__X + k as u32,
            20..40 => vr::FLOOR_1__V + (k - 20) as u32,
            _ => vr::GROUND_X + (k - 40) as u32,
        }
    };
    let unknowns: Vec<u32> = (0..N).map(der).collect();
    for k in [0, 2, 21, 22, 40, 41, 42, 43] {
        let mut j = vec![f64::NAN; N];
        let s = unsafe {
            inst.lib.fmi2GetDirectionalDerivative(
                inst.c,
                unknowns.as_ptr(),
                N,
                &state(k),
                1,
                &1.0,
                j.as_mut_ptr(),
            )
        };
        assert_eq!(s, OK, "{:?}", inst.logs());
        let mut moved = x.clone();
        moved[k] += 1.0;
        assert_eq!(inst.set_states(&moved), OK);
        let (_, d1) = inst.derivatives(N);
        assert_eq!(inst.set_states(&x), OK);
        for i in 0..N {
            let want = d1[i] - d0[i];
            assert!(
                (j[i] - want).abs() <= 1e-9 * want.abs().max(1.0),
                "d der[{i}] / d state[{k}]: {} vs {want}",
                j[i]
            );
        }
    }
    let one = |unknown: u32, known: u32| {
        let mut v = f64::NAN;
        let s = unsafe {
            inst.lib
                .fmi2GetDirectionalDerivative(inst.c, &unknown, 1, &known, 1, &1.0, &mut v)
        };
        assert_eq!(s, OK, "{:?}", inst.logs());
        v
    };
    assert_eq!(one(vr::ROOF_X, vr::FLOOR_1__X + 2), 1.0);
    assert_eq!(one(vr::ROOF_X, vr::FLOOR_1__X), 0.0);
    let floor = 168.0 + 0.35;
    assert!((one(vr::TLD_A, vr::TLD_FORCE) - 1.0 / floor).abs() < 1e-15);
    // A known that is neither a state nor an input, an unknown that is neither a derivative
    // nor an output: refused, saying so.
    let mut v = 0.0;
    let bad = unsafe {
        inst.lib
            .fmi2GetDirectionalDerivative(inst.c, &vr::ROOF_X, 1, &vr::STOREYS, 1, &1.0, &mut v)
    };
    assert_eq!(bad, ERROR);
    assert!(
        inst.logs()
            .join("\n")
            .contains("neither a continuous state nor an input")
    );
}

/// The inputs drive the derivatives through B: from the same state, tld.force F on the
/// damper's floor (3) adds F/(m_3 + tld.mass) to floor[3].v's derivative and nothing to the
/// others; ground.a adds -a_g to every floor's relative acceleration and a_g to ground.v's. The locals ground.x,
/// ground.v, ground.motion.x and .v read the state's last four entries.
#[test]
fn inputs_enter_the_derivatives_and_the_ground_locals_read_the_state() {
    let inst = running("me-inputs");
    let x = some_state();
    assert_eq!(inst.set_states(&x), OK);
    for k in 0..4 {
        assert_eq!(
            inst.real(vr::GROUND_X + k),
            x[40 + k as usize],
            "ground local {k}"
        );
    }
    let (_, d0) = inst.derivatives(N);
    let (force, ag) = (12.0, 0.7);
    let m3 = inst.real(vr::STOREY_1__MASS + 2) + 0.35;
    assert_eq!(inst.set_real(vr::TLD_FORCE, force), OK);
    let (_, d1) = inst.derivatives(N);
    assert_eq!(inst.set_real(vr::TLD_FORCE, 0.0), OK);
    assert_eq!(inst.set_real(vr::GROUND_A, ag), OK);
    let (_, d2) = inst.derivatives(N);
    for k in 0..N {
        let by_force = if k == 22 { force / m3 } else { 0.0 };
        let by_ground = match k {
            20..23 => -ag,
            41 => ag, // ground.v integrates ground.a
            _ => 0.0,
        };
        assert!(
            (d1[k] - d0[k] - by_force).abs() < 1e-12,
            "tld.force, {k}: {} {}",
            d1[k],
            d0[k]
        );
        assert!(
            (d2[k] - d0[k] - by_ground).abs() < 1e-12,
            "ground.a, {k}: {} {}",
            d2[k],
            d0[k]
        );
    }
}

/// The nominals (MODEL_EXCHANGE.md): floors' displacements the first storey's static drift
/// under 1 g of the building's mass, m g / k_1, velocities that times omega_1 = sqrt(k_1 / m)
/// (one storey, stiff enough that neither is clamped to 1), the ground's 1.
#[test]
fn nominals_are_the_static_drift_and_its_velocity() {
    let (m, k) = (168.0_f64, 53420.0_f64);
    let inst = Instance::model_exchange("me-nominals");
    inst.initialise(&[
        (vr::STOREYS, 1.0),
        (vr::STOREY_1__MASS, m),
        (vr::STOREY_1__STIFFNESS, k),
    ]);
    let (s, nominal) = inst.nominals(N);
    assert_eq!(s, OK);
    let x = m * 9.81 / k;
    let v = x * (k / m).sqrt();
    assert!(v < 1.0);
    for (j, got) in nominal.iter().enumerate() {
        let want = match j {
            0..20 => x,
            20..40 => v,
            _ => 1.0,
        };
        assert!(
            (got - want).abs() <= 1e-12 * want,
            "nominal {j}: {got} vs {want}"
        );
    }
}

/// tld.impulse, a discrete input: refused in continuous-time mode; set in event mode, the
/// next fmi2NewDiscreteStates makes the damper's floor's velocity jump by the change over its
/// mass with tld.mass (the other floors and the displacements unchanged, states reported
/// changed), tld.v.jump reports the jumps so far, and a second call changes nothing.
#[test]
fn an_impulse_on_the_damper_floor_jumps_its_velocity_by_the_change_over_its_mass() {
    let inst = running("me-impulse");
    assert_eq!(inst.set_states(&some_state()), OK);
    assert_eq!(inst.set_real(vr::TLD_IMPULSE, 1.0), ERROR);
    let floor_mass = 168.0 + 0.35; // storey[3].mass (default) + tld.mass
    let mut expected = some_state();
    for (k, p) in [(1, 2.5), (2, 2.5 - 4.0)] {
        let (_, before) = inst.states(N);
        assert_eq!(inst.enter_event_mode(), OK);
        assert_eq!(inst.set_real(vr::TLD_IMPULSE, p), OK);
        let (s, info) = inst.new_discrete_states();
        assert_eq!(
            (s, info.valuesOfContinuousStatesChanged),
            (OK, 1),
            "event {k}"
        );
        let (_, after) = inst.states(N);
        let change = if k == 1 { 2.5 } else { -4.0 };
        expected[22] += change / floor_mass;
        for i in 0..N {
            assert!(
                (after[i] - expected[i]).abs() <= 1e-15,
                "event {k}, state {i}"
            );
            if i != 22 {
                assert_eq!(after[i], before[i], "event {k}, state {i}");
            }
        }
        assert!((inst.real(vr::TLD_V_JUMP) - p / floor_mass).abs() < 1e-16);
        let (_, again) = inst.new_discrete_states();
        assert_eq!(again.valuesOfContinuousStatesChanged, 0);
        assert_eq!(inst.enter_continuous_time_mode(), OK);
    }
}
