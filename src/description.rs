//! The model description as Rust, shared by the FMI layer and the models: what the build
//! script (build/) generates from modelDescription/modelDescription.xml, and the types it uses:
//! - `VARIABLES` (the variable table) and `vr::*` (value references, `.` becomes `_`);
//! - one enum per enumeration type, named after it with `Item` appended (`ModelKindItem`,
//!   `DampingLawItem`, `AmplitudeModeItem`, `SolverMethodItem`): the XML's items as variants with
//!   their values as discriminants, `ALL`, `from_value`/`from_f64`/`TryFrom<i64>`, `value()`,
//!   `name()`, `description()`;
//! - `LOG_CATEGORIES` and `log_category::*` (one constant per category);
//! - `limits::*`: the declared bounds (`limits::MODES_MAX` is the max of `modes`);
//! - `TABLE`, the table the shared FMI layer reads, and `index_of` (both, with the generated
//!   code, from `fmi2_slave::model_description!`, which Building's description uses too).

pub use fmi2_slave::description::{Causality, Table, VarType, Variability, Variable, finite};

fmi2_slave::model_description!();
