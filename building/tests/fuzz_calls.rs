//! Call-sequence fuzzing of Building.fmu with the workspace's fuzzer (tests/fuzz/mod.rs, the
//! engine TLD.fmu's fuzz test uses): every sequence starts with a building of 1 to 20 storeys
//! and a damper floor drawn at random (some of them not in the building).

#[path = "../../tests/fuzz/mod.rs"]
mod fuzz;
mod host;

use building_model::description::{VARIABLES, vr};
use fuzz::{Call, Target};
use host::*;
use proptest::prelude::*;

#[test]
fn random_call_sequences_keep_the_invariants() {
    let building = (1..=20i32, 0..=21i32).prop_map(|(storeys, floor)| Call::SetInteger {
        vrs: vec![vr::STOREYS, vr::TLD_FLOOR],
        values: vec![storeys, floor.min(storeys), 0, 0],
    });
    let target = Target {
        value_references: VARIABLES.iter().map(|v| v.vr).collect(),
        output: vr::TLD_A,
        states: 44,
    };
    fuzz::run(target, fuzz::starting_with(building));
}
