//! fmi2Get/Set{Real,Integer} and the input and output derivatives, driven as a host drives them
//! on the test slave Probe (probe.rs), whose answers are worked out by hand: y = k u, g = 2 k,
//! dy/dt = k du. Both paths are taken: the quick one (k, u and n are stored values Probe answers
//! there) and the full one (everything else, or any call with logging on).

use fmi_sys::fmi2::*;

use super::*;
use crate::exports::probe::{C, G, K, MODE, N, P, Rig, U, Y, last_log};

fn get_reals(rig: &Rig<P>, vrs: &[u32]) -> (fmi2Status, Vec<f64>) {
    let mut out = vec![f64::NAN; vrs.len()];
    // SAFETY: our live instance; arrays of vrs.len() elements.
    let status = unsafe { fmi2GetReal::<P>(rig.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
    (status, out)
}

fn get_integers(rig: &Rig<P>, vrs: &[u32]) -> (fmi2Status, Vec<i32>) {
    let mut out = vec![-99; vrs.len()];
    // SAFETY: as above.
    let status = unsafe { fmi2GetInteger::<P>(rig.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
    (status, out)
}

fn set_reals(rig: &Rig<P>, vrs: &[u32], values: &[f64]) -> fmi2Status {
    // SAFETY: as above.
    unsafe { fmi2SetReal::<P>(rig.c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
}

fn set_integers(rig: &Rig<P>, vrs: &[u32], values: &[i32]) -> fmi2Status {
    // SAFETY: as above.
    unsafe { fmi2SetInteger::<P>(rig.c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
}

const OK: fmi2Status = fmi2Status_fmi2OK;
const ERROR: fmi2Status = fmi2Status_fmi2Error;

/// Reals go out and come back as they are, on the quick path and the full one, one at a time
/// and several at once, with logging off and on.
#[test]
fn reals_travel_unchanged_both_ways() {
    for (name, logging) in [("reals quiet", false), ("reals logged", true)] {
        let rig = Rig::<P>::running(name, fmi2Type_fmi2CoSimulation, logging);
        // Start values: k = 2, c = 0.1, u = 0; g = 2 k = 4, y = k u = 0.
        assert_eq!(get_reals(&rig, &[K]), (OK, vec![2.0]), "{name}");
        assert_eq!(get_reals(&rig, &[C]), (OK, vec![0.1]));
        assert_eq!(get_reals(&rig, &[G, K, U]), (OK, vec![4.0, 2.0, 0.0]));
        // u alone: the slave's quick set; c: the full one (a tunable parameter).
        assert_eq!(set_reals(&rig, &[U], &[-1.25]), OK);
        assert_eq!(set_reals(&rig, &[C], &[0.375]), OK);
        assert_eq!(get_reals(&rig, &[U]), (OK, vec![-1.25]));
        assert_eq!(get_reals(&rig, &[C, Y, K]), (OK, vec![0.375, -2.5, 2.0]));
        // Two at once: the full path.
        assert_eq!(set_reals(&rig, &[U, C], &[3.5, 7.0]), OK);
        assert_eq!(get_reals(&rig, &[Y, C, U]), (OK, vec![7.0, 7.0, 3.5]));
    }
}

/// Integers and Enumerations travel through fmi2Get/SetInteger as the integers they are.
#[test]
fn integers_and_enumerations_travel_as_integers() {
    let name = "integers";
    let rig = Rig::<P>::in_initialisation(name, fmi2Type_fmi2CoSimulation, false);
    // Start values: n = 3, mode = 2 (B).
    assert_eq!(get_integers(&rig, &[N]), (OK, vec![3]));
    assert_eq!(get_integers(&rig, &[MODE, N]), (OK, vec![2, 3]));
    assert_eq!(set_integers(&rig, &[N], &[7]), OK);
    assert_eq!(set_integers(&rig, &[MODE], &[5]), OK);
    assert_eq!(get_integers(&rig, &[N]), (OK, vec![7]));
    assert_eq!(get_integers(&rig, &[MODE]), (OK, vec![5]));
    assert_eq!(set_integers(&rig, &[N, MODE], &[-4, 1]), ERROR);
    assert_eq!(
        last_log(name).map(|l| l.1),
        Some("fmi2SetInteger: 'n' = -4 is below its minimum 1".into())
    );
    // Refused as a whole: mode kept its value.
    assert_eq!(get_integers(&rig, &[N, MODE]), (OK, vec![7, 5]));
    // A Real read as an Integer is refused, naming its type.
    assert_eq!(get_integers(&rig, &[K]).0, ERROR);
    assert_eq!(
        last_log(name).map(|l| l.1),
        Some("fmi2GetInteger: 'k' (value reference 10) is of type Real".into())
    );
}

/// An output that overflows from finite inputs is refused with fmi2Error, naming it and its
/// value, on every path that hands it out; the instance goes on.
#[test]
fn an_output_that_overflows_is_refused_not_handed_out() {
    let name = "overflow";
    let rig = Rig::<P>::running(name, fmi2Type_fmi2CoSimulation, false);
    // u = 1e308 is finite; y = k u = 2e308 is not.
    assert_eq!(set_reals(&rig, &[U], &[1e308]), OK);
    for vrs in [&[Y][..], &[K, Y], &[U, Y]] {
        assert_eq!(get_reals(&rig, vrs).0, ERROR, "{vrs:?}");
        let (level, message) = last_log(name).expect("the refusal");
        assert_eq!(level, log::Level::Error);
        assert!(
            message.starts_with("fmi2GetReal: the variable with value reference 30 would be inf: "),
            "{message}"
        );
    }
    assert_eq!(get_reals(&rig, &[U]), (OK, vec![1e308]));
    assert_eq!(set_reals(&rig, &[U], &[0.5]), OK);
    assert_eq!(get_reals(&rig, &[Y]), (OK, vec![1.0]));
}

fn set_input_derivative(rig: &Rig<P>, vr: u32, order: i32, value: f64) -> fmi2Status {
    // SAFETY: our live instance; one element each.
    unsafe { fmi2SetRealInputDerivatives::<P>(rig.c, &vr, 1, &order, &value) }
}

fn output_derivative(rig: &Rig<P>, vr: u32, order: i32) -> (fmi2Status, f64) {
    let mut out = f64::NAN;
    // SAFETY: as above.
    let status = unsafe { fmi2GetRealOutputDerivatives::<P>(rig.c, &vr, 1, &order, &mut out) };
    (status, out)
}

/// dy/dt = k du, where du is u's input derivative; a derivative that overflows is refused.
#[test]
fn output_derivatives_follow_the_input_derivatives() {
    let name = "derivatives";
    let rig = Rig::<P>::running(name, fmi2Type_fmi2CoSimulation, false);
    assert_eq!(output_derivative(&rig, Y, 1), (OK, 0.0));
    assert_eq!(set_input_derivative(&rig, U, 1, -0.75), OK);
    assert_eq!(output_derivative(&rig, Y, 1), (OK, -1.5));
    assert_eq!(set_input_derivative(&rig, K, 1, 1.0), ERROR);
    assert_eq!(
        last_log(name).map(|l| l.1),
        Some("fmi2SetRealInputDerivatives: 'k' is not a Real input".into())
    );
    assert_eq!(set_input_derivative(&rig, U, 1, 1e308), OK);
    assert_eq!(output_derivative(&rig, Y, 1).0, ERROR);
    let message = last_log(name).expect("the refusal").1;
    assert!(
        message.starts_with(
            "fmi2GetRealOutputDerivatives: the derivative of order 1 of value reference 30 would be inf: "
        ),
        "{message}"
    );
}

/// This FMU has no String variables: an empty request is carried out, any value reference is
/// unknown.
#[test]
fn strings_have_no_variables() {
    let name = "strings";
    let rig = Rig::<P>::running(name, fmi2Type_fmi2CoSimulation, false);
    let mut out: fmi2String = std::ptr::null();
    let value: fmi2String = c"text".as_ptr();
    // SAFETY: our live instance; arrays of the lengths given (none for 0).
    unsafe {
        assert_eq!(
            fmi2GetString::<P>(rig.c, std::ptr::null(), 0, std::ptr::null_mut()),
            OK
        );
        assert_eq!(
            fmi2SetString::<P>(rig.c, std::ptr::null(), 0, std::ptr::null()),
            OK
        );
        assert_eq!(fmi2GetString::<P>(rig.c, &U, 1, &mut out), ERROR);
        assert_eq!(
            last_log(name).map(|l| l.1),
            Some(
                "fmi2GetString: unknown value reference 20 (this FMU has no String variables)"
                    .into()
            )
        );
        assert_eq!(fmi2SetString::<P>(rig.c, &K, 1, &value), ERROR);
        assert_eq!(
            last_log(name).map(|l| l.1),
            Some(
                "fmi2SetString: unknown value reference 10 (this FMU has no String variables)"
                    .into()
            )
        );
    }
}
