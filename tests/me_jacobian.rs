//! TLD.fmu's directional derivatives in Model Exchange through its C entry points, as an
//! implicit solver's host asks for them: every column of J (the four states and the inputs
//! base.a, base.v, base.x) for the state derivatives and the Real outputs, against central
//! differences of fmi2GetDerivatives and fmi2GetReal, for every offered model and exponents
//! eta of Eq 2.13 integer and not, at states near the rest position and far from it; at x = 0
//! with a non-integer eta (where Phi' has a cusp) the entry against its closed form; and the
//! pairs not supported refused with a reason.

mod common;

use common::*;
use tld_fmu::fmi::vars::vr;

/// The states perturbed here (those of the oscillator models), of all the continuous states.
const N: usize = 4;
/// All continuous states: these models use the first four (the rest are frozen at 0).
const STATES: usize = tld_fmu::model::continuous::ALL_STATES;
const LINEAR: i32 = 1;
const NONLINEAR: i32 = 2;
const AUTO: i32 = 4;

const DERIVATIVES: [u32; N] = [
    vr::DER_SLOSH_X_,
    vr::DER_SLOSH_V_,
    vr::DER_ENERGY_INPUT_,
    vr::DER_ENERGY_DISSIPATED_,
];
/// The knowns: the states, then the inputs.
const KNOWNS: [u32; 7] = [
    vr::SLOSH_X,
    vr::SLOSH_V,
    vr::ENERGY_INPUT,
    vr::ENERGY_DISSIPATED,
    vr::BASE_A,
    vr::BASE_V,
    vr::BASE_X,
];

/// An ME instance of `model` with exponent `eta`, constant damping 0.03, amplitude Fixed, in
/// continuous-time mode.
fn running(name: &str, model: i32, eta: f64) -> Instance {
    let inst = Instance::model_exchange(name);
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.set_integer(vr::MODEL, model), OK);
    assert_eq!(inst.set_real(vr::ETA, eta), OK);
    assert_eq!(inst.set_integer(vr::DAMPING, 1), OK);
    assert_eq!(inst.set_real(vr::ZETA, 0.03), OK);
    assert_eq!(inst.set_integer(vr::AMPLITUDE, 1), OK);
    inst.start_continuous_time();
    inst
}

fn outputs() -> Vec<u32> {
    real_outputs()
}

fn unknowns() -> Vec<u32> {
    DERIVATIVES.iter().copied().chain(outputs()).collect()
}

/// J's column for the known `known` at the current states and inputs.
fn column(inst: &Instance, known: u32) -> Vec<f64> {
    jacobian_column(inst, &unknowns(), known)
}

/// The unknowns' values: the derivatives, then the outputs.
fn values(inst: &Instance) -> Vec<f64> {
    let (s, mut out) = inst.derivatives(STATES);
    assert_eq!(s, OK, "{:?}", inst.logs());
    out.truncate(N);
    out.extend(outputs().into_iter().map(|r| inst.real(r)));
    out
}

/// Set the states and inputs `p` (KNOWNS' order).
fn put(inst: &Instance, p: &[f64]) {
    let mut states = [0.0; STATES];
    states[..N].copy_from_slice(&p[..N]);
    assert_eq!(inst.set_states(&states), OK, "{:?}", inst.logs());
    for (k, &r) in KNOWNS.iter().enumerate().skip(N) {
        assert_eq!(inst.set_real(r, p[k]), OK);
    }
}

/// Every column at the point `p` against central differences; returns the largest error
/// relative to the tolerance (<= 1 passes).
/// `cusp`: eta < 1.5, where Phi'' is singular at x = 0 and differences there converge to
/// Phi'(0) only as h^(2 eta - 2): the x column at x = 0 is left to
/// `at_rest_the_stiffness_is_the_linear_one_for_every_eta`.
fn check_point(inst: &Instance, what: &str, p: [f64; 7], cusp: bool) -> f64 {
    // Typical magnitudes where a coordinate is 0: 1 mm, 1 mm/s, 1 J, 1 J, 1 mm/s^2, ...
    let typical = [1e-3, 1e-3, 1.0, 1.0, 1e-3, 1e-3, 1e-3];
    let mut worst: f64 = 0.0;
    for k in 0..KNOWNS.len() {
        if cusp && k == 0 && p[0] == 0.0 {
            continue;
        }
        put(inst, &p);
        let j = column(inst, KNOWNS[k]);
        // Relative steps: near x = 0, where Phi's higher derivatives grow as |x|^(2 eta - 4),
        // a step of a small part of x keeps the difference's truncation error small.
        let h = if p[k] != 0.0 {
            1e-4 * p[k].abs()
        } else {
            1e-5 * typical[k]
        };
        let (up, down) = values_either_side(&p, k, h, |q| put(inst, q), || values(inst));
        let names = unknowns();
        worst = worst.max(against_differences(&j, &up, &down, h, |i| {
            format!("{what} at {p:?}: d[{}]/d[{}]", names[i], KNOWNS[k])
        }));
    }
    put(inst, &p);
    worst
}

/// Points [x, v, energy.input, energy.dissipated, base.a, base.v, base.x]: at rest, near the
/// rest position, halfway to a wall (the tank is 0.25 m long), beyond it, with the base
/// accelerating.
const POINTS: [[f64; 7]; 5] = [
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [1e-7, 0.01, 0.5, 0.1, 0.0, 0.0, 0.0],
    [0.03, -0.2, 1.5, 0.25, 0.7, 0.1, 0.002],
    [-0.07, 0.4, 2.0, 0.5, -1.3, -0.2, 0.01],
    [0.16, -0.9, 3.0, 1.0, 2.1, 0.05, -0.003],
];

#[test]
fn directional_derivatives_match_central_differences_for_every_offered_model() {
    let mut cases = vec![(LINEAR, 2.0)];
    for model in [NONLINEAR, AUTO] {
        for eta in [2.0, 1.25, 1.5, 2.7, 4.0] {
            cases.push((model, eta));
        }
    }
    // force, force.mean, base_shear, slosh.x, slosh.v, 3 energies, A_e.estimate,
    // zeta.effective, impact.z, surface.left, surface.right, impact.impulse (discrete: its
    // tangent is 0; impacts is an Integer).
    assert_eq!(outputs().len(), 14);
    let mut worst: f64 = 0.0;
    for (model, eta) in cases {
        let what = format!("model {model} eta {eta}");
        let inst = running(&format!("jac-{model}-{eta}"), model, eta);
        for p in POINTS {
            worst = worst.max(check_point(&inst, &what, p, eta < 1.5));
        }
    }
    println!("largest error / tolerance: {worst:.3e}");
}

/// At x = 0 Phi'(0) = omega_f^2 for every eta >= 1 (the hardening's slope (2 eta - 1) phi
/// |2x/a|^(2 eta - 2) vanishes), finite even where Phi'' is singular (eta < 1.5): J's entry is
/// that exactly, and the differences approach it as h^(2 eta - 2), too slowly to compare.
#[test]
fn at_rest_the_stiffness_is_the_linear_one_for_every_eta() {
    for (k, eta) in [1.1, 1.25, 1.5, 1.75, 2.0, 3.3].into_iter().enumerate() {
        let inst = running(&format!("jac-rest-{k}"), NONLINEAR, eta);
        put(&inst, &[0.0; 7]);
        let w = inst.real(vr::OMEGA_F);
        let j = column(&inst, vr::SLOSH_X);
        // der(slosh.v) by slosh.x: -Phi'(0).
        assert!(j.iter().all(|v| v.is_finite()), "eta {eta}: {j:?}");
        assert!(
            (j[1] + w * w).abs() <= 1e-13 * w * w,
            "eta {eta}: {} vs {}",
            j[1],
            -w * w
        );
        // The differences converge to it (their error shrinks with h).
        let fd = |h: f64| {
            put(&inst, &[h, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
            let up = values(&inst)[1];
            put(&inst, &[-h, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
            let down = values(&inst)[1];
            (up - down) / (2.0 * h)
        };
        let (coarse, fine) = ((fd(1e-4) - j[1]).abs(), (fd(1e-8) - j[1]).abs());
        assert!(
            fine < coarse || fine <= 1e-9 * w * w,
            "eta {eta}: {coarse:e} at h 1e-4, {fine:e} at 1e-8"
        );
    }
}

#[test]
fn pairs_not_supported_are_refused_with_a_reason() {
    let inst = running("jac-refused", NONLINEAR, 2.0);
    let call = |unknown: u32, known: u32| {
        let mut v = 123.0;
        let s = unsafe {
            inst.lib
                .fmi2GetDirectionalDerivative(inst.c, &unknown, 1, &known, 1, &1.0, &mut v)
        };
        (s, v)
    };
    // A known that is a parameter; an unknown that is an input, or an Integer output.
    for (unknown, known, says) in [
        (vr::FORCE, vr::ETA, "neither a continuous state"),
        (vr::BASE_A, vr::SLOSH_X, "neither a state derivative"),
        (vr::IMPACTS, vr::SLOSH_X, "Real output"),
    ] {
        assert_eq!(call(unknown, known), (ERROR, 123.0), "{unknown} by {known}");
        assert!(
            inst.logs().join("\n").contains(says),
            "{says}: {:?}",
            inst.logs()
        );
    }
}

/// The models not offered in Model Exchange run only in Co-Simulation, where the
/// call-sequence guard refuses directional derivatives (providesDirectionalDerivative is
/// false there): fmi2Error and the reason, no numbers. (The model's own refusal:
/// `model::continuous`'s unit tests.)
#[test]
fn a_model_not_offered_is_refused() {
    let inst = Instance::new("jac-shallow-water");
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.set_integer(vr::MODEL, 5), OK);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.exit(), OK);
    let mut v = 123.0;
    let s = unsafe {
        inst.lib
            .fmi2GetDirectionalDerivative(inst.c, &vr::FORCE, 1, &vr::SLOSH_X, 1, &1.0, &mut v)
    };
    assert_eq!((s, v), (ERROR, 123.0));
    assert!(
        inst.logs().join("\n").contains("fmi2ModelExchange"),
        "{:?}",
        inst.logs()
    );
}
