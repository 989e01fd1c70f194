//! TLD.fmu's shared library driven through its fmi2* C entry points, as any host does: the
//! library is dlopened (fmi-sys), every function the master calls is resolved once at load (a
//! missing one is an error, not a panic), and each call's status is checked.

use std::collections::VecDeque;
use std::ffi::CString;
use std::sync::Mutex;

use fmi_sys::fmi2::*;

/// One parameter value to set before initialisation, by value reference (the names were
/// resolved against the modelDescription by the caller): exactly one of real, integer (an
/// Enumeration's too) and boolean.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Param {
    pub vr: u32,
    #[serde(default, deserialize_with = "crate::protocol::some_number")]
    pub real: Option<f64>,
    #[serde(default)]
    pub integer: Option<i32>,
    #[serde(default)]
    pub boolean: Option<bool>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Real(f64),
    Integer(i32),
    Boolean(bool),
}

impl Param {
    pub fn value(&self) -> Result<Value, String> {
        match (self.real, self.integer, self.boolean) {
            (Some(x), None, None) => Ok(Value::Real(x)),
            (None, Some(i), None) => Ok(Value::Integer(i)),
            (None, None, Some(b)) => Ok(Value::Boolean(b)),
            _ => Err(format!(
                "parameter vr {}: give exactly one of real, integer, boolean",
                self.vr
            )),
        }
    }
}

/// The value references the coupling uses, from the modelDescription (the caller reads them).
#[derive(Clone, Copy, Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vrs {
    #[serde(rename = "base.a")]
    pub base_a: u32,
    #[serde(rename = "base.v")]
    pub base_v: u32,
    #[serde(rename = "base.x")]
    pub base_x: u32,
    pub force: u32,
    #[serde(rename = "force.mean")]
    pub force_mean: u32,
    #[serde(rename = "mass.inactive")]
    pub mass_inactive: u32,
}

type SetReal = unsafe extern "C" fn(fmi2Component, *const u32, usize, *const f64) -> fmi2Status;
type GetReal = unsafe extern "C" fn(fmi2Component, *const u32, usize, *mut f64) -> fmi2Status;
type SetInteger = unsafe extern "C" fn(fmi2Component, *const u32, usize, *const i32) -> fmi2Status;
type Derivatives =
    unsafe extern "C" fn(fmi2Component, *const u32, usize, *const i32, *const f64) -> fmi2Status;
type OutputDerivatives =
    unsafe extern "C" fn(fmi2Component, *const u32, usize, *const i32, *mut f64) -> fmi2Status;
type DoStep = unsafe extern "C" fn(fmi2Component, f64, f64, fmi2Boolean) -> fmi2Status;
type Plain = unsafe extern "C" fn(fmi2Component) -> fmi2Status;
type SetupExperiment =
    unsafe extern "C" fn(fmi2Component, fmi2Boolean, f64, f64, fmi2Boolean, f64) -> fmi2Status;
type Instantiate = unsafe extern "C" fn(
    fmi2String,
    fmi2Type,
    fmi2String,
    fmi2String,
    *const fmi2CallbackFunctions,
    fmi2Boolean,
    fmi2Boolean,
) -> fmi2Component;
type FreeInstance = unsafe extern "C" fn(fmi2Component);

/// The fmi2 functions the master calls, resolved at load.
#[derive(Clone, Copy)]
struct Functions {
    instantiate: Instantiate,
    free_instance: FreeInstance,
    setup_experiment: SetupExperiment,
    enter_initialization_mode: Plain,
    exit_initialization_mode: Plain,
    terminate: Plain,
    reset: Plain,
    set_real: SetReal,
    get_real: GetReal,
    set_integer: SetInteger,
    set_boolean: SetInteger,
    set_input_derivatives: Derivatives,
    get_output_derivatives: OutputDerivatives,
    do_step: DoStep,
}

/// A loaded FMU binary: the library, its GUID, the resource location and the value references.
pub struct Library {
    _lib: Fmi2Binding,
    f: Functions,
    guid: CString,
    resources: CString,
    pub vrs: Vrs,
}

/// The FMU's log messages (status Warning or worse), the last few, for the error of a run.
static MESSAGES: Mutex<VecDeque<String>> = Mutex::new(VecDeque::new());
const KEEP: usize = 4;

struct Collector;

impl log::Log for Collector {
    fn enabled(&self, m: &log::Metadata) -> bool {
        m.level() <= log::Level::Warn
    }
    fn log(&self, r: &log::Record) {
        if r.level() <= log::Level::Warn
            && let Ok(mut q) = MESSAGES.lock()
        {
            if q.len() == KEEP {
                q.pop_front();
            }
            q.push_back(format!("[{}] {}", r.level(), r.args()));
        }
    }
    fn flush(&self) {}
}

static COLLECTOR: Collector = Collector;

/// The FMU's messages since the last call (joined; empty if none), and forget them.
pub fn take_messages() -> String {
    match MESSAGES.lock() {
        Ok(mut q) => q.drain(..).collect::<Vec<_>>().join(" | "),
        Err(_) => String::new(),
    }
}

fn resolved<T: Copy, E: std::fmt::Display>(
    name: &str,
    f: &Result<T, E>,
    path: &str,
) -> Result<T, String> {
    f.as_ref()
        .copied()
        .map_err(|e| format!("{path} has no {name}: {e}"))
}

impl Library {
    /// dlopen `path` (the FMU's binaries/linux64/<modelIdentifier>.so).
    pub fn load(path: &str, guid: &str, resources: &str, vrs: Vrs) -> Result<Self, String> {
        // the first library sets the logger; later ones (a reload) keep it
        let _ = log::set_logger(&COLLECTOR).map(|()| log::set_max_level(log::LevelFilter::Warn));
        // SAFETY: the FMU's own library; its fmi2* symbols follow the FMI 2.0 ABI.
        let lib = unsafe { Fmi2Binding::new(path) }.map_err(|e| format!("load {path}: {e}"))?;
        let f = Functions {
            instantiate: resolved("fmi2Instantiate", &lib.fmi2Instantiate, path)?,
            free_instance: resolved("fmi2FreeInstance", &lib.fmi2FreeInstance, path)?,
            setup_experiment: resolved("fmi2SetupExperiment", &lib.fmi2SetupExperiment, path)?,
            enter_initialization_mode: resolved(
                "fmi2EnterInitializationMode",
                &lib.fmi2EnterInitializationMode,
                path,
            )?,
            exit_initialization_mode: resolved(
                "fmi2ExitInitializationMode",
                &lib.fmi2ExitInitializationMode,
                path,
            )?,
            terminate: resolved("fmi2Terminate", &lib.fmi2Terminate, path)?,
            reset: resolved("fmi2Reset", &lib.fmi2Reset, path)?,
            set_real: resolved("fmi2SetReal", &lib.fmi2SetReal, path)?,
            get_real: resolved("fmi2GetReal", &lib.fmi2GetReal, path)?,
            set_integer: resolved("fmi2SetInteger", &lib.fmi2SetInteger, path)?,
            set_boolean: resolved("fmi2SetBoolean", &lib.fmi2SetBoolean, path)?,
            set_input_derivatives: resolved(
                "fmi2SetRealInputDerivatives",
                &lib.fmi2SetRealInputDerivatives,
                path,
            )?,
            get_output_derivatives: resolved(
                "fmi2GetRealOutputDerivatives",
                &lib.fmi2GetRealOutputDerivatives,
                path,
            )?,
            do_step: resolved("fmi2DoStep", &lib.fmi2DoStep, path)?,
        };
        let c = |s: &str, what: &str| CString::new(s).map_err(|_| format!("{what} holds a NUL"));
        Ok(Library {
            _lib: lib,
            f,
            guid: c(guid, "the GUID")?,
            resources: c(resources, "the resource location")?,
            vrs,
        })
    }
}

fn check(what: &str, s: fmi2Status) -> Result<(), String> {
    if s == fmi2Status_fmi2OK || s == fmi2Status_fmi2Warning {
        Ok(())
    } else {
        Err(format!("{what} returned status {s}"))
    }
}

/// One FMU instance (co-simulation), reused across runs through fmi2Reset.
pub struct Instance {
    f: Functions,
    c: fmi2Component,
    vrs: Vrs,
    /// the outputs read after every step: force, force.mean
    out_vr: [u32; 2],
    pub force: f64,
    pub force_mean: f64,
    _callbacks: Box<fmi2CallbackFunctions>,
    fresh: bool,
    /// time spent inside fmi2DoStep, measured only when `timed` (the clock costs ~50 ns a step)
    pub timed: bool,
    pub in_do_step: std::time::Duration,
}

impl Instance {
    pub fn new(lib: &Library, name: &str) -> Result<Self, String> {
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: Some(logger::callback_logger_handler),
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: std::ptr::null_mut(),
        });
        let cname = CString::new(name).map_err(|_| "instance name holds a NUL".to_string())?;
        // SAFETY: valid C strings; the callbacks live as long as the instance (boxed in it).
        let c = unsafe {
            (lib.f.instantiate)(
                cname.as_ptr(),
                fmi2Type_fmi2CoSimulation,
                lib.guid.as_ptr(),
                lib.resources.as_ptr(),
                &*callbacks,
                0,
                0,
            )
        };
        if c.is_null() {
            return Err("fmi2Instantiate returned NULL".into());
        }
        Ok(Instance {
            f: lib.f,
            c,
            vrs: lib.vrs,
            out_vr: [lib.vrs.force, lib.vrs.force_mean],
            force: 0.0,
            force_mean: 0.0,
            _callbacks: callbacks,
            fresh: true,
            timed: false,
            in_do_step: std::time::Duration::ZERO,
        })
    }

    /// Set up a run: fmi2Reset (unless fresh), fmi2SetupExperiment(start 0, no tolerance, no
    /// stop time), the parameters in order, initialisation; returns mass.inactive.
    pub fn configure(&mut self, params: &[Param]) -> Result<f64, String> {
        // SAFETY: c is a live instance of this library; pointers point to live locals.
        unsafe {
            if !self.fresh {
                check("fmi2Reset", (self.f.reset)(self.c))?;
            }
            self.fresh = false;
            check(
                "fmi2SetupExperiment",
                (self.f.setup_experiment)(self.c, 0, 0.0, 0.0, 0, 0.0),
            )?;
            for p in params {
                let vr = p.vr;
                match p.value()? {
                    Value::Real(v) => check(
                        &format!("fmi2SetReal(vr {vr} = {v})"),
                        (self.f.set_real)(self.c, &vr, 1, &v),
                    )?,
                    Value::Integer(v) => check(
                        &format!("fmi2SetInteger(vr {vr} = {v})"),
                        (self.f.set_integer)(self.c, &vr, 1, &v),
                    )?,
                    Value::Boolean(v) => check(
                        &format!("fmi2SetBoolean(vr {vr} = {v})"),
                        (self.f.set_boolean)(self.c, &vr, 1, &i32::from(v)),
                    )?,
                }
            }
            check(
                "fmi2EnterInitializationMode",
                (self.f.enter_initialization_mode)(self.c),
            )?;
            check(
                "fmi2ExitInitializationMode",
                (self.f.exit_initialization_mode)(self.c),
            )?;
        }
        let mut inactive = 0.0;
        // SAFETY: as above.
        check("fmi2GetReal(mass.inactive)", unsafe {
            (self.f.get_real)(self.c, &self.vrs.mass_inactive, 1, &mut inactive)
        })?;
        self.read()?;
        Ok(inactive)
    }

    /// force and force.mean now.
    pub fn read(&mut self) -> Result<(), String> {
        let mut v = [0.0; 2];
        // SAFETY: live instance, buffers of the length passed.
        let s = unsafe { (self.f.get_real)(self.c, self.out_vr.as_ptr(), 2, v.as_mut_ptr()) };
        if s > fmi2Status_fmi2Warning {
            return Err("fmi2GetReal failed".into());
        }
        [self.force, self.force_mean] = v;
        Ok(())
    }

    /// The floor's absolute acceleration, velocity and displacement (base.a, base.v, base.x).
    pub fn set_inputs(&mut self, t: f64, a: f64, v: f64, x: f64) -> Result<(), String> {
        let vr = [self.vrs.base_a, self.vrs.base_v, self.vrs.base_x];
        let val = [a, v, x];
        // SAFETY: live instance, buffers of the length passed.
        let s = unsafe { (self.f.set_real)(self.c, vr.as_ptr(), 3, val.as_ptr()) };
        if s > fmi2Status_fmi2Warning {
            return Err(format!("the damper refused its inputs at t = {t}"));
        }
        Ok(())
    }

    /// fmi2DoStep from t by h with the inputs set (a_rate, if given, is d(base.a)/dt at t,
    /// fmi2SetRealInputDerivatives of order 1); then read the outputs.
    pub fn step_with_rate(&mut self, t: f64, h: f64, a_rate: Option<f64>) -> Result<(), String> {
        // SAFETY: live instance, pointers to live locals.
        unsafe {
            if let Some(r) = a_rate {
                let s = (self.f.set_input_derivatives)(self.c, &self.vrs.base_a, 1, &1, &r);
                if s > fmi2Status_fmi2Warning {
                    return Err(format!(
                        "the damper refused the input derivative at t = {t}"
                    ));
                }
            }
            let status = if self.timed {
                let t0 = std::time::Instant::now();
                let s = (self.f.do_step)(self.c, t, h, 1);
                self.in_do_step += t0.elapsed();
                s
            } else {
                (self.f.do_step)(self.c, t, h, 1)
            };
            if status > fmi2Status_fmi2Warning {
                return Err(format!("the damper refused a step at t = {t}"));
            }
        }
        self.read()
    }

    /// fmi2DoStep from t by h with these inputs held over the step.
    pub fn step(&mut self, t: f64, h: f64, a: f64, v: f64, x: f64) -> Result<(), String> {
        self.set_inputs(t, a, v, x)?;
        self.step_with_rate(t, h, None)
    }

    /// d(force)/dt now (fmi2GetRealOutputDerivatives, order 1).
    pub fn force_rate(&mut self) -> Result<f64, String> {
        let mut d = 0.0;
        // SAFETY: live instance, pointers to live locals.
        let s = unsafe { (self.f.get_output_derivatives)(self.c, &self.vrs.force, 1, &1, &mut d) };
        if s > fmi2Status_fmi2Warning {
            return Err("fmi2GetRealOutputDerivatives failed".into());
        }
        Ok(d)
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: c is live until here; freed once.
        unsafe {
            (self.f.terminate)(self.c);
            (self.f.free_instance)(self.c);
        }
    }
}
