//! A native FMI host for the tests: loads the built cdylib with dlopen (through fmi-sys's
//! bindgen loader) and drives it through the C entry points, as a real host does.
#![allow(dead_code)]

use std::ffi::CString;
use std::path::PathBuf;
use std::sync::{Mutex, OnceLock};

use fmi_sys::fmi2::*;
use tld_fmu::fmi::vars::{GUID, vr};

/// Log records captured from the FMU: (instance name, level, message).
static RECORDS: Mutex<Vec<(String, log::Level, String)>> = Mutex::new(Vec::new());

struct Capture;

impl log::Log for Capture {
    fn enabled(&self, _: &log::Metadata) -> bool {
        true
    }
    fn log(&self, record: &log::Record) {
        // The fuzzer's instances log thousands of refusals: formatted (the path is exercised)
        // but not kept.
        if record.target().starts_with("fuzz") {
            return;
        }
        if let Ok(mut r) = RECORDS.lock() {
            r.push((
                record.target().to_string(),
                record.level(),
                record.args().to_string(),
            ));
        }
    }
    fn flush(&self) {}
}

/// The cdylib built with this test: the library's crate types include cdylib, so cargo compiles
/// the library this test links as rlib and cdylib in one rustc invocation and writes both into
/// the directory of the test executable (target/<profile>/deps). A plain `cargo test` therefore
/// builds what this host loads, from the same sources, in the same profile: nothing to build
/// first, nothing stale.
pub fn library_path() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let name = format!(
        "{}tld_fmu{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    );
    let path = exe.parent().expect("target/<profile>/deps").join(name);
    assert!(
        path.is_file(),
        "{} is missing: cargo builds it with the test (crate-type cdylib in Cargo.toml)",
        path.display()
    );
    path
}

pub fn library() -> &'static Fmi2Binding {
    static LIB: OnceLock<Fmi2Binding> = OnceLock::new();
    LIB.get_or_init(|| {
        let _ = log::set_logger(&Capture).map(|()| log::set_max_level(log::LevelFilter::Trace));
        // SAFETY: loading our own library, built with this test by cargo.
        unsafe { Fmi2Binding::new(library_path()) }.expect("load libtld_fmu.so")
    })
}

pub const OK: fmi2Status = fmi2Status_fmi2OK;
pub const WARNING: fmi2Status = fmi2Status_fmi2Warning;
pub const DISCARD: fmi2Status = fmi2Status_fmi2Discard;
pub const ERROR: fmi2Status = fmi2Status_fmi2Error;

pub fn callbacks() -> Box<fmi2CallbackFunctions> {
    Box::new(fmi2CallbackFunctions {
        logger: Some(logger::callback_logger_handler),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    })
}

pub struct Instance {
    pub lib: &'static Fmi2Binding,
    pub c: fmi2Component,
    pub name: String,
    pub time: f64,
    _callbacks: Box<fmi2CallbackFunctions>,
}

impl Instance {
    pub fn new(name: &str) -> Self {
        let lib = library();
        let callbacks = callbacks();
        let cname = CString::new(name).expect("name");
        let guid = CString::new(GUID).expect("guid");
        // SAFETY: valid strings and callbacks that outlive the instance.
        let c = unsafe {
            lib.fmi2Instantiate(
                cname.as_ptr(),
                fmi2Type_fmi2CoSimulation,
                guid.as_ptr(),
                std::ptr::null(),
                &*callbacks,
                0,
                0,
            )
        };
        assert!(!c.is_null(), "instantiate {name}");
        Instance {
            lib,
            c,
            name: name.to_string(),
            time: 0.0,
            _callbacks: callbacks,
        }
    }

    /// Messages the FMU logged for this instance so far.
    pub fn logs(&self) -> Vec<String> {
        RECORDS
            .lock()
            .map(|r| {
                r.iter()
                    .filter(|(n, _, _)| *n == self.name)
                    .map(|(_, _, m)| m.clone())
                    .collect()
            })
            .unwrap_or_default()
    }

    pub fn setup(&self) -> fmi2Status {
        unsafe { self.lib.fmi2SetupExperiment(self.c, 0, 0.0, 0.0, 0, 0.0) }
    }
    pub fn enter(&self) -> fmi2Status {
        unsafe { self.lib.fmi2EnterInitializationMode(self.c) }
    }
    pub fn exit(&self) -> fmi2Status {
        unsafe { self.lib.fmi2ExitInitializationMode(self.c) }
    }
    pub fn terminate(&self) -> fmi2Status {
        unsafe { self.lib.fmi2Terminate(self.c) }
    }
    pub fn reset(&self) -> fmi2Status {
        unsafe { self.lib.fmi2Reset(self.c) }
    }
    pub fn set_real(&self, r: u32, v: f64) -> fmi2Status {
        unsafe { self.lib.fmi2SetReal(self.c, &r, 1, &v) }
    }
    pub fn set_integer(&self, r: u32, v: i32) -> fmi2Status {
        unsafe { self.lib.fmi2SetInteger(self.c, &r, 1, &v) }
    }
    pub fn get_real(&self, r: u32) -> (fmi2Status, f64) {
        let mut v = f64::NAN;
        let s = unsafe { self.lib.fmi2GetReal(self.c, &r, 1, &mut v) };
        (s, v)
    }
    pub fn do_step(&mut self, h: f64) -> fmi2Status {
        let s = unsafe { self.lib.fmi2DoStep(self.c, self.time, h, 1) };
        if s == OK {
            self.time += h;
        }
        s
    }

    /// setup, enter, exit: ready to step.
    pub fn initialise(&self) {
        assert_eq!(self.setup(), OK);
        assert_eq!(self.enter(), OK);
        assert_eq!(self.exit(), OK);
    }

    /// Harmonic base motion near resonance for `n` steps of `h`; returns slosh.x at the end.
    pub fn run_harmonic(&mut self, n: usize, h: f64) -> f64 {
        let w = 6.0;
        for _ in 0..n {
            let t = self.time;
            assert_eq!(
                self.set_real(vr::BASE_A, -w * w * 0.004 * (w * t).sin()),
                OK
            );
            assert_eq!(self.do_step(h), OK, "{:?}", self.logs());
        }
        self.get_real(vr::SLOSH_X).1
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: our instance, freed once.
        unsafe { self.lib.fmi2FreeInstance(self.c) }
    }
}

/// The instance's FMU state (fmi2GetFMUstate), which the caller frees.
pub fn get_state(inst: &Instance) -> fmi_sys::fmi2::fmi2FMUstate {
    let mut s: fmi_sys::fmi2::fmi2FMUstate = std::ptr::null_mut();
    assert_eq!(
        unsafe { inst.lib.fmi2GetFMUstate(inst.c, &mut s) },
        OK,
        "{:?}",
        inst.logs()
    );
    assert!(!s.is_null());
    s
}

/// The serialised bytes of state `s` (fmi2SerializedFMUstateSize, fmi2SerializeFMUstate).
pub fn serialize(inst: &Instance, s: fmi_sys::fmi2::fmi2FMUstate) -> Vec<u8> {
    let mut n = 0usize;
    unsafe {
        assert_eq!(inst.lib.fmi2SerializedFMUstateSize(inst.c, s, &mut n), OK);
        let mut bytes = vec![0u8; n];
        assert_eq!(
            inst.lib
                .fmi2SerializeFMUstate(inst.c, s, bytes.as_mut_ptr() as *mut _, n),
            OK
        );
        bytes
    }
}

/// fmi2DeSerializeFMUstate of `bytes`: its status and the new state (null when refused).
pub fn deserialize(inst: &Instance, bytes: &[u8]) -> (u32, fmi_sys::fmi2::fmi2FMUstate) {
    let mut s: fmi_sys::fmi2::fmi2FMUstate = std::ptr::null_mut();
    let status = unsafe {
        inst.lib
            .fmi2DeSerializeFMUstate(inst.c, bytes.as_ptr() as *const _, bytes.len(), &mut s)
    };
    (status, s)
}

/// `bytes` deserialised and set into `inst` (both calls must succeed); the state, to be freed.
pub fn restore(inst: &Instance, bytes: &[u8]) -> fmi_sys::fmi2::fmi2FMUstate {
    let (status, restored) = deserialize(inst, bytes);
    assert_eq!(status, OK, "{:?}", inst.logs());
    // SAFETY: our instance and a state it just made.
    let set = unsafe { inst.lib.fmi2SetFMUstate(inst.c, restored) };
    assert_eq!(set, OK, "{:?}", inst.logs());
    restored
}

/// An instance out of initialisation mode with the Tracked amplitude estimate (amplitude = 2),
/// whose state holds more than x and v.
pub fn tracked(name: &str) -> Instance {
    let inst = Instance::new(name);
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.set_integer(vr::AMPLITUDE, 2), OK);
    assert_eq!(inst.exit(), OK);
    inst
}
