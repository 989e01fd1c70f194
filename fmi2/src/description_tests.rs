//! The table's lookups and the checks every setter makes, on the test slave Probe's table
//! (exports/probe.rs: every causality and variability the layer handles, positions that are not
//! the value references). The expected answers are FMI 2.0's rules, written out by hand:
//!
//! - fmi2Get/SetInteger serve Integer and Enumeration variables (FMI 2.0 has no Enumeration
//!   access functions), each other type its own functions (2.1.7);
//! - a fixed parameter is set only before fmi2ExitInitializationMode, a tunable one and an
//!   input also later; calculated parameters, outputs and locals are never set (2.2.7);
//! - in Model Exchange a discrete input changes in event mode only (3.2.3);
//! - a value must be finite, within min and max, and an Enumeration's one of its items;
//! - fmi2SetRealInputDerivatives takes Real inputs only, orders 1..maxInputDerivativeOrder;
//!   fmi2GetRealOutputDerivatives outputs only, orders 1..maxOutputDerivativeOrder (4.2.2).

use super::*;
use crate::exports::probe::{C, G, JUMP, K, L, MODE, N, ON, TABLE, U, VARIABLES, Y, at};

const F: &str = "fmi2SetX";

/// The message of a refusal, or "" for a success.
fn said<T>(r: Result<T, Refusal>) -> String {
    r.err().map(|e| *e.message).unwrap_or_default()
}

#[test]
fn finite_is_is_finite() {
    let values = [
        0.0,
        -0.0,
        1.5,
        -7.25e-300,
        f64::MIN_POSITIVE,
        f64::MAX,
        f64::MIN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
        -f64::NAN,
    ];
    let expected = [
        true, true, true, true, true, true, true, false, false, false, false,
    ];
    for (x, want) in values.into_iter().zip(expected) {
        assert_eq!(finite(x), want, "{x}");
    }
}

/// Every value reference of the table finds its own variable at its position; the holes in
/// the index and the references past its end find none.
#[test]
fn value_references_find_their_variables() {
    // Written out: the positions of k, c, n, mode, g, u, jump, on, y, l in VARIABLES.
    let expected = [
        (K, 0),
        (C, 1),
        (N, 2),
        (MODE, 3),
        (G, 4),
        (U, 5),
        (JUMP, 6),
        (ON, 7),
        (Y, 8),
        (L, 9),
    ];
    for (vr, position) in expected {
        assert_eq!(TABLE.index_of(vr), Some(position), "vr {vr}");
        let (i, var) = TABLE.variable(vr, F).expect("a variable");
        assert_eq!((i, var.vr), (position, vr));
    }
    for vr in [0, 1, 9, 15, 19, 29, 32, 33, 1000, u32::MAX] {
        assert_eq!(TABLE.index_of(vr), None, "vr {vr}");
        assert_eq!(
            said(TABLE.variable(vr, F)),
            format!("{F}: unknown value reference {vr}")
        );
    }
}

/// Which getters and setters address which variables: the table of FMI 2.0, by hand.
#[test]
fn each_type_is_accessed_by_its_own_functions_and_enumerations_by_integer() {
    use VarType::*;
    let types = [Real, Integer, Boolean, Enumeration];
    // Row: the variable's type; column: the access type, in the order of `types`.
    let allowed = [
        [true, false, false, false],
        [false, true, false, false],
        [false, false, true, false],
        [false, true, false, true],
    ];
    for (ty, row) in types.iter().zip(allowed) {
        let var = Variable {
            ty: *ty,
            ..VARIABLES[0]
        };
        for (access, want) in types.iter().zip(row) {
            assert_eq!(var.accessed_as(*access), want, "{ty:?} as {access:?}");
        }
    }
    // Through the table: n (Integer) and mode (Enumeration) as Integer, k as Real.
    assert_eq!(
        TABLE.typed_variable(N, VarType::Integer, F).map(|v| v.0),
        Ok(2)
    );
    assert_eq!(
        TABLE.typed_variable(MODE, VarType::Integer, F).map(|v| v.0),
        Ok(3)
    );
    assert_eq!(
        TABLE.typed_variable(K, VarType::Real, F).map(|v| v.0),
        Ok(0)
    );
    assert_eq!(
        said(TABLE.typed_variable(K, VarType::Integer, F)),
        "fmi2SetX: 'k' (value reference 10) is of type Real"
    );
    assert_eq!(
        said(TABLE.typed_variable(ON, VarType::Real, F)),
        "fmi2SetX: 'on' (value reference 22) is of type Boolean"
    );
}

/// Who may be set in which phase: FMI 2.0's table for Co-Simulation and Model Exchange, by
/// hand. A success answers the variable's position.
#[test]
fn parameters_inputs_and_the_rest_are_settable_when_fmi2_says() {
    use Phase::*;
    let phases = [
        Instantiated,
        InitializationMode,
        StepComplete,
        EventMode,
        ContinuousTimeMode,
    ];
    let fixed = "is a fixed parameter and can only be set before fmi2ExitInitializationMode";
    let discrete = "is a discrete input: set it in event mode (fmi2EnterEventMode), then call fmi2NewDiscreteStates";
    let computed = "is computed by the FMU and cannot be set";
    // (vr, value, type, the reply in each phase: "" for Ok).
    let cases: [(u32, f64, VarType, [&str; 5]); 9] = [
        (K, 3.0, VarType::Real, ["", "", fixed, fixed, fixed]),
        (C, 0.5, VarType::Real, ["", "", "", "", ""]),
        (N, 4.0, VarType::Integer, ["", "", fixed, fixed, fixed]),
        (MODE, 5.0, VarType::Integer, ["", "", fixed, fixed, fixed]),
        (U, -1.0, VarType::Real, ["", "", "", "", ""]),
        (JUMP, 0.25, VarType::Real, ["", "", "", "", discrete]),
        (G, 1.0, VarType::Real, [computed; 5]),
        (Y, 1.0, VarType::Real, [computed; 5]),
        (L, 1.0, VarType::Real, [computed; 5]),
    ];
    for (vr, value, ty, replies) in cases {
        let name = VARIABLES[at(vr)].name;
        for (phase, reply) in phases.iter().zip(replies) {
            let got = TABLE.settable(*phase, vr, value, ty, F);
            if reply.is_empty() {
                assert_eq!(got, Ok(at(vr)), "{name} in {phase:?}");
            } else {
                assert_eq!(said(got), format!("{F}: '{name}' {reply}"), "{phase:?}");
            }
        }
    }
    // A Boolean input, set as a Boolean: a discrete input too.
    assert_eq!(
        TABLE.settable(EventMode, ON, 1.0, VarType::Boolean, F),
        Ok(7)
    );
    assert!(
        said(TABLE.settable(ContinuousTimeMode, ON, 1.0, VarType::Boolean, F)).contains(discrete)
    );
    // The type is checked before anything else.
    assert!(
        said(TABLE.settable(Instantiated, K, 3.0, VarType::Integer, F)).contains("of type Real")
    );
}

/// Bounds are inclusive, values must be finite, an Enumeration takes its items only; each
/// refusal names the variable and the rule.
#[test]
fn values_outside_their_range_or_items_are_refused_and_said_why() {
    use Phase::Instantiated as I;
    let set = |vr, value, ty| said(TABLE.settable(I, vr, value, ty, F));
    let real = VarType::Real;
    // k: min 0.5, max 4.
    for ok in [0.5, 0.5000001, 2.0, 3.9999999, 4.0] {
        assert_eq!(set(K, ok, real), "", "k = {ok}");
    }
    assert_eq!(
        set(K, 0.49, real),
        "fmi2SetX: 'k' = 0.49 is below its minimum 0.5"
    );
    assert_eq!(
        set(K, -3.0, real),
        "fmi2SetX: 'k' = -3 is below its minimum 0.5"
    );
    assert_eq!(
        set(K, 4.01, real),
        "fmi2SetX: 'k' = 4.01 is above its maximum 4"
    );
    assert_eq!(
        set(K, 40.0, real),
        "fmi2SetX: 'k' = 40 is above its maximum 4"
    );
    // c: min 0 only; u: no bounds.
    assert_eq!(set(C, 0.0, real), "");
    assert_eq!(set(C, 1e300, real), "");
    assert_eq!(
        set(C, -0.001, real),
        "fmi2SetX: 'c' = -0.001 is below its minimum 0"
    );
    assert!(set(C, -1e-300, real).contains("below its minimum 0"));
    for x in [f64::MAX, f64::MIN, 0.0, -2.5] {
        assert_eq!(set(U, x, real), "", "u = {x}");
    }
    // Not finite: refused whatever the bounds, the unbounded u too.
    for (vr, name) in [(U, "u"), (K, "k"), (C, "c")] {
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert_eq!(
                set(vr, x, real),
                format!("fmi2SetX: '{name}' cannot be set to {x}: the value must be finite")
            );
        }
    }
    // n: an Integer within 1..=10.
    assert_eq!(set(N, 1.0, VarType::Integer), "");
    assert_eq!(set(N, 10.0, VarType::Integer), "");
    assert_eq!(
        set(N, 11.0, VarType::Integer),
        "fmi2SetX: 'n' = 11 is above its maximum 10"
    );
    assert_eq!(
        set(N, 0.0, VarType::Integer),
        "fmi2SetX: 'n' = 0 is below its minimum 1"
    );
    // mode: items 1 = A, 2 = B, 5 = C, nothing between.
    for item in [1.0, 2.0, 5.0] {
        assert_eq!(set(MODE, item, VarType::Integer), "", "mode = {item}");
    }
    for other in [0.0, 3.0, 4.0, 6.0, -1.0] {
        assert_eq!(
            set(MODE, other, VarType::Integer),
            format!(
                "fmi2SetX: 'mode' cannot be set to {other}: not an item of its enumeration (1 = A, 2 = B, 5 = C)"
            )
        );
    }
    // `reject` alone: None for an acceptable value, the reason otherwise.
    let mode = &VARIABLES[at(MODE)];
    assert_eq!(mode.reject(5.0), None);
    assert!(
        mode.reject(f64::NAN)
            .is_some_and(|r| r.contains("must be finite"))
    );
}

/// fmi2SetRealInputDerivatives: Real inputs, orders 1 up to the slave's maximum, finite values.
#[test]
fn input_derivatives_are_checked_entry_by_entry() {
    let check = |vr, order, value, max| said(TABLE.check_input_derivative(vr, order, value, max));
    assert_eq!(check(U, 1, 0.5, 1), "");
    assert_eq!(check(JUMP, 1, -0.5, 1), "");
    assert_eq!(check(U, 2, 3.0, 2), "");
    assert_eq!(
        TABLE.check_input_derivative(U, 1, 0.5, 1).map(|v| v.name),
        Ok("u")
    );
    for (vr, name) in [(K, "k"), (C, "c"), (Y, "y"), (ON, "on"), (L, "l")] {
        assert_eq!(
            check(vr, 1, 0.5, 1),
            format!("fmi2SetRealInputDerivatives: '{name}' is not a Real input")
        );
    }
    for order in [0, 2, -1, i32::MAX] {
        assert_eq!(
            check(U, order, 0.5, 1),
            format!("fmi2SetRealInputDerivatives: order {order} for 'u' is not supported (1 or 1)")
        );
    }
    assert!(check(U, 3, 0.5, 2).contains("order 3"));
    for x in [f64::NAN, f64::INFINITY] {
        assert_eq!(
            check(U, 1, x, 1),
            format!("fmi2SetRealInputDerivatives: derivative {x} of 'u' must be finite")
        );
    }
    assert_eq!(
        check(40, 1, 0.5, 1),
        "fmi2SetRealInputDerivatives: unknown value reference 40"
    );
}

/// fmi2GetRealOutputDerivatives of a slave with exact first derivatives: each output's rate,
/// at its position; anything else refused, naming it.
#[test]
fn output_derivatives_are_first_order_rates_of_outputs() {
    let output = |r: u32| (r == Y || r == L).then_some(r);
    let rate = |m: f64, r: u32| m * f64::from(r);
    let run = |model, vrs: &[u32], orders: &[i32]| {
        let mut got = vec![f64::NAN; vrs.len()];
        let reply =
            TABLE.first_output_derivatives(model, vrs, orders, output, rate, |k, v| got[k] = v);
        (said(reply), got)
    };
    let (reply, got) = run(Some(0.5), &[L, Y, L], &[1, 1, 1]);
    assert_eq!(reply, "");
    assert_eq!(got, [15.5, 15.0, 15.5]);
    let f = "fmi2GetRealOutputDerivatives";
    for order in [2, 0, -1] {
        assert_eq!(
            run(Some(0.5), &[Y], &[order]).0,
            format!("{f}: order {order} of 'y' is not offered (maxOutputDerivativeOrder = 1)")
        );
    }
    assert_eq!(
        run(Some(0.5), &[U], &[1]).0,
        format!("{f}: 'u' is not an output")
    );
    assert_eq!(
        run(Some(0.5), &[3], &[1]).0,
        format!("{f}: unknown value reference 3")
    );
    assert_eq!(run(None, &[Y], &[1]).0, format!("{f}: not initialised"));
    assert_eq!(
        TABLE.no_value(Y, "fmi2GetReal").message.as_str(),
        "fmi2GetReal: 'y' has no value"
    );
    assert_eq!(
        TABLE.no_value(3, "fmi2GetReal").message.as_str(),
        "fmi2GetReal: '?' has no value"
    );
}
