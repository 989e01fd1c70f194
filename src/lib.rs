//! A tuned liquid damper (TLD) as an FMI 2.0 Co-Simulation FMU.
//!
//! Layers, data flowing one way: `fmi` (the only place that speaks FMI) -> `model` (the models
//! behind one contract, and the damper that steps the chosen one over communication intervals)
//! -> `physics` (the equations of the seed, corrected) and `solver` (integrators generic over a
//! right-hand side). `description` is the model description (value references, variables),
//! generated from modelDescription.xml, which the FMI layer and the models share.

pub mod analysis;
pub mod description;
pub mod fmi;
pub mod model;
pub mod physics;
pub mod solver;
