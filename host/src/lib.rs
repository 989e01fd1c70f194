//! The host side of FMI 2.0 Co-Simulation, as tld-bench and tld-study drive TLD.fmu: the FMU's
//! binary dlopened (fmi-sys), every fmi2 function a host here calls resolved once at load (a
//! missing one is an error that names it, not a panic at its first call), instances that call
//! them through plain function pointers (no lookup and no allocation per call) and check each
//! status, and the FMU's log messages printed or kept for an error message.
//!
//! What a host sees of a refused call is a [`Refused`] (the call and its status): it converts
//! into a `String` with `?`, or the host words it its own way (`map_err`), on the error path only.

use std::collections::VecDeque;
use std::ffi::CString;
use std::fmt;
use std::sync::{Arc, Mutex};

use fmi_sys::fmi2::*;

/// An fmi2 status (fmi2OK = 0, fmi2Warning = 1, fmi2Discard = 2, fmi2Error = 3, fmi2Fatal = 4,
/// fmi2Pending = 5).
pub use fmi_sys::fmi2::fmi2Status as Status;

/// A value to set by value reference (an Enumeration's is an Integer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Real(f64),
    Integer(i32),
    Boolean(bool),
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Real(x) => write!(f, "{x}"),
            Value::Integer(i) => write!(f, "{i}"),
            Value::Boolean(b) => write!(f, "{b}"),
        }
    }
}

/// An fmi2 call that returned a status worse than fmi2Warning: which call, and its status.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Refused {
    pub call: &'static str,
    pub status: Status,
}

impl fmt::Display for Refused {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} returned status {}", self.call, self.status)
    }
}

impl std::error::Error for Refused {}

impl From<Refused> for String {
    fn from(r: Refused) -> String {
        r.to_string()
    }
}

/// fmi2OK and fmi2Warning pass; anything else is the call refused.
#[inline(always)]
fn check(call: &'static str, status: Status) -> Result<(), Refused> {
    if status <= fmi2Status_fmi2Warning {
        Ok(())
    } else {
        Err(Refused { call, status })
    }
}

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
type SetupExperiment =
    unsafe extern "C" fn(fmi2Component, fmi2Boolean, f64, f64, fmi2Boolean, f64) -> Status;
type Plain = unsafe extern "C" fn(fmi2Component) -> Status;
type SetReal = unsafe extern "C" fn(fmi2Component, *const u32, usize, *const f64) -> Status;
type GetReal = unsafe extern "C" fn(fmi2Component, *const u32, usize, *mut f64) -> Status;
type SetInteger = unsafe extern "C" fn(fmi2Component, *const u32, usize, *const i32) -> Status;
type InputDerivatives =
    unsafe extern "C" fn(fmi2Component, *const u32, usize, *const i32, *const f64) -> Status;
type OutputDerivatives =
    unsafe extern "C" fn(fmi2Component, *const u32, usize, *const i32, *mut f64) -> Status;
type DoStep = unsafe extern "C" fn(fmi2Component, f64, f64, fmi2Boolean) -> Status;

/// The fmi2 functions the hosts call, resolved at load.
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
    set_input_derivatives: InputDerivatives,
    get_output_derivatives: OutputDerivatives,
    do_step: DoStep,
}

fn resolved<T: Copy, E: fmt::Display>(
    name: &str,
    f: &Result<T, E>,
    path: &str,
) -> Result<T, String> {
    f.as_ref()
        .copied()
        .map_err(|e| format!("{path} has no {name}: {e}"))
}

/// A loaded FMU binary, its GUID and resource location. Its instances keep the binary loaded:
/// the library may go before them.
pub struct Library {
    binding: Arc<Fmi2Binding>,
    f: Functions,
    guid: CString,
    resources: Option<CString>,
}

impl Library {
    /// dlopen `path` (an FMU's binaries/<platform>/<modelIdentifier>.so) and resolve its fmi2
    /// functions. `resources` is the fmuResourceLocation handed to fmi2Instantiate (None: a null
    /// pointer). Errors: the library does not load, lacks an fmi2 function (named), or a
    /// string holds a NUL.
    ///
    /// # Safety
    ///
    /// `path` must be an FMI 2.0 binary: loading it runs its initialisers, and its fmi2*
    /// symbols are called with the signatures of the FMI 2.0 standard.
    pub unsafe fn load(path: &str, guid: &str, resources: Option<&str>) -> Result<Self, String> {
        // SAFETY: the caller's promise (above).
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
            binding: Arc::new(lib),
            f,
            guid: c(guid, "the GUID")?,
            resources: resources
                .map(|r| c(r, "the resource location"))
                .transpose()?,
        })
    }
}

/// One co-simulation instance: fmi2Terminate and fmi2FreeInstance when dropped.
pub struct Instance {
    f: Functions,
    c: fmi2Component,
    _callbacks: Box<fmi2CallbackFunctions>,
    /// the binary stays loaded while the instance lives (dropped after `drop` freed it)
    _binding: Arc<Fmi2Binding>,
}

impl Instance {
    /// fmi2Instantiate (co-simulation, not visible, logging off) named `name`, the FMU's
    /// messages through fmi-sys's logger callback to the `log` crate (see [`print_messages`]).
    pub fn new(lib: &Library, name: &str) -> Result<Self, String> {
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: Some(logger::callback_logger_handler),
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: std::ptr::null_mut(),
        });
        let cname = CString::new(name).map_err(|_| "instance name holds a NUL".to_string())?;
        let resources = lib
            .resources
            .as_ref()
            .map_or(std::ptr::null(), |r| r.as_ptr());
        // SAFETY: valid C strings (copied by the FMU) and callbacks that live as long as the
        // instance (boxed in it); the library's promise of the FMI 2.0 ABI.
        let c = unsafe {
            (lib.f.instantiate)(
                cname.as_ptr(),
                fmi2Type_fmi2CoSimulation,
                lib.guid.as_ptr(),
                resources,
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
            _callbacks: callbacks,
            _binding: Arc::clone(&lib.binding),
        })
    }

    /// fmi2SetupExperiment: the tolerance (None: undefined), start and stop time (None:
    /// undefined).
    pub fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    ) -> Result<(), Refused> {
        let (tol_defined, tol) = tolerance.map_or((0, 0.0), |t| (1, t));
        let (stop_defined, stop) = stop.map_or((0, 0.0), |t| (1, t));
        // SAFETY: a live instance of this library.
        check("fmi2SetupExperiment", unsafe {
            (self.f.setup_experiment)(self.c, tol_defined, tol, start, stop_defined, stop)
        })
    }

    pub fn enter_initialization_mode(&mut self) -> Result<(), Refused> {
        // SAFETY: a live instance of this library.
        check("fmi2EnterInitializationMode", unsafe {
            (self.f.enter_initialization_mode)(self.c)
        })
    }

    pub fn exit_initialization_mode(&mut self) -> Result<(), Refused> {
        // SAFETY: a live instance of this library.
        check("fmi2ExitInitializationMode", unsafe {
            (self.f.exit_initialization_mode)(self.c)
        })
    }

    /// A run's start: fmi2SetupExperiment (start 0, no tolerance, no stop time), the
    /// parameters set in order, fmi2EnterInitializationMode, fmi2ExitInitializationMode. A
    /// refused parameter is named with its value reference and value.
    pub fn initialize(&mut self, params: &[(u32, Value)]) -> Result<(), String> {
        self.setup_experiment(None, 0.0, None)?;
        for &(vr, v) in params {
            self.set_value(vr, v)
                .map_err(|r| format!("{}(vr {vr} = {v}) returned status {}", r.call, r.status))?;
        }
        self.enter_initialization_mode()?;
        self.exit_initialization_mode()?;
        Ok(())
    }

    /// fmi2Reset: back to the state after fmi2Instantiate.
    pub fn reset(&mut self) -> Result<(), Refused> {
        // SAFETY: a live instance of this library.
        check("fmi2Reset", unsafe { (self.f.reset)(self.c) })
    }

    /// One value by its type: fmi2SetReal, fmi2SetInteger or fmi2SetBoolean.
    pub fn set_value(&mut self, vr: u32, value: Value) -> Result<(), Refused> {
        // SAFETY: a live instance; pointers to one live value each.
        unsafe {
            match value {
                Value::Real(x) => check("fmi2SetReal", (self.f.set_real)(self.c, &vr, 1, &x)),
                Value::Integer(i) => {
                    check("fmi2SetInteger", (self.f.set_integer)(self.c, &vr, 1, &i))
                }
                Value::Boolean(b) => check(
                    "fmi2SetBoolean",
                    (self.f.set_boolean)(self.c, &vr, 1, &fmi2Boolean::from(b)),
                ),
            }
        }
    }

    /// fmi2SetReal of `values` to the value references `vr`.
    ///
    /// # Panics
    ///
    /// If `vr` and `values` differ in length.
    #[inline]
    pub fn set_real(&mut self, vr: &[u32], values: &[f64]) -> Result<(), Refused> {
        assert_eq!(
            vr.len(),
            values.len(),
            "fmi2SetReal: one value per reference"
        );
        // SAFETY: a live instance; both buffers hold vr.len() elements.
        check("fmi2SetReal", unsafe {
            (self.f.set_real)(self.c, vr.as_ptr(), vr.len(), values.as_ptr())
        })
    }

    /// fmi2GetReal of the value references `vr` into `values`.
    ///
    /// # Panics
    ///
    /// If `vr` and `values` differ in length.
    #[inline]
    pub fn get_real(&self, vr: &[u32], values: &mut [f64]) -> Result<(), Refused> {
        assert_eq!(
            vr.len(),
            values.len(),
            "fmi2GetReal: one value per reference"
        );
        // SAFETY: a live instance; both buffers hold vr.len() elements.
        check("fmi2GetReal", unsafe {
            (self.f.get_real)(self.c, vr.as_ptr(), vr.len(), values.as_mut_ptr())
        })
    }

    /// fmi2SetInteger of `values` to the value references `vr`.
    ///
    /// # Panics
    ///
    /// If `vr` and `values` differ in length.
    #[inline]
    pub fn set_integer(&mut self, vr: &[u32], values: &[i32]) -> Result<(), Refused> {
        assert_eq!(
            vr.len(),
            values.len(),
            "fmi2SetInteger: one value per reference"
        );
        // SAFETY: a live instance; both buffers hold vr.len() elements.
        check("fmi2SetInteger", unsafe {
            (self.f.set_integer)(self.c, vr.as_ptr(), vr.len(), values.as_ptr())
        })
    }

    /// fmi2SetRealInputDerivatives: the `order`-th time derivatives of the inputs `vr`.
    ///
    /// # Panics
    ///
    /// If `vr`, `order` and `values` differ in length.
    #[inline]
    pub fn set_real_input_derivatives(
        &mut self,
        vr: &[u32],
        order: &[i32],
        values: &[f64],
    ) -> Result<(), Refused> {
        assert!(
            vr.len() == order.len() && vr.len() == values.len(),
            "fmi2SetRealInputDerivatives: one order and value per reference"
        );
        // SAFETY: a live instance; the buffers hold vr.len() elements.
        check("fmi2SetRealInputDerivatives", unsafe {
            (self.f.set_input_derivatives)(
                self.c,
                vr.as_ptr(),
                vr.len(),
                order.as_ptr(),
                values.as_ptr(),
            )
        })
    }

    /// fmi2GetRealOutputDerivatives: the `order`-th time derivatives of the outputs `vr`.
    ///
    /// # Panics
    ///
    /// If `vr`, `order` and `values` differ in length.
    #[inline]
    pub fn get_real_output_derivatives(
        &self,
        vr: &[u32],
        order: &[i32],
        values: &mut [f64],
    ) -> Result<(), Refused> {
        assert!(
            vr.len() == order.len() && vr.len() == values.len(),
            "fmi2GetRealOutputDerivatives: one order and value per reference"
        );
        // SAFETY: a live instance; the buffers hold vr.len() elements.
        check("fmi2GetRealOutputDerivatives", unsafe {
            (self.f.get_output_derivatives)(
                self.c,
                vr.as_ptr(),
                vr.len(),
                order.as_ptr(),
                values.as_mut_ptr(),
            )
        })
    }

    /// fmi2DoStep from `t` by `h`, noSetFMUStatePriorToCurrentPoint = true (no rollback).
    #[inline]
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<(), Refused> {
        // SAFETY: a live instance of this library.
        check("fmi2DoStep", unsafe {
            (self.f.do_step)(self.c, t, h, fmi2True as fmi2Boolean)
        })
    }
}

/// The instance's state through fmi2GetFMUstate and fmi2SerializeFMUstate, and back through
/// fmi2DeSerializeFMUstate and fmi2SetFMUstate: a state serialised by one binary of the FMU (one
/// platform) can be restored by another.
impl Instance {
    /// The state now, serialised (fmi2GetFMUstate, fmi2SerializedFMUstateSize,
    /// fmi2SerializeFMUstate; the state is freed after).
    pub fn serialize_state(&mut self) -> Result<Vec<u8>, String> {
        let b = &self._binding;
        let get = resolved("fmi2GetFMUstate", &b.fmi2GetFMUstate, "the FMU")?;
        let size_of = resolved(
            "fmi2SerializedFMUstateSize",
            &b.fmi2SerializedFMUstateSize,
            "the FMU",
        )?;
        let serialize = resolved("fmi2SerializeFMUstate", &b.fmi2SerializeFMUstate, "the FMU")?;
        let free = resolved("fmi2FreeFMUstate", &b.fmi2FreeFMUstate, "the FMU")?;
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: a live instance of this library; out-pointers to locals; the buffer holds
        // `size` bytes as fmi2SerializeFMUstate is told.
        unsafe {
            check("fmi2GetFMUstate", get(self.c, &mut state))?;
            let mut size = 0usize;
            let mut bytes = Vec::new();
            let done = check(
                "fmi2SerializedFMUstateSize",
                size_of(self.c, state, &mut size),
            )
            .and_then(|()| {
                bytes = vec![0u8; size];
                check(
                    "fmi2SerializeFMUstate",
                    serialize(self.c, state, bytes.as_mut_ptr().cast(), size),
                )
            });
            check("fmi2FreeFMUstate", free(self.c, &mut state))?;
            done?;
            Ok(bytes)
        }
    }

    /// The instance takes the serialised state `bytes` (fmi2DeSerializeFMUstate,
    /// fmi2SetFMUstate; the state is freed after).
    pub fn restore_state(&mut self, bytes: &[u8]) -> Result<(), String> {
        let b = &self._binding;
        let deserialize = resolved(
            "fmi2DeSerializeFMUstate",
            &b.fmi2DeSerializeFMUstate,
            "the FMU",
        )?;
        let set = resolved("fmi2SetFMUstate", &b.fmi2SetFMUstate, "the FMU")?;
        let free = resolved("fmi2FreeFMUstate", &b.fmi2FreeFMUstate, "the FMU")?;
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: a live instance of this library; `bytes` is read, its length given.
        unsafe {
            check(
                "fmi2DeSerializeFMUstate",
                deserialize(self.c, bytes.as_ptr().cast(), bytes.len(), &mut state),
            )?;
            let done = check("fmi2SetFMUstate", set(self.c, state));
            check("fmi2FreeFMUstate", free(self.c, &mut state))?;
            Ok(done?)
        }
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: c is live until here and freed once; the binary is still loaded (_binding).
        unsafe {
            (self.f.terminate)(self.c);
            (self.f.free_instance)(self.c);
        }
    }
}

/// How many of the FMU's last messages [`keep_messages`] keeps.
pub const KEPT_MESSAGES: usize = 4;

/// The FMU's last messages (status Warning or worse), for the error of a run.
static MESSAGES: Mutex<VecDeque<String>> = Mutex::new(VecDeque::new());

/// The `log` logger the FMU's messages reach (fmi-sys's callback logs them with the instance
/// name as target): those of status Warning or worse are printed or kept.
enum Logger {
    Print,
    Keep,
}

static PRINT: Logger = Logger::Print;
static KEEP: Logger = Logger::Keep;

impl log::Log for Logger {
    fn enabled(&self, m: &log::Metadata) -> bool {
        m.level() <= log::Level::Warn
    }
    fn log(&self, r: &log::Record) {
        if r.level() > log::Level::Warn {
            return;
        }
        match self {
            Logger::Print => eprintln!("[fmu {} {}] {}", r.target(), r.level(), r.args()),
            Logger::Keep => {
                if let Ok(mut q) = MESSAGES.lock() {
                    if q.len() == KEPT_MESSAGES {
                        q.pop_front();
                    }
                    q.push_back(format!("[{}] {}", r.level(), r.args()));
                }
            }
        }
    }
    fn flush(&self) {}
}

fn install(logger: &'static Logger) {
    // the first call in a process sets the logger; later ones keep it
    let _ = log::set_logger(logger).map(|()| log::set_max_level(log::LevelFilter::Warn));
}

/// The FMU's messages of status Warning or worse go to standard error, as `[fmu INSTANCE
/// LEVEL] message`. The first of this and [`keep_messages`] in a process decides; without
/// either, the messages are dropped.
pub fn print_messages() {
    install(&PRINT);
}

/// The FMU's messages of status Warning or worse are kept, the last [`KEPT_MESSAGES`], for
/// [`take_messages`]. The first of this and [`print_messages`] in a process decides.
pub fn keep_messages() {
    install(&KEEP);
}

/// The kept messages since the last call, joined by ` | ` (empty if none), and forget them.
pub fn take_messages() -> String {
    match MESSAGES.lock() {
        Ok(mut q) => q.drain(..).collect::<Vec<_>>().join(" | "),
        Err(_) => String::new(),
    }
}
