//! Call-sequence fuzzing of TLD.fmu (the engine and its invariants: tests/fuzz/mod.rs, shared
//! with Building.fmu's fuzz test): every sequence starts with a model drawn from every item of
//! the model enumeration and either amplitude source, so that every model gets the same
//! fuzzing, in Co-Simulation and in Model Exchange.

mod common;
mod fuzz;

use common::*;
use fuzz::{Call, Target};
use proptest::prelude::*;
use tld_fmu::fmi::vars::{ModelKindItem, VARIABLES, vr};

#[test]
fn random_call_sequences_keep_the_invariants() {
    let models: Vec<i32> = ModelKindItem::ALL
        .iter()
        .map(|m| m.value() as i32)
        .collect();
    // amplitude Fixed (1) or Tracked (2), both offered in Model Exchange.
    let model = (proptest::sample::select(models), 1..=2i32).prop_map(|(model, amplitude)| {
        Call::SetInteger {
            vrs: vec![vr::MODEL, vr::AMPLITUDE],
            values: vec![model, amplitude, 0, 0],
        }
    });
    let target = Target {
        value_references: VARIABLES.iter().map(|v| v.vr).collect(),
        output: vr::FORCE,
        states: tld_fmu::model::continuous::ALL_STATES,
    };
    fuzz::run(target, fuzz::starting_with(model));
}
