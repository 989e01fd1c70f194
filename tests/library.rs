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
    let models: Vec<i32> = ModelKindItem::ALL
        .iter()
        .map(|m| m.value() as i32)
        .collect();
    let run = move |name: String, model: i32, k: usize| {
        let mut inst = Instance::new(&name);
        assert_eq!(inst.setup(), OK);
        assert_eq!(inst.enter(), OK);
        assert_eq!(inst.set_integer(vr::MODEL, model), OK);
        assert_eq!(inst.exit(), OK);
        inst.run_harmonic(300 + 50 * k, 0.01).to_bits()
    };
    let cases: Vec<(i32, usize)> = models
        .iter()
        .flat_map(|&m| (0..2usize).map(move |k| (m, k)))
        .collect();
    let serial: Vec<u64> = cases
        .iter()
        .map(|&(m, k)| run(format!("serial-{m}-{k}"), m, k))
        .collect();
    let threads: Vec<_> = cases
        .iter()
        .map(|&(m, k)| std::thread::spawn(move || run(format!("thread-{m}-{k}"), m, k)))
        .collect();
    let parallel: Vec<u64> = threads
        .into_iter()
        .map(|t| t.join().expect("thread"))
        .collect();
    assert_eq!(serial, parallel);
}

/// The library exports the 44 fmi2 functions and nothing of its own, except `callback_log`:
/// a #[no_mangle] function inside the fmi-sys crate (its logger shim for FMU importers), which
/// rustc exports from every cdylib that links fmi-sys. It is never called by this FMU.
#[test]
fn exports_only_fmi2_functions() {
    let out = std::process::Command::new("nm")
        .args(["-D", "--defined-only"])
        .arg(library_path())
        .output()
        .expect("nm (binutils) must be installed");
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    let symbols: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split_whitespace().nth(2))
        .collect();
    let fmi: Vec<&&str> = symbols.iter().filter(|s| s.starts_with("fmi2")).collect();
    let other: Vec<&&str> = symbols.iter().filter(|s| !s.starts_with("fmi2")).collect();
    assert_eq!(fmi.len(), 44, "{fmi:?}");
    assert_eq!(other, vec![&"callback_log"], "unexpected exports");
}
