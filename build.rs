//! Reads modelDescription/modelDescription.xml (the single source of truth for the FMU's
//! variables), checks it for internal consistency, and generates `$OUT_DIR/model_description.rs`
//! (included by src/fmi/vars.rs): the variable table and value references, a Rust enum for every
//! enumeration SimpleType, the log categories and the declared min/max of every variable. Any
//! inconsistency fails the build with a message that says what is wrong and where.

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

/// An enumeration SimpleType of the TypeDefinitions.
#[derive(Debug, Default)]
struct EnumType {
    description: String,
    /// Whether the SimpleType holds an Enumeration (other SimpleTypes get no Rust type).
    is_enumeration: bool,
    items: Vec<Item>,
}

#[derive(Debug)]
struct Item {
    name: String,
    value: i64,
    description: String,
}

/// A LogCategories entry.
#[derive(Debug)]
struct LogCategory {
    name: String,
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
    let mut enums: BTreeMap<String, EnumType> = BTreeMap::new();
    let mut log_categories: Vec<LogCategory> = Vec::new();
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
                let t = EnumType {
                    description: a.get("description").cloned().unwrap_or_default(),
                    ..Default::default()
                };
                if enums.insert(name.clone(), t).is_some() {
                    fail(format!("SimpleType '{name}' is defined twice"));
                }
                current_type = Some(name);
            }
            b"Enumeration" if !in_var => {
                let t = current_type
                    .as_ref()
                    .unwrap_or_else(|| fail("Enumeration outside a SimpleType".into()));
                if let Some(t) = enums.get_mut(t) {
                    t.is_enumeration = true;
                }
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
                if let Some(enum_type) = enums.get_mut(&t) {
                    enum_type.items.push(Item {
                        name,
                        value,
                        description: a.get("description").cloned().unwrap_or_default(),
                    })
                }
            }
            b"Category" => {
                let name = a
                    .get("name")
                    .cloned()
                    .unwrap_or_else(|| fail("log Category without name".into()));
                log_categories.push(LogCategory {
                    name,
                    description: a.get("description").cloned().unwrap_or_default(),
                });
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
    check_types(&enums, &log_categories);
    let mut code = generate(&vars, &enums, &guid);
    generate_enums(&mut code, &enums);
    generate_log_categories(&mut code, &log_categories);
    generate_limits(&mut code, &vars);
    let out =
        PathBuf::from(std::env::var("OUT_DIR").unwrap_or_else(|_| fail("OUT_DIR not set".into())));
    std::fs::write(out.join("model_description.rs"), code)
        .unwrap_or_else(|e| fail(format!("cannot write generated code: {e}")));
}

fn check(
    vars: &[Var],
    enums: &BTreeMap<String, EnumType>,
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
            let enum_type = enums
                .get(t)
                .filter(|t| t.is_enumeration)
                .unwrap_or_else(|| fail(format!("'{}': unknown enumeration type {t}", v.name)));
            if let Some(s) = start
                && !enum_type.items.iter().any(|i| i.value as f64 == s)
            {
                fail(format!("'{}': start {s} is not an item of {t}", v.name));
            }
        }
        if v.ty == "Integer" {
            // fmi2Integer is 32 bits: the generated limits are i32.
            for (what, x) in [("start", start), ("min", min), ("max", max)] {
                if let Some(x) = x
                    && (x.fract() != 0.0 || x < i32::MIN as f64 || x > i32::MAX as f64)
                {
                    fail(format!("'{}': {what} {x} is not a 32-bit integer", v.name));
                }
            }
        }
    }
    check_aliases(vars, enums);
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

fn generate(vars: &[Var], enums: &BTreeMap<String, EnumType>, guid: &str) -> String {
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
            .map(|t| {
                t.items
                    .iter()
                    .map(|i| format!("({:?}, {})", i.name, i.value))
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

/// `X_id` is the Integer alias of the Enumeration variable `X` (for hosts that cannot set
/// Enumerations): it must accept 0 ("use X") and exactly the values of X's items.
fn check_aliases(vars: &[Var], enums: &BTreeMap<String, EnumType>) {
    for alias in vars.iter().filter(|v| v.ty == "Integer") {
        let Some(target) = alias.name.strip_suffix("_id") else {
            continue;
        };
        let Some(var) = vars
            .iter()
            .find(|v| v.name == target && v.ty == "Enumeration")
        else {
            continue;
        };
        let Some(enum_type) = var.declared_type.as_ref().and_then(|t| enums.get(t)) else {
            continue;
        };
        let mut values: Vec<i64> = enum_type.items.iter().map(|i| i.value).collect();
        values.sort_unstable();
        let contiguous = values.iter().zip(1..).all(|(v, k)| *v == k);
        let want = (Some(0.0), values.last().map(|v| *v as f64));
        let got = (num(alias, "min", &alias.min), num(alias, "max", &alias.max));
        if !contiguous || got != want {
            fail(format!(
                "'{}' aliases '{target}': its min/max must be 0/{} and the items of {} numbered \
                 1..n, found min/max {:?}/{:?} and item values {values:?}",
                alias.name,
                values.len(),
                var.declared_type.as_deref().unwrap_or_default(),
                alias.min,
                alias.max
            ));
        }
    }
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// What the generated Rust types need of the TypeDefinitions and LogCategories.
fn check_types(enums: &BTreeMap<String, EnumType>, log_categories: &[LogCategory]) {
    for (name, t) in enums.iter().filter(|(_, t)| t.is_enumeration) {
        if !is_identifier(name) {
            fail(format!("SimpleType '{name}' must be a Rust identifier"));
        }
        if t.items.is_empty() {
            fail(format!("enumeration {name} has no items"));
        }
        for (k, item) in t.items.iter().enumerate() {
            if !is_identifier(&item.name) || item.name == "Self" {
                fail(format!(
                    "enumeration {name}: item '{}' must be a Rust identifier",
                    item.name
                ));
            }
            if i32::try_from(item.value).is_err() {
                fail(format!(
                    "enumeration {name}: value {} of '{}' is not a 32-bit integer",
                    item.value, item.name
                ));
            }
            for other in &t.items[..k] {
                if other.name == item.name {
                    fail(format!("enumeration {name}: item '{}' twice", item.name));
                }
                if other.value == item.value {
                    fail(format!(
                        "enumeration {name}: '{}' and '{}' share the value {}",
                        other.name, item.name, item.value
                    ));
                }
            }
        }
    }
    let mut seen = BTreeSet::new();
    for c in log_categories {
        if c.name.is_empty() || !seen.insert(c.name.as_str()) {
            fail(format!("log category '{}' is empty or used twice", c.name));
        }
        if !is_identifier(&c.name) {
            fail(format!("log category '{}' must be an identifier", c.name));
        }
    }
}

/// `logStatusError` -> `LOG_STATUS_ERROR`.
fn screaming_snake(name: &str) -> String {
    let mut out = String::new();
    for (k, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() && k > 0 {
            out.push('_');
        }
        out.push(c.to_ascii_uppercase());
    }
    out
}

/// One enum per enumeration SimpleType, named after it with `Item` appended (`ModelKind` ->
/// `ModelKindItem`): the XML's items are its variants and their values its discriminants.
/// The suffix keeps the generated types apart from the simulation's own (`ModelKind`,
/// `DampingLaw`) and says what a value is: an item of the XML type.
fn generate_enums(s: &mut String, enums: &BTreeMap<String, EnumType>) {
    for (type_name, t) in enums.iter().filter(|(_, t)| t.is_enumeration) {
        let rust = format!("{type_name}Item");
        let n = t.items.len();
        let _ = writeln!(
            s,
            "\n#[doc = {:?}]",
            format!(
                "{}: the items of the enumeration type `{type_name}` of the model description.",
                t.description
            )
        );
        let _ = writeln!(
            s,
            "#[allow(clippy::upper_case_acronyms)] // the XML's item names"
        );
        let _ = writeln!(s, "#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]");
        let _ = writeln!(s, "#[repr(i32)]");
        let _ = writeln!(s, "pub enum {rust} {{");
        for i in &t.items {
            let _ = writeln!(s, "    #[doc = {:?}]", i.description);
            let _ = writeln!(s, "    {} = {},", i.name, i.value);
        }
        let _ = writeln!(s, "}}");
        let _ = writeln!(s, "impl {rust} {{");
        let _ = writeln!(
            s,
            "    /// The SimpleType's name in the model description.\n    pub const TYPE_NAME: &'static str = {type_name:?};"
        );
        let _ = writeln!(
            s,
            "    /// The SimpleType's description.\n    pub const DESCRIPTION: &'static str = {:?};",
            t.description
        );
        let all: Vec<String> = t
            .items
            .iter()
            .map(|i| format!("Self::{}", i.name))
            .collect();
        let _ = writeln!(
            s,
            "    /// Every item, in the order of the model description.\n    pub const ALL: [Self; {n}] = [{}];",
            all.join(", ")
        );
        let _ = writeln!(
            s,
            "    /// The item's value (what fmi2SetInteger/fmi2GetInteger carry).\n    pub const fn value(self) -> i64 {{\n        self as i64\n    }}"
        );
        let _ = writeln!(
            s,
            "    /// The item with this value, if any.\n    pub const fn from_value(value: i64) -> Option<Self> {{\n        match value {{"
        );
        for i in &t.items {
            let _ = writeln!(s, "            {} => Some(Self::{}),", i.value, i.name);
        }
        let _ = writeln!(s, "            _ => None,\n        }}\n    }}");
        let _ = writeln!(
            s,
            "    /// The item with this value, for values held as f64 (integral values only).\n    pub fn from_f64(value: f64) -> Option<Self> {{\n        if value.fract() == 0.0 {{ Self::from_value(value as i64) }} else {{ None }}\n    }}"
        );
        for (method, what) in [("name", "name"), ("description", "description")] {
            let _ = writeln!(
                s,
                "    /// The item's {what} in the model description.\n    pub const fn {method}(self) -> &'static str {{\n        match self {{"
            );
            for i in &t.items {
                let text = if method == "name" {
                    &i.name
                } else {
                    &i.description
                };
                let _ = writeln!(s, "            Self::{} => {text:?},", i.name);
            }
            let _ = writeln!(s, "        }}\n    }}");
        }
        let _ = writeln!(s, "}}");
        let _ = writeln!(
            s,
            "impl TryFrom<i64> for {rust} {{\n    type Error = i64;\n    fn try_from(value: i64) -> Result<Self, i64> {{\n        Self::from_value(value).ok_or(value)\n    }}\n}}"
        );
        let _ = writeln!(
            s,
            "impl From<{rust}> for i64 {{\n    fn from(item: {rust}) -> i64 {{\n        item.value()\n    }}\n}}"
        );
        let _ = writeln!(
            s,
            "impl std::fmt::Display for {rust} {{\n    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {{\n        f.write_str(self.name())\n    }}\n}}"
        );
    }
}

/// The LogCategories: one constant per category and the list fmi2SetDebugLogging accepts.
fn generate_log_categories(s: &mut String, categories: &[LogCategory]) {
    let _ = writeln!(
        s,
        "\n/// The log categories of the model description, one constant each.\npub mod log_category {{"
    );
    for c in categories {
        let _ = writeln!(
            s,
            "    #[doc = {:?}]\n    pub const {}: &str = {:?};",
            c.description,
            screaming_snake(&c.name),
            c.name
        );
    }
    let _ = writeln!(
        s,
        "    /// A category's description, by name.\n    pub fn description(name: &str) -> Option<&'static str> {{\n        match name {{"
    );
    for c in categories {
        let _ = writeln!(s, "            {:?} => Some({:?}),", c.name, c.description);
    }
    let _ = writeln!(s, "            _ => None,\n        }}\n    }}\n}}");
    let names: Vec<String> = categories
        .iter()
        .map(|c| format!("log_category::{}", screaming_snake(&c.name)))
        .collect();
    let _ = writeln!(
        s,
        "/// Every log category, in the order of the model description.\npub const LOG_CATEGORIES: [&str; {}] = [{}];",
        categories.len(),
        names.join(", ")
    );
}

/// The declared min and max of every variable that has them: `limits::MODES_MAX` is the max
/// of `modes`. Integers as i32 (fmi2Integer), Reals as f64.
fn generate_limits(s: &mut String, vars: &[Var]) {
    let _ = writeln!(
        s,
        "\n/// Declared bounds of the variables (`<NAME>_MIN`, `<NAME>_MAX`; `.` becomes `_`).\npub mod limits {{"
    );
    for v in vars {
        for (suffix, text) in [("MIN", &v.min), ("MAX", &v.max)] {
            let Some(x) = num(v, &suffix.to_lowercase(), text) else {
                continue;
            };
            let (ty, value) = match v.ty.as_str() {
                "Integer" => ("i32", format!("{}", x as i32)),
                "Real" => ("f64", format!("{x:?}")),
                other => fail(format!("'{}': min/max on a {other} variable", v.name)),
            };
            let _ = writeln!(
                s,
                "    pub const {}_{suffix}: {ty} = {value};",
                const_name(&v.name)
            );
        }
    }
    let _ = writeln!(s, "}}");
}
