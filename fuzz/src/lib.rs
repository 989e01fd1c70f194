//! The fuzz targets' harness, generic over the slave (TLD.fmu's `Tld`, Building.fmu's
//! `Building`): it drives the shared FMI layer's entry points (`fmi2_slave::exports`, the
//! bodies the FMUs' `extern "C"` functions inline) as a host does, with a logger callback that
//! records every message, and checks the invariants after every call:
//!
//! - every status is a valid fmi2Status a call may return (OK, Warning, Discard, Error: never
//!   Fatal or Pending), and nothing panics, not even a panic the FMI layer would catch and
//!   turn into a logged "internal error": libfuzzer-sys's panic hook aborts the process on any
//!   panic, caught or not. (Not by looking for the message: libFuzzer learns the strings the
//!   harness compares with and puts them into a state's GUID, which the FMU's refusal quotes.)
//! - a refused call (fmi2Error, fmi2Discard) on an instance logs why and leaves the instance
//!   exactly as it was (its serialised state, which holds every variable, the phase, the time
//!   and the simulation, byte for byte);
//! - what the FMU hands out as numbers (fmi2GetReal, states, derivatives, nominals, event
//!   indicators, directional derivatives) is finite when the call returns fmi2OK or
//!   fmi2Warning;
//! - a state fmi2DeSerializeFMUstate accepts is one fmi2SetFMUstate takes, and the instance it
//!   makes saves a state that loads back to itself.
//!
//! `deserialize` is the fmi2DeSerializeFMUstate target, `calls` the call-sequence target
//! (module `calls`: the calls and how bytes decode to them).

pub mod arguments;
pub mod calls;

use std::ffi::CString;
use std::marker::PhantomData;
use std::sync::{Mutex, Once};

use fmi_sys::fmi2::*;
use fmi2_slave::Slave;
use fmi2_slave::exports as fmi;

pub const OK: fmi2Status = fmi2Status_fmi2OK;
pub const WARNING: fmi2Status = fmi2Status_fmi2Warning;
pub const DISCARD: fmi2Status = fmi2Status_fmi2Discard;
pub const ERROR: fmi2Status = fmi2Status_fmi2Error;

/// What the host's logger received: (level, message); the fuzz targets run one input at a time.
static RECORDS: Mutex<Vec<(log::Level, String)>> = Mutex::new(Vec::new());

struct Capture;

impl log::Log for Capture {
    fn enabled(&self, _: &log::Metadata) -> bool {
        true
    }
    fn log(&self, record: &log::Record) {
        if let Ok(mut records) = RECORDS.lock() {
            records.push((record.level(), record.args().to_string()));
        }
    }
    fn flush(&self) {}
}

/// How many messages the FMU has logged so far (in this input).
pub fn logged() -> usize {
    RECORDS.lock().map(|r| r.len()).unwrap_or(0)
}

/// Statuses a call may return to a host.
pub fn assert_valid_status(status: fmi2Status, what: &dyn std::fmt::Debug) {
    assert!(
        matches!(status, OK | WARNING | DISCARD | ERROR),
        "{what:?} returned {status}"
    );
}

pub fn refused(status: fmi2Status) -> bool {
    status == ERROR || status == DISCARD
}

/// One instance of slave `S`, as a host holds it, with a state slot.
pub struct Host<S: Slave> {
    pub c: fmi2Component,
    pub model_exchange: bool,
    _callbacks: Box<fmi2CallbackFunctions>,
    /// The host's fmi2FMUstate (fmi2GetFMUstate / fmi2SetFMUstate / fmi2FreeFMUstate).
    pub state: fmi2FMUstate,
    _slave: PhantomData<S>,
}

impl<S: Slave> Host<S> {
    /// A new instance (Model Exchange or Co-Simulation), the log emptied.
    pub fn new(model_exchange: bool, logging_on: bool) -> Self {
        static LOGGER: Once = Once::new();
        LOGGER.call_once(|| {
            let _ = log::set_logger(&Capture).map(|()| log::set_max_level(log::LevelFilter::Trace));
        });
        if let Ok(mut records) = RECORDS.lock() {
            records.clear();
        }
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: Some(logger::callback_logger_handler),
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: std::ptr::null_mut(),
        });
        let guid = CString::new(S::TABLE.guid).expect("the GUID has no NUL");
        let kind = if model_exchange {
            fmi2Type_fmi2ModelExchange
        } else {
            fmi2Type_fmi2CoSimulation
        };
        // SAFETY: valid strings and callbacks that outlive the instance.
        let c = unsafe {
            fmi::fmi2Instantiate::<S>(
                c"fuzz".as_ptr(),
                kind,
                guid.as_ptr(),
                c"file:///nonexistent".as_ptr(),
                &*callbacks,
                0,
                i32::from(logging_on),
            )
        };
        assert!(!c.is_null(), "fmi2Instantiate refused a valid call");
        Host {
            c,
            model_exchange,
            _callbacks: callbacks,
            state: std::ptr::null_mut(),
            _slave: PhantomData,
        }
    }

    /// `depth` steps into initialisation: 0 none, 1 initialisation mode, 2 initialised (as far
    /// as the instance goes: the parameters a fuzz input set may be refused there).
    pub fn initialise(&mut self, depth: u8) {
        // SAFETY: our live instance.
        unsafe {
            if depth >= 1 {
                fmi::fmi2SetupExperiment::<S>(self.c, 0, 0.0, 0.0, 0, 0.0);
                fmi::fmi2EnterInitializationMode::<S>(self.c);
            }
            if depth >= 2 {
                fmi::fmi2ExitInitializationMode::<S>(self.c);
            }
        }
    }

    /// The instance's complete serialised state (empty if fmi2GetFMUstate refuses, as it does
    /// for an instance that panicked).
    pub fn serialised(&self) -> Vec<u8> {
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: our live instance; a state we made and free here.
        unsafe {
            if fmi::fmi2GetFMUstate::<S>(self.c, &mut state) != OK {
                return Vec::new();
            }
            let mut size = 0usize;
            let sized = fmi::fmi2SerializedFMUstateSize::<S>(self.c, state, &mut size);
            let mut bytes = vec![0u8; size];
            let written = fmi::fmi2SerializeFMUstate::<S>(
                self.c,
                state,
                bytes.as_mut_ptr() as *mut fmi2Byte,
                size,
            );
            fmi::fmi2FreeFMUstate::<S>(self.c, &mut state);
            assert!(sized == OK && written == OK, "serialising a state failed");
            bytes
        }
    }

    /// fmi2DeSerializeFMUstate of `bytes`, then fmi2SetFMUstate of what it made (if it made
    /// one): the two statuses.
    pub fn load(&mut self, bytes: &[u8]) -> (fmi2Status, Option<fmi2Status>) {
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: our live instance, a buffer of bytes.len() bytes, a state we free here.
        unsafe {
            let made = fmi::fmi2DeSerializeFMUstate::<S>(
                self.c,
                bytes.as_ptr() as *const fmi2Byte,
                bytes.len(),
                &mut state,
            );
            if made != OK {
                assert!(
                    state.is_null(),
                    "a refused fmi2DeSerializeFMUstate made a state"
                );
                return (made, None);
            }
            let set = fmi::fmi2SetFMUstate::<S>(self.c, state);
            let freed = fmi::fmi2FreeFMUstate::<S>(self.c, &mut state);
            assert_eq!(freed, OK, "fmi2FreeFMUstate of a state just made");
            (made, Some(set))
        }
    }
}

impl<S: Slave> Drop for Host<S> {
    fn drop(&mut self) {
        // SAFETY: our live instance and its state slot; the instance is not used again.
        unsafe {
            fmi::fmi2FreeFMUstate::<S>(self.c, &mut self.state);
            fmi::fmi2FreeInstance::<S>(self.c);
        }
    }
}

/// Makes `bytes` pass the frame's checks that come before the parser (see fmi2_slave::frame):
/// this FMU's tag, the payload length the buffer's length implies, the checksum.
pub fn seal<S: Slave>(bytes: &mut [u8]) {
    if bytes.len() < 10 {
        return;
    }
    bytes[..4].copy_from_slice(&S::STATE_TAG);
    let at = 10 + usize::from(u16::from_le_bytes([bytes[8], bytes[9]]));
    let Some(payload) = bytes.len().checked_sub(at + 4 + 8) else {
        return;
    };
    bytes[at..at + 4].copy_from_slice(&(payload as u32).to_le_bytes());
    let end = bytes.len() - 8;
    let sum = fmi2_slave::frame::fnv1a(&bytes[..end]);
    bytes[end..].copy_from_slice(&sum.to_le_bytes());
}

/// The fmi2DeSerializeFMUstate target. The first byte chooses the instance (bit 0: Model
/// Exchange; bits 1-2: how far into initialisation, 0 to 2; bit 3: logging on) and whether the
/// rest is sealed (bit 4: tag, payload length and checksum made right, so that half of the
/// inputs reach the parser behind the checksum); the rest is the serialised state.
pub fn deserialize<S: Slave>(data: &[u8]) {
    let Some((&flags, rest)) = data.split_first() else {
        return;
    };
    let mut bytes = rest.to_vec();
    if flags & 16 != 0 {
        seal::<S>(&mut bytes);
    }
    let mut host = Host::<S>::new(flags & 1 != 0, flags & 8 != 0);
    host.initialise((flags >> 1) % 4 % 3);
    let before = host.serialised();
    let from = logged();
    let (made, set) = host.load(&bytes);
    let what = format!("loading {} bytes (made {made}, set {set:?})", bytes.len());
    assert_valid_status(made, &what);
    match set {
        Some(OK) => {}
        Some(status) => {
            assert_valid_status(status, &what);
            assert!(refused(status), "{what}: fmi2SetFMUstate warned");
            assert_eq!(
                before,
                host.serialised(),
                "{what}: refused, yet changed the instance"
            );
            return;
        }
        None => {
            assert!(refused(made), "{what}");
            assert!(logged() > from, "{what}: refused without a message");
            assert_eq!(
                before,
                host.serialised(),
                "{what}: refused, yet changed the instance"
            );
            return;
        }
    }
    // Accepted: the instance's own state loads back to the same instance.
    let once = host.serialised();
    assert_eq!(
        host.load(&once),
        (OK, Some(OK)),
        "{what}: its own state refused"
    );
    assert_eq!(once, host.serialised(), "{what}: save and load disagree");
    // What the loaded instance does next keeps the invariants too.
    let mut run = calls::Run::new(host);
    for call in calls::after_load::<S>() {
        run.perform_checked(&call);
    }
}
