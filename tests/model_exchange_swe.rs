//! model = ShallowWater in Model Exchange through TLD.fmu's C entry points: not offered. Its
//! states are 2 x swe.cells while FMI 2.0 fixes the number of continuous states in the model
//! description, and a declared bank of cells would be integrated by every other model's host
//! (docs/MODEL_EXCHANGE.md). fmi2ExitInitializationMode refuses it and says why; the instance
//! stays usable (fmi2Reset, then an offered model runs), and Co-Simulation of the same
//! parameters runs.

mod common;

use common::*;
use tld_fmu::fmi::vars::vr;

const SHALLOW_WATER: i32 = 5;
const NONLINEAR: i32 = 2;

fn set_up(inst: &Instance, model: i32) {
    assert_eq!(inst.setup(), OK);
    assert_eq!(inst.set_integer(vr::MODEL, model), OK);
    assert_eq!(inst.set_integer(vr::DAMPING, 1), OK);
    assert_eq!(inst.set_integer(vr::AMPLITUDE, 1), OK);
    assert_eq!(inst.set_integer(vr::SWE_CELLS, 40), OK);
    assert_eq!(inst.set_real(vr::SLOSH_X0, 0.003), OK);
}

#[test]
fn shallow_water_is_refused_in_model_exchange_and_says_why() {
    let inst = Instance::model_exchange("swe-me-refused");
    set_up(&inst, SHALLOW_WATER);
    assert_eq!(inst.enter(), OK);
    assert_ne!(inst.exit(), OK, "ShallowWater initialised in ME");
    let said = inst.logs().join("\n");
    for part in [
        "not offered in Model Exchange",
        "FMI 2.0 fixes the number of states",
        "use Co-Simulation",
    ] {
        assert!(said.contains(part), "no '{part}' in: {said}");
    }
    // Usable after the refusal: reset, an offered model initialises and gives its states.
    assert_eq!(inst.reset(), OK, "{:?}", inst.logs());
    set_up(&inst, NONLINEAR);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
    let (status, x) = inst.states(tld_fmu::model::continuous::ALL_STATES);
    assert_eq!(status, OK);
    assert_eq!(x[0], 0.003);
}

#[test]
fn the_same_parameters_run_in_co_simulation() {
    let mut inst = Instance::new("swe-cs");
    set_up(&inst, SHALLOW_WATER);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
    let x = inst.run_harmonic(10, 0.01);
    assert!(x.is_finite());
    assert!(inst.get_real(vr::SLOSH_X).1.is_finite());
}

/// A Co-Simulation instance may ask for continuous states and derivatives once terminated (the
/// call table allows it): for ShallowWater they are refused with the reason, not a panic (found
/// by the call-sequence fuzzer after the cell bank was taken out).
#[test]
fn a_terminated_co_simulation_of_shallow_water_refuses_derivatives() {
    let inst = Instance::new("swe-cs-terminated");
    set_up(&inst, SHALLOW_WATER);
    assert_eq!(inst.enter(), OK);
    assert_eq!(inst.exit(), OK, "{:?}", inst.logs());
    assert_eq!(inst.terminate(), OK);
    let n = tld_fmu::model::continuous::ALL_STATES;
    assert_ne!(inst.derivatives(n).0, OK);
    assert_ne!(inst.states(n).0, OK);
    let said = inst.logs().join("\n");
    assert!(
        said.contains("fmi2GetDerivatives: model = ShallowWater")
            && said.contains("not offered in Model Exchange")
            && !said.contains("internal error"),
        "{said}"
    );
}
