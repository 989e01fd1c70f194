//! The built library as a host loads it (dlopen): what it exports, instances in threads, and
//! the FMI layer's transparency (the same run through the C interface and directly through the
//! simulation).

mod common;

use common::*;
use tld_fmu::fmi::vars::{ModelKindItem, vr};
use tld_fmu::model::{Damper, Inputs, Output, StartValues};

/// The FMI layer adds nothing and loses nothing: the same run through the C interface and
/// directly through the simulation is bit-identical.
#[test]
fn fmi_layer_is_transparent() {
    let mut inst = Instance::new("transparent");
    inst.initialise();
    let x_fmu = inst.run_harmonic(500, 0.01);
    // The model description's defaults, which the instance runs too.
    let (mut sim, _) = Damper::configure(&StartValues::default()).expect("defaults");
    let w = 6.0;
    let mut t = 0.0;
    for _ in 0..500 {
        let inputs = Inputs {
            a: -w * w * 0.004 * f64::sin(w * t),
            ..Inputs::default()
        };
        sim.step(t, 0.01, &inputs).expect("step");
        t += 0.01;
    }
    let direct = sim.output(Output::X, &Inputs::default());
    assert_eq!(x_fmu.to_bits(), direct.to_bits(), "{x_fmu} vs {direct}");
    assert!(x_fmu.abs() > 1e-3, "the run must actually slosh: {x_fmu}");
}

/// Instances in threads give the serial runs' numbers bit for bit, for every model (the
/// items of the model description's `model` enumeration), two instances of each.
#[test]
fn concurrent_instances_match_serial_runs() {
    let cases: Vec<(i32, usize)> = ModelKindItem::ALL
        .iter()
        .flat_map(|m| (0..2usize).map(move |k| (m.value() as i32, k)))
        .collect();
    assert_threads_match_serial(&cases, |name, (model, k)| {
        let mut inst = Instance::new(&name);
        assert_eq!(inst.setup(), OK);
        assert_eq!(inst.enter(), OK);
        assert_eq!(inst.set_integer(vr::MODEL, model), OK);
        assert_eq!(inst.exit(), OK);
        inst.run_harmonic(300 + 50 * k, 0.01).to_bits()
    });
}

/// The library exports the 44 fmi2 functions and nothing of its own but fmi-sys's
/// `callback_log` (see tests/fmi_host).
#[test]
fn exports_only_fmi2_functions() {
    assert_exports_only_fmi2_functions();
}
