//! Call-sequence fuzzing of TLD.fmu (the engine and its invariants: tests/fuzz/mod.rs, shared
//! with Building.fmu's fuzz test): every sequence starts with a model drawn from every item of
//! the model enumeration, so that every model gets the same fuzzing.

mod common;
mod fuzz;

use common::*;
use fmi_sys::fmi2::*;
use fuzz::{Call, Host, Target};
use proptest::prelude::*;
use tld_fmu::fmi::vars::{ModelKindItem, VARIABLES, vr};

impl Host for Instance {
    fn lib(&self) -> &'static Fmi2Binding {
        self.lib
    }
    fn component(&self) -> fmi2Component {
        self.c
    }
}

#[test]
fn random_call_sequences_keep_the_invariants() {
    // A third of the sequences start initialised, a third in initialisation mode, so that the
    // calls reach every state, not mostly the first.
    let models: Vec<i32> = ModelKindItem::ALL
        .iter()
        .map(|m| m.value() as i32)
        .collect();
    let prefix = (0..3usize, proptest::sample::select(models)).prop_map(|(depth, model)| {
        let mut calls = vec![Call::SetInteger {
            vrs: vec![vr::MODEL],
            values: vec![model, 0, 0, 0],
        }];
        calls.extend(fuzz::initialisation(depth));
        calls
    });
    let target = Target {
        new: || Instance::new("fuzz"),
        value_references: VARIABLES.iter().map(|v| v.vr).collect(),
        output: vr::FORCE,
    };
    fuzz::run(target, prefix);
}
