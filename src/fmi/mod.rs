//! TLD.fmu's side of the FMI layer: the slave the shared layer (`fmi2_slave`, fmi2/) drives,
//! its variable access, its parameters and its part of the saved state. The fmi2* exports, the
//! call-sequence table, logging and the state frame are the shared layer's; this module emits
//! them for [`slave::Tld`].

mod access;
#[cfg(test)]
mod generated_tests;
mod me;
mod me_cells;
#[cfg(test)]
mod me_tests;
#[cfg(test)]
mod me_tracked_tests;
mod params;
mod slave;
mod snapshot;

/// The model description's table, where the FMI layer has always offered it.
pub use crate::description as vars;
pub use fmi2_slave::Status;
pub use slave::Tld;

fmi2_slave::export_fmi2!(slave::Tld);
