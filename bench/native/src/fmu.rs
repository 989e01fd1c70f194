//! TLD.fmu's shared library driven through its fmi2* C entry points (dlopen via fmi-sys).

use std::ffi::CString;

use fmi_sys::fmi2::*;

/// Value references the loop uses (from modelDescription.xml, passed in by the driver).
#[derive(Clone, Copy, Debug)]
pub struct Vrs {
    pub base_a: u32,
    pub x: u32,
    pub v: u32,
    pub force: u32,
    pub mass_inactive: u32,
}

/// A parameter to set before initialisation: (value reference, value); Real or Integer.
#[derive(Clone, Debug)]
pub enum Param {
    Real(u32, f64),
    Integer(u32, i32),
}

type SetReal = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Real,
) -> fmi2Status;
type GetReal = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *mut fmi2Real,
) -> fmi2Status;
type DoStep = unsafe extern "C" fn(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean) -> fmi2Status;

pub struct Library {
    lib: Fmi2Binding,
    guid: CString,
}

struct Logger;

impl log::Log for Logger {
    fn enabled(&self, m: &log::Metadata) -> bool {
        m.level() <= log::Level::Warn
    }
    fn log(&self, r: &log::Record) {
        if r.level() <= log::Level::Warn {
            eprintln!("[fmu {} {}] {}", r.target(), r.level(), r.args());
        }
    }
    fn flush(&self) {}
}

static LOGGER: Logger = Logger;

impl Library {
    pub fn load(path: &str, guid: &str) -> Result<Self, String> {
        let _ = log::set_logger(&LOGGER).map(|()| log::set_max_level(log::LevelFilter::Warn));
        // SAFETY: loading the FMU's own library; its fmi2* symbols follow the FMI 2.0 ABI.
        let lib = unsafe { Fmi2Binding::new(path) }.map_err(|e| format!("load {path}: {e}"))?;
        Ok(Library {
            lib,
            guid: CString::new(guid).map_err(|e| e.to_string())?,
        })
    }
}

/// One initialised instance, ready to step.
pub struct Instance<'a> {
    lib: &'a Library,
    c: fmi2Component,
    set_real: SetReal,
    get_real: GetReal,
    do_step: DoStep,
    vrs: Vrs,
    out_vr: [u32; 3],
    out: [f64; 3],
    _callbacks: Box<fmi2CallbackFunctions>,
}

fn ok(what: &str, s: fmi2Status) -> Result<(), String> {
    if s == fmi2Status_fmi2OK || s == fmi2Status_fmi2Warning {
        Ok(())
    } else {
        Err(format!("{what} returned status {s}"))
    }
}

impl<'a> Instance<'a> {
    pub fn new(lib: &'a Library, vrs: Vrs, params: &[Param]) -> Result<Self, String> {
        let l = &lib.lib;
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: Some(logger::callback_logger_handler),
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: std::ptr::null_mut(),
        });
        let name = CString::new("bench").unwrap();
        // SAFETY: valid strings; the callbacks outlive the instance (kept in the struct).
        let c = unsafe {
            l.fmi2Instantiate(
                name.as_ptr(),
                fmi2Type_fmi2CoSimulation,
                lib.guid.as_ptr(),
                std::ptr::null(),
                &*callbacks,
                0,
                0,
            )
        };
        if c.is_null() {
            return Err("fmi2Instantiate returned NULL".into());
        }
        let set_real = *l.fmi2SetReal.as_ref().map_err(|e| e.to_string())?;
        let get_real = *l.fmi2GetReal.as_ref().map_err(|e| e.to_string())?;
        let do_step = *l.fmi2DoStep.as_ref().map_err(|e| e.to_string())?;
        let inst = Instance {
            lib,
            c,
            set_real,
            get_real,
            do_step,
            vrs,
            out_vr: [vrs.x, vrs.v, vrs.force],
            out: [0.0; 3],
            _callbacks: callbacks,
        };
        unsafe {
            ok(
                "fmi2SetupExperiment",
                l.fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0),
            )?;
            for p in params {
                match *p {
                    Param::Real(vr, v) => ok(
                        &format!("fmi2SetReal(vr {vr})"),
                        l.fmi2SetReal(c, &vr, 1, &v),
                    )?,
                    Param::Integer(vr, v) => ok(
                        &format!("fmi2SetInteger(vr {vr})"),
                        l.fmi2SetInteger(c, &vr, 1, &v),
                    )?,
                }
            }
            ok(
                "fmi2EnterInitializationMode",
                l.fmi2EnterInitializationMode(c),
            )?;
            ok(
                "fmi2ExitInitializationMode",
                l.fmi2ExitInitializationMode(c),
            )?;
        }
        Ok(inst)
    }

    pub fn get(&self, vr: u32) -> Result<f64, String> {
        let mut v = 0.0;
        ok("fmi2GetReal", unsafe {
            (self.get_real)(self.c, &vr, 1, &mut v)
        })?;
        Ok(v)
    }

    pub fn mass_inactive(&self) -> Result<f64, String> {
        self.get(self.vrs.mass_inactive)
    }
}

impl crate::Damper for Instance<'_> {
    /// fmi2SetReal(base.a) + fmi2DoStep + fmi2GetReal(slosh.x, slosh.v, force).
    #[inline]
    fn step(&mut self, t: f64, dt: f64, ab: f64) -> Result<[f64; 3], String> {
        unsafe {
            let s = (self.set_real)(self.c, &self.vrs.base_a, 1, &ab);
            if s > fmi2Status_fmi2Warning {
                return Err(format!("fmi2SetReal(base.a) status {s}"));
            }
            let s = (self.do_step)(self.c, t, dt, fmi2True as fmi2Boolean);
            if s > fmi2Status_fmi2Warning {
                return Err(format!("fmi2DoStep at t = {t} status {s}"));
            }
            let s = (self.get_real)(self.c, self.out_vr.as_ptr(), 3, self.out.as_mut_ptr());
            if s > fmi2Status_fmi2Warning {
                return Err(format!("fmi2GetReal status {s}"));
            }
        }
        Ok(self.out)
    }

    fn outputs(&mut self) -> Result<[f64; 3], String> {
        let s = unsafe { (self.get_real)(self.c, self.out_vr.as_ptr(), 3, self.out.as_mut_ptr()) };
        ok("fmi2GetReal", s)?;
        Ok(self.out)
    }
}

impl Drop for Instance<'_> {
    fn drop(&mut self) {
        unsafe {
            self.lib.lib.fmi2Terminate(self.c);
            self.lib.lib.fmi2FreeInstance(self.c);
        }
    }
}
