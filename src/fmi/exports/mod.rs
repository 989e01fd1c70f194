//! The exported fmi2* C entry points. Each is thin: it checks the call against its phase mask
//! (the table in `calls`) and the pointers the host hands over, catches any panic, and delegates
//! to [`Instance`]. Nothing here unwraps host data.
#![allow(non_snake_case)]
#![allow(clippy::missing_safety_doc)]

mod lifecycle;
mod state;
mod values;

use std::ffi::CStr;
use std::panic::{AssertUnwindSafe, catch_unwind};

use fmi_sys::fmi2::{fmi2Component, fmi2Status, fmi2String};

use super::calls::Call;
use super::instance::Instance;
use super::status::{Refusal, Reply, Status, refuse};
use super::vars::log_category;

/// The one way into an instance: `body` runs on the instance behind `c` if `call` is allowed in
/// its phase; refusals become logged statuses, and a panic a logged fmi2Error that leaves the
/// instance usable only for reset or free.
#[inline(always)]
fn guard(
    c: fmi2Component,
    call: &'static Call,
    body: impl FnOnce(&mut Instance) -> Reply,
) -> fmi2Status {
    // SAFETY: `c` is what the host passed as our component; from_ptr accepts only our mark.
    let Some(inst) = (unsafe { Instance::from_ptr(c) }) else {
        return Status::Error as fmi2Status;
    };
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        inst.require(call)?;
        body(inst)
    }));
    // Every arm takes its value: nothing is left to drop on the way out.
    match outcome {
        Ok(Ok(Status::Ok)) if !inst.logs_calls() => Status::Ok as fmi2Status,
        Ok(reply) => report(inst, call, reply),
        Err(panic) => broken(inst, call, panic),
    }
}

/// What `guard` tells the host about a call that was carried out with logging or a warning,
/// or refused.
#[cold]
#[inline(never)]
fn report(inst: &mut Instance, call: &Call, reply: Reply) -> fmi2Status {
    match reply {
        // Carried out (a warning has said why itself): traced when the host asked for logCalls.
        Ok(status) => {
            if inst.logs_calls() {
                inst.log(Status::Ok, log_category::LOG_CALLS, call.name);
            }
            status as fmi2Status
        }
        Err(Refusal { status, message }) => {
            let category = if status >= Status::Error {
                log_category::LOG_STATUS_ERROR
            } else {
                log_category::LOG_STATUS_WARNING
            };
            inst.log(status, category, &message);
            status as fmi2Status
        }
    }
}

/// A panic caught in `guard`: the instance is left usable only for reset or free.
#[cold]
#[inline(never)]
fn broken(inst: &mut Instance, call: &Call, panic: Box<dyn std::any::Any + Send>) -> fmi2Status {
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

#[cold]
fn bad_pointer(call: &Call, what: &str, n: usize) -> Refusal {
    refuse(format!(
        "{}: {what} is a null or misaligned pointer for {n} elements",
        call.name
    ))
}

/// Whether `ptr` can be a host array of `n` > 0 elements.
#[inline(always)]
fn valid_array<T>(ptr: *const T, n: usize) -> bool {
    !ptr.is_null() && ptr.is_aligned() && n <= isize::MAX as usize / size_of::<T>().max(1)
}

/// A host array of `n` elements; `n` = 0 accepts a null pointer.
#[inline(always)]
unsafe fn host_slice<'a, T>(
    ptr: *const T,
    n: usize,
    call: &Call,
    what: &str,
) -> Result<&'a [T], Refusal> {
    if n == 0 {
        return Ok(&[]);
    }
    if !valid_array(ptr, n) {
        return Err(bad_pointer(call, what, n));
    }
    // SAFETY: non-null, aligned, and the host promises n elements.
    Ok(unsafe { std::slice::from_raw_parts(ptr, n) })
}

/// A host output array of `n` elements.
#[inline(always)]
unsafe fn host_slice_mut<'a, T>(
    ptr: *mut T,
    n: usize,
    call: &Call,
    what: &str,
) -> Result<&'a mut [T], Refusal> {
    if n == 0 {
        return Ok(&mut []);
    }
    if !valid_array(ptr, n) {
        return Err(bad_pointer(call, what, n));
    }
    // SAFETY: as above, for an array the host owns and lets us fill.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr, n) })
}

/// A host output scalar.
unsafe fn host_ref<'a, T>(ptr: *mut T, call: &Call, what: &str) -> Result<&'a mut T, Refusal> {
    // SAFETY: checked for null and alignment; the host owns the memory.
    unsafe { host_slice_mut(ptr, 1, call, what).map(|s| &mut s[0]) }
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
