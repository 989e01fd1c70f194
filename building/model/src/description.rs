//! Building.fmu's model description as Rust: the variable table and value references
//! (`vr::*`, `.` and brackets become `_`) the shared build script generates from
//! modelDescription/modelDescription.xml, and the table the shared FMI layer reads.

pub use fmi2_slave::description::{Causality, Table, VarType, Variability, Variable, finite};

include!(concat!(env!("OUT_DIR"), "/model_description.rs"));

/// The table as the shared FMI layer reads it.
pub const TABLE: Table = Table {
    model_identifier: MODEL_IDENTIFIER,
    guid: GUID,
    variables: VARIABLES,
    vr_index: &VR_INDEX,
    log_categories: &LOG_CATEGORIES,
};

/// Position in [`VARIABLES`] of a value reference, if it names a variable.
pub const fn index_of(vr: u32) -> Option<usize> {
    TABLE.index_of(vr)
}

/// Value reference of storey `i`'s variable in the block starting at `first` (1-based `i`).
pub const fn per_storey(first: u32, i: usize) -> u32 {
    first + i as u32 - 1
}
