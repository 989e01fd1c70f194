//! Instances and the call sequence: instantiate and free, logging, the experiment,
//! initialisation, stepping, termination, reset and the status queries.

use std::ffi::{CString, c_char};
use std::panic::catch_unwind;

use fmi_sys::fmi2::*;

use super::{guard, host_ref, host_slice, host_text};
use crate::fmi::calls::{self, Call};
use crate::fmi::instance::Instance;
use crate::fmi::logger::Logger;
use crate::fmi::status::{Refusal, Status, refuse};
use crate::fmi::vars::{GUID, log_category};

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
            logger.log(
                &name,
                Status::Error,
                log_category::LOG_STATUS_ERROR,
                message,
            );
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
    const CALL: &Call = &calls::SET_DEBUG_LOGGING;
    guard(c, CALL, |inst| {
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

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    toleranceDefined: fmi2Boolean,
    tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    guard(c, &calls::SETUP_EXPERIMENT, |inst| {
        let tolerance = (toleranceDefined != 0).then_some(tolerance);
        let stop = (stopTimeDefined != 0).then_some(stopTime);
        inst.setup_experiment(tolerance, startTime, stop)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    guard(c, &calls::ENTER_INITIALIZATION_MODE, |inst| {
        inst.enter_initialization_mode()
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    guard(c, &calls::EXIT_INITIALIZATION_MODE, |inst| {
        inst.exit_initialization_mode()
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    guard(c, &calls::TERMINATE, |inst| inst.terminate())
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    guard(c, &calls::RESET, |inst| inst.reset())
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    guard(c, &calls::DO_STEP, |inst| {
        inst.do_step(currentCommunicationPoint, communicationStepSize)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    // Never allowed: the guard refuses it with the table's reason.
    guard(c, &calls::CANCEL_STEP, |_| Ok(Status::Ok))
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    _s: fmi2StatusKind,
    value: *mut fmi2Status,
) -> fmi2Status {
    const CALL: &Call = &calls::GET_STATUS;
    guard(c, CALL, |_| {
        // SAFETY: host output scalar.
        unsafe { host_ref(value, CALL, "value")? };
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
    const CALL: &Call = &calls::GET_REAL_STATUS;
    guard(c, CALL, |inst| {
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

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Integer,
) -> fmi2Status {
    const CALL: &Call = &calls::GET_INTEGER_STATUS;
    guard(c, CALL, |_| {
        // SAFETY: host output scalar.
        unsafe { host_ref(value, CALL, "value")? };
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
    const CALL: &Call = &calls::GET_BOOLEAN_STATUS;
    guard(c, CALL, |_| {
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

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2String,
) -> fmi2Status {
    const CALL: &Call = &calls::GET_STRING_STATUS;
    guard(c, CALL, |_| {
        // SAFETY: host output scalar.
        unsafe { host_ref(value, CALL, "value")? };
        Err(Refusal::new(
            Status::Discard,
            format!("fmi2GetStringStatus: status kind {s}: nothing is pending"),
        ))
    })
}

/// Functions this FMU exports so that every host resolves its symbols, but never carries out:
/// the table gives them no phase, and the guard refuses them with the table's reason.
macro_rules! not_offered {
    ($( fn $name:ident ( $( $arg:ident : $ty:ty ),* ) = $call:expr ; )*) => {
        $(
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn $name(c: fmi2Component $(, $arg: $ty)*) -> fmi2Status {
                $( let _ = $arg; )*
                guard(c, &$call, |_| Ok(Status::Ok))
            }
        )*
    };
}

not_offered! {
    fn fmi2EnterEventMode() = calls::ENTER_EVENT_MODE;
    fn fmi2NewDiscreteStates(info: *mut fmi2EventInfo) = calls::NEW_DISCRETE_STATES;
    fn fmi2EnterContinuousTimeMode() = calls::ENTER_CONTINUOUS_TIME_MODE;
    fn fmi2CompletedIntegratorStep(no_set_prior: fmi2Boolean, enter_event: *mut fmi2Boolean, terminate: *mut fmi2Boolean) = calls::COMPLETED_INTEGRATOR_STEP;
    fn fmi2SetTime(time: fmi2Real) = calls::SET_TIME;
    fn fmi2SetContinuousStates(x: *const fmi2Real, nx: usize) = calls::SET_CONTINUOUS_STATES;
    fn fmi2GetDerivatives(derivatives: *mut fmi2Real, nx: usize) = calls::GET_DERIVATIVES;
    fn fmi2GetEventIndicators(indicators: *mut fmi2Real, ni: usize) = calls::GET_EVENT_INDICATORS;
    fn fmi2GetContinuousStates(x: *mut fmi2Real, nx: usize) = calls::GET_CONTINUOUS_STATES;
    fn fmi2GetNominalsOfContinuousStates(nominals: *mut fmi2Real, nx: usize) = calls::GET_NOMINALS_OF_CONTINUOUS_STATES;
    fn fmi2GetDirectionalDerivative(unknowns: *const fmi2ValueReference, n_unknown: usize, knowns: *const fmi2ValueReference, n_known: usize, dv_known: *const fmi2Real, dv_unknown: *mut fmi2Real) = calls::GET_DIRECTIONAL_DERIVATIVE;
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
const _: fmi2DoStepTYPE = Some(fmi2DoStep);
const _: fmi2CancelStepTYPE = Some(fmi2CancelStep);
const _: fmi2GetStatusTYPE = Some(fmi2GetStatus);
const _: fmi2GetRealStatusTYPE = Some(fmi2GetRealStatus);
const _: fmi2GetIntegerStatusTYPE = Some(fmi2GetIntegerStatus);
const _: fmi2GetBooleanStatusTYPE = Some(fmi2GetBooleanStatus);
const _: fmi2GetStringStatusTYPE = Some(fmi2GetStringStatus);
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
