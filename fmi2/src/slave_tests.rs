//! The slave contract's defaults that the shared layer writes into a saved state: a slave that
//! keeps `Slave::flag` (Probe, exports/probe.rs) saves the flag bit clear (frame.rs: bit 0 of
//! the flags, the slave's own) and is handed it back clear when the state is restored.

use fmi_sys::fmi2::*;

use crate::exports::probe::{P, Rig};
use crate::exports::{
    fmi2FreeFMUstate, fmi2GetFMUstate, fmi2SerializeFMUstate, fmi2SerializedFMUstateSize,
    fmi2SetFMUstate,
};
use crate::frame;
use crate::slave::Slave;

#[test]
fn the_default_flag_is_saved_and_restored_clear() {
    let rig = Rig::<P>::running("flag", fmi2Type_fmi2CoSimulation, false);
    let mut state: fmi2FMUstate = std::ptr::null_mut();
    let mut size = 0;
    // SAFETY: our live instance, valid out slots and a buffer of the size asked.
    let bytes = unsafe {
        assert_eq!(fmi2GetFMUstate::<P>(rig.c, &mut state), fmi2Status_fmi2OK);
        assert_eq!(
            fmi2SerializedFMUstateSize::<P>(rig.c, state, &mut size),
            fmi2Status_fmi2OK
        );
        let mut bytes = vec![0u8; size];
        let status = fmi2SerializeFMUstate::<P>(rig.c, state, bytes.as_mut_ptr().cast(), size);
        assert_eq!(status, fmi2Status_fmi2OK);
        bytes
    };
    let t = P::TABLE;
    let (common, _) = frame::decode(&bytes, &P::STATE_TAG, P::STATE_VERSION, t.guid, "Probe")
        .expect("a good state");
    assert!(!common.flag);
    assert_eq!(rig.instance().slave.restored_flag, None);
    // SAFETY: our live instance and state, freed once.
    unsafe {
        assert_eq!(fmi2SetFMUstate::<P>(rig.c, state), fmi2Status_fmi2OK);
        assert_eq!(fmi2FreeFMUstate::<P>(rig.c, &mut state), fmi2Status_fmi2OK);
    }
    assert_eq!(rig.instance().slave.restored_flag, Some(false));
}
