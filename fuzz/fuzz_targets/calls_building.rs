//! Call sequences on Building.fmu, Co-Simulation and Model Exchange (the harness:
//! fuzz/src/calls.rs).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| tld_fuzz::calls::calls::<building_model::Building>(data));
