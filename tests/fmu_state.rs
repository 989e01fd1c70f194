//! FMU states through the C entry points of the built library: get/set round trips, serialised
//! states restored in another instance (the S^2 model's impact state included), and buffers
//! that are not states of this FMU refused.

mod common;

use common::*;
use tld_fmu::fmi::vars::{ModelKindItem, vr};

/// Get a state, run on, set it back, run the same again: bit-identical.
#[test]
fn fmu_state_round_trip_is_bit_identical() {
    let mut inst = tracked("state-roundtrip");
    inst.run_harmonic(150, 0.01);
    let s = get_state(&inst);
    let t_saved = inst.time;
    let first = inst.run_harmonic(200, 0.01);
    let first_estimate = inst.get_real(vr::A_E_ESTIMATE).1;
    assert_eq!(unsafe { inst.lib.fmi2SetFMUstate(inst.c, s) }, OK);
    inst.time = t_saved;
    let again = inst.run_harmonic(200, 0.01);
    assert_eq!(first.to_bits(), again.to_bits());
    assert_eq!(
        first_estimate.to_bits(),
        inst.get_real(vr::A_E_ESTIMATE).1.to_bits()
    );
    // Overwriting an existing state in place, then freeing it (twice: the slot is nulled).
    let mut s2 = s;
    unsafe {
        assert_eq!(inst.lib.fmi2GetFMUstate(inst.c, &mut s2), OK);
        assert_eq!(s2, s, "the host's state is reused");
        assert_eq!(inst.lib.fmi2FreeFMUstate(inst.c, &mut s2), OK);
        assert!(s2.is_null());
        assert_eq!(inst.lib.fmi2FreeFMUstate(inst.c, &mut s2), OK);
    }
}

/// A serialised state restores in another instance that never ran, and continues exactly as
/// the uninterrupted run.
#[test]
fn serialized_state_restores_in_another_instance() {
    let mut a = tracked("state-source");
    a.run_harmonic(120, 0.01);
    let s = get_state(&a);
    let bytes = serialize(&a, s);
    let t_saved = a.time;
    let uninterrupted = a.run_harmonic(180, 0.01);
    let mut b = Instance::new("state-target");
    let restored = restore(&b, &bytes);
    b.time = t_saved;
    let continued = b.run_harmonic(180, 0.01);
    assert_eq!(uninterrupted.to_bits(), continued.to_bits());
    // A state taken before initialisation brings an initialised instance back there.
    let fresh = Instance::new("state-early");
    assert_eq!(fresh.setup(), OK);
    assert_eq!(fresh.enter(), OK);
    let early = get_state(&fresh);
    assert_eq!(unsafe { b.lib.fmi2SetFMUstate(b.c, early) }, OK);
    assert_eq!(b.exit(), OK, "back in initialisation mode");
    unsafe {
        let mut s = s;
        let mut restored = restored;
        let mut early = early;
        a.lib.fmi2FreeFMUstate(a.c, &mut s);
        b.lib.fmi2FreeFMUstate(b.c, &mut restored);
        fresh.lib.fmi2FreeFMUstate(fresh.c, &mut early);
    }
}

/// Truncated, corrupted, foreign and wrong-version buffers are refused with a reason, and the
/// instance is unharmed.
#[test]
fn bad_serialized_states_are_refused() {
    let mut inst = Instance::new("state-bad");
    inst.initialise();
    inst.run_harmonic(50, 0.01);
    let s = get_state(&inst);
    let bytes = serialize(&inst, s);
    let reference = {
        let mut clean = Instance::new("state-bad-clean");
        clean.initialise();
        clean.run_harmonic(50, 0.01);
        clean.run_harmonic(50, 0.01)
    };
    let mut refused = 0;
    for len in 0..bytes.len() {
        assert_eq!(
            deserialize(&inst, &bytes[..len]).0,
            ERROR,
            "truncated to {len}"
        );
        refused += 1;
    }
    for at in 0..bytes.len() {
        let mut bad = bytes.clone();
        bad[at] ^= 0x5a;
        assert_eq!(deserialize(&inst, &bad).0, ERROR, "byte {at} flipped");
        refused += 1;
    }
    let mut longer = bytes.clone();
    longer.push(0);
    assert_eq!(deserialize(&inst, &longer).0, ERROR, "trailing byte");
    let foreign: Vec<u8> = (0..bytes.len()).map(|i| (i * 37 % 251) as u8).collect();
    assert_eq!(deserialize(&inst, &foreign).0, ERROR, "foreign bytes");
    // A well-formed buffer of another format version (checksum recomputed).
    let mut other = bytes[..bytes.len() - 8].to_vec();
    other[4] = 2;
    other.extend_from_slice(&fmi2_slave::frame::fnv1a(&other).to_le_bytes());
    assert_eq!(deserialize(&inst, &other).0, ERROR, "version 2");
    let logs = inst.logs();
    assert!(logs.iter().any(|m| m.contains("truncated")), "{logs:?}");
    assert!(logs.iter().any(|m| m.contains("checksum")), "{logs:?}");
    assert!(logs.iter().any(|m| m.contains("version 2")), "{logs:?}");
    assert!(refused > 2 * 100);
    unsafe {
        // Pointers that are not states of ours.
        let mut junk = 7u64;
        assert_eq!(
            inst.lib
                .fmi2SetFMUstate(inst.c, &mut junk as *mut u64 as *mut _),
            ERROR
        );
        assert_eq!(
            inst.lib.fmi2SetFMUstate(inst.c, std::ptr::null_mut()),
            ERROR
        );
        let mut s = s;
        inst.lib.fmi2FreeFMUstate(inst.c, &mut s);
    }
    assert_eq!(inst.run_harmonic(50, 0.01).to_bits(), reference.to_bits());
}

/// An initialised instance of the shallow-water model with 30 cells.
/// Where a serialised TLD state's payload starts (fmi2_slave::frame: tag, version, GUID length
/// and GUID, payload length): its phase first.
fn payload_at(bytes: &[u8]) -> usize {
    10 + usize::from(u16::from_le_bytes([bytes[8], bytes[9]])) + 4
}

/// The little-endian u32 at `at`, as an index.
fn u32_at(bytes: &[u8], at: usize) -> usize {
    u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize
}

/// Where TLD's simulation list starts (its length, then the model's state and the frame): after
/// the payload's phase, flags, four times, two input derivatives and the values (src/fmi/snapshot.rs).
fn simulation_at(bytes: &[u8]) -> usize {
    let values = payload_at(bytes) + 2 + 4 * 8 + 2 * 8;
    values + 4 + 8 * u32_at(bytes, values)
}

fn shallow_water(name: &str) -> Instance {
    let inst = Instance::new(name);
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(
        inst.set_integer(vr::MODEL, ModelKindItem::ShallowWater.value() as i32),
        OK
    );
    assert_eq!(inst.set_integer(vr::SWE_CELLS, 30), OK);
    assert_eq!(inst.exit(), OK);
    inst
}

/// The shallow-water model's state (every cell's depth and discharge, the work done) survives
/// a serialised round trip into another instance, and both continue bit for bit.
#[test]
fn shallow_water_state_round_trip() {
    let start = shallow_water;
    let mut a = start("swe-source");
    a.run_harmonic(200, 0.01);
    let s = get_state(&a);
    let bytes = serialize(&a, s);
    let t_saved = a.time;
    let uninterrupted = a.run_harmonic(200, 0.01);
    let mut b = start("swe-target");
    let restored = restore(&b, &bytes);
    b.time = t_saved;
    let continued = b.run_harmonic(200, 0.01);
    assert_eq!(continued.to_bits(), uninterrupted.to_bits());
    let mut s = s;
    let mut r = restored;
    unsafe {
        a.lib.fmi2FreeFMUstate(a.c, &mut s);
        b.lib.fmi2FreeFMUstate(b.c, &mut r);
    }
}

/// A shallow-water state whose discharges are finite but absurd (1e290 m^2/s), its checksum
/// recomputed, is refused by fmi2DeSerializeFMUstate with the variable it would make
/// non-finite: before, it was accepted and fmi2GetReal then handed out force = -inf and NaN
/// derivatives (found by the coverage-guided fuzzer: fuzz/, deserialize_tld).
#[test]
fn a_state_whose_outputs_would_not_be_finite_is_refused() {
    let inst = shallow_water("state-absurd");
    let s = get_state(&inst);
    let bytes = serialize(&inst, s);
    // The frame (fmi2_slave::frame) and TLD's part (src/fmi/snapshot.rs): header, then the
    // payload's phase, flags, four times, two input derivatives, the values, the simulation
    // (the model's state first: 30 depths, then 30 discharges).
    let simulation = simulation_at(&bytes);
    assert!(u32_at(&bytes, simulation) > 60);
    let mut absurd = bytes[..bytes.len() - 8].to_vec();
    for cell in 30..60 {
        let at = simulation + 4 + 8 * cell;
        absurd[at..at + 8].copy_from_slice(&1e290f64.to_le_bytes());
    }
    absurd.extend_from_slice(&fmi2_slave::frame::fnv1a(&absurd).to_le_bytes());
    let (status, mut made) = deserialize(&inst, &absurd);
    assert_eq!(status, ERROR);
    assert!(made.is_null());
    let logs = inst.logs();
    assert!(
        logs.last().is_some_and(|m| m.contains("its values give")),
        "{logs:?}"
    );
    // The same bytes with the discharges left as they were load.
    let (status, mut good) = deserialize(&inst, &bytes);
    assert_eq!(status, OK);
    let mut s = s;
    unsafe {
        inst.lib.fmi2FreeFMUstate(inst.c, &mut s);
        inst.lib.fmi2FreeFMUstate(inst.c, &mut good);
        inst.lib.fmi2FreeFMUstate(inst.c, &mut made);
    }
}

/// A state of a model Model Exchange does not offer (ShallowWater) does not restore into a Model
/// Exchange instance, whatever phase it claims: before, a forged one (phase ContinuousTimeMode,
/// checksum right) was taken and fmi2GetContinuousStates panicked on the missing cell bank,
/// caught as an internal error (found by the coverage-guided fuzzer: fuzz/, deserialize_tld).
#[test]
fn a_state_of_a_model_not_offered_in_model_exchange_is_refused_there() {
    let inst = shallow_water("swe-cs-state");
    let s = get_state(&inst);
    let bytes = serialize(&inst, s);
    // The payload starts with the phase (fmi2_slave::frame): 3 Terminated, 5 ContinuousTimeMode.
    let payload = payload_at(&bytes);
    let me = Instance::model_exchange("swe-me-target");
    for phase in [3u8, 5] {
        let mut forged = bytes[..bytes.len() - 8].to_vec();
        forged[payload] = phase;
        forged.extend_from_slice(&fmi2_slave::frame::fnv1a(&forged).to_le_bytes());
        let (status, made) = deserialize(&me, &forged);
        assert_eq!(status, ERROR, "phase {phase}");
        assert!(made.is_null());
        let logs = me.logs();
        assert!(
            logs.last()
                .is_some_and(|m| m.contains("Model Exchange is not offered")),
            "{logs:?}"
        );
    }
    let mut s = s;
    unsafe { inst.lib.fmi2FreeFMUstate(inst.c, &mut s) };
}

/// The S^2 model's state (impact mass position, velocity, wall contact, count) survives a
/// serialised round trip into another instance, bit for bit.
#[test]
fn slamming_state_round_trip() {
    let start = |name: &str| {
        let inst = Instance::new(name);
        assert_eq!(inst.setup(), OK);
        assert_eq!(inst.enter(), OK);
        assert_eq!(inst.set_integer(vr::MODEL, 3), OK);
        assert_eq!(inst.set_real(vr::SLAMMING_OMEGA, 0.9), OK);
        assert_eq!(inst.exit(), OK);
        inst
    };
    let mut a = start("s2-source");
    a.run_harmonic(300, 0.01);
    let s = get_state(&a);
    let bytes = serialize(&a, s);
    let t_saved = a.time;
    let uninterrupted = a.run_harmonic(300, 0.01);
    let impacts = |i: &Instance| {
        let mut n = 0;
        unsafe { i.lib.fmi2GetInteger(i.c, &vr::IMPACTS, 1, &mut n) };
        n
    };
    let n_a = impacts(&a);
    assert!(n_a >= 1, "the scene must slam: {n_a} impacts");
    let mut b = start("s2-target");
    let restored = restore(&b, &bytes);
    b.time = t_saved;
    assert_eq!(b.run_harmonic(300, 0.01).to_bits(), uninterrupted.to_bits());
    assert_eq!(impacts(&b), n_a);
    assert_eq!(
        b.get_real(vr::IMPACT_Z).1.to_bits(),
        a.get_real(vr::IMPACT_Z).1.to_bits()
    );
    unsafe {
        let (mut s, mut r) = (s, restored);
        a.lib.fmi2FreeFMUstate(a.c, &mut s);
        b.lib.fmi2FreeFMUstate(b.c, &mut r);
    }
}

/// Nominals are always usable scales: a state whose fixed amplitude is finite but extreme
/// (forged, checksum right) made the estimator's nominals overflow to inf in
/// fmi2GetNominalsOfContinuousStates (found by the coverage-guided fuzzer: deserialize_tld);
/// a nominal that is not finite and positive is now 1.
#[test]
fn nominals_stay_finite_for_an_extreme_restored_amplitude() {
    let inst = Instance::model_exchange("me-extreme-amplitude");
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.set_integer(vr::MODEL, 2), OK);
    assert_eq!(inst.set_integer(vr::AMPLITUDE, 1), OK);
    assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
    let s = get_state(&inst);
    let bytes = serialize(&inst, s);
    let simulation = simulation_at(&bytes);
    // The frame after the model's state: the amplitude first, then 10 more numbers.
    let amplitude = simulation + 4 + 8 * (u32_at(&bytes, simulation) - 11);
    let mut forged = bytes[..bytes.len() - 8].to_vec();
    forged[amplitude..amplitude + 8].copy_from_slice(&1e200f64.to_le_bytes());
    forged.extend_from_slice(&fmi2_slave::frame::fnv1a(&forged).to_le_bytes());
    let (status, mut made) = deserialize(&inst, &forged);
    assert_eq!(status, OK, "{:?}", inst.logs());
    assert_eq!(unsafe { inst.lib.fmi2SetFMUstate(inst.c, made) }, OK);
    assert_eq!(
        inst.get_real(vr::A_E_ESTIMATE).1,
        1e200,
        "not the forged amplitude"
    );
    let (status, nominals) = inst.nominals(tld_fmu::model::continuous::ALL_STATES);
    assert_eq!(status, OK);
    assert!(
        nominals.iter().all(|n| n.is_finite() && *n > 0.0),
        "{nominals:?}"
    );
    let mut s = s;
    unsafe {
        inst.lib.fmi2FreeFMUstate(inst.c, &mut s);
        inst.lib.fmi2FreeFMUstate(inst.c, &mut made);
    }
}
