//! The FMI 2.0 Co-Simulation and Model Exchange layer every FMU of this workspace shares: the only place that
//! speaks fmi2. An FMU implements [`Slave`] (its variables, its model) and invokes
//! [`export_fmi2!`] once with its type; the macro emits the `extern "C"` fmi2* functions, each a
//! call of the generic body in [`exports`] monomorphised for that slave (no dynamic dispatch,
//! no cost over hand-written exports).
//!
//! - `continuous`: the Model Exchange side of the slave contract (states, derivatives, events);
//! - `calls`: the call-sequence table (phases, one mask per function), checked first in every
//!   call by the guard in `exports`;
//! - `instance`: what every instance holds (name, logger, phase, experiment, time) around the
//!   slave, and the call sequence itself;
//! - `description`: the variable table's types and the checks every setter makes;
//! - `frame`: the saved state's frame (tag, version, GUID, checksum, the shared header);
//! - `host`, `logger`, `status`: host pointers, the host's logger, statuses and refusals.

pub mod calls;
pub mod continuous;
pub mod description;
pub mod exports;
pub mod frame;
pub mod host;
pub mod instance;
pub mod logger;
pub mod slave;
pub mod status;

pub use continuous::{Continuous, EventUpdate};
pub use fmi_sys;
pub use instance::Kind;
pub use slave::{Context, Slave};
pub use status::{Refusal, Reply, Status, refuse};

/// Emits the fmi2* C entry points of an FMU whose slave is `$slave` (a type implementing
/// [`Slave`]). Invoke it once, in the FMU's cdylib crate.
#[macro_export]
macro_rules! export_fmi2 {
    ($slave:ty) => {
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        mod fmi2_exports {
            use super::*;
            use $crate::exports as body;
            use $crate::fmi_sys::fmi2::*;
            type S = $slave;

            $crate::export_fmi2!(@fns S;
                fn fmi2GetTypesPlatform() -> *const ::std::ffi::c_char => fmi2GetTypesPlatformTYPE;
                fn fmi2GetVersion() -> *const ::std::ffi::c_char => fmi2GetVersionTYPE;
                fn fmi2Instantiate(instanceName: fmi2String, fmuType: fmi2Type, fmuGUID: fmi2String, fmuResourceLocation: fmi2String, functions: *const fmi2CallbackFunctions, visible: fmi2Boolean, loggingOn: fmi2Boolean) -> fmi2Component => fmi2InstantiateTYPE;
                fn fmi2FreeInstance(c: fmi2Component) -> () => fmi2FreeInstanceTYPE;
                fn fmi2SetDebugLogging(c: fmi2Component, loggingOn: fmi2Boolean, nCategories: usize, categories: *const fmi2String) -> fmi2Status => fmi2SetDebugLoggingTYPE;
                fn fmi2SetupExperiment(c: fmi2Component, toleranceDefined: fmi2Boolean, tolerance: fmi2Real, startTime: fmi2Real, stopTimeDefined: fmi2Boolean, stopTime: fmi2Real) -> fmi2Status => fmi2SetupExperimentTYPE;
                fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status => fmi2EnterInitializationModeTYPE;
                fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status => fmi2ExitInitializationModeTYPE;
                fn fmi2Terminate(c: fmi2Component) -> fmi2Status => fmi2TerminateTYPE;
                fn fmi2Reset(c: fmi2Component) -> fmi2Status => fmi2ResetTYPE;
                fn fmi2DoStep(c: fmi2Component, currentCommunicationPoint: fmi2Real, communicationStepSize: fmi2Real, noSetFMUStatePriorToCurrentPoint: fmi2Boolean) -> fmi2Status => fmi2DoStepTYPE;
                fn fmi2CancelStep(c: fmi2Component) -> fmi2Status => fmi2CancelStepTYPE;
                fn fmi2GetStatus(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2Status) -> fmi2Status => fmi2GetStatusTYPE;
                fn fmi2GetRealStatus(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2Real) -> fmi2Status => fmi2GetRealStatusTYPE;
                fn fmi2GetIntegerStatus(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2Integer) -> fmi2Status => fmi2GetIntegerStatusTYPE;
                fn fmi2GetBooleanStatus(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2Boolean) -> fmi2Status => fmi2GetBooleanStatusTYPE;
                fn fmi2GetStringStatus(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2String) -> fmi2Status => fmi2GetStringStatusTYPE;
                fn fmi2GetReal(c: fmi2Component, vr: *const fmi2ValueReference, nvr: usize, value: *mut fmi2Real) -> fmi2Status => fmi2GetRealTYPE;
                fn fmi2GetInteger(c: fmi2Component, vr: *const fmi2ValueReference, nvr: usize, value: *mut fmi2Integer) -> fmi2Status => fmi2GetIntegerTYPE;
                fn fmi2GetBoolean(c: fmi2Component, vr: *const fmi2ValueReference, nvr: usize, value: *mut fmi2Boolean) -> fmi2Status => fmi2GetBooleanTYPE;
                fn fmi2GetString(c: fmi2Component, vr: *const fmi2ValueReference, nvr: usize, value: *mut fmi2String) -> fmi2Status => fmi2GetStringTYPE;
                fn fmi2SetReal(c: fmi2Component, vr: *const fmi2ValueReference, nvr: usize, value: *const fmi2Real) -> fmi2Status => fmi2SetRealTYPE;
                fn fmi2SetInteger(c: fmi2Component, vr: *const fmi2ValueReference, nvr: usize, value: *const fmi2Integer) -> fmi2Status => fmi2SetIntegerTYPE;
                fn fmi2SetBoolean(c: fmi2Component, vr: *const fmi2ValueReference, nvr: usize, value: *const fmi2Boolean) -> fmi2Status => fmi2SetBooleanTYPE;
                fn fmi2SetString(c: fmi2Component, vr: *const fmi2ValueReference, nvr: usize, value: *const fmi2String) -> fmi2Status => fmi2SetStringTYPE;
                fn fmi2SetRealInputDerivatives(c: fmi2Component, vr: *const fmi2ValueReference, nvr: usize, order: *const fmi2Integer, value: *const fmi2Real) -> fmi2Status => fmi2SetRealInputDerivativesTYPE;
                fn fmi2GetRealOutputDerivatives(c: fmi2Component, vr: *const fmi2ValueReference, nvr: usize, order: *const fmi2Integer, value: *mut fmi2Real) -> fmi2Status => fmi2GetRealOutputDerivativesTYPE;
                fn fmi2GetFMUstate(c: fmi2Component, FMUstate: *mut fmi2FMUstate) -> fmi2Status => fmi2GetFMUstateTYPE;
                fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status => fmi2SetFMUstateTYPE;
                fn fmi2FreeFMUstate(c: fmi2Component, FMUstate: *mut fmi2FMUstate) -> fmi2Status => fmi2FreeFMUstateTYPE;
                fn fmi2SerializedFMUstateSize(c: fmi2Component, FMUstate: fmi2FMUstate, size: *mut usize) -> fmi2Status => fmi2SerializedFMUstateSizeTYPE;
                fn fmi2SerializeFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate, serializedState: *mut fmi2Byte, size: usize) -> fmi2Status => fmi2SerializeFMUstateTYPE;
                fn fmi2DeSerializeFMUstate(c: fmi2Component, serializedState: *const fmi2Byte, size: usize, FMUstate: *mut fmi2FMUstate) -> fmi2Status => fmi2DeSerializeFMUstateTYPE;
            );

            $crate::export_fmi2!(@fns S;
                fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status => fmi2EnterEventModeTYPE;
                fn fmi2NewDiscreteStates(c: fmi2Component, info: *mut fmi2EventInfo) -> fmi2Status => fmi2NewDiscreteStatesTYPE;
                fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status => fmi2EnterContinuousTimeModeTYPE;
                fn fmi2CompletedIntegratorStep(c: fmi2Component, noSetFMUStatePriorToCurrentPoint: fmi2Boolean, enterEventMode: *mut fmi2Boolean, terminateSimulation: *mut fmi2Boolean) -> fmi2Status => fmi2CompletedIntegratorStepTYPE;
                fn fmi2SetTime(c: fmi2Component, time: fmi2Real) -> fmi2Status => fmi2SetTimeTYPE;
                fn fmi2SetContinuousStates(c: fmi2Component, x: *const fmi2Real, nx: usize) -> fmi2Status => fmi2SetContinuousStatesTYPE;
                fn fmi2GetDerivatives(c: fmi2Component, derivatives: *mut fmi2Real, nx: usize) -> fmi2Status => fmi2GetDerivativesTYPE;
                fn fmi2GetEventIndicators(c: fmi2Component, eventIndicators: *mut fmi2Real, ni: usize) -> fmi2Status => fmi2GetEventIndicatorsTYPE;
                fn fmi2GetContinuousStates(c: fmi2Component, x: *mut fmi2Real, nx: usize) -> fmi2Status => fmi2GetContinuousStatesTYPE;
                fn fmi2GetNominalsOfContinuousStates(c: fmi2Component, x_nominal: *mut fmi2Real, nx: usize) -> fmi2Status => fmi2GetNominalsOfContinuousStatesTYPE;
                fn fmi2GetDirectionalDerivative(c: fmi2Component, vUnknown_ref: *const fmi2ValueReference, nUnknown: usize, vKnown_ref: *const fmi2ValueReference, nKnown: usize, dvKnown: *const fmi2Real, dvUnknown: *mut fmi2Real) -> fmi2Status => fmi2GetDirectionalDerivativeTYPE;
            );
        }
    };
    // Each function calls its generic body; the signature is checked at compile time against
    // fmi-sys's bindgen type of the FMI 2.0 header (`fmi2XxxTYPE`).
    (@fns $s:ident; $( fn $name:ident ( $( $arg:ident : $ty:ty ),* ) -> $ret:ty => $check:ident ; )*) => {
        $(
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn $name( $( $arg : $ty ),* ) -> $ret {
                // SAFETY: the host's arguments, checked by the body before use.
                unsafe { body::$name::<$s>( $( $arg ),* ) }
            }
            const _: $check = Some($name);
        )*
    };
}
