//! Reads modelDescription/modelDescription.xml (the single source of truth for the FMU's
//! variables), checks it for internal consistency, and generates `$OUT_DIR/model_description.rs`
//! (included by src/description.rs): the variable table and value references, a Rust enum for every
//! enumeration SimpleType, the log categories and the declared min/max of every variable. Any
//! inconsistency fails the build with a message that says what is wrong and where.
//!
//! model.rs reads the XML, check.rs checks it, generate.rs writes the Rust.

mod check;
mod generate;
mod model;

use model::{XML, fail};
use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-changed={XML}");
    println!("cargo:rerun-if-changed=build");
    let text = std::fs::read_to_string(XML).unwrap_or_else(|e| fail(format!("cannot read: {e}")));
    let md = model::read(&text);
    check::all(&md);
    let code = generate::all(&md);
    let out =
        PathBuf::from(std::env::var("OUT_DIR").unwrap_or_else(|_| fail("OUT_DIR not set".into())));
    std::fs::write(out.join("model_description.rs"), code)
        .unwrap_or_else(|e| fail(format!("cannot write generated code: {e}")));
}
