//! FMU states: fmi2GetFMUstate and its kin. A state is the instance's serialised bytes (one
//! format, `snapshot`, for in-memory and serialised states) in a marked box.

use fmi_sys::fmi2::*;

use super::{guard, host_ref, host_slice, host_slice_mut};
use crate::calls::{self, Call};
use crate::slave::Slave;
use crate::status::{Refusal, Status, refuse};

/// What an fmi2FMUstate points to: the instance's state in its serialised form (one code path
/// for in-memory and serialised states), with a mark to recognise it.
struct StateBox {
    magic: u64,
    bytes: Vec<u8>,
}

/// The state behind a host's fmi2FMUstate, if it is one of ours.
unsafe fn state_box<'a, S: Slave>(
    state: fmi2FMUstate,
    function: &str,
) -> Result<&'a mut StateBox, Refusal> {
    let p = state as *mut StateBox;
    // SAFETY: non-null, aligned, and marked: a state this library allocated and did not free.
    if !p.is_null() && p.is_aligned() && unsafe { (*p).magic } == state_mark::<S>() {
        Ok(unsafe { &mut *p })
    } else {
        Err(refuse(format!(
            "{function}: the FMU state pointer is null or not a state of this FMU"
        )))
    }
}

/// The mark of a state box of this slave: not its instances' mark.
const fn state_mark<S: Slave>() -> u64 {
    S::MARK ^ 0x0000_0000_5354_4154
}

fn new_state<S: Slave>(bytes: Vec<u8>) -> fmi2FMUstate {
    Box::into_raw(Box::new(StateBox {
        magic: state_mark::<S>(),
        bytes,
    })) as fmi2FMUstate
}

#[inline(always)]
pub unsafe fn fmi2GetFMUstate<S: Slave>(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    const CALL: &Call = &calls::GET_FMU_STATE;
    guard::<S>(c, CALL, |inst| {
        // SAFETY: host output scalar.
        let out = unsafe { host_ref(FMUstate, CALL, "FMUstate")? };
        let bytes = inst.save();
        if out.is_null() {
            *out = new_state::<S>(bytes);
        } else {
            // The host hands back a state to overwrite.
            unsafe { state_box::<S>(*out, "fmi2GetFMUstate")? }.bytes = bytes;
        }
        Ok(Status::Ok)
    })
}

#[inline(always)]
pub unsafe fn fmi2SetFMUstate<S: Slave>(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    const CALL: &Call = &calls::SET_FMU_STATE;
    guard::<S>(c, CALL, |inst| {
        // SAFETY: a host state pointer, recognised by its mark.
        let state = unsafe { state_box::<S>(FMUstate, "fmi2SetFMUstate")? };
        inst.load(&state.bytes)
    })
}

#[inline(always)]
pub unsafe fn fmi2FreeFMUstate<S: Slave>(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    const CALL: &Call = &calls::FREE_FMU_STATE;
    guard::<S>(c, CALL, |_| {
        // SAFETY: host in-out scalar.
        let slot = unsafe { host_ref(FMUstate, CALL, "FMUstate")? };
        if slot.is_null() {
            return Ok(Status::Ok);
        }
        // SAFETY: a state of ours: unmark, then take the box back exactly once.
        let state = unsafe { state_box::<S>(*slot, "fmi2FreeFMUstate")? };
        state.magic = 0;
        drop(unsafe { Box::from_raw(state as *mut StateBox) });
        *slot = std::ptr::null_mut();
        Ok(Status::Ok)
    })
}

#[inline(always)]
pub unsafe fn fmi2SerializedFMUstateSize<S: Slave>(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    const CALL: &Call = &calls::SERIALIZED_FMU_STATE_SIZE;
    guard::<S>(c, CALL, |_| {
        // SAFETY: host state and output scalar.
        let (state, out) = unsafe {
            (
                state_box::<S>(FMUstate, "fmi2SerializedFMUstateSize")?,
                host_ref(size, CALL, "size")?,
            )
        };
        *out = state.bytes.len();
        Ok(Status::Ok)
    })
}

#[inline(always)]
pub unsafe fn fmi2SerializeFMUstate<S: Slave>(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    const CALL: &Call = &calls::SERIALIZE_FMU_STATE;
    guard::<S>(c, CALL, |_| {
        // SAFETY: host state pointer.
        let state = unsafe { state_box::<S>(FMUstate, "fmi2SerializeFMUstate")? };
        if size != state.bytes.len() {
            return Err(refuse(format!(
                "fmi2SerializeFMUstate: size {size} is not the serialised size {} (ask fmi2SerializedFMUstateSize)",
                state.bytes.len()
            )));
        }
        // SAFETY: host buffer of `size` bytes.
        let out = unsafe { host_slice_mut(serializedState as *mut u8, size, CALL, "buffer")? };
        out.copy_from_slice(&state.bytes);
        Ok(Status::Ok)
    })
}

#[inline(always)]
pub unsafe fn fmi2DeSerializeFMUstate<S: Slave>(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: usize,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    const CALL: &Call = &calls::DE_SERIALIZE_FMU_STATE;
    guard::<S>(c, CALL, |inst| {
        // SAFETY: host buffer of `size` bytes and host output scalar.
        let (bytes, out) = unsafe {
            (
                host_slice(serializedState as *const u8, size, CALL, "buffer")?,
                host_ref(FMUstate, CALL, "FMUstate")?,
            )
        };
        inst.check_saved(bytes)
            .map_err(|r| refuse(format!("fmi2DeSerializeFMUstate: {}", r.message)))?;
        // A host may hand back one of our states for reuse (fmpy does); anything else in the
        // slot is not ours to free, and a new state is made.
        // SAFETY: a host state pointer, recognised by its mark.
        match unsafe { state_box::<S>(*out, "fmi2DeSerializeFMUstate") } {
            Ok(state) => state.bytes = bytes.to_vec(),
            Err(_) => *out = new_state::<S>(bytes.to_vec()),
        }
        Ok(Status::Ok)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exports::tests::{Host, Testy, logs_of};

    /// A box whose mark is not this FMU's state mark is refused, even when it holds a good
    /// state: the mark wiped by fmi2FreeFMUstate (0), an instance's mark, any other word. The
    /// boxes are real `StateBox`es, so that accepting one (the mutants of `state_mark`) is a
    /// wrong answer, not undefined behaviour.
    #[test]
    fn only_a_box_with_this_fmus_state_mark_is_a_state() {
        let name = "marks";
        let host = Host::new(name, None);
        assert_eq!(host.step(1.0), fmi2Status_fmi2OK);
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: our live instance, a valid out slot.
        assert_eq!(
            unsafe { fmi2GetFMUstate::<Testy>(host.c, &mut state) },
            fmi2Status_fmi2OK
        );
        // SAFETY: a state just made by fmi2GetFMUstate, not freed.
        let bytes = unsafe { &*(state as *const StateBox) }.bytes.clone();
        for magic in [0, 1, u64::MAX, Testy::MARK] {
            let mut forged = StateBox {
                magic,
                bytes: bytes.clone(),
            };
            let p = &mut forged as *mut StateBox as fmi2FMUstate;
            // SAFETY: our live instance; `p` points to a StateBox.
            assert_eq!(
                unsafe { fmi2SetFMUstate::<Testy>(host.c, p) },
                fmi2Status_fmi2Error,
                "mark {magic:#x}"
            );
            let logs = logs_of(name);
            assert_eq!(
                logs.last().map(|(_, m)| m.as_str()),
                Some("fmi2SetFMUstate: the FMU state pointer is null or not a state of this FMU")
            );
        }
        assert_eq!(logs_of(name).len(), 4);
        // The state itself is taken, and freed once.
        assert_eq!(host.step(1.0), fmi2Status_fmi2OK);
        // SAFETY: our live instance and state.
        unsafe {
            assert_eq!(fmi2SetFMUstate::<Testy>(host.c, state), fmi2Status_fmi2OK);
            assert_eq!(host.instance().context.time, 1.0);
            assert_eq!(
                fmi2FreeFMUstate::<Testy>(host.c, &mut state),
                fmi2Status_fmi2OK
            );
        }
        assert!(state.is_null());
        assert_eq!(logs_of(name).len(), 4);
    }
}

#[cfg(test)]
#[path = "state_tests.rs"]
mod mark_tests;
