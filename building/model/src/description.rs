//! Building.fmu's model description as Rust: the variable table and value references
//! (`vr::*`, `.` and brackets become `_`) the shared build script generates from
//! modelDescription/modelDescription.xml, and the table the shared FMI layer reads.

pub use fmi2_slave::description::{Causality, Table, VarType, Variability, Variable, finite};

fmi2_slave::model_description!();

/// Value reference of storey `i`'s variable in the block starting at `first` (1-based `i`).
pub const fn per_storey(first: u32, i: usize) -> u32 {
    first + i as u32 - 1
}
