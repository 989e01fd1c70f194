//! fmi2DeSerializeFMUstate of TLD.fmu (the harness: fuzz/src/lib.rs, `deserialize`).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| tld_fuzz::deserialize::<tld_fmu::fmi::Tld>(data));
