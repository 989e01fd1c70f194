//! The only place that speaks FMI: exported fmi2* functions (thin, panic-safe), the instance and
//! its call-sequence state machine, variable access and logging.

mod exports;
#[cfg(test)]
mod generated_tests;
mod instance;
mod logger;
mod params;
mod snapshot;

/// The model description's table, where the FMI layer has always offered it.
pub use crate::description as vars;

pub use instance::Status;
