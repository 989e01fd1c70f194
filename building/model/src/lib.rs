//! Building.fmu's model: a linear N-storey shear building, advanced exactly over
//! each communication step, and its slave of the shared FMI layer. The exports live in the
//! cdylib crate (building/), so that the packaging tool can link this crate beside TLD's.
//!
//! Layers, data flowing one way: `slave` (Building's side of the shared FMI layer, fmi2/:
//! variables, parameters, the saved state) -> `structure` (the building's matrices, modes and
//! Rayleigh damping) and `propagator` (the exact step of a linear system for polynomial inputs).
//! Only `slave` knows FMI.

pub mod description;
pub mod propagator;
pub mod slave;
pub mod structure;
#[cfg(test)]
mod structure_tests;

pub use slave::Building;
