//! The Butcher tableau of Dormand & Prince (1980), 5(4), for the benchmark's two anchors written
//! apart from TLD.fmu: the plain-Rust baseline (baseline.rs) and the C FMU's Rust port
//! (bench/port), each of which includes this file, as bench/c/tld_c.c spells it. TLD.fmu's own
//! Dormand-Prince (src/solver/dopri5.rs) does not use it: an anchor shares no code with what it
//! measures.

pub const A21: f64 = 1.0 / 5.0;
pub const A31: f64 = 3.0 / 40.0;
pub const A32: f64 = 9.0 / 40.0;
pub const A41: f64 = 44.0 / 45.0;
pub const A42: f64 = -56.0 / 15.0;
pub const A43: f64 = 32.0 / 9.0;
pub const A51: f64 = 19372.0 / 6561.0;
pub const A52: f64 = -25360.0 / 2187.0;
pub const A53: f64 = 64448.0 / 6561.0;
pub const A54: f64 = -212.0 / 729.0;
pub const A61: f64 = 9017.0 / 3168.0;
pub const A62: f64 = -355.0 / 33.0;
pub const A63: f64 = 46732.0 / 5247.0;
pub const A64: f64 = 49.0 / 176.0;
pub const A65: f64 = -5103.0 / 18656.0;
pub const B1: f64 = 35.0 / 384.0;
pub const B3: f64 = 500.0 / 1113.0;
pub const B4: f64 = 125.0 / 192.0;
pub const B5: f64 = -2187.0 / 6784.0;
pub const B6: f64 = 11.0 / 84.0;
pub const E1: f64 = 71.0 / 57600.0;
pub const E3: f64 = -71.0 / 16695.0;
pub const E4: f64 = 71.0 / 1920.0;
pub const E5: f64 = -17253.0 / 339200.0;
pub const E6: f64 = 22.0 / 525.0;
pub const E7: f64 = -1.0 / 40.0;
