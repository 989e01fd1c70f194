//! Call sequences on TLD.fmu, Co-Simulation and Model Exchange (the harness:
//! fuzz/src/calls.rs).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| tld_fuzz::calls::calls::<tld_fmu::fmi::Tld>(data));
