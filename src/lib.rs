//! A tuned liquid damper (TLD) as an FMI 2.0 Co-Simulation FMU.
//!
//! Layers, data flowing one way: `fmi` (the only place that speaks FMI) -> `simulation` (a
//! configured damper stepping over communication intervals) -> `physics` (the equations of the
//! seed, corrected) and `solver` (integrators generic over a right-hand side).

pub mod analysis;
pub mod fmi;
pub mod physics;
pub mod simulation;
pub mod solver;
