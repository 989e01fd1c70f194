//! fmi2DeSerializeFMUstate of Building.fmu (the harness: fuzz/src/lib.rs, `deserialize`).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| tld_fuzz::deserialize::<building_model::Building>(data));
