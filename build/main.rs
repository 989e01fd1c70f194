//! Reads modelDescription/modelDescription.xml (the single source of truth for the FMU's
//! variables), checks it for internal consistency, and generates `$OUT_DIR/model_description.rs`
//! (included by src/description.rs): the variable table and value references, a Rust enum for every
//! enumeration SimpleType, the log categories and the declared min/max of every variable. Any
//! inconsistency fails the build with a message that says what is wrong and where.
//!
//! model.rs reads the XML, check.rs checks it, generate.rs writes the Rust, run.rs ties them
//! together; Building.fmu's build script (building/build.rs) uses the same four files.

mod check;
mod generate;
mod model;
mod run;

fn main() {
    run::description("TLD", "build");
}
