//! The raw FMI 2.0 test host that the tests of every FMU of the workspace share (TLD.fmu's
//! through tests/common, Building.fmu's through building/tests/host.rs): it loads the cdylib
//! cargo builds with the test (dlopen, through fmi-sys's bindgen loader) and drives it through
//! the C entry points, as a real host does, handing back the raw statuses (unlike the fmi2-host
//! crate, which checks them) so that the tests can see every refusal.
//!
//! The module that includes this one names its FMU: `LIBRARY`, the library's crate name
//! (`tld_fmu`), and `GUID`, its model description's guid. Each FMU's tests add their own
//! helpers in further `impl Instance` blocks.
#![allow(dead_code)]

use std::ffi::CString;
use std::path::PathBuf;
use std::sync::{Mutex, OnceLock};

use super::{GUID, LIBRARY};
use fmi_sys::fmi2::*;

pub const OK: fmi2Status = fmi2Status_fmi2OK;
pub const WARNING: fmi2Status = fmi2Status_fmi2Warning;
pub const DISCARD: fmi2Status = fmi2Status_fmi2Discard;
pub const ERROR: fmi2Status = fmi2Status_fmi2Error;

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
        "{}{LIBRARY}{}",
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
        unsafe { Fmi2Binding::new(library_path()) }
            .unwrap_or_else(|e| panic!("load {}: {e}", library_path().display()))
    })
}

/// Messages the FMU logged so far for the instance named `name`.
pub fn logs_of(name: &str) -> Vec<String> {
    RECORDS
        .lock()
        .map(|r| {
            r.iter()
                .filter(|(n, _, _)| n == name)
                .map(|(_, _, m)| m.clone())
                .collect()
        })
        .unwrap_or_default()
}

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
    /// A Co-Simulation instance.
    pub fn new(name: &str) -> Self {
        Self::of_type(name, fmi2Type_fmi2CoSimulation)
    }

    /// A Model Exchange instance.
    pub fn model_exchange(name: &str) -> Self {
        Self::of_type(name, fmi2Type_fmi2ModelExchange)
    }

    pub fn of_type(name: &str, fmu_type: fmi2Type) -> Self {
        let lib = library();
        let callbacks = callbacks();
        let cname = CString::new(name).expect("name");
        let guid = CString::new(GUID).expect("guid");
        // SAFETY: valid strings and callbacks that outlive the instance.
        let c = unsafe {
            lib.fmi2Instantiate(
                cname.as_ptr(),
                fmu_type,
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
        logs_of(&self.name)
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
    /// fmi2GetReal of one variable: the status and the value (NaN if untouched).
    pub fn get_real(&self, r: u32) -> (fmi2Status, f64) {
        let mut v = f64::NAN;
        let s = unsafe { self.lib.fmi2GetReal(self.c, &r, 1, &mut v) };
        (s, v)
    }
    /// The value of one variable, which must be readable.
    pub fn real(&self, r: u32) -> f64 {
        let (s, v) = self.get_real(r);
        assert_eq!(s, OK, "get {r}: {:?}", self.logs());
        v
    }
    pub fn do_step(&mut self, h: f64) -> fmi2Status {
        let s = unsafe { self.lib.fmi2DoStep(self.c, self.time, h, 1) };
        if s == OK {
            self.time += h;
        }
        s
    }

    // Model Exchange.
    pub fn set_time(&self, t: f64) -> fmi2Status {
        unsafe { self.lib.fmi2SetTime(self.c, t) }
    }
    pub fn enter_event_mode(&self) -> fmi2Status {
        unsafe { self.lib.fmi2EnterEventMode(self.c) }
    }
    pub fn enter_continuous_time_mode(&self) -> fmi2Status {
        unsafe { self.lib.fmi2EnterContinuousTimeMode(self.c) }
    }
    /// fmi2NewDiscreteStates: the status and the event info.
    pub fn new_discrete_states(&self) -> (fmi2Status, fmi2EventInfo) {
        let mut info = fmi2EventInfo {
            newDiscreteStatesNeeded: 1,
            terminateSimulation: 1,
            nominalsOfContinuousStatesChanged: 1,
            valuesOfContinuousStatesChanged: 1,
            nextEventTimeDefined: 1,
            nextEventTime: -1.0,
        };
        let s = unsafe { self.lib.fmi2NewDiscreteStates(self.c, &mut info) };
        (s, info)
    }
    /// fmi2CompletedIntegratorStep: the status and (enterEventMode, terminateSimulation).
    pub fn completed_integrator_step(&self) -> (fmi2Status, (i32, i32)) {
        let (mut enter, mut terminate) = (-1, -1);
        let s = unsafe {
            self.lib
                .fmi2CompletedIntegratorStep(self.c, 1, &mut enter, &mut terminate)
        };
        (s, (enter, terminate))
    }
    pub fn set_states(&self, x: &[f64]) -> fmi2Status {
        unsafe {
            self.lib
                .fmi2SetContinuousStates(self.c, x.as_ptr(), x.len())
        }
    }
    /// One of fmi2GetContinuousStates, fmi2GetDerivatives, fmi2GetNominalsOfContinuousStates,
    /// fmi2GetEventIndicators into an array of `n`: the status and the values (NaN if untouched).
    pub fn get_array(
        &self,
        f: unsafe fn(&Fmi2Binding, fmi2Component, *mut f64, usize) -> fmi2Status,
        n: usize,
    ) -> (fmi2Status, Vec<f64>) {
        let mut out = vec![f64::NAN; n];
        let s = unsafe { f(self.lib, self.c, out.as_mut_ptr(), n) };
        (s, out)
    }
    pub fn states(&self, n: usize) -> (fmi2Status, Vec<f64>) {
        self.get_array(
            |l, c, p, n| unsafe { l.fmi2GetContinuousStates(c, p, n) },
            n,
        )
    }
    pub fn derivatives(&self, n: usize) -> (fmi2Status, Vec<f64>) {
        self.get_array(|l, c, p, n| unsafe { l.fmi2GetDerivatives(c, p, n) }, n)
    }
    pub fn nominals(&self, n: usize) -> (fmi2Status, Vec<f64>) {
        self.get_array(
            |l, c, p, n| unsafe { l.fmi2GetNominalsOfContinuousStates(c, p, n) },
            n,
        )
    }
    pub fn event_indicators(&self, n: usize) -> (fmi2Status, Vec<f64>) {
        self.get_array(|l, c, p, n| unsafe { l.fmi2GetEventIndicators(c, p, n) }, n)
    }

    /// Integrate the states over [t0, t1] by classical RK4 in `steps` steps, as an ME host
    /// does: fmi2SetTime, fmi2SetContinuousStates, fmi2GetDerivatives for each stage, then
    /// fmi2CompletedIntegratorStep; `input(t)` is called before each evaluation (set inputs).
    pub fn rk4(&self, n: usize, t0: f64, t1: f64, steps: usize, input: impl Fn(&Self, f64)) {
        let h = (t1 - t0) / steps as f64;
        let (s, mut x) = self.states(n);
        assert_eq!(s, OK, "{:?}", self.logs());
        let f = |t: f64, x: &[f64]| {
            assert_eq!(self.set_time(t), OK);
            input(self, t);
            assert_eq!(self.set_states(x), OK, "{:?}", self.logs());
            let (s, d) = self.derivatives(n);
            assert_eq!(s, OK, "{:?}", self.logs());
            d
        };
        let axpy = |x: &[f64], k: &[f64], a: f64| -> Vec<f64> {
            x.iter().zip(k).map(|(x, k)| x + a * k).collect()
        };
        for i in 0..steps {
            let t = t0 + i as f64 * h;
            let k1 = f(t, &x);
            let k2 = f(t + h / 2.0, &axpy(&x, &k1, h / 2.0));
            let k3 = f(t + h / 2.0, &axpy(&x, &k2, h / 2.0));
            let k4 = f(t + h, &axpy(&x, &k3, h));
            for j in 0..n {
                x[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
            }
            assert_eq!(self.set_time(t + h), OK);
            input(self, t + h);
            assert_eq!(self.set_states(&x), OK);
            let (s, (event, terminate)) = self.completed_integrator_step();
            assert_eq!((s, event, terminate), (OK, 0, 0), "{:?}", self.logs());
        }
    }

    /// The serialised bytes of the instance's current FMU state (got, serialised and freed).
    pub fn serialised(&self) -> Vec<u8> {
        let mut s = get_state(self);
        let bytes = serialize(self, s);
        assert_eq!(unsafe { self.lib.fmi2FreeFMUstate(self.c, &mut s) }, OK);
        bytes
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: our instance, freed once.
        unsafe { self.lib.fmi2FreeInstance(self.c) }
    }
}

/// The instance's FMU state (fmi2GetFMUstate), which the caller frees.
pub fn get_state(inst: &Instance) -> fmi2FMUstate {
    let mut s: fmi2FMUstate = std::ptr::null_mut();
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
pub fn serialize(inst: &Instance, s: fmi2FMUstate) -> Vec<u8> {
    let mut n = 0usize;
    unsafe {
        assert_eq!(inst.lib.fmi2SerializedFMUstateSize(inst.c, s, &mut n), OK);
        let mut bytes = vec![0u8; n];
        assert_eq!(
            inst.lib
                .fmi2SerializeFMUstate(inst.c, s, bytes.as_mut_ptr() as *mut fmi2Byte, n),
            OK
        );
        bytes
    }
}

/// fmi2DeSerializeFMUstate of `bytes`: its status and the new state (null when refused).
pub fn deserialize(inst: &Instance, bytes: &[u8]) -> (u32, fmi2FMUstate) {
    let mut s: fmi2FMUstate = std::ptr::null_mut();
    let status = unsafe {
        inst.lib.fmi2DeSerializeFMUstate(
            inst.c,
            bytes.as_ptr() as *const fmi2Byte,
            bytes.len(),
            &mut s,
        )
    };
    (status, s)
}

/// Instances in threads give the serial runs' numbers bit for bit: `run` (an instance's name,
/// a case; the bits of what the run ends with) of every case serially, then each in a thread
/// of its own.
pub fn assert_threads_match_serial<C: Copy + Send + 'static>(
    cases: &[C],
    run: impl Fn(String, C) -> u64 + Copy + Send + 'static,
) {
    let serial: Vec<u64> = (cases.iter().enumerate())
        .map(|(k, &case)| run(format!("serial-{k}"), case))
        .collect();
    let threads: Vec<_> = (cases.iter().enumerate())
        .map(|(k, &case)| std::thread::spawn(move || run(format!("thread-{k}"), case)))
        .collect();
    let parallel: Vec<u64> = threads
        .into_iter()
        .map(|t| t.join().expect("thread"))
        .collect();
    assert_eq!(serial, parallel);
}

/// The library exports the 44 fmi2 functions and nothing of its own, except `callback_log`:
/// a #[no_mangle] function inside the fmi-sys crate (its logger shim for FMU importers), which
/// rustc exports from every cdylib that links fmi-sys. It is never called by the FMU.
pub fn assert_exports_only_fmi2_functions() {
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
