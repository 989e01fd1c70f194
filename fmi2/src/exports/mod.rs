//! The bodies of the fmi2* C entry points, generic over the slave; [`crate::export_fmi2`]
//! emits the `extern "C"` functions that call them (one monomorphised copy per FMU, inlined).
//! Each is thin: it checks the call against its phase mask (the table in `calls`) and the
//! pointers the host hands over, catches any panic, and delegates to [`Instance`]. Nothing here
//! unwraps host data.
#![allow(non_snake_case)]
#![allow(clippy::missing_safety_doc)]

mod lifecycle;
mod me;
mod state;
mod values;

pub use lifecycle::*;
pub use me::*;
pub use state::*;
pub use values::*;

use std::panic::{AssertUnwindSafe, catch_unwind};

use fmi_sys::fmi2::{fmi2Component, fmi2Status};

use crate::calls::Call;
use crate::description::log_category;
use crate::host::{host_ref, host_slice, host_slice_mut, host_text};
use crate::instance::Instance;
use crate::slave::Slave;
use crate::status::{Refusal, Reply, Status, refuse};

/// The one way into an instance: `body` runs on the instance behind `c` if `call` is allowed in
/// its phase; refusals become logged statuses, and a panic a logged fmi2Error that leaves the
/// instance usable only for reset or free.
#[inline(always)]
fn guard<S: Slave>(
    c: fmi2Component,
    call: &'static Call,
    body: impl FnOnce(&mut Instance<S>) -> Reply,
) -> fmi2Status {
    // SAFETY: `c` is what the host passed as our component; from_ptr accepts only our mark.
    let Some(inst) = (unsafe { Instance::<S>::from_ptr(c) }) else {
        return Status::Error as fmi2Status;
    };
    // The usual outcome, carried out with nothing to say, is told apart inside: a bare None
    // leaves the closure, not the whole reply.
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        match inst.require(call).and_then(|()| body(inst)) {
            Ok(Status::Ok) if !inst.logs_calls() => None,
            reply => Some(reply),
        }
    }));
    // Every arm takes its value: nothing is left to drop on the way out.
    match outcome {
        Ok(None) => Status::Ok as fmi2Status,
        Ok(Some(reply)) => report(inst, call, reply),
        Err(panic) => broken(inst, call, panic),
    }
}

/// What `guard` tells the host about a call that was carried out with logging or a warning,
/// or refused.
#[cold]
#[inline(never)]
fn report<S: Slave>(inst: &mut Instance<S>, call: &Call, reply: Reply) -> fmi2Status {
    match reply {
        // Carried out (a warning has said why itself): traced when the host asked for logCalls.
        Ok(status) => {
            if inst.logs_calls() {
                inst.log(Status::Ok, log_category::LOG_CALLS, call.name);
            }
            status as fmi2Status
        }
        Err(Refusal { status, message }) => {
            inst.log(status, status_category(status), &message);
            status as fmi2Status
        }
    }
}

/// The log category of a refusal with `status`: errors (and fatal errors) to logStatusError,
/// the rest to logStatusWarning (the model descriptions' LogCategories).
fn status_category(status: Status) -> &'static str {
    if status >= Status::Error {
        log_category::LOG_STATUS_ERROR
    } else {
        log_category::LOG_STATUS_WARNING
    }
}

/// A panic caught in `guard`: the instance is left usable only for reset or free.
#[cold]
#[inline(never)]
fn broken<S: Slave>(
    inst: &mut Instance<S>,
    call: &Call,
    panic: Box<dyn std::any::Any + Send>,
) -> fmi2Status {
    drop(panic);
    inst.set_broken();
    inst.log(
        Status::Error,
        log_category::LOG_STATUS_ERROR,
        &format!(
            "{}: internal error (please report it); call fmi2Reset or fmi2FreeInstance",
            call.name
        ),
    );
    Status::Error as fmi2Status
}

/// Nothing leaves the FMU that a host cannot use: `values` a call is about to hand out, all
/// finite, or refused (fmi2Error, the instance unchanged: only the host's array was written),
/// naming `what` the k-th value is. Finite inputs and states can still overflow on their way
/// out (a base.v of 1e300 squared in the amplitude estimator: found by coverage-guided fuzzing,
/// docs/FUZZING.md); the models' own checks say more where they can.
fn handed_out_finite(
    call: &Call,
    values: &[f64],
    what: impl Fn(usize) -> String,
) -> Result<(), Refusal> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(k) => Err(refuse(format!(
            "{}: {} would be {}: an input or state is too large for the model's arithmetic; \
             set finite values of a physical size (or reset the instance)",
            call.name,
            what(k),
            values[k]
        ))),
    }
}

#[cfg(test)]
mod guard_tests;
#[cfg(test)]
pub(crate) mod probe;
#[cfg(test)]
pub(crate) mod tests;
