//! Variable access: one generic path for the Real, Integer and Boolean getters and setters,
//! String access (this FMU has no String variables), and the input and output derivatives.

use fmi_sys::fmi2::*;

use std::panic::{AssertUnwindSafe, catch_unwind};

use super::{guard, handed_out_finite, host_slice, host_slice_mut};
use crate::calls::{self, Call};
use crate::description::VarType;
use crate::host::valid_array;
use crate::instance::Instance;
use crate::slave::Slave;
use crate::status::{Reply, Status, refuse};

/// How one FMI value type travels to and from the instance's f64 values.
trait Access {
    type Host: Copy;
    const TYPE: VarType;
    /// fmi2Get and fmi2Set of this type (constants of the type: the out-of-line full paths then
    /// take the host's arguments as they came, in the same registers).
    const GET: &'static Call;
    const SET: &'static Call;
    fn to_host(value: f64) -> Self::Host;
    fn from_host(value: Self::Host) -> f64;
    /// The values handed out, as reals (to be checked finite; Integers and Booleans always
    /// are).
    fn reals(values: &[Self::Host]) -> &[f64] {
        let _ = values;
        &[]
    }
}

struct Reals;
struct Integers;
struct Booleans;

impl Access for Reals {
    type Host = fmi2Real;
    const TYPE: VarType = VarType::Real;
    const GET: &'static Call = &calls::GET_REAL;
    const SET: &'static Call = &calls::SET_REAL;
    #[inline(always)]
    fn to_host(value: f64) -> fmi2Real {
        value
    }
    #[inline(always)]
    fn from_host(value: fmi2Real) -> f64 {
        value
    }
    fn reals(values: &[fmi2Real]) -> &[f64] {
        values
    }
}

impl Access for Integers {
    type Host = fmi2Integer;
    const TYPE: VarType = VarType::Integer;
    const GET: &'static Call = &calls::GET_INTEGER;
    const SET: &'static Call = &calls::SET_INTEGER;
    fn to_host(value: f64) -> fmi2Integer {
        value as fmi2Integer
    }
    fn from_host(value: fmi2Integer) -> f64 {
        f64::from(value)
    }
}

impl Access for Booleans {
    type Host = fmi2Boolean;
    const TYPE: VarType = VarType::Boolean;
    const GET: &'static Call = &calls::GET_BOOLEAN;
    const SET: &'static Call = &calls::SET_BOOLEAN;
    fn to_host(value: f64) -> fmi2Boolean {
        fmi2Boolean::from(value != 0.0)
    }
    fn from_host(value: fmi2Boolean) -> f64 {
        f64::from(i32::from(value != 0))
    }
}

/// Our instance behind `c` if `call` passes quietly on it (its phase allows the call, no call
/// logging) with `n` > 0 values in valid host arrays `vr` and `value`: what the quick paths of
/// `get` and `set` assume. The checks of [`valid_array`], stricter on the length (values of 8
/// bytes at most, up to 2^30 of them), once for both arrays.
///
/// # Safety
/// `c` as for [`Instance::from_ptr`].
#[inline(always)]
unsafe fn quiet<'a, S: Slave, R, V>(
    c: fmi2Component,
    call: &Call,
    vr: *const R,
    n: usize,
    value: *const V,
) -> Option<&'a mut Instance<S>> {
    // Up to 2^30 values (any more: the full path, which takes up to isize::MAX bytes): a
    // bound the compiler tests in one compare (2^31 took it three instructions).
    const QUICK_MAX: usize = 1 << 30;
    const { assert!(size_of::<R>() <= 8 && size_of::<V>() <= 8) };
    const { assert!(QUICK_MAX <= isize::MAX as usize / 8) };
    let arrays = n.wrapping_sub(1) < QUICK_MAX
        && !vr.is_null()
        && vr.is_aligned()
        && !value.is_null()
        && value.is_aligned();
    debug_assert!(!arrays || (valid_array(vr, n) && valid_array(value, n)));
    if !arrays {
        return None;
    }
    // SAFETY: per the contract above.
    let inst = unsafe { Instance::<S>::from_ptr(c) }?;
    inst.passes_quietly(call).then_some(inst)
}

/// fmi2Get{Real,Integer,Boolean}: the quick path ([`Slave::get_quietly`]) when every value is
/// a load and the call passes quietly, else the full one. The quick path needs no saved
/// registers and no reply to carry: the full one is a call away, with the same arguments.
#[inline(always)]
unsafe fn get<S: Slave, A: Access>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut A::Host,
) -> fmi2Status {
    // SAFETY: the host's component and arrays, checked there.
    if let Some(inst) = unsafe { quiet::<S, _, _>(c, A::GET, vr, nvr, value) } {
        // SAFETY: host arrays of nvr elements, checked above.
        let (vrs, out) = unsafe {
            (
                std::slice::from_raw_parts(vr, nvr),
                std::slice::from_raw_parts_mut(value, nvr),
            )
        };
        // A panic (none is expected) is left to the full path, which catches it.
        let quietly = || inst.slave.get_quietly(vrs, out, A::TYPE, A::to_host);
        if catch_unwind(AssertUnwindSafe(quietly)).unwrap_or(false) {
            return Status::Ok as fmi2Status;
        }
    }
    // SAFETY: the host's arguments, as handed over.
    unsafe { get_in_full::<S, A>(c, vr, nvr, value) }
}

/// fmi2Get{Real,Integer,Boolean}, every case. extern "C", with the export's arguments: it
/// never unwinds (the guard catches every panic), so the quick path's call of it is a jump,
/// with no frame of its own.
#[inline(never)]
unsafe extern "C" fn get_in_full<S: Slave, A: Access>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut A::Host,
) -> fmi2Status {
    let call = A::GET;
    guard::<S>(c, call, |inst| {
        // SAFETY: host arrays of nvr elements.
        let (vrs, out) = unsafe {
            (
                host_slice(vr, nvr, call, "vr")?,
                host_slice_mut(value, nvr, call, "value")?,
            )
        };
        let status = inst
            .slave
            .get(&inst.context, vrs, out, A::TYPE, call.name, A::to_host)?;
        handed_out_finite(call, A::reals(out), |k| {
            format!("the variable with value reference {}", vrs[k])
        })?;
        Ok(status)
    })
}

/// fmi2Set{Real,Integer,Boolean}: the quick path ([`Slave::set_quietly`]) for one value the
/// slave takes as it is, in a call that passes quietly (the per-step input), else the full one.
#[inline(always)]
unsafe fn set<S: Slave, A: Access>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const A::Host,
) -> fmi2Status {
    // SAFETY: as in `get`.
    if nvr == 1
        && let Some(inst) = unsafe { quiet::<S, _, _>(c, A::SET, vr, nvr, value) }
    {
        // SAFETY: host arrays of one element, checked above.
        let (r, v) = unsafe { (*vr, A::from_host(*value)) };
        // A panic (none is expected) is left to the full path, which catches it.
        let done = catch_unwind(AssertUnwindSafe(|| inst.slave.set_quietly(r, v, A::TYPE)))
            .unwrap_or(false);
        if done {
            return Status::Ok as fmi2Status;
        }
    }
    // SAFETY: the host's arguments, as handed over.
    unsafe { set_in_full::<S, A>(c, vr, nvr, value) }
}

/// fmi2Set{Real,Integer,Boolean}, every case (extern "C" as `get_in_full`).
#[inline(never)]
unsafe extern "C" fn set_in_full<S: Slave, A: Access>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const A::Host,
) -> fmi2Status {
    let call = A::SET;
    guard::<S>(c, call, |inst| {
        // SAFETY: host arrays of nvr elements.
        let (vrs, values) = unsafe {
            (
                host_slice(vr, nvr, call, "vr")?,
                host_slice(value, nvr, call, "value")?,
            )
        };
        inst.slave
            .set(&inst.context, vrs, values, A::TYPE, call.name, A::from_host)
    })
}

#[inline(always)]
pub unsafe fn fmi2GetReal<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    // SAFETY: the host's arguments, checked before use.
    unsafe { get::<S, Reals>(c, vr, nvr, value) }
}

#[inline(always)]
pub unsafe fn fmi2GetInteger<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    // SAFETY: as above.
    unsafe { get::<S, Integers>(c, vr, nvr, value) }
}

#[inline(always)]
pub unsafe fn fmi2GetBoolean<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    // SAFETY: as above.
    unsafe { get::<S, Booleans>(c, vr, nvr, value) }
}

#[inline(always)]
pub unsafe fn fmi2SetReal<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    // SAFETY: as above.
    unsafe { set::<S, Reals>(c, vr, nvr, value) }
}

#[inline(always)]
pub unsafe fn fmi2SetInteger<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    // SAFETY: as above.
    unsafe { set::<S, Integers>(c, vr, nvr, value) }
}

#[inline(always)]
pub unsafe fn fmi2SetBoolean<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    // SAFETY: as above.
    unsafe { set::<S, Booleans>(c, vr, nvr, value) }
}

/// This FMU has no String variables: any value reference is unknown.
fn no_strings(vrs: &[u32], call: &Call) -> Reply {
    match vrs.first() {
        None => Ok(Status::Ok),
        Some(r) => Err(refuse(format!(
            "{}: unknown value reference {r} (this FMU has no String variables)",
            call.name
        ))),
    }
}

#[inline(always)]
pub unsafe fn fmi2GetString<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    const CALL: &Call = &calls::GET_STRING;
    guard::<S>(c, CALL, |_| {
        // SAFETY: host arrays of nvr elements.
        let vrs = unsafe {
            host_slice_mut(value, nvr, CALL, "value")?;
            host_slice(vr, nvr, CALL, "vr")?
        };
        no_strings(vrs, CALL)
    })
}

#[inline(always)]
pub unsafe fn fmi2SetString<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    const CALL: &Call = &calls::SET_STRING;
    guard::<S>(c, CALL, |_| {
        // SAFETY: host arrays of nvr elements.
        let vrs = unsafe {
            host_slice(value, nvr, CALL, "value")?;
            host_slice(vr, nvr, CALL, "vr")?
        };
        no_strings(vrs, CALL)
    })
}

#[inline(always)]
pub unsafe fn fmi2SetRealInputDerivatives<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    const CALL: &Call = &calls::SET_REAL_INPUT_DERIVATIVES;
    guard::<S>(c, CALL, |inst: &mut Instance<S>| {
        // SAFETY: host arrays of nvr elements.
        let (vrs, orders, values) = unsafe {
            (
                host_slice(vr, nvr, CALL, "vr")?,
                host_slice(order, nvr, CALL, "order")?,
                host_slice(value, nvr, CALL, "value")?,
            )
        };
        inst.slave.set_input_derivatives(vrs, orders, values)
    })
}

#[inline(always)]
pub unsafe fn fmi2GetRealOutputDerivatives<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *mut fmi2Real,
) -> fmi2Status {
    const CALL: &Call = &calls::GET_REAL_OUTPUT_DERIVATIVES;
    guard::<S>(c, CALL, |inst| {
        // SAFETY: host arrays of nvr elements.
        let (vrs, orders, out) = unsafe {
            (
                host_slice(vr, nvr, CALL, "vr")?,
                host_slice(order, nvr, CALL, "order")?,
                host_slice_mut(value, nvr, CALL, "value")?,
            )
        };
        let status = inst
            .slave
            .output_derivatives(&inst.context, vrs, orders, |k, v| out[k] = v)?;
        handed_out_finite(CALL, out, |k| {
            format!(
                "the derivative of order {} of value reference {}",
                orders[k], vrs[k]
            )
        })?;
        Ok(status)
    })
}

#[cfg(test)]
#[path = "values_tests.rs"]
mod tests;
