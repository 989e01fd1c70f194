//! The consistency checks of the model description: everything the FMU and the generated code
//! take for granted of it (FMI 2.0 standard sections 2.2.7 and 2.2.8 on variables and the
//! ModelStructure, and what a Rust type needs of a name), each failing the build with a message
//! that says what is wrong and where.

use std::collections::{BTreeMap, BTreeSet};

use crate::model::{Description, EnumType, LogCategory, Var, fail, num};

/// Every check, in the order of the messages a broken document would give; `identifier` is
/// the modelIdentifier the package builds.
pub fn all(md: &Description, identifier: &str) {
    let model_identifier = &md.model_identifier;
    if model_identifier != identifier {
        fail(format!(
            "CoSimulation modelIdentifier must be {identifier}, found '{model_identifier}'"
        ));
    }
    check(&md.vars, &md.enums, &md.outputs, &md.initial_unknowns);
    check_types(&md.enums, &md.log_categories);
    // The shared FMI layer (fmi2/) logs under these names.
    for required in ["logStatusError", "logStatusWarning", "logCalls"] {
        if !md.log_categories.iter().any(|c| c.name == required) {
            fail(format!("LogCategories must declare '{required}'"));
        }
    }
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
    // Model Exchange's continuous states: the variables a derivative names.
    let states: Vec<usize> = vars.iter().filter_map(|v| v.derivative).collect();
    for (i, d) in outputs {
        for &k in d {
            if by_index(k, "Outputs").causality != "input" && !states.contains(&k) {
                fail(format!(
                    "Outputs: output {i} may depend on inputs and continuous states only, not on variable {k}"
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
            // Model Exchange's states and derivatives are the continuous locals.
            (matches!(v.causality.as_str(), "output" | "local")
                && v.initial.as_deref() != Some("exact"))
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
