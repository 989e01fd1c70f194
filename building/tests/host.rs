//! A native FMI host for Building.fmu's tests: loads the cdylib cargo builds with the test (as
//! TLD.fmu's tests do) and drives it through the C entry points.
#![allow(dead_code)]

use std::ffi::CString;
use std::path::PathBuf;
use std::sync::{Mutex, OnceLock};

use building_model::description::GUID;
pub use building_model::description::vr;
pub use fmi_sys::fmi2::*;

pub const OK: fmi2Status = fmi2Status_fmi2OK;
pub const ERROR: fmi2Status = fmi2Status_fmi2Error;

/// Log records: (instance name, message).
static RECORDS: Mutex<Vec<(String, String)>> = Mutex::new(Vec::new());

struct Capture;

impl log::Log for Capture {
    fn enabled(&self, _: &log::Metadata) -> bool {
        true
    }
    fn log(&self, record: &log::Record) {
        if let Ok(mut r) = RECORDS.lock() {
            r.push((record.target().to_string(), record.args().to_string()));
        }
    }
    fn flush(&self) {}
}

/// The cdylib cargo builds with this test (the package's library, crate types cdylib and
/// rlib), beside the test executable.
pub fn library_path() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable");
    exe.parent().expect("deps").join(format!(
        "{}building_fmu{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ))
}

pub fn library() -> &'static Fmi2Binding {
    static LIB: OnceLock<Fmi2Binding> = OnceLock::new();
    LIB.get_or_init(|| {
        let _ = log::set_logger(&Capture).map(|()| log::set_max_level(log::LevelFilter::Trace));
        // SAFETY: our own library, built with this test.
        unsafe { Fmi2Binding::new(library_path()) }.expect("load libbuilding_fmu.so")
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
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: Some(fmi_sys::fmi2::logger::callback_logger_handler),
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: std::ptr::null_mut(),
        });
        let (cname, guid) = (CString::new(name).unwrap(), CString::new(GUID).unwrap());
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
            name: name.into(),
            time: 0.0,
            _callbacks: callbacks,
        }
    }
    pub fn logs(&self) -> Vec<String> {
        RECORDS
            .lock()
            .map(|r| {
                let mine = r.iter().filter(|(n, _)| *n == self.name);
                mine.map(|(_, m)| m.clone()).collect()
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
    pub fn set_real(&self, r: u32, v: f64) -> fmi2Status {
        unsafe { self.lib.fmi2SetReal(self.c, &r, 1, &v) }
    }
    pub fn set_integer(&self, r: u32, v: i32) -> fmi2Status {
        unsafe { self.lib.fmi2SetInteger(self.c, &r, 1, &v) }
    }
    pub fn get_real(&self, r: u32) -> f64 {
        let mut v = f64::NAN;
        let s = unsafe { self.lib.fmi2GetReal(self.c, &r, 1, &mut v) };
        assert_eq!(s, OK, "get {r}: {:?}", self.logs());
        v
    }
    pub fn derivative(&self, r: u32, order: i32, v: f64) -> fmi2Status {
        unsafe {
            self.lib
                .fmi2SetRealInputDerivatives(self.c, &r, 1, &order, &v)
        }
    }
    pub fn rate(&self, r: u32) -> f64 {
        let (mut v, order) = (f64::NAN, 1);
        let s = unsafe {
            self.lib
                .fmi2GetRealOutputDerivatives(self.c, &r, 1, &order, &mut v)
        };
        assert_eq!(s, OK, "rate {r}: {:?}", self.logs());
        v
    }
    pub fn do_step(&mut self, h: f64) -> fmi2Status {
        let s = unsafe { self.lib.fmi2DoStep(self.c, self.time, h, 1) };
        if s == OK {
            self.time += h;
        }
        s
    }
    /// The parameters (value reference, value; integers for storeys and tld.floor), then
    /// initialised.
    pub fn initialise(&self, params: &[(u32, f64)]) {
        assert_eq!(self.setup(), OK);
        assert_eq!(self.enter(), OK);
        for &(r, v) in params {
            let s = if r == vr::STOREYS || r == vr::TLD_FLOOR {
                self.set_integer(r, v as i32)
            } else {
                self.set_real(r, v)
            };
            assert_eq!(s, OK, "{r} = {v}: {:?}", self.logs());
        }
        assert_eq!(self.exit(), OK, "{:?}", self.logs());
    }
    /// The serialised FMU state.
    pub fn serialised(&self) -> Vec<u8> {
        let mut s: fmi2FMUstate = std::ptr::null_mut();
        unsafe {
            assert_eq!(self.lib.fmi2GetFMUstate(self.c, &mut s), OK);
            let mut n = 0;
            assert_eq!(self.lib.fmi2SerializedFMUstateSize(self.c, s, &mut n), OK);
            let mut bytes = vec![0u8; n];
            assert_eq!(
                self.lib
                    .fmi2SerializeFMUstate(self.c, s, bytes.as_mut_ptr() as *mut fmi2Byte, n),
                OK
            );
            assert_eq!(self.lib.fmi2FreeFMUstate(self.c, &mut s), OK);
            bytes
        }
    }
    /// Become the serialised state `bytes`; the status of the restore.
    pub fn restore(&self, bytes: &[u8]) -> fmi2Status {
        unsafe {
            let mut s: fmi2FMUstate = std::ptr::null_mut();
            let st = self.lib.fmi2DeSerializeFMUstate(
                self.c,
                bytes.as_ptr() as *const fmi2Byte,
                bytes.len(),
                &mut s,
            );
            if st != OK {
                return st;
            }
            let st = self.lib.fmi2SetFMUstate(self.c, s);
            assert_eq!(self.lib.fmi2FreeFMUstate(self.c, &mut s), OK);
            st
        }
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: our instance, freed once.
        unsafe { self.lib.fmi2FreeInstance(self.c) }
    }
}
