//! The checks of a host's arrays: null and misaligned pointers are refused for any length but
//! 0, and so is a length no array of that type can have; anything else is taken as it is.

use super::*;
use crate::calls;

const CALL: &Call = &calls::GET_REAL;

fn refusal(what: &str, n: usize) -> String {
    format!("fmi2GetReal: {what} is a null or misaligned pointer for {n} elements")
}

#[test]
fn arrays_of_any_usable_length_are_taken_as_they_are() {
    let values: Vec<f64> = (0..100).map(f64::from).collect();
    let mut out = [0u32; 100];
    for n in [1, 2, 7, 8, 9, 31, 100] {
        // SAFETY: arrays of at least n elements.
        unsafe {
            let got = host_slice(values.as_ptr(), n, CALL, "value").expect("an array");
            assert_eq!(got, &values[..n]);
            let put = host_slice_mut(out.as_mut_ptr(), n, CALL, "value").expect("an array");
            put[n - 1] = 42;
        }
        assert_eq!(out[n - 1], 42);
    }
    let mut one = 1.5;
    // SAFETY: a valid scalar.
    let r = unsafe { host_ref(&mut one, CALL, "value") }.expect("a scalar");
    *r = 2.5;
    assert_eq!(one, 2.5);
    // The largest lengths an array can have (not dereferenced: valid_array only).
    let p = values.as_ptr();
    assert!(valid_array(p, isize::MAX as usize / 8));
    assert!(valid_array(&0u8, isize::MAX as usize));
}

#[test]
fn null_misaligned_and_impossible_arrays_are_refused() {
    let null: *const f64 = std::ptr::null();
    let words = [0u64; 4];
    // One byte into an 8-byte aligned array: misaligned for f64, aligned for u8.
    // SAFETY: within the array.
    let odd = unsafe { words.as_ptr().cast::<u8>().add(1) };
    let misaligned = odd.cast::<f64>();
    for n in [1, 2, 3] {
        // Asked first, so that a wrong answer fails here, not in the slice's own checks.
        assert!(!valid_array(null, n));
        assert!(!valid_array(misaligned, n));
        assert!(valid_array(odd, n));
        // SAFETY: each is refused before any read.
        unsafe {
            let why = host_slice(null, n, CALL, "vr").expect_err("null");
            assert_eq!(*why.message, refusal("vr", n));
            let why = host_slice(misaligned, n, CALL, "value").expect_err("misaligned");
            assert_eq!(*why.message, refusal("value", n));
            let why =
                host_slice_mut(misaligned.cast_mut(), n, CALL, "out").expect_err("misaligned");
            assert_eq!(*why.message, refusal("out", n));
        }
    }
    // SAFETY: refused before any write.
    let why = unsafe { host_ref(std::ptr::null_mut::<i32>(), CALL, "size") }.expect_err("null");
    assert_eq!(*why.message, refusal("size", 1));
    // More elements than any array of them can hold.
    let p = words.as_ptr();
    for n in [isize::MAX as usize / 8 + 1, usize::MAX / 2, usize::MAX] {
        assert!(!valid_array(p, n), "{n}");
        // SAFETY: refused before any read.
        let why = unsafe { host_slice(p, n, CALL, "value") }.expect_err("too long");
        assert_eq!(*why.message, refusal("value", n));
    }
    // Length 0: no array needed, none read.
    // SAFETY: nothing is read.
    unsafe {
        assert_eq!(host_slice(null, 0, CALL, "vr").map(|s| s.len()), Ok(0));
        assert_eq!(
            host_slice(misaligned, 0, CALL, "vr").map(|s| s.len()),
            Ok(0)
        );
    }
}
