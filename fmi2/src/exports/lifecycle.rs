//! Instances and the call sequence: instantiate and free, logging, the experiment,
//! initialisation, stepping, termination, reset and the status queries.

use std::ffi::{CString, c_char};
use std::panic::catch_unwind;

use fmi_sys::fmi2::*;

use super::{guard, host_ref, host_slice, host_text};
use crate::calls::{self, Call};
use crate::description::log_category;
use crate::instance::{Instance, Kind};
use crate::logger::Logger;
use crate::slave::Slave;
use crate::status::{Refusal, Status, refuse};

#[inline(always)]
pub unsafe fn fmi2GetTypesPlatform<S: Slave>() -> *const c_char {
    c"default".as_ptr()
}

#[inline(always)]
pub unsafe fn fmi2GetVersion<S: Slave>() -> *const c_char {
    c"2.0".as_ptr()
}

#[inline(always)]
pub unsafe fn fmi2Instantiate<S: Slave>(
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
            logger.log(
                &name,
                Status::Error,
                log_category::LOG_STATUS_ERROR,
                message,
            );
        };
        let model = S::TABLE.model_identifier;
        let Some(name) = name else {
            report(model, "fmi2Instantiate: instanceName is NULL");
            return std::ptr::null_mut();
        };
        #[allow(non_upper_case_globals)]
        let kind = match fmuType {
            fmi2Type_fmi2CoSimulation => Kind::CoSimulation,
            fmi2Type_fmi2ModelExchange => Kind::ModelExchange,
            other => {
                report(
                    &name,
                    &format!(
                        "fmi2Instantiate: fmuType {other} is neither fmi2ModelExchange (0) nor fmi2CoSimulation (1)"
                    ),
                );
                return std::ptr::null_mut();
            }
        };
        // SAFETY: as above.
        match unsafe { host_text(fmuGUID) } {
            Some(guid) if guid == S::TABLE.guid => {}
            other => {
                report(
                    &name,
                    &format!(
                        "fmi2Instantiate: GUID {other:?} does not match this binary's {}: wrong modelDescription.xml?",
                        S::TABLE.guid
                    ),
                );
                return std::ptr::null_mut();
            }
        }
        let c_name = CString::new(name.replace('\0', " ")).unwrap_or_default();
        let instance = Box::new(Instance::<S>::new(c_name, logger, loggingOn != 0, kind));
        if kind == Kind::ModelExchange
            && loggingOn != 0
            && let Some(note) = S::MODEL_EXCHANGE_NOTE
        {
            instance.log(Status::Ok, log_category::LOG_CALLS, note);
        }
        Box::into_raw(instance) as fmi2Component
    });
    made.unwrap_or(std::ptr::null_mut())
}

#[inline(always)]
pub unsafe fn fmi2FreeInstance<S: Slave>(c: fmi2Component) {
    let _ = catch_unwind(|| {
        // SAFETY: only a pointer carrying our mark is taken back; the mark is wiped first, so
        // freeing the same pointer twice is recognised as long as the memory is not reused.
        if let Some(inst) = unsafe { Instance::<S>::from_ptr(c) } {
            inst.unmark();
            drop(unsafe { Box::from_raw(inst as *mut Instance<S>) });
        }
    });
}

#[inline(always)]
pub unsafe fn fmi2SetDebugLogging<S: Slave>(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    const CALL: &Call = &calls::SET_DEBUG_LOGGING;
    guard::<S>(c, CALL, |inst| {
        // SAFETY: host array of category strings.
        let raw = unsafe { host_slice(categories, nCategories, CALL, "categories")? };
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

#[inline(always)]
pub unsafe fn fmi2SetupExperiment<S: Slave>(
    c: fmi2Component,
    toleranceDefined: fmi2Boolean,
    tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    guard::<S>(c, &calls::SETUP_EXPERIMENT, |inst| {
        let tolerance = (toleranceDefined != 0).then_some(tolerance);
        let stop = (stopTimeDefined != 0).then_some(stopTime);
        inst.setup_experiment(tolerance, startTime, stop)
    })
}

#[inline(always)]
pub unsafe fn fmi2EnterInitializationMode<S: Slave>(c: fmi2Component) -> fmi2Status {
    guard::<S>(c, &calls::ENTER_INITIALIZATION_MODE, |inst| {
        inst.enter_initialization_mode()
    })
}

#[inline(always)]
pub unsafe fn fmi2ExitInitializationMode<S: Slave>(c: fmi2Component) -> fmi2Status {
    guard::<S>(c, &calls::EXIT_INITIALIZATION_MODE, |inst| {
        inst.exit_initialization_mode()
    })
}

#[inline(always)]
pub unsafe fn fmi2Terminate<S: Slave>(c: fmi2Component) -> fmi2Status {
    guard::<S>(c, &calls::TERMINATE, |inst| inst.terminate())
}

#[inline(always)]
pub unsafe fn fmi2Reset<S: Slave>(c: fmi2Component) -> fmi2Status {
    guard::<S>(c, &calls::RESET, |inst| inst.reset())
}

#[inline(always)]
pub unsafe fn fmi2DoStep<S: Slave>(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    guard::<S>(c, &calls::DO_STEP, |inst| {
        inst.do_step(currentCommunicationPoint, communicationStepSize)
    })
}

#[inline(always)]
pub unsafe fn fmi2CancelStep<S: Slave>(c: fmi2Component) -> fmi2Status {
    // Never allowed: the guard refuses it with the table's reason.
    guard::<S>(c, &calls::CANCEL_STEP, |_| Ok(Status::Ok))
}

#[inline(always)]
pub unsafe fn fmi2GetStatus<S: Slave>(
    c: fmi2Component,
    _s: fmi2StatusKind,
    value: *mut fmi2Status,
) -> fmi2Status {
    const CALL: &Call = &calls::GET_STATUS;
    guard::<S>(c, CALL, |_| {
        // SAFETY: host output scalar.
        unsafe { host_ref(value, CALL, "value")? };
        Err(Refusal::new(
            Status::Discard,
            "fmi2GetStatus: no status is pending (fmi2DoStep never returns fmi2Pending)",
        ))
    })
}

#[inline(always)]
pub unsafe fn fmi2GetRealStatus<S: Slave>(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    const CALL: &Call = &calls::GET_REAL_STATUS;
    guard::<S>(c, CALL, |inst| {
        // SAFETY: host output scalar.
        let out = unsafe { host_ref(value, CALL, "value")? };
        if s != fmi2StatusKind_fmi2LastSuccessfulTime {
            return Err(Refusal::new(
                Status::Discard,
                format!(
                    "fmi2GetRealStatus: status kind {s} has no Real value (only fmi2LastSuccessfulTime)"
                ),
            ));
        }
        *out = inst.last_successful_time();
        Ok(Status::Ok)
    })
}

#[inline(always)]
pub unsafe fn fmi2GetIntegerStatus<S: Slave>(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Integer,
) -> fmi2Status {
    const CALL: &Call = &calls::GET_INTEGER_STATUS;
    guard::<S>(c, CALL, |_| {
        // SAFETY: host output scalar.
        unsafe { host_ref(value, CALL, "value")? };
        Err(Refusal::new(
            Status::Discard,
            format!("fmi2GetIntegerStatus: status kind {s} has no Integer value"),
        ))
    })
}

#[inline(always)]
pub unsafe fn fmi2GetBooleanStatus<S: Slave>(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    const CALL: &Call = &calls::GET_BOOLEAN_STATUS;
    guard::<S>(c, CALL, |_| {
        // SAFETY: host output scalar.
        let out = unsafe { host_ref(value, CALL, "value")? };
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

#[inline(always)]
pub unsafe fn fmi2GetStringStatus<S: Slave>(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2String,
) -> fmi2Status {
    const CALL: &Call = &calls::GET_STRING_STATUS;
    guard::<S>(c, CALL, |_| {
        // SAFETY: host output scalar.
        unsafe { host_ref(value, CALL, "value")? };
        Err(Refusal::new(
            Status::Discard,
            format!("fmi2GetStringStatus: status kind {s}: nothing is pending"),
        ))
    })
}
