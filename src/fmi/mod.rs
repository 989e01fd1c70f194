//! The only place that speaks FMI: exported fmi2* functions (thin, panic-safe), the instance and
//! its call-sequence state machine, variable access and logging.

mod exports;
#[cfg(test)]
mod generated_tests;
mod instance;
mod logger;
mod params;
mod snapshot;
pub mod vars;

pub use instance::Status;
