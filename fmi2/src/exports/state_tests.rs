//! The state boxes' mark, for FMUs whose instance marks are chosen against it: whatever an
//! FMU's instance mark, its states' mark is neither that mark (a state pointer passed as a
//! component, or the reverse, is refused) nor 0 (the mark fmi2FreeFMUstate wipes a state to).

use super::*;
use crate::exports::probe::{Probe, Rig, last_log};

/// Every bit of the word state_mark mixes in set: the states' mark must still not be the
/// instances'.
const ALL_BITS: u64 = 0x4142_4344_5354_4154;
/// None of those bits set: the states' mark must still not be 0.
const NO_BITS: u64 = 0x4142_4344_0000_0000;

fn a_state_box_needs_its_fmus_own_mark<const M: u64>(name: &str) {
    type S<const M: u64> = Probe<M>;
    let rig = Rig::<S<M>>::running(name, fmi2Type_fmi2CoSimulation, false);
    let mut state: fmi2FMUstate = std::ptr::null_mut();
    // SAFETY: our live instance, a valid out slot.
    let made = unsafe { fmi2GetFMUstate::<S<M>>(rig.c, &mut state) };
    assert_eq!(made, fmi2Status_fmi2OK);
    // SAFETY: a state just made by fmi2GetFMUstate, not freed.
    let genuine = unsafe { &*(state as *const StateBox) };
    assert_ne!(genuine.magic, M, "{name}: the instances' mark");
    assert_ne!(genuine.magic, 0, "{name}: the freed mark");
    for magic in [0, M, !genuine.magic] {
        let mut forged = StateBox {
            magic,
            bytes: genuine.bytes.clone(),
        };
        let p = &mut forged as *mut StateBox as fmi2FMUstate;
        // SAFETY: our live instance; `p` points to a StateBox.
        let status = unsafe { fmi2SetFMUstate::<S<M>>(rig.c, p) };
        assert_eq!(status, fmi2Status_fmi2Error, "{name}: mark {magic:#x}");
        assert_eq!(
            last_log(name).map(|l| l.1),
            Some(
                "fmi2SetFMUstate: the FMU state pointer is null or not a state of this FMU".into()
            )
        );
    }
    // SAFETY: our live instance and state, freed once.
    unsafe {
        assert_eq!(fmi2SetFMUstate::<S<M>>(rig.c, state), fmi2Status_fmi2OK);
        assert_eq!(
            fmi2FreeFMUstate::<S<M>>(rig.c, &mut state),
            fmi2Status_fmi2OK
        );
    }
}

#[test]
fn a_state_box_needs_its_fmus_own_mark_whatever_the_instance_mark() {
    a_state_box_needs_its_fmus_own_mark::<ALL_BITS>("marks, all bits");
    a_state_box_needs_its_fmus_own_mark::<NO_BITS>("marks, no bits");
}
