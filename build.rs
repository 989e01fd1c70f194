//! Reads modelDescription/modelDescription.xml (the single source of truth for the FMU's
//! variables), checks it for internal consistency, and generates the Rust value-reference table
//! `$OUT_DIR/model_description.rs`. Any inconsistency fails the build with a message that says
//! what is wrong and where.

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::PathBuf;

const XML: &str = "modelDescription/modelDescription.xml";
const MODEL_IDENTIFIER: &str = "TLD";

#[derive(Debug, Default)]
struct Var {
    index: usize,
    name: String,
    vr: u32,
    causality: String,
    variability: String,
    initial: Option<String>,
    ty: String,
    declared_type: Option<String>,
    start: Option<String>,
    min: Option<String>,
    max: Option<String>,
    unit: Option<String>,
    description: String,
}

fn fail(msg: String) -> ! {
    panic!("\n\n{XML}: {msg}\n\n");
}

fn attrs(e: &BytesStart) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for a in e.attributes() {
        let a = a.unwrap_or_else(|err| fail(format!("malformed attribute: {err}")));
        let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
        let value = a
            .unescape_value()
            .unwrap_or_else(|err| fail(format!("bad attribute value for {key}: {err}")))
            .into_owned();
        out.insert(key, value);
    }
    out
}

fn num(var: &Var, what: &str, s: &Option<String>) -> Option<f64> {
    s.as_ref().map(|v| {
        v.trim().parse::<f64>().unwrap_or_else(|_| {
            fail(format!(
                "variable '{}': {what}=\"{v}\" is not a number",
                var.name
            ))
        })
    })
}

fn deps(s: &str, ctx: &str) -> Vec<usize> {
    s.split_whitespace()
        .map(|d| {
            d.parse::<usize>()
                .unwrap_or_else(|_| fail(format!("{ctx}: dependency '{d}' is not an index")))
        })
        .collect()
}

fn const_name(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_uppercase()
            } else {
                '_'
            }
        })
        .collect()
}

fn opt_f64(v: Option<f64>) -> String {
    match v {
        Some(x) => format!("Some({x:?})"),
        None => "None".into(),
    }
}

fn main() {
    println!("cargo:rerun-if-changed={XML}");
    println!("cargo:rerun-if-changed=build.rs");
    let text = std::fs::read_to_string(XML).unwrap_or_else(|e| fail(format!("cannot read: {e}")));
    let mut reader = Reader::from_str(&text);
    reader.config_mut().trim_text(true);

    let mut vars: Vec<Var> = Vec::new();
    let mut enums: BTreeMap<String, Vec<(String, i64)>> = BTreeMap::new();
    let mut current_type: Option<String> = None;
    let mut in_var = false;
    let mut section = String::new();
    let mut outputs: Vec<(usize, Vec<usize>)> = Vec::new();
    let mut initial_unknowns: Vec<(usize, Vec<usize>)> = Vec::new();
    let mut guid = String::new();
    let mut model_identifier = String::new();

    loop {
        let event = reader.read_event().unwrap_or_else(|e| {
            fail(format!(
                "XML error at byte {}: {e}",
                reader.buffer_position()
            ))
        });
        let (e, is_empty) = match &event {
            Event::Start(e) => (e.clone(), false),
            Event::Empty(e) => (e.clone(), true),
            Event::End(e) => {
                match e.name().as_ref() {
                    b"ScalarVariable" => in_var = false,
                    b"SimpleType" => current_type = None,
                    b"Outputs" | b"InitialUnknowns" => section.clear(),
                    _ => {}
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        let a = attrs(&e);
        match e.name().as_ref() {
            b"fmiModelDescription" => {
                guid = a
                    .get("guid")
                    .cloned()
                    .unwrap_or_else(|| fail("no guid".into()));
                if a.get("fmiVersion").map(String::as_str) != Some("2.0") {
                    fail("fmiVersion must be \"2.0\"".into());
                }
            }
            b"CoSimulation" => {
                model_identifier = a.get("modelIdentifier").cloned().unwrap_or_default();
            }
            b"SimpleType" => {
                let name = a
                    .get("name")
                    .cloned()
                    .unwrap_or_else(|| fail("SimpleType without name".into()));
                enums.insert(name.clone(), Vec::new());
                current_type = Some(name);
            }
            b"Item" => {
                let t = current_type
                    .clone()
                    .unwrap_or_else(|| fail("Item outside a SimpleType".into()));
                let name = a.get("name").cloned().unwrap_or_default();
                let value = a
                    .get("value")
                    .and_then(|v| v.parse::<i64>().ok())
                    .unwrap_or_else(|| {
                        fail(format!(
                            "enumeration {t}: item '{name}' needs an integer value"
                        ))
                    });
                if let Some(items) = enums.get_mut(&t) {
                    items.push((name, value))
                }
            }
            b"ScalarVariable" => {
                let name = a
                    .get("name")
                    .cloned()
                    .unwrap_or_else(|| fail("ScalarVariable without name".into()));
                let vr = a
                    .get("valueReference")
                    .and_then(|v| v.parse::<u32>().ok())
                    .unwrap_or_else(|| {
                        fail(format!("variable '{name}': bad or missing valueReference"))
                    });
                vars.push(Var {
                    index: vars.len() + 1,
                    name,
                    vr,
                    causality: a
                        .get("causality")
                        .cloned()
                        .unwrap_or_else(|| "local".into()),
                    variability: a
                        .get("variability")
                        .cloned()
                        .unwrap_or_else(|| "continuous".into()),
                    initial: a.get("initial").cloned(),
                    description: a.get("description").cloned().unwrap_or_default(),
                    ..Default::default()
                });
                in_var = !is_empty;
            }
            b"Real" | b"Integer" | b"Boolean" | b"String" | b"Enumeration" if in_var => {
                let v = vars
                    .last_mut()
                    .unwrap_or_else(|| fail("type element outside a variable".into()));
                if !v.ty.is_empty() {
                    fail(format!("variable '{}' has two type elements", v.name));
                }
                v.ty = String::from_utf8_lossy(e.name().as_ref()).into_owned();
                v.declared_type = a.get("declaredType").cloned();
                v.start = a.get("start").cloned();
                v.min = a.get("min").cloned();
                v.max = a.get("max").cloned();
                v.unit = a.get("unit").cloned();
            }
            b"Outputs" => section = "Outputs".into(),
            b"InitialUnknowns" => section = "InitialUnknowns".into(),
            b"Derivatives" => fail("a Co-Simulation-only FMU has no Derivatives".into()),
            b"Unknown" => {
                let ctx = format!("ModelStructure/{section}");
                let index = a
                    .get("index")
                    .and_then(|v| v.parse::<usize>().ok())
                    .unwrap_or_else(|| fail(format!("{ctx}: Unknown without index")));
                let d = deps(
                    a.get("dependencies").map(String::as_str).unwrap_or(""),
                    &ctx,
                );
                if !a.contains_key("dependencies") {
                    fail(format!(
                        "{ctx}: Unknown {index} must list its dependencies explicitly"
                    ));
                }
                match section.as_str() {
                    "Outputs" => outputs.push((index, d)),
                    "InitialUnknowns" => initial_unknowns.push((index, d)),
                    _ => fail(format!("Unknown {index} outside Outputs/InitialUnknowns")),
                }
            }
            _ => {}
        }
    }

    if model_identifier != MODEL_IDENTIFIER {
        fail(format!(
            "CoSimulation modelIdentifier must be {MODEL_IDENTIFIER}, found '{model_identifier}'"
        ));
    }
    check(&vars, &enums, &outputs, &initial_unknowns);
    let code = generate(&vars, &enums, &guid);
    let out =
        PathBuf::from(std::env::var("OUT_DIR").unwrap_or_else(|_| fail("OUT_DIR not set".into())));
    std::fs::write(out.join("model_description.rs"), code)
        .unwrap_or_else(|e| fail(format!("cannot write generated code: {e}")));
}

fn check(
    vars: &[Var],
    enums: &BTreeMap<String, Vec<(String, i64)>>,
    outputs: &[(usize, Vec<usize>)],
    initial_unknowns: &[(usize, Vec<usize>)],
) {
    let mut names = BTreeSet::new();
    let mut vrs = BTreeSet::new();
    for v in vars {
        if !names.insert(v.name.as_str()) {
            fail(format!("variable name '{}' is used twice", v.name));
        }
        // One value-reference space across all types keeps the Rust table simple.
        if !vrs.insert(v.vr) {
            fail(format!(
                "valueReference {} is used twice (at '{}')",
                v.vr, v.name
            ));
        }
        if v.ty.is_empty() {
            fail(format!("variable '{}' has no type element", v.name));
        }
        let needs_start = matches!(v.causality.as_str(), "parameter" | "input");
        if needs_start && v.start.is_none() {
            fail(format!("{} '{}' needs a start value", v.causality, v.name));
        }
        if v.causality == "calculatedParameter" && v.initial.as_deref() != Some("calculated") {
            fail(format!(
                "calculatedParameter '{}' must have initial=\"calculated\"",
                v.name
            ));
        }
        if matches!(v.causality.as_str(), "output" | "calculatedParameter") && v.start.is_some() {
            fail(format!(
                "'{}' is calculated and must not have a start value",
                v.name
            ));
        }
        if v.ty == "Real" && v.unit.is_none() {
            fail(format!("Real variable '{}' needs a unit", v.name));
        }
        let (start, min, max) = (
            num(v, "start", &v.start),
            num(v, "min", &v.min),
            num(v, "max", &v.max),
        );
        if let (Some(s), Some(lo)) = (start, min)
            && s < lo
        {
            fail(format!("'{}': start {s} below min {lo}", v.name));
        }
        if let (Some(s), Some(hi)) = (start, max)
            && s > hi
        {
            fail(format!("'{}': start {s} above max {hi}", v.name));
        }
        if v.ty == "Enumeration" {
            let t = v
                .declared_type
                .as_ref()
                .unwrap_or_else(|| fail(format!("'{}' needs declaredType", v.name)));
            let items = enums
                .get(t)
                .unwrap_or_else(|| fail(format!("'{}': unknown type {t}", v.name)));
            if let Some(s) = start
                && !items.iter().any(|(_, val)| *val as f64 == s)
            {
                fail(format!("'{}': start {s} is not an item of {t}", v.name));
            }
        }
    }
    let by_index = |i: usize, ctx: &str| -> &Var {
        vars.get(i.wrapping_sub(1))
            .unwrap_or_else(|| fail(format!("{ctx}: index {i} is not a variable")))
    };
    let want_outputs: Vec<usize> = vars
        .iter()
        .filter(|v| v.causality == "output")
        .map(|v| v.index)
        .collect();
    let got_outputs: Vec<usize> = outputs.iter().map(|(i, _)| *i).collect();
    if want_outputs != got_outputs {
        fail(format!(
            "ModelStructure/Outputs must list every output once, in order: {want_outputs:?}, found {got_outputs:?}"
        ));
    }
    for (i, d) in outputs {
        for &k in d {
            if by_index(k, "Outputs").causality != "input" {
                fail(format!(
                    "Outputs: output {i} may depend on inputs only, not on variable {k}"
                ));
            }
        }
        if !d.windows(2).all(|w| w[0] < w[1]) {
            fail(format!("Outputs: dependencies of {i} must be ascending"));
        }
    }
    let want_initial: Vec<usize> = vars
        .iter()
        .filter(|v| {
            (v.causality == "output" && v.initial.as_deref() != Some("exact"))
                || v.causality == "calculatedParameter"
        })
        .map(|v| v.index)
        .collect();
    let got_initial: Vec<usize> = initial_unknowns.iter().map(|(i, _)| *i).collect();
    if want_initial != got_initial {
        fail(format!(
            "ModelStructure/InitialUnknowns must be {want_initial:?}, found {got_initial:?}"
        ));
    }
    for (i, d) in initial_unknowns {
        for &k in d {
            let known = by_index(k, "InitialUnknowns");
            if !(known.causality == "input"
                || (known.causality == "parameter" && known.initial.as_deref() == Some("exact")))
            {
                fail(format!(
                    "InitialUnknowns: {i} may depend on inputs and exact parameters only, not on '{}'",
                    known.name
                ));
            }
        }
        if !d.windows(2).all(|w| w[0] < w[1]) {
            fail(format!(
                "InitialUnknowns: dependencies of {i} must be ascending"
            ));
        }
    }
}

fn generate(vars: &[Var], enums: &BTreeMap<String, Vec<(String, i64)>>, guid: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "// Generated by build.rs from {XML}. Do not edit.");
    let _ = writeln!(s, "pub const GUID: &str = {guid:?};");
    let _ = writeln!(
        s,
        "pub const MODEL_IDENTIFIER: &str = {MODEL_IDENTIFIER:?};"
    );
    let _ = writeln!(s, "pub const VARIABLES: &[Variable] = &[");
    for v in vars {
        let ty = match v.ty.as_str() {
            "Real" => "VarType::Real",
            "Integer" => "VarType::Integer",
            "Boolean" => "VarType::Boolean",
            "Enumeration" => "VarType::Enumeration",
            other => fail(format!("'{}': type {other} is not supported", v.name)),
        };
        let causality = match v.causality.as_str() {
            "parameter" => "Causality::Parameter",
            "calculatedParameter" => "Causality::CalculatedParameter",
            "input" => "Causality::Input",
            "output" => "Causality::Output",
            "local" => "Causality::Local",
            other => fail(format!("'{}': causality {other} is not supported", v.name)),
        };
        let variability = match v.variability.as_str() {
            "constant" => "Variability::Constant",
            "fixed" => "Variability::Fixed",
            "tunable" => "Variability::Tunable",
            "discrete" => "Variability::Discrete",
            "continuous" => "Variability::Continuous",
            other => fail(format!(
                "'{}': variability {other} is not supported",
                v.name
            )),
        };
        let items: Vec<String> = v
            .declared_type
            .as_ref()
            .and_then(|t| enums.get(t))
            .map(|items| {
                items
                    .iter()
                    .map(|(n, val)| format!("({n:?}, {val})"))
                    .collect()
            })
            .unwrap_or_default();
        let _ = writeln!(
            s,
            "    Variable {{ name: {:?}, vr: {}, ty: {ty}, causality: {causality}, variability: {variability}, start: {}, min: {}, max: {}, items: &[{}], unit: {:?}, description: {:?} }},",
            v.name,
            v.vr,
            opt_f64(num(v, "start", &v.start)),
            opt_f64(num(v, "min", &v.min)),
            opt_f64(num(v, "max", &v.max)),
            items.join(", "),
            v.unit.clone().unwrap_or_default(),
            v.description
        );
    }
    let _ = writeln!(s, "];");
    let _ = writeln!(
        s,
        "/// Value references, named after the variables (`.` becomes `_`)."
    );
    let _ = writeln!(s, "pub mod vr {{");
    for v in vars {
        let _ = writeln!(s, "    pub const {}: u32 = {};", const_name(&v.name), v.vr);
    }
    let _ = writeln!(s, "}}");
    let max_vr = vars.iter().map(|v| v.vr).max().unwrap_or(0) as usize;
    let mut index = vec![-1i32; max_vr + 1];
    for (i, v) in vars.iter().enumerate() {
        index[v.vr as usize] = i as i32;
    }
    let _ = writeln!(
        s,
        "/// Position in VARIABLES of each value reference (-1: none)."
    );
    let _ = writeln!(s, "pub const VR_INDEX: [i32; {}] = {index:?};", max_vr + 1);
    s
}
