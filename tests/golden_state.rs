//! The saved-state layout is pinned: a state of format version 1 for every model is committed
//! under tests/golden/. A run that reaches the same point must serialise to exactly those bytes,
//! and the committed bytes, restored into a new instance, must continue exactly as the
//! uninterrupted run. A change of the layout (or of what a model saves) fails here; regenerate
//! the files with `TLD_BLESS=1 cargo test --test golden_state` only together with a new format
//! version or a deliberate change of the numbers, and say so in the commit.
//!
//! The input is built from + and * only, so the scene is the same wherever it runs; the
//! model's own libm calls (exp, sin, cos of the propagators) make the bytes those of this
//! platform (x86_64 Linux, glibc).

mod common;

use common::*;
use std::path::PathBuf;
use tld_fmu::fmi::vars::{AmplitudeModeItem, ModelKindItem, vr};

/// Steps before the state is taken, and after.
const BEFORE: usize = 150;
const AFTER: usize = 100;
const H: f64 = 0.01;

/// A triangle wave of base acceleration, 0.4 s period, +-0.8 m/s^2: arithmetic only.
fn base_a(k: usize) -> f64 {
    let phase = (k % 40) as f64;
    let tri = if phase < 20.0 {
        phase - 10.0
    } else {
        30.0 - phase
    };
    0.08 * tri
}

fn configured(name: &str, model: ModelKindItem) -> Instance {
    let inst = Instance::new(name);
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.set_integer(vr::MODEL, model.value() as i32), OK);
    // The tracked amplitude saves its estimator too.
    assert_eq!(
        inst.set_integer(vr::AMPLITUDE, AmplitudeModeItem::Tracked.value() as i32),
        OK
    );
    if model == ModelKindItem::Linear {
        assert_eq!(inst.set_integer(vr::MODES, 3), OK);
    }
    if model == ModelKindItem::SloshingSlamming {
        // A clearance small enough for impacts within the run.
        assert_eq!(inst.set_real(vr::SLAMMING_CLEARANCE, 0.01), OK);
    }
    assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
    inst
}

/// Steps k = from..to; slosh.x and force after each.
fn run(inst: &mut Instance, from: usize, to: usize) -> Vec<(u64, u64)> {
    (from..to)
        .map(|k| {
            assert_eq!(inst.set_real(vr::BASE_A, base_a(k)), OK);
            assert_eq!(inst.do_step(H), OK, "{:?}", inst.logs());
            (
                inst.get_real(vr::SLOSH_X).1.to_bits(),
                inst.get_real(vr::FORCE).1.to_bits(),
            )
        })
        .collect()
}

/// The instance's state, serialised (the state itself freed).
fn state_bytes(inst: &Instance) -> Vec<u8> {
    let mut s = get_state(inst);
    let bytes = serialize(inst, s);
    // SAFETY: our instance and its state, freed once.
    assert_eq!(unsafe { inst.lib.fmi2FreeFMUstate(inst.c, &mut s) }, OK);
    bytes
}

fn golden(model: ModelKindItem) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("state-v1-{}.bin", model.name()))
}

#[test]
fn committed_states_of_version_1_restore_and_continue_bit_for_bit() {
    let bless = std::env::var_os("TLD_BLESS").is_some();
    for model in ModelKindItem::ALL {
        let mut source = configured(&format!("golden-{}", model.name()), model);
        run(&mut source, 0, BEFORE);
        let bytes = state_bytes(&source);
        let uninterrupted = run(&mut source, BEFORE, BEFORE + AFTER);
        let path = golden(model);
        if bless {
            std::fs::write(&path, &bytes).expect("write the golden state");
        }
        let committed = std::fs::read(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (TLD_BLESS=1 writes it)", path.display()));
        // The header: magic, then the format version, little-endian.
        assert_eq!(&committed[..4], b"TLDs");
        assert_eq!(u16::from_le_bytes([committed[4], committed[5]]), 1);
        assert!(
            committed == bytes,
            "{}: the state this build saves differs from the committed one ({} vs {} bytes, first difference at byte {:?})",
            model.name(),
            bytes.len(),
            committed.len(),
            committed.iter().zip(&bytes).position(|(a, b)| a != b)
        );
        let mut older = vec![committed];
        if model == ModelKindItem::SloshingSlamming {
            // The same point saved by the builds before S^2's impulse was saved (the slot of
            // impact.impulse not listed): it restores, and the motion continues the same.
            older.push(
                std::fs::read(path.with_file_name("state-v1-SloshingSlamming-before-impulse.bin"))
                    .expect("the state of the earlier builds"),
            );
        }
        for committed in older {
            let mut target = Instance::new(&format!("golden-target-{}", model.name()));
            let mut restored = restore(&target, &committed);
            // SAFETY: our instance and its state, freed once.
            assert_eq!(
                unsafe { target.lib.fmi2FreeFMUstate(target.c, &mut restored) },
                OK
            );
            target.time = BEFORE as f64 * H;
            let continued = run(&mut target, BEFORE, BEFORE + AFTER);
            assert_eq!(continued, uninterrupted, "{}", model.name());
            assert_ne!(continued[AFTER - 1].0, 0f64.to_bits(), "the run must slosh");
        }
    }
}

/// impact.impulse is part of the saved state: an S^2 instance restored mid-run hands the same
/// impulse over as the run it was taken from (before, it counted from 0 again, and a host
/// that restored Building.fmu too would have seen the impulse taken back).
#[test]
fn the_impact_impulse_is_saved_and_restored() {
    let model = ModelKindItem::SloshingSlamming;
    let mut source = configured("impulse-source", model);
    run(&mut source, 0, BEFORE);
    let impulse = source.real(vr::IMPACT_IMPULSE);
    assert_ne!(impulse, 0.0, "the run must have impacts");
    let bytes = state_bytes(&source);
    let target = Instance::new("impulse-target");
    let mut restored = restore(&target, &bytes);
    // SAFETY: our instance and its state, freed once.
    assert_eq!(
        unsafe { target.lib.fmi2FreeFMUstate(target.c, &mut restored) },
        OK
    );
    assert_eq!(target.real(vr::IMPACT_IMPULSE).to_bits(), impulse.to_bits());
}
