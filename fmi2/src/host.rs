//! What the host hands over: arrays, output scalars and strings, each checked before use.
//! Nothing here trusts a host pointer beyond null, alignment and the length the host gives.

use std::ffi::CStr;

use fmi_sys::fmi2::fmi2String;

use crate::calls::Call;
use crate::status::{Refusal, refuse};

#[cold]
fn bad_pointer(call: &Call, what: &str, n: usize) -> Refusal {
    refuse(format!(
        "{}: {what} is a null or misaligned pointer for {n} elements",
        call.name
    ))
}

/// Whether `ptr` can be a host array of `n` > 0 elements.
#[inline(always)]
pub(crate) fn valid_array<T>(ptr: *const T, n: usize) -> bool {
    !ptr.is_null() && ptr.is_aligned() && n <= isize::MAX as usize / size_of::<T>().max(1)
}

/// A host array of `n` elements; `n` = 0 accepts a null pointer.
///
/// # Safety
/// A non-null `ptr` must point to `n` readable elements.
#[inline(always)]
pub unsafe fn host_slice<'a, T>(
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
///
/// # Safety
/// A non-null `ptr` must point to `n` writable elements.
#[inline(always)]
pub unsafe fn host_slice_mut<'a, T>(
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
///
/// # Safety
/// A non-null `ptr` must point to a writable element.
pub unsafe fn host_ref<'a, T>(ptr: *mut T, call: &Call, what: &str) -> Result<&'a mut T, Refusal> {
    // SAFETY: checked for null and alignment; the host owns the memory.
    unsafe { host_slice_mut(ptr, 1, call, what).map(|s| &mut s[0]) }
}

/// A host string for a message (untrusted: lossy and shortened).
///
/// # Safety
/// A non-null `ptr` must be a NUL-terminated string.
pub unsafe fn host_text(ptr: fmi2String) -> Option<String> {
    if ptr.is_null() {
        return None;
    }
    // SAFETY: the host promises a NUL-terminated string.
    let text = unsafe { CStr::from_ptr(ptr) }.to_string_lossy();
    Some(text.chars().take(256).collect())
}

#[cfg(test)]
#[path = "host_tests.rs"]
mod tests;
