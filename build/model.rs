//! The model description as the build script reads it: the variables, enumeration types, log
//! categories and ModelStructure of modelDescription.xml, parsed with quick-xml. What is read is
//! checked in check.rs; a document this reader cannot follow fails here, with the reason.

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};
use std::collections::BTreeMap;

pub const XML: &str = "modelDescription/modelDescription.xml";

#[derive(Debug, Default)]
pub struct Var {
    pub index: usize,
    pub name: String,
    pub vr: u32,
    pub causality: String,
    pub variability: String,
    pub initial: Option<String>,
    pub ty: String,
    pub declared_type: Option<String>,
    pub start: Option<String>,
    pub min: Option<String>,
    pub max: Option<String>,
    pub unit: Option<String>,
    /// Model Exchange: the index of the state this variable is the derivative of.
    pub derivative: Option<usize>,
    pub description: String,
}

/// An enumeration SimpleType of the TypeDefinitions.
#[derive(Debug, Default)]
pub struct EnumType {
    pub description: String,
    /// Whether the SimpleType holds an Enumeration (other SimpleTypes get no Rust type).
    pub is_enumeration: bool,
    pub items: Vec<Item>,
}

#[derive(Debug)]
pub struct Item {
    pub name: String,
    pub value: i64,
    pub description: String,
}

/// A LogCategories entry.
#[derive(Debug)]
pub struct LogCategory {
    pub name: String,
    pub description: String,
}

pub fn fail(msg: String) -> ! {
    panic!("\n\n{XML}: {msg}\n\n");
}

pub fn attrs(e: &BytesStart) -> BTreeMap<String, String> {
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

pub fn num(var: &Var, what: &str, s: &Option<String>) -> Option<f64> {
    s.as_ref().map(|v| {
        v.trim().parse::<f64>().unwrap_or_else(|_| {
            fail(format!(
                "variable '{}': {what}=\"{v}\" is not a number",
                var.name
            ))
        })
    })
}

pub fn deps(s: &str, ctx: &str) -> Vec<usize> {
    s.split_whitespace()
        .map(|d| {
            d.parse::<usize>()
                .unwrap_or_else(|_| fail(format!("{ctx}: dependency '{d}' is not an index")))
        })
        .collect()
}

/// Everything the checks and the generator need of the document.
#[derive(Debug, Default)]
pub struct Description {
    pub vars: Vec<Var>,
    pub enums: BTreeMap<String, EnumType>,
    pub log_categories: Vec<LogCategory>,
    /// ModelStructure/Outputs: (index, dependencies).
    pub outputs: Vec<(usize, Vec<usize>)>,
    /// ModelStructure/InitialUnknowns: (index, dependencies).
    pub initial_unknowns: Vec<(usize, Vec<usize>)>,
    pub guid: String,
    pub model_identifier: String,
}

/// Parses the document `text`.
pub fn read(text: &str) -> Description {
    let mut reader = Reader::from_str(text);
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
                v.derivative = a.get("derivative").map(|d| {
                    d.parse().unwrap_or_else(|_| {
                        fail(format!(
                            "variable '{}': derivative=\"{d}\" is no index",
                            v.name
                        ))
                    })
                });
            }
            b"Outputs" => section = "Outputs".into(),
            b"InitialUnknowns" => section = "InitialUnknowns".into(),
            // Model Exchange's states: their derivatives (checked by fmpy's validation and the
            // tests that run the FMUs in Model Exchange).
            b"Derivatives" => section = "Derivatives".into(),
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
                    "Derivatives" => {}
                    _ => fail(format!("Unknown {index} outside Outputs/InitialUnknowns")),
                }
            }
            _ => {}
        }
    }
    Description {
        vars,
        enums,
        log_categories,
        outputs,
        initial_unknowns,
        guid,
        model_identifier,
    }
}
