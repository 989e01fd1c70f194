//! The exported fmi2* C entry points. Each is thin: it checks the pointers the host hands
//! over, catches any panic, and delegates to [`Instance`]. Nothing here unwraps host data.
#![allow(non_snake_case)]
#![allow(clippy::missing_safety_doc)]

use std::ffi::{CStr, CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

use fmi_sys::fmi2::*;

use super::instance::{Instance, Refusal, Reply, Status, allow, refuse};
use super::logger::Logger;
use super::vars::{GUID, VarType};

/// Run `body` on the instance behind `c`, turning refusals into logged statuses and panics
/// into a logged fmi2Error that leaves the instance usable only for reset or free.
fn guard(
    c: fmi2Component,
    function: &'static str,
    body: impl FnOnce(&mut Instance) -> Reply,
) -> fmi2Status {
    // SAFETY: `c` is what the host passed as our component; from_ptr accepts only our mark.
    let Some(inst) = (unsafe { Instance::from_ptr(c) }) else {
        return Status::Error as fmi2Status;
    };
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        inst.trace(|| function.to_string());
        body(inst)
    }));
    match outcome {
        Ok(Ok(status)) => status as fmi2Status,
        Ok(Err(Refusal { status, message })) => {
            let category = if status >= Status::Error {
                "logStatusError"
            } else {
                "logStatusWarning"
            };
            inst.log(status, category, &message);
            status as fmi2Status
        }
        Err(_) => {
            inst.set_broken();
            inst.log(
                Status::Error,
                "logStatusError",
                &format!("{function}: internal error (please report it); call fmi2Reset or fmi2FreeInstance"),
            );
            Status::Error as fmi2Status
        }
    }
}

/// A per-step call's fast path on the instance behind `c` (see `Instance::fast_get_real`):
/// its status if it took the call, None to send the call down the general path, which checks
/// in full, logs, and turns panics into errors (a panic here only sends the call there).
#[inline(always)]
fn fast(
    c: fmi2Component,
    body: impl FnOnce(&mut Instance) -> Option<Status>,
) -> Option<fmi2Status> {
    // SAFETY: as in `guard`.
    let inst = unsafe { Instance::from_ptr(c) }?;
    match catch_unwind(AssertUnwindSafe(|| body(inst))) {
        Ok(Some(status)) => Some(status as fmi2Status),
        _ => None,
    }
}

/// A host array of `n` elements; `n` = 0 accepts a null pointer.
#[inline(always)]
unsafe fn host_slice<'a, T>(ptr: *const T, n: usize, what: &str) -> Result<&'a [T], Refusal> {
    if n == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() || !ptr.is_aligned() || n > isize::MAX as usize / size_of::<T>().max(1) {
        return Err(refuse(format!(
            "{what} is a null or misaligned pointer for {n} elements"
        )));
    }
    // SAFETY: non-null, aligned, and the host promises n elements.
    Ok(unsafe { std::slice::from_raw_parts(ptr, n) })
}

/// A host output array of `n` elements.
#[inline(always)]
unsafe fn host_slice_mut<'a, T>(ptr: *mut T, n: usize, what: &str) -> Result<&'a mut [T], Refusal> {
    if n == 0 {
        return Ok(&mut []);
    }
    if ptr.is_null() || !ptr.is_aligned() || n > isize::MAX as usize / size_of::<T>().max(1) {
        return Err(refuse(format!(
            "{what} is a null or misaligned pointer for {n} elements"
        )));
    }
    // SAFETY: as above, for an array the host owns and lets us fill.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr, n) })
}

/// A host output scalar.
unsafe fn host_ref<'a, T>(ptr: *mut T, what: &str) -> Result<&'a mut T, Refusal> {
    // SAFETY: checked for null and alignment; the host owns the memory.
    unsafe { host_slice_mut(ptr, 1, what).map(|s| &mut s[0]) }
}

/// A host string for a message (untrusted: lossy and shortened).
unsafe fn host_text(ptr: fmi2String) -> Option<String> {
    if ptr.is_null() {
        return None;
    }
    // SAFETY: the host promises a NUL-terminated string.
    let text = unsafe { CStr::from_ptr(ptr) }.to_string_lossy();
    Some(text.chars().take(256).collect())
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: fmi2Type,
    fmuGUID: fmi2String,
    _fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    let made = catch_unwind(|| {
        if functions.is_null() || !functions.is_aligned() {
            return std::ptr::null_mut();
        }
        // SAFETY: non-null and aligned; the host owns the struct for the duration of the call.
        let callbacks = unsafe { &*functions };
        let logger = Logger::new(callbacks.logger, callbacks.componentEnvironment);
        // SAFETY: host strings, NUL-terminated or null.
        let name = unsafe { host_text(instanceName) };
        let report = |name: &str, message: &str| {
            let name = CString::new(name.replace('\0', " ")).unwrap_or_default();
            logger.log(&name, Status::Error, "logStatusError", message);
        };
        let Some(name) = name else {
            report("TLD", "fmi2Instantiate: instanceName is NULL");
            return std::ptr::null_mut();
        };
        if fmuType != fmi2Type_fmi2CoSimulation {
            report(
                &name,
                "fmi2Instantiate: TLD.fmu supports Co-Simulation only (fmuType must be fmi2CoSimulation)",
            );
            return std::ptr::null_mut();
        }
        // SAFETY: as above.
        match unsafe { host_text(fmuGUID) } {
            Some(guid) if guid == GUID => {}
            other => {
                report(
                    &name,
                    &format!(
                        "fmi2Instantiate: GUID {other:?} does not match this binary's {GUID}: wrong modelDescription.xml?"
                    ),
                );
                return std::ptr::null_mut();
            }
        }
        let c_name = CString::new(name.replace('\0', " ")).unwrap_or_default();
        let instance = Box::new(Instance::new(c_name, logger, loggingOn != 0));
        Box::into_raw(instance) as fmi2Component
    });
    made.unwrap_or(std::ptr::null_mut())
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    let _ = catch_unwind(|| {
        // SAFETY: only a pointer carrying our mark is taken back; the mark is wiped first, so
        // freeing the same pointer twice is recognised as long as the memory is not reused.
        if let Some(inst) = unsafe { Instance::from_ptr(c) } {
            inst.unmark();
            drop(unsafe { Box::from_raw(inst as *mut Instance) });
        }
    });
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    guard(c, "fmi2SetDebugLogging", |inst| {
        inst.require(allow::ANY, "fmi2SetDebugLogging")?;
        // SAFETY: host array of category strings.
        let raw =
            unsafe { host_slice(categories, nCategories, "fmi2SetDebugLogging: categories")? };
        let mut names = Vec::with_capacity(raw.len());
        for &p in raw {
            // SAFETY: host string.
            let text = unsafe { host_text(p) }
                .ok_or_else(|| refuse("fmi2SetDebugLogging: a category is NULL"))?;
            names.push(text);
        }
        inst.set_debug_logging(loggingOn != 0, &names)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    toleranceDefined: fmi2Boolean,
    tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2SetupExperiment", |inst| {
        let tolerance = (toleranceDefined != 0).then_some(tolerance);
        let stop = (stopTimeDefined != 0).then_some(stopTime);
        inst.setup_experiment(tolerance, startTime, stop)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    guard(c, "fmi2EnterInitializationMode", |inst| {
        inst.enter_initialization_mode()
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    guard(c, "fmi2ExitInitializationMode", |inst| {
        inst.exit_initialization_mode()
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    guard(c, "fmi2Terminate", |inst| inst.terminate())
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    guard(c, "fmi2Reset", |inst| inst.reset())
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    // SAFETY: the host's arrays of nvr elements, checked by the fast path before use.
    if let Some(status) = fast(c, |inst| unsafe { inst.fast_get_real(vr, nvr, value) }) {
        return status;
    }
    // SAFETY: the host's arguments, passed on as they came.
    unsafe { general_get_real(c, vr, nvr, value) }
}

/// fmi2GetReal's general path, out of line: the fast path then needs no stack frame
/// of its size.
#[inline(never)]
unsafe fn general_get_real(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2GetReal", |inst| {
        // SAFETY: host arrays of nvr elements.
        let (vrs, out) = unsafe {
            (
                host_slice(vr, nvr, "fmi2GetReal: vr")?,
                host_slice_mut(value, nvr, "fmi2GetReal: value")?,
            )
        };
        inst.get(vrs, VarType::Real, "fmi2GetReal", |k, v| out[k] = v)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    guard(c, "fmi2GetInteger", |inst| {
        // SAFETY: host arrays of nvr elements.
        let (vrs, out) = unsafe {
            (
                host_slice(vr, nvr, "fmi2GetInteger: vr")?,
                host_slice_mut(value, nvr, "fmi2GetInteger: value")?,
            )
        };
        inst.get(vrs, VarType::Integer, "fmi2GetInteger", |k, v| {
            out[k] = v as fmi2Integer
        })
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    guard(c, "fmi2GetBoolean", |inst| {
        // SAFETY: host arrays of nvr elements.
        let (vrs, out) = unsafe {
            (
                host_slice(vr, nvr, "fmi2GetBoolean: vr")?,
                host_slice_mut(value, nvr, "fmi2GetBoolean: value")?,
            )
        };
        inst.get(vrs, VarType::Boolean, "fmi2GetBoolean", |k, v| {
            out[k] = fmi2Boolean::from(v != 0.0)
        })
    })
}

/// This FMU has no String variables: any value reference is unknown.
fn no_strings(inst: &mut Instance, vrs: &[u32], allowed: u8, function: &str) -> Reply {
    inst.require(allowed, function)?;
    match vrs.first() {
        None => Ok(Status::Ok),
        Some(r) => Err(refuse(format!(
            "{function}: unknown value reference {r} (this FMU has no String variables)"
        ))),
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    guard(c, "fmi2GetString", |inst| {
        // SAFETY: host arrays of nvr elements.
        let vrs = unsafe {
            host_slice_mut(value, nvr, "fmi2GetString: value")?;
            host_slice(vr, nvr, "fmi2GetString: vr")?
        };
        no_strings(inst, vrs, allow::GET, "fmi2GetString")
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    // SAFETY: the host's arrays of nvr elements, checked by the fast path before use.
    if let Some(status) = fast(c, |inst| unsafe { inst.fast_set_real(vr, nvr, value) }) {
        return status;
    }
    // SAFETY: the host's arguments, passed on as they came.
    unsafe { general_set_real(c, vr, nvr, value) }
}

/// fmi2SetReal's general path, out of line: the fast path then needs no stack frame
/// of its size.
#[inline(never)]
unsafe fn general_set_real(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2SetReal", |inst| {
        // SAFETY: host arrays of nvr elements.
        let (vrs, vals) = unsafe {
            (
                host_slice(vr, nvr, "fmi2SetReal: vr")?,
                host_slice(value, nvr, "fmi2SetReal: value")?,
            )
        };
        inst.set(vrs, vals, VarType::Real, "fmi2SetReal")
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    guard(c, "fmi2SetInteger", |inst| {
        // SAFETY: host arrays of nvr elements.
        let (vrs, vals) = unsafe {
            (
                host_slice(vr, nvr, "fmi2SetInteger: vr")?,
                host_slice(value, nvr, "fmi2SetInteger: value")?,
            )
        };
        let vals: Vec<f64> = vals.iter().map(|&v| f64::from(v)).collect();
        inst.set(vrs, &vals, VarType::Integer, "fmi2SetInteger")
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    guard(c, "fmi2SetBoolean", |inst| {
        // SAFETY: host arrays of nvr elements.
        let (vrs, vals) = unsafe {
            (
                host_slice(vr, nvr, "fmi2SetBoolean: vr")?,
                host_slice(value, nvr, "fmi2SetBoolean: value")?,
            )
        };
        let vals: Vec<f64> = vals.iter().map(|&v| f64::from(i32::from(v != 0))).collect();
        inst.set(vrs, &vals, VarType::Boolean, "fmi2SetBoolean")
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    guard(c, "fmi2SetString", |inst| {
        // SAFETY: host arrays of nvr elements.
        let vrs = unsafe {
            host_slice(value, nvr, "fmi2SetString: value")?;
            host_slice(vr, nvr, "fmi2SetString: vr")?
        };
        no_strings(inst, vrs, allow::SET, "fmi2SetString")
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    guard(c, "fmi2DoStep", |inst| {
        inst.do_step(currentCommunicationPoint, communicationStepSize)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    guard(c, "fmi2CancelStep", |inst| {
        inst.require(0, "fmi2CancelStep (no asynchronous step is ever running)")
            .map(|_| Status::Ok)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    _s: fmi2StatusKind,
    value: *mut fmi2Status,
) -> fmi2Status {
    guard(c, "fmi2GetStatus", |inst| {
        inst.require(allow::STATUS, "fmi2GetStatus")?;
        // SAFETY: host output scalar.
        unsafe { host_ref(value, "fmi2GetStatus: value")? };
        Err(Refusal::new(
            Status::Discard,
            "fmi2GetStatus: no status is pending (fmi2DoStep never returns fmi2Pending)",
        ))
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2GetRealStatus", |inst| {
        let time = inst.last_successful_time()?;
        // SAFETY: host output scalar.
        let out = unsafe { host_ref(value, "fmi2GetRealStatus: value")? };
        if s != fmi2StatusKind_fmi2LastSuccessfulTime {
            return Err(Refusal::new(
                Status::Discard,
                format!(
                    "fmi2GetRealStatus: status kind {s} has no Real value (only fmi2LastSuccessfulTime)"
                ),
            ));
        }
        *out = time;
        Ok(Status::Ok)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Integer,
) -> fmi2Status {
    guard(c, "fmi2GetIntegerStatus", |inst| {
        inst.require(allow::STATUS, "fmi2GetIntegerStatus")?;
        // SAFETY: host output scalar.
        unsafe { host_ref(value, "fmi2GetIntegerStatus: value")? };
        Err(Refusal::new(
            Status::Discard,
            format!("fmi2GetIntegerStatus: status kind {s} has no Integer value"),
        ))
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    guard(c, "fmi2GetBooleanStatus", |inst| {
        inst.require(allow::STATUS, "fmi2GetBooleanStatus")?;
        // SAFETY: host output scalar.
        let out = unsafe { host_ref(value, "fmi2GetBooleanStatus: value")? };
        if s != fmi2StatusKind_fmi2Terminated {
            return Err(Refusal::new(
                Status::Discard,
                format!(
                    "fmi2GetBooleanStatus: status kind {s} has no Boolean value (only fmi2Terminated)"
                ),
            ));
        }
        // The FMU never asks the master to end the simulation.
        *out = 0;
        Ok(Status::Ok)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2String,
) -> fmi2Status {
    guard(c, "fmi2GetStringStatus", |inst| {
        inst.require(allow::STATUS, "fmi2GetStringStatus")?;
        // SAFETY: host output scalar.
        unsafe { host_ref(value, "fmi2GetStringStatus: value")? };
        Err(Refusal::new(
            Status::Discard,
            format!("fmi2GetStringStatus: status kind {s}: nothing is pending"),
        ))
    })
}

/// Functions this FMU exports so that every host resolves its symbols, but does not offer.
macro_rules! not_offered {
    ($why:expr => $( fn $name:ident ( $( $arg:ident : $ty:ty ),* ) ; )*) => {
        $(
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn $name(c: fmi2Component $(, $arg: $ty)*) -> fmi2Status {
                $( let _ = $arg; )*
                guard(c, stringify!($name), |_| Err(refuse(format!("{}: {}", stringify!($name), $why))))
            }
        )*
    };
}

not_offered! { "TLD.fmu is a Co-Simulation FMU; Model Exchange is not provided" =>
    fn fmi2EnterEventMode();
    fn fmi2NewDiscreteStates(info: *mut fmi2EventInfo);
    fn fmi2EnterContinuousTimeMode();
    fn fmi2CompletedIntegratorStep(no_set_prior: fmi2Boolean, enter_event: *mut fmi2Boolean, terminate: *mut fmi2Boolean);
    fn fmi2SetTime(time: fmi2Real);
    fn fmi2SetContinuousStates(x: *const fmi2Real, nx: usize);
    fn fmi2GetDerivatives(derivatives: *mut fmi2Real, nx: usize);
    fn fmi2GetEventIndicators(indicators: *mut fmi2Real, ni: usize);
    fn fmi2GetContinuousStates(x: *mut fmi2Real, nx: usize);
    fn fmi2GetNominalsOfContinuousStates(nominals: *mut fmi2Real, nx: usize);
}

/// What an fmi2FMUstate points to: the instance's state in its serialised form (one code path
/// for in-memory and serialised states), with a mark to recognise it.
struct StateBox {
    magic: u64,
    bytes: Vec<u8>,
}

const STATE_MAGIC: u64 = 0x544c_445f_5354_4154;

/// The state behind a host's fmi2FMUstate, if it is one of ours.
unsafe fn state_box<'a>(state: fmi2FMUstate, function: &str) -> Result<&'a mut StateBox, Refusal> {
    let p = state as *mut StateBox;
    // SAFETY: non-null, aligned, and marked: a state this library allocated and did not free.
    if !p.is_null() && p.is_aligned() && unsafe { (*p).magic } == STATE_MAGIC {
        Ok(unsafe { &mut *p })
    } else {
        Err(refuse(format!(
            "{function}: the FMU state pointer is null or not a state of this FMU"
        )))
    }
}

fn new_state(bytes: Vec<u8>) -> fmi2FMUstate {
    Box::into_raw(Box::new(StateBox {
        magic: STATE_MAGIC,
        bytes,
    })) as fmi2FMUstate
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    guard(c, "fmi2GetFMUstate", |inst| {
        inst.require(allow::ANY, "fmi2GetFMUstate")?;
        // SAFETY: host output scalar.
        let out = unsafe { host_ref(FMUstate, "fmi2GetFMUstate: FMUstate")? };
        let bytes = inst.save();
        if out.is_null() {
            *out = new_state(bytes);
        } else {
            // The host hands back a state to overwrite.
            unsafe { state_box(*out, "fmi2GetFMUstate")? }.bytes = bytes;
        }
        Ok(Status::Ok)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    guard(c, "fmi2SetFMUstate", |inst| {
        inst.require(allow::ANY, "fmi2SetFMUstate")?;
        // SAFETY: a host state pointer, recognised by its mark.
        let state = unsafe { state_box(FMUstate, "fmi2SetFMUstate")? };
        inst.load(&state.bytes)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    guard(c, "fmi2FreeFMUstate", |inst| {
        inst.require(allow::ANY, "fmi2FreeFMUstate")?;
        // SAFETY: host in-out scalar.
        let slot = unsafe { host_ref(FMUstate, "fmi2FreeFMUstate: FMUstate")? };
        if slot.is_null() {
            return Ok(Status::Ok);
        }
        // SAFETY: a state of ours: unmark, then take the box back exactly once.
        let state = unsafe { state_box(*slot, "fmi2FreeFMUstate")? };
        state.magic = 0;
        drop(unsafe { Box::from_raw(state as *mut StateBox) });
        *slot = std::ptr::null_mut();
        Ok(Status::Ok)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    guard(c, "fmi2SerializedFMUstateSize", |inst| {
        inst.require(allow::ANY, "fmi2SerializedFMUstateSize")?;
        // SAFETY: host state and output scalar.
        let (state, out) = unsafe {
            (
                state_box(FMUstate, "fmi2SerializedFMUstateSize")?,
                host_ref(size, "fmi2SerializedFMUstateSize: size")?,
            )
        };
        *out = state.bytes.len();
        Ok(Status::Ok)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    guard(c, "fmi2SerializeFMUstate", |inst| {
        inst.require(allow::ANY, "fmi2SerializeFMUstate")?;
        // SAFETY: host state pointer.
        let state = unsafe { state_box(FMUstate, "fmi2SerializeFMUstate")? };
        if size != state.bytes.len() {
            return Err(refuse(format!(
                "fmi2SerializeFMUstate: size {size} is not the serialised size {} (ask fmi2SerializedFMUstateSize)",
                state.bytes.len()
            )));
        }
        // SAFETY: host buffer of `size` bytes.
        let out = unsafe {
            host_slice_mut(
                serializedState as *mut u8,
                size,
                "fmi2SerializeFMUstate: buffer",
            )?
        };
        out.copy_from_slice(&state.bytes);
        Ok(Status::Ok)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: usize,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    guard(c, "fmi2DeSerializeFMUstate", |inst| {
        inst.require(allow::ANY, "fmi2DeSerializeFMUstate")?;
        // SAFETY: host buffer of `size` bytes and host output scalar.
        let (bytes, out) = unsafe {
            (
                host_slice(
                    serializedState as *const u8,
                    size,
                    "fmi2DeSerializeFMUstate: buffer",
                )?,
                host_ref(FMUstate, "fmi2DeSerializeFMUstate: FMUstate")?,
            )
        };
        Instance::check_saved(bytes)
            .map_err(|r| refuse(format!("fmi2DeSerializeFMUstate: {}", r.message)))?;
        // A host may hand back one of our states for reuse (fmpy does); anything else in the
        // slot is not ours to free, and a new state is made.
        // SAFETY: a host state pointer, recognised by its mark.
        match unsafe { state_box(*out, "fmi2DeSerializeFMUstate") } {
            Ok(state) => state.bytes = bytes.to_vec(),
            Err(_) => *out = new_state(bytes.to_vec()),
        }
        Ok(Status::Ok)
    })
}

not_offered! { "providesDirectionalDerivative is false" =>
    fn fmi2GetDirectionalDerivative(unknowns: *const fmi2ValueReference, n_unknown: usize, knowns: *const fmi2ValueReference, n_known: usize, dv_known: *const fmi2Real, dv_unknown: *mut fmi2Real);
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2SetRealInputDerivatives";
    guard(c, F, |inst| {
        // SAFETY: host arrays of nvr elements.
        let (vrs, orders, values) = unsafe {
            (
                host_slice(vr, nvr, "vr")?,
                host_slice(order, nvr, "order")?,
                host_slice(value, nvr, "value")?,
            )
        };
        inst.set_input_derivatives(vrs, orders, values)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetRealOutputDerivatives";
    guard(c, F, |inst| {
        // SAFETY: host arrays of nvr elements.
        let (vrs, orders, out) = unsafe {
            (
                host_slice(vr, nvr, "vr")?,
                host_slice(order, nvr, "order")?,
                host_slice_mut(value, nvr, "value")?,
            )
        };
        inst.output_derivatives(vrs, orders, |k, v| out[k] = v)
    })
}

// The signatures above must match the FMI 2.0 headers exactly (checked at compile time against
// fmi-sys's bindgen types).
const _: fmi2GetTypesPlatformTYPE = Some(fmi2GetTypesPlatform);
const _: fmi2GetVersionTYPE = Some(fmi2GetVersion);
const _: fmi2SetDebugLoggingTYPE = Some(fmi2SetDebugLogging);
const _: fmi2InstantiateTYPE = Some(fmi2Instantiate);
const _: fmi2FreeInstanceTYPE = Some(fmi2FreeInstance);
const _: fmi2SetupExperimentTYPE = Some(fmi2SetupExperiment);
const _: fmi2EnterInitializationModeTYPE = Some(fmi2EnterInitializationMode);
const _: fmi2ExitInitializationModeTYPE = Some(fmi2ExitInitializationMode);
const _: fmi2TerminateTYPE = Some(fmi2Terminate);
const _: fmi2ResetTYPE = Some(fmi2Reset);
const _: fmi2GetRealTYPE = Some(fmi2GetReal);
const _: fmi2GetIntegerTYPE = Some(fmi2GetInteger);
const _: fmi2GetBooleanTYPE = Some(fmi2GetBoolean);
const _: fmi2GetStringTYPE = Some(fmi2GetString);
const _: fmi2SetRealTYPE = Some(fmi2SetReal);
const _: fmi2SetIntegerTYPE = Some(fmi2SetInteger);
const _: fmi2SetBooleanTYPE = Some(fmi2SetBoolean);
const _: fmi2SetStringTYPE = Some(fmi2SetString);
const _: fmi2GetFMUstateTYPE = Some(fmi2GetFMUstate);
const _: fmi2SetFMUstateTYPE = Some(fmi2SetFMUstate);
const _: fmi2FreeFMUstateTYPE = Some(fmi2FreeFMUstate);
const _: fmi2SerializedFMUstateSizeTYPE = Some(fmi2SerializedFMUstateSize);
const _: fmi2SerializeFMUstateTYPE = Some(fmi2SerializeFMUstate);
const _: fmi2DeSerializeFMUstateTYPE = Some(fmi2DeSerializeFMUstate);
const _: fmi2GetDirectionalDerivativeTYPE = Some(fmi2GetDirectionalDerivative);
const _: fmi2EnterEventModeTYPE = Some(fmi2EnterEventMode);
const _: fmi2NewDiscreteStatesTYPE = Some(fmi2NewDiscreteStates);
const _: fmi2EnterContinuousTimeModeTYPE = Some(fmi2EnterContinuousTimeMode);
const _: fmi2CompletedIntegratorStepTYPE = Some(fmi2CompletedIntegratorStep);
const _: fmi2SetTimeTYPE = Some(fmi2SetTime);
const _: fmi2SetContinuousStatesTYPE = Some(fmi2SetContinuousStates);
const _: fmi2GetDerivativesTYPE = Some(fmi2GetDerivatives);
const _: fmi2GetEventIndicatorsTYPE = Some(fmi2GetEventIndicators);
const _: fmi2GetContinuousStatesTYPE = Some(fmi2GetContinuousStates);
const _: fmi2GetNominalsOfContinuousStatesTYPE = Some(fmi2GetNominalsOfContinuousStates);
const _: fmi2SetRealInputDerivativesTYPE = Some(fmi2SetRealInputDerivatives);
const _: fmi2GetRealOutputDerivativesTYPE = Some(fmi2GetRealOutputDerivatives);
const _: fmi2DoStepTYPE = Some(fmi2DoStep);
const _: fmi2CancelStepTYPE = Some(fmi2CancelStep);
const _: fmi2GetStatusTYPE = Some(fmi2GetStatus);
const _: fmi2GetRealStatusTYPE = Some(fmi2GetRealStatus);
const _: fmi2GetIntegerStatusTYPE = Some(fmi2GetIntegerStatus);
const _: fmi2GetBooleanStatusTYPE = Some(fmi2GetBooleanStatus);
const _: fmi2GetStringStatusTYPE = Some(fmi2GetStringStatus);
