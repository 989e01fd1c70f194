//! Model Exchange's exports on the test slave Probe (probe.rs): two states x, x' = (x1, -k x0)
//! with k = 2, one event indicator x0. The arrays must be exactly as long as the model
//! description declares (FMI 2.0, 3.2.2: nx and ni are the numbers of states and event
//! indicators); what the slave answers reaches the host unchanged.

use fmi_sys::fmi2::*;

use super::*;
use crate::exports::probe::{P, Rig, last_log};

const OK: fmi2Status = fmi2Status_fmi2OK;
const ERROR: fmi2Status = fmi2Status_fmi2Error;

/// An instance in continuous-time mode with x = (0.5, -1).
fn integrating(name: &str) -> Rig<P> {
    let rig = Rig::<P>::running(name, fmi2Type_fmi2ModelExchange, false);
    let x = [0.5, -1.0];
    // SAFETY: our live instance; an array of 2.
    unsafe {
        assert_eq!(fmi2EnterContinuousTimeMode::<P>(rig.c), OK);
        assert_eq!(fmi2SetContinuousStates::<P>(rig.c, x.as_ptr(), 2), OK);
    }
    rig
}

type Fill = unsafe fn(fmi2Component, *mut fmi2Real, usize) -> fmi2Status;

/// `fill` called with an array of `n` (NaN before the call).
fn filled(rig: &Rig<P>, fill: Fill, n: usize) -> (fmi2Status, Vec<f64>) {
    let mut out = vec![f64::NAN; n];
    // SAFETY: our live instance; an array of n.
    let status = unsafe { fill(rig.c, out.as_mut_ptr(), n) };
    (status, out)
}

#[test]
fn the_arrays_carry_the_slaves_states_derivatives_and_indicators() {
    let rig = integrating("me arrays");
    assert_eq!(
        filled(&rig, fmi2GetContinuousStates::<P>, 2),
        (OK, vec![0.5, -1.0])
    );
    // x' = (x1, -k x0) = (-1, -2 * 0.5).
    assert_eq!(
        filled(&rig, fmi2GetDerivatives::<P>, 2),
        (OK, vec![-1.0, -1.0])
    );
    assert_eq!(
        filled(&rig, fmi2GetEventIndicators::<P>, 1),
        (OK, vec![0.5])
    );
    // Probe keeps Continuous's default nominals: FMI 2.0 (3.2.2) asks for 1.0 where the FMU
    // knows no nominal.
    assert_eq!(
        filled(&rig, fmi2GetNominalsOfContinuousStates::<P>, 2),
        (OK, vec![1.0, 1.0])
    );
}

#[test]
fn an_array_of_another_length_than_declared_is_refused() {
    let name = "me lengths";
    let rig = integrating(name);
    let declared = |f: &str, what: &str, n: usize, d: usize| {
        format!("{f}: {what} = {n}, but the model description declares {d}")
    };
    let cases: [(Fill, &str, usize); 4] = [
        (fmi2GetContinuousStates::<P>, "fmi2GetContinuousStates", 2),
        (fmi2GetDerivatives::<P>, "fmi2GetDerivatives", 2),
        (
            fmi2GetNominalsOfContinuousStates::<P>,
            "fmi2GetNominalsOfContinuousStates",
            2,
        ),
        (fmi2GetEventIndicators::<P>, "fmi2GetEventIndicators", 1),
    ];
    for (fill, f, d) in cases {
        for n in [d - 1, d + 1, 2 * d + 3] {
            let (status, out) = filled(&rig, fill, n);
            assert_eq!(status, ERROR, "{f} {n}");
            assert!(out.iter().all(|v| v.is_nan()), "{f}: nothing written");
            assert_eq!(
                last_log(name).map(|l| l.1),
                Some(declared(f, "the array length", n, d))
            );
        }
    }
    let x = [9.0; 3];
    for n in [1, 3] {
        // SAFETY: our live instance; an array of 3.
        let status = unsafe { fmi2SetContinuousStates::<P>(rig.c, x.as_ptr(), n) };
        assert_eq!(status, ERROR);
        assert_eq!(
            last_log(name).map(|l| l.1),
            Some(declared("fmi2SetContinuousStates", "nx", n, 2))
        );
    }
    // The states were left as they were.
    assert_eq!(
        filled(&rig, fmi2GetContinuousStates::<P>, 2),
        (OK, vec![0.5, -1.0])
    );
}
