//! Building.fmu's saved-state layout is pinned: a state of format version 2 (tag "BLDs") is
//! committed under building/tests/golden/. A run that reaches the same point must serialise to
//! exactly those bytes, and the committed bytes, restored into a new instance, must continue
//! exactly as the uninterrupted run. Regenerate with `BUILDING_BLESS=1 cargo test -p
//! building-fmu --test golden_state` only with a new format version or a deliberate change of
//! the numbers, and say so in the commit.
//!
//! Version 2 (2026-11-24) added the built-in ground motion's oscillator to the state
//! (ground.amplitude, ground.omega; the run below uses it beside ground.a); the version 1 file
//! stays, and is refused by name.
//!
//! The inputs are built from + and * only; the matrix exponential is nalgebra's (Pade, scaling
//! and squaring), so the bytes are those of this platform (x86_64 Linux).

mod host;

use host::*;
use std::path::PathBuf;

const BEFORE: usize = 120;
const AFTER: usize = 80;
const H: f64 = 0.01;

/// Triangle waves of ground acceleration and damper force: arithmetic only.
fn inputs(k: usize) -> (f64, f64) {
    let phase = (k % 40) as f64;
    let tri = if phase < 20.0 {
        phase - 10.0
    } else {
        30.0 - phase
    };
    (0.05 * tri, 0.3 * tri - 1.0)
}

fn drive(inst: &mut Instance, from: usize, steps: usize) {
    for k in from..from + steps {
        let (a, f) = inputs(k);
        assert_eq!(inst.set_real(vr::GROUND_A, a), OK);
        assert_eq!(inst.set_real(vr::TLD_FORCE, f), OK);
        assert_eq!(inst.derivative(vr::GROUND_A, 1, 0.05 * 25.0), OK);
        assert_eq!(inst.do_step(H), OK);
    }
}

fn configured(name: &str) -> Instance {
    let inst = Instance::new(name);
    inst.initialise(&[
        (vr::STOREYS, 3.0),
        (vr::TLD_FLOOR, 2.0),
        (vr::TLD_MASS, 1.5),
        (vr::DAMPING_ZETA1, 0.02),
        (vr::DAMPING_ZETA2, 0.03),
        (vr::STOREY_1__STIFFNESS + 2, 4000.0),
        (vr::GROUND_AMPLITUDE, 0.004),
        (vr::GROUND_OMEGA, 6.5),
    ]);
    inst
}

#[test]
fn version_2_state_is_pinned_and_continues_bit_for_bit() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden/state-v2.bin");
    let mut run = configured("golden-run");
    drive(&mut run, 0, BEFORE);
    let bytes = run.serialised();
    if std::env::var_os("BUILDING_BLESS").is_some() {
        std::fs::write(&path, &bytes).expect("write the golden state");
    }
    let golden = std::fs::read(&path).expect("building/tests/golden/state-v2.bin");
    assert_eq!(&golden[..4], b"BLDs");
    assert_eq!(bytes, golden, "the saved state's bytes changed");
    let mut restored = Instance::new("golden-restored");
    assert_eq!(restored.restore(&golden), OK, "{:?}", restored.logs());
    restored.time = run.time;
    drive(&mut run, BEFORE, AFTER);
    drive(&mut restored, BEFORE, AFTER);
    for r in [vr::TLD_A, vr::TLD_V, vr::TLD_X, vr::ROOF_X, vr::BASE_SHEAR] {
        assert_eq!(run.real(r).to_bits(), restored.real(r).to_bits(), "{r}");
    }
}

/// A version 1 state (before the built-in ground motion) is refused, saying why, and the
/// instance is left as it was.
#[test]
fn version_1_state_is_refused_by_its_version() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden/state-v1.bin");
    let old = std::fs::read(&path).expect("building/tests/golden/state-v1.bin");
    let mut inst = configured("golden-v1");
    drive(&mut inst, 0, 3);
    let before = inst.real(vr::ROOF_X);
    assert_ne!(inst.restore(&old), OK);
    let logs = inst.logs().join("\n");
    assert!(logs.contains("version 1 is not supported"), "{logs}");
    assert_eq!(inst.real(vr::ROOF_X).to_bits(), before.to_bits());
}
