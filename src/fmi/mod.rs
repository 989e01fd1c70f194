//! The only place that speaks FMI: exported fmi2* functions (thin, panic-safe, each checked
//! against its phase mask first), the instance and its call sequence, variable access, the
//! saved-state format and logging.

mod access;
mod calls;
mod exports;
#[cfg(test)]
mod generated_tests;
mod instance;
mod logger;
mod params;
mod snapshot;
mod status;

/// The model description's table, where the FMI layer has always offered it.
pub use crate::description as vars;
pub use status::Status;
