//! Building.fmu's library as a host loads it: what it exports, instances in threads, and the
//! FMI layer's transparency (the same run through the C interface and directly through the
//! model).

mod host;

use building_model::propagator::Propagator;
use building_model::structure::{Building, Design, Harmonic};
use host::*;

/// The same run through the C interface and through the structure and its propagator directly
/// is bit-identical: the FMI layer adds nothing and loses nothing (ground.a and the built-in
/// ground motion together).
#[test]
fn fmi_layer_is_transparent() {
    let (h, steps) = (0.01, 300);
    let mut inst = Instance::new("transparent");
    inst.initialise(&[
        (vr::STOREYS, 2.0),
        (vr::TLD_MASS, 3.0),
        (vr::GROUND_AMPLITUDE, 0.002),
        (vr::GROUND_OMEGA, 7.0),
    ]);
    let ground = |t: f64| 0.4 * (5.0 * t).sin();
    for _ in 0..steps {
        assert_eq!(inst.set_real(vr::GROUND_A, ground(inst.time)), OK);
        assert_eq!(inst.do_step(h), OK);
    }
    let through_fmi = inst.real(vr::ROOF_X);
    // The model description's defaults for the two storeys.
    let building = Building::new(&Design {
        masses: vec![168.0; 2],
        stiffnesses: vec![5342.0; 2],
        zeta: [0.02; 2],
        damper_floor: 2,
        damper_mass: 3.0,
        ground: Harmonic {
            amplitude: 0.002,
            omega: 7.0,
        },
    })
    .expect("design");
    let (a, b) = building.state_space();
    let step = Propagator::new(&a, &b, h);
    let mut z = building.initial_state();
    let mut t = 0.0;
    for _ in 0..steps {
        let mut p = vec![0.0; 3 * building.channels()];
        p[0] = ground(t);
        let mut next = vec![0.0; z.len()];
        step.advance(&z, &p, &mut next);
        z = next;
        t += h;
    }
    assert_eq!(
        through_fmi.to_bits(),
        z[1].to_bits(),
        "{through_fmi} vs {}",
        z[1]
    );
    assert!(through_fmi.abs() > 1e-4, "the run must move: {through_fmi}");
}

/// Instances in threads give the serial runs' numbers bit for bit.
#[test]
fn concurrent_instances_match_serial_runs() {
    let cases: Vec<usize> = (1..=8).collect();
    assert_threads_match_serial(&cases, |name, storeys| {
        let mut inst = Instance::new(&name);
        inst.initialise(&[(vr::STOREYS, storeys as f64)]);
        for _ in 0..200 {
            let t = inst.time;
            assert_eq!(inst.set_real(vr::GROUND_A, (3.0 * t).sin()), OK);
            assert_eq!(inst.do_step(0.01), OK);
        }
        inst.real(vr::TLD_A).to_bits()
    });
}

/// The library exports the 44 fmi2 functions and nothing of its own but fmi-sys's
/// `callback_log` (see tests/fmi_host).
#[test]
fn exports_only_fmi2_functions() {
    assert_exports_only_fmi2_functions();
}
