//! The model description as Rust, shared by the FMI layer and the models: what the build
//! script (build/) generates from modelDescription/modelDescription.xml, and the types it uses:
//! - `VARIABLES` (the variable table) and `vr::*` (value references, `.` becomes `_`);
//! - one enum per enumeration type, named after it with `Item` appended (`ModelKindItem`,
//!   `DampingLawItem`, `AmplitudeModeItem`, `SolverMethodItem`): the XML's items as variants with
//!   their values as discriminants, `ALL`, `from_value`/`from_f64`/`TryFrom<i64>`, `value()`,
//!   `name()`, `description()`;
//! - `LOG_CATEGORIES` and `log_category::*` (one constant per category);
//! - `limits::*`: the declared bounds (`limits::MODES_MAX` is the max of `modes`).

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
