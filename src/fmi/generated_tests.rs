//! The items the build script (build/) generates, checked against modelDescription.xml read here by a scanner of
//! its own: a slip in the generator (an item dropped, a value or name swapped, a category or
//! limit lost) fails these tests instead of reaching the FMU.

use super::vars::{
    AmplitudeModeItem, DampingLawItem, LOG_CATEGORIES, ModelKindItem, ScreensResponseItem,
    SolverMethodItem, VARIABLES, VarType, limits, log_category, vr,
};

const XML: &str = include_str!("../../modelDescription/modelDescription.xml");

/// The value of attribute `key` in the tag text `tag` (the XML uses no entities).
fn attr<'a>(tag: &'a str, key: &str) -> Option<&'a str> {
    let pattern = format!(" {key}=\"");
    let start = tag.find(&pattern)? + pattern.len();
    let len = tag[start..].find('"')?;
    Some(&tag[start..start + len])
}

/// The text of every `<element ...>` tag (up to its `>`) in `text`, in order.
fn tags<'a>(text: &'a str, element: &str) -> Vec<&'a str> {
    let open = format!("<{element} ");
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(k) = rest.find(&open) {
        let tail = &rest[k..];
        let end = tail.find('>').expect("unterminated tag");
        out.push(&tail[..=end]);
        rest = &tail[end..];
    }
    out
}

/// The body of each `<SimpleType>`: (name, description, items as (name, value, description)).
type XmlItem = (String, i64, String);
fn simple_types() -> Vec<(String, String, Vec<XmlItem>)> {
    let mut out = Vec::new();
    let mut rest = XML;
    while let Some(k) = rest.find("<SimpleType ") {
        let block = &rest[k..];
        let end = block
            .find("</SimpleType>")
            .expect("unterminated SimpleType");
        let block = &block[..end];
        let head = tags(block, "SimpleType")[0];
        let items = tags(block, "Item")
            .into_iter()
            .map(|t| {
                (
                    attr(t, "name").unwrap().to_string(),
                    attr(t, "value").unwrap().parse().unwrap(),
                    attr(t, "description").unwrap_or("").to_string(),
                )
            })
            .collect();
        out.push((
            attr(head, "name").unwrap().to_string(),
            attr(head, "description").unwrap_or("").to_string(),
            items,
        ));
        rest = &rest[k + end..];
    }
    out
}

/// The XML's items of one generated enumeration, and the generated enum's view of itself.
struct Generated {
    type_name: &'static str,
    description: &'static str,
    /// (name, value, description) of ALL, in order.
    all: Vec<XmlItem>,
    /// Every value of ALL back through from_value, from_f64 and TryFrom, to (name, value).
    round_trip: Vec<Option<(String, i64)>>,
    /// from_value of values that are no item (0, one above the largest, negative).
    strays: Vec<bool>,
}

macro_rules! generated {
    ($t:ty) => {{
        let all = <$t>::ALL;
        let top = all.iter().map(|i| i.value()).max().unwrap();
        Generated {
            type_name: <$t>::TYPE_NAME,
            description: <$t>::DESCRIPTION,
            all: all
                .iter()
                .map(|i| (i.name().to_string(), i.value(), i.description().to_string()))
                .collect(),
            round_trip: all
                .iter()
                .map(|i| {
                    let back = <$t>::from_value(i.value())?;
                    let via_f64 = <$t>::from_f64(i.value() as f64)?;
                    let via_try = <$t>::try_from(i.value()).ok()?;
                    let as_i64: i64 = back.into();
                    (back == via_f64 && back == via_try && back == *i)
                        .then(|| (back.to_string(), as_i64))
                })
                .collect(),
            strays: vec![
                <$t>::from_value(0).is_none(),
                <$t>::from_value(top + 1).is_none(),
                <$t>::from_value(-1).is_none(),
                <$t>::from_f64(all[0].value() as f64 + 0.5).is_none(),
                <$t>::try_from(top + 1) == Err(top + 1),
            ],
        }
    }};
}

fn all_generated() -> Vec<Generated> {
    vec![
        generated!(ModelKindItem),
        generated!(DampingLawItem),
        generated!(AmplitudeModeItem),
        generated!(SolverMethodItem),
        generated!(ScreensResponseItem),
    ]
}

#[test]
fn every_enumeration_of_the_xml_has_a_generated_enum_with_its_items() {
    let xml = simple_types();
    let generated = all_generated();
    let mut xml_names: Vec<&str> = xml.iter().map(|t| t.0.as_str()).collect();
    let mut rust_names: Vec<&str> = generated.iter().map(|g| g.type_name).collect();
    xml_names.sort_unstable();
    rust_names.sort_unstable();
    assert_eq!(
        xml_names, rust_names,
        "a SimpleType without its generated enum in this test (add it to all_generated)"
    );
    for g in &generated {
        let (_, description, items) = xml.iter().find(|t| t.0 == g.type_name).unwrap();
        assert_eq!(g.description, description, "{}", g.type_name);
        assert_eq!(
            &g.all, items,
            "{}: items, values or descriptions",
            g.type_name
        );
    }
}

#[test]
fn generated_enums_round_trip_every_item() {
    for g in all_generated() {
        let want: Vec<Option<(String, i64)>> = g
            .all
            .iter()
            .map(|(name, value, _)| Some((name.clone(), *value)))
            .collect();
        assert_eq!(
            g.round_trip, want,
            "{}: value -> item -> value",
            g.type_name
        );
        assert!(
            g.strays.iter().all(|&ok| ok),
            "{}: {:?}",
            g.type_name,
            g.strays
        );
    }
}

#[test]
fn same_item_names_stay_apart() {
    // "Auto" is an item of two enumerations with different values.
    assert_eq!(ModelKindItem::Auto.value(), 4);
    assert_eq!(SolverMethodItem::Auto.value(), 4);
    assert_eq!(
        ModelKindItem::from_value(3),
        Some(ModelKindItem::SloshingSlamming)
    );
    assert_eq!(
        SolverMethodItem::from_value(3),
        Some(SolverMethodItem::SDIRK4)
    );
}

#[test]
fn enumeration_variables_carry_the_items_of_their_type() {
    let items = |vr: u32| {
        VARIABLES
            .iter()
            .find(|v| v.vr == vr)
            .map(|v| (v.ty, v.items.to_vec()))
            .unwrap()
    };
    let expect = |all: Vec<(&'static str, i64)>| (VarType::Enumeration, all);
    assert_eq!(
        items(vr::MODEL),
        expect(ModelKindItem::ALL.map(|i| (i.name(), i.value())).to_vec())
    );
    assert_eq!(
        items(vr::DAMPING),
        expect(DampingLawItem::ALL.map(|i| (i.name(), i.value())).to_vec())
    );
    assert_eq!(
        items(vr::AMPLITUDE),
        expect(
            AmplitudeModeItem::ALL
                .map(|i| (i.name(), i.value()))
                .to_vec()
        )
    );
    assert_eq!(
        items(vr::SOLVER),
        expect(
            SolverMethodItem::ALL
                .map(|i| (i.name(), i.value()))
                .to_vec()
        )
    );
    assert_eq!(
        items(vr::SCREENS_RESPONSE),
        expect(
            ScreensResponseItem::ALL
                .map(|i| (i.name(), i.value()))
                .to_vec()
        )
    );
    // The Integer aliases accept 0 ("use the enumeration") and every item.
    for (max, n) in [
        (limits::MODEL_ID_MAX, ModelKindItem::ALL.len()),
        (limits::DAMPING_ID_MAX, DampingLawItem::ALL.len()),
        (limits::AMPLITUDE_ID_MAX, AmplitudeModeItem::ALL.len()),
        (limits::SOLVER_ID_MAX, SolverMethodItem::ALL.len()),
        (
            limits::SCREENS_RESPONSE_ID_MAX,
            ScreensResponseItem::ALL.len(),
        ),
    ] {
        assert_eq!(max as usize, n);
    }
}

#[test]
fn log_categories_are_those_of_the_xml() {
    let block = &XML[XML.find("<LogCategories>").unwrap()..XML.find("</LogCategories>").unwrap()];
    let xml: Vec<(&str, &str)> = tags(block, "Category")
        .into_iter()
        .map(|t| (attr(t, "name").unwrap(), attr(t, "description").unwrap()))
        .collect();
    let generated: Vec<(&str, &str)> = LOG_CATEGORIES
        .iter()
        .map(|&name| (name, log_category::description(name).unwrap()))
        .collect();
    assert_eq!(generated, xml);
    assert_eq!(log_category::LOG_CALLS, "logCalls");
    assert_eq!(log_category::description("logAll"), None);
}

#[test]
fn limits_are_the_declared_bounds() {
    // The scalar variable's type element follows its tag: min/max of the named variable.
    let bounds = |name: &str| {
        let k = XML.find(&format!("name=\"{name}\"")).unwrap();
        let rest = &XML[k..];
        let body = &rest[..rest.find("</ScalarVariable>").unwrap()];
        let ty = body[body.find(">\n").unwrap()..].trim_start_matches(">\n");
        let bound = |key| attr(ty, key).map(|v| v.parse::<f64>().unwrap());
        (bound("min"), bound("max"))
    };
    assert_eq!(
        bounds("modes"),
        (
            Some(limits::MODES_MIN as f64),
            Some(limits::MODES_MAX as f64)
        )
    );
    assert_eq!(
        bounds("slamming.Omega"),
        (
            Some(limits::SLAMMING_OMEGA_MIN),
            Some(limits::SLAMMING_OMEGA_MAX)
        )
    );
    assert_eq!(
        bounds("solver.max_substeps"),
        (
            Some(limits::SOLVER_MAX_SUBSTEPS_MIN as f64),
            Some(limits::SOLVER_MAX_SUBSTEPS_MAX as f64)
        )
    );
    assert_eq!(
        bounds("tank.length"),
        (Some(limits::TANK_LENGTH_MIN), Some(limits::TANK_LENGTH_MAX))
    );
    // And the table the setters check agrees with the constants.
    let modes = VARIABLES.iter().find(|v| v.vr == vr::MODES).unwrap();
    assert_eq!(modes.max, Some(limits::MODES_MAX as f64));
}
