//! TLD.fmu in Model Exchange: the value references of the states beyond the first four.
//! The amplitude estimator's (amplitude = Tracked): A_e.tracker.* = 200 + k and their
//! derivatives 250 + k, k = 0 .. 6 in `AmplitudeTracker::continuous_state`'s order. The
//! ShallowWater cell bank (scripts/me-cells-xml declares it): swe.h[i] = 1000 + i,
//! swe.q[i] = 1500 + i and their derivatives der(swe.h[i]) = 2000 + i, der(swe.q[i]) =
//! 2500 + i, i = 1 .. ME_CELLS. A position in the bank is cell i - 1 for a depth, ME_CELLS +
//! i - 1 for a discharge.

use crate::model::shallow_water::continuous::ME_CELLS;
use crate::physics::amplitude::TRACKER_CONTINUOUS;

const TRACKER: u32 = 200;
const DER_TRACKER: u32 = 250;

/// The estimator's state `r` names (its position), and whether as a derivative.
pub fn tracker_of(r: u32) -> Option<(usize, bool)> {
    let at = |base: u32| {
        let k = r.checked_sub(base)? as usize;
        (k < TRACKER_CONTINUOUS).then_some(k)
    };
    at(TRACKER)
        .map(|k| (k, false))
        .or_else(|| at(DER_TRACKER).map(|k| (k, true)))
}

const DEPTH: u32 = 1000;
const DISCHARGE: u32 = 1500;
const DER_DEPTH: u32 = 2000;
const DER_DISCHARGE: u32 = 2500;

/// What a bank value reference is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cell {
    /// A state, at this position of the bank.
    State(usize),
    /// A state's derivative, at this position of the bank.
    Derivative(usize),
}

/// The bank position `r` names, if it names one.
pub fn cell_of(r: u32) -> Option<Cell> {
    cell_in(r, ME_CELLS)
}

/// The position `r` names in a bank of `cells` cells (a parameter, so that the tests check the
/// numbering with a bank of their own while the declared one is empty).
#[inline]
fn cell_in(r: u32, cells: usize) -> Option<Cell> {
    let at = |base: u32, offset: usize| {
        let i = r.checked_sub(base)? as usize;
        (1..cells + 1).contains(&i).then(|| offset + i - 1)
    };
    at(DEPTH, 0)
        .or_else(|| at(DISCHARGE, cells))
        .map(Cell::State)
        .or_else(|| {
            at(DER_DEPTH, 0)
                .or_else(|| at(DER_DISCHARGE, cells))
                .map(Cell::Derivative)
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi::vars::{VARIABLES, index_of};

    /// The model description declares exactly the bank these value references name (the
    /// script that writes it and ME_CELLS agree), in state order after the four states.
    #[test]
    fn bank_is_declared_as_named() {
        let name = |r: u32| index_of(r).map(|k| VARIABLES[k].name);
        for i in 1..=ME_CELLS as u32 {
            assert_eq!(name(DEPTH + i), Some(format!("swe.h[{i}]").as_str()));
            assert_eq!(name(DISCHARGE + i), Some(format!("swe.q[{i}]").as_str()));
            assert_eq!(
                name(DER_DEPTH + i),
                Some(format!("der(swe.h[{i}])").as_str())
            );
            assert_eq!(
                name(DER_DISCHARGE + i),
                Some(format!("der(swe.q[{i}])").as_str())
            );
        }
        let i = ME_CELLS as u32 + 1;
        for r in [
            DEPTH + i,
            DISCHARGE + i,
            DER_DEPTH + i,
            DER_DISCHARGE + i,
            DEPTH,
        ] {
            assert_eq!(name(r), None, "{r}");
            assert_eq!(cell_of(r), None, "{r}");
        }
        if let Some(last) = (2 * ME_CELLS).checked_sub(1) {
            assert_eq!(cell_of(DEPTH + 1), Some(Cell::State(0)));
            assert_eq!(cell_of(DISCHARGE + 2), Some(Cell::State(ME_CELLS + 1)));
            assert_eq!(
                cell_of(DER_DISCHARGE + ME_CELLS as u32),
                Some(Cell::Derivative(last))
            );
        }
        let names = [
            "A_e.tracker.v",
            "A_e.tracker.v2[1]",
            "A_e.tracker.v2[2]",
            "A_e.tracker.a2[1]",
            "A_e.tracker.a2[2]",
            "A_e.tracker.weight[1]",
            "A_e.tracker.weight[2]",
        ];
        for (k, n) in names.iter().enumerate() {
            assert_eq!(name(TRACKER + k as u32), Some(*n));
            assert_eq!(
                name(DER_TRACKER + k as u32),
                Some(format!("der({n})").as_str())
            );
            assert_eq!(tracker_of(TRACKER + k as u32), Some((k, false)));
            assert_eq!(tracker_of(DER_TRACKER + k as u32), Some((k, true)));
        }
        assert_eq!(tracker_of(TRACKER + 7), None);
        assert_eq!(tracker_of(DER_TRACKER - 1), None);
        // The variables of the bank are the last in the model description.
        let last = VARIABLES
            .iter()
            .rposition(|v| !v.name.contains("swe."))
            .unwrap_or(0);
        assert_eq!(VARIABLES.len() - last - 1, 4 * ME_CELLS);
    }

    /// The numbering of the module's header, in a bank of 3 cells: swe.h[i] is position i - 1,
    /// swe.q[i] is 3 + i - 1, each derivative the same position; nothing else is in the bank.
    #[test]
    fn a_bank_numbers_depths_then_discharges() {
        let cells = 3;
        for i in 1..=3u32 {
            let k = i as usize - 1;
            assert_eq!(cell_in(1000 + i, cells), Some(Cell::State(k)));
            assert_eq!(cell_in(1500 + i, cells), Some(Cell::State(cells + k)));
            assert_eq!(cell_in(2000 + i, cells), Some(Cell::Derivative(k)));
            assert_eq!(cell_in(2500 + i, cells), Some(Cell::Derivative(cells + k)));
        }
        for r in [
            0, 999, 1000, 1004, 1499, 1500, 1504, 1999, 2000, 2004, 2500, 2504, 3000,
        ] {
            assert_eq!(cell_in(r, cells), None, "vr {r}");
        }
    }
}
