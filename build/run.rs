//! The build script's work, shared by every FMU package of the workspace (TLD's build/main.rs,
//! building/build.rs): read the package's modelDescription/modelDescription.xml (the single
//! source of truth for its variables), check it, and generate `$OUT_DIR/model_description.rs`.

use std::path::PathBuf;

use crate::model::{self, XML, fail};
use crate::{check, generate};

/// Generate the model description of the FMU whose modelIdentifier is `identifier`; `scripts`
/// is this directory, relative to the package.
pub fn description(identifier: &str, scripts: &str) {
    println!("cargo:rerun-if-changed={XML}");
    println!("cargo:rerun-if-changed={scripts}");
    let text = std::fs::read_to_string(XML).unwrap_or_else(|e| fail(format!("cannot read: {e}")));
    let md = model::read(&text);
    check::all(&md, identifier);
    let code = generate::all(&md);
    let out =
        PathBuf::from(std::env::var("OUT_DIR").unwrap_or_else(|_| fail("OUT_DIR not set".into())));
    std::fs::write(out.join("model_description.rs"), code)
        .unwrap_or_else(|e| fail(format!("cannot write generated code: {e}")));
}
