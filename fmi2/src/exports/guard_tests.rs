//! The guard every export goes through: what it logs, under which category, and the check
//! that nothing leaves the FMU that a host cannot use.

use super::probe::{K, P, Rig, last_log};
use super::*;
use crate::calls;
use fmi_sys::fmi2::*;

/// With logging on (fmi2Instantiate's loggingOn, which switches logCalls on), every call
/// carried out is traced with its name (FMI 2.0: the FMU logs through the host's logger what the
/// host asked for); with it off, nothing is said.
#[test]
fn a_call_carried_out_is_traced_when_the_host_asked_for_it() {
    for (name, logging) in [("traced", true), ("quiet", false)] {
        let rig = Rig::<P>::running(name, fmi2Type_fmi2CoSimulation, logging);
        let before = tests::logs_of(name).len();
        let mut k = 0.0;
        // SAFETY: our live instance; one value reference and one value.
        let status = unsafe { fmi2GetReal::<P>(rig.c, &K, 1, &mut k) };
        assert_eq!((status, k), (fmi2Status_fmi2OK, 2.0));
        let logs = tests::logs_of(name);
        if logging {
            assert_eq!(logs.len(), before + 1);
            assert_eq!(
                last_log(name),
                Some((log::Level::Info, "fmi2GetReal".into()))
            );
        } else {
            assert_eq!(logs, []);
        }
    }
}

/// Errors and fatal errors go to logStatusError, warnings to logStatusWarning: the categories
/// the model descriptions declare ("Errors: illegal calls, bad values, failed steps" and
/// "Warnings", modelDescription/modelDescription.xml).
#[test]
fn refusals_are_logged_under_the_category_of_their_status() {
    assert_eq!(status_category(Status::Error), "logStatusError");
    assert_eq!(status_category(Status::Fatal), "logStatusError");
    assert_eq!(status_category(Status::Warning), "logStatusWarning");
}

/// A value about to be handed out that is not finite is refused, naming the first such value
/// and what it is; finite values pass, the largest and smallest too.
#[test]
fn only_finite_values_are_handed_out() {
    let call = &calls::GET_REAL;
    let what = |k: usize| format!("value {k}");
    assert_eq!(handed_out_finite(call, &[], what), Ok(()));
    assert_eq!(
        handed_out_finite(call, &[0.0, f64::MAX, f64::MIN, -1e-320], what),
        Ok(())
    );
    let tail = "an input or state is too large for the model's arithmetic; \
                set finite values of a physical size (or reset the instance)";
    for (values, k, shown) in [
        (vec![1.0, f64::INFINITY, f64::NAN], 1, "inf"),
        (vec![f64::NAN], 0, "NaN"),
        (vec![2.0, 3.0, f64::NEG_INFINITY], 2, "-inf"),
    ] {
        let refusal = handed_out_finite(call, &values, what).expect_err("not finite");
        assert_eq!(refusal.status, Status::Error);
        assert_eq!(
            *refusal.message,
            format!("fmi2GetReal: value {k} would be {shown}: {tail}")
        );
    }
}
