//! The physics of a tuned liquid damper, restated from the seed with MODEL.md's corrections.
//! Plain Rust: no FFI and nothing of FMI here.

pub mod amplitude;
#[cfg(test)]
pub(crate) mod amplitude_tests;
pub mod base;
pub mod geometry;
pub mod laws;
pub mod linear;
pub mod nonlinear;
pub mod power;
pub mod screens;
pub mod shallow_water;
pub mod slamming;
