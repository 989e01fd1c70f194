//! The values' table (params.rs) against the model description: FMU.md's defaults, the saved
//! list's length rule (the 54 variables of the first version-1 build, then the later ones up to
//! the last one away from its start), the checks of a saved list, and the inputs the models
//! read.

use super::*;
use crate::fmi::vars::VARIABLES;

fn slot_of(name: &str) -> usize {
    VARIABLES
        .iter()
        .position(|v| v.name == name)
        .unwrap_or_else(|| panic!("no variable {name}"))
}

fn bits(list: &[f64]) -> Vec<u64> {
    list.iter().map(|x| x.to_bits()).collect()
}

/// Start values: FMU.md's defaults, by name; none (NaN) for what is calculated.
#[test]
fn start_values_are_fmu_mds_defaults() {
    let v = Values::start();
    let defaults = [
        ("tank.length", 0.25),
        ("tank.breadth", 0.32),
        ("tank.depth", 0.021),
        ("liquid.density", 1000.0),
        ("g", 9.81),
        ("tanks", 1.0),
        ("modes", 1.0),
        ("eta", 2.0),
        ("phi", 1.0),
        ("zeta", 0.01),
        ("nsd.c", 0.5),
        ("nsd.p", 0.35),
        ("lambda.min", 1e-3),
        ("lambda.max", 0.1),
        ("A_e", 0.005),
        ("liquid.viscosity", 1e-6),
        ("base.a", 0.0),
        ("base.v", 0.0),
        ("base.x", 0.0),
    ];
    for (name, want) in defaults {
        let k = slot_of(name);
        assert_eq!(v.at(k), want, "{name}");
        assert_eq!(v.get(VARIABLES[k].vr), want, "{name}");
    }
    for name in ["omega_f", "mass.slosh", "force", "slosh.x"] {
        assert!(v.at(slot_of(name)).is_nan(), "{name}");
    }
    // Outside the table: no value, and nothing stored.
    assert!(v.get(9999).is_nan());
    assert!(v.at(VARIABLES.len()).is_nan());
    let mut w = v.clone();
    w.set_at(VARIABLES.len(), 1.0);
    assert_eq!(bits(w.to_saved()), bits(v.to_saved()));
}

/// A saved list holds the 54 variables of the first version-1 build always, and the later ones
/// up to the last one away from its start; it reads back to the same values.
#[test]
fn the_saved_list_ends_at_the_last_moved_later_variable() {
    let mut v = Values::start();
    assert_eq!(VERSION_1_VARIABLES, 54);
    assert_eq!(
        slot_of("swe.cells"),
        54,
        "the first variable added after version 1"
    );
    let saved = v.to_saved().to_vec();
    assert_eq!(saved.len(), 54);
    assert_eq!(bits(&saved), bits(&v.0[..54]));
    // Every start value moved back to it: still 54 (trailing start values are not listed).
    let jump = slot_of("base.v.jump");
    assert!(jump > 55);
    v.set_at(54, 100.0);
    assert_eq!(v.to_saved().len(), 55);
    v.set_at(jump, 0.25);
    assert_eq!(v.to_saved().len(), jump + 1);
    let back = Values::from_saved(v.to_saved()).expect("taken");
    assert_eq!(bits(&back.0), bits(&v.0));
    v.set_at(jump, 0.0);
    assert_eq!(v.to_saved().len(), 55);
    v.set_at(54, 150.0);
    assert_eq!(v.to_saved().len(), 54);
    // A value of the first 54 at its start is listed all the same.
    v.set_at(53, v.at(53));
    assert_eq!(v.to_saved().len(), 54);
}

/// A saved list of another length, or with a value its variable refuses, is refused with the
/// reason; calculated variables' slots are ignored (they carry no value).
#[test]
fn saved_lists_are_checked_value_by_value() {
    let start = Values::start();
    let n = VARIABLES.len();
    let short = Values::from_saved(&start.0[..53]).err();
    assert_eq!(short, Some(format!("53 values for {n} variables")));
    let mut long = start.0.to_vec();
    long.push(0.0);
    let long = Values::from_saved(&long).err();
    assert_eq!(long, Some(format!("{} values for {n} variables", n + 1)));
    let full = Values::from_saved(&start.0).expect("taken");
    assert_eq!(bits(&full.0), bits(&start.0));
    let mut bad = start.0[..54].to_vec();
    bad[slot_of("tank.length")] = -1.0;
    let why = Values::from_saved(&bad).err().unwrap_or_default();
    assert!(why.contains("tank.length"), "{why}");
    let mut odd = start.0[..54].to_vec();
    odd[slot_of("omega_f")] = 123.0;
    odd[slot_of("tank.depth")] = 0.03;
    let taken = Values::from_saved(&odd).expect("taken");
    assert!(taken.at(slot_of("omega_f")).is_nan());
    assert_eq!(taken.at(slot_of("tank.depth")), 0.03);
}

/// The inputs the models read: base.a, base.v and the derivatives given.
#[test]
fn inputs_are_base_a_and_base_v() {
    let mut v = Values::start();
    v.set_at(slot_of("base.a"), 1.5);
    v.set_at(slot_of("base.v"), -0.5);
    v.set_at(slot_of("base.x"), 9.0);
    let i = v.inputs([0.1, 0.2]);
    assert_eq!((i.a, i.v, i.a_derivatives), (1.5, -0.5, [0.1, 0.2]));
}
