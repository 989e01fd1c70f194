//! Building.fmu: a linear N-storey shear building (SYSTEM.md), advanced exactly over each
//! communication step, as an FMI 2.0 Co-Simulation FMU, the reference structure for TLD.fmu.
//!
//! Layers, data flowing one way: `slave` (Building's side of the shared FMI layer, fmi2/:
//! variables, parameters, the saved state) -> `structure` (the building's matrices, modes and
//! Rayleigh damping) and `propagator` (the exact step of a linear system for polynomial inputs).
//! Only `slave` knows FMI.

pub mod description;
pub mod propagator;
pub mod slave;
pub mod structure;

fmi2_slave::export_fmi2!(slave::Building);
