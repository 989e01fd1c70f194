//! TLD.fmu's part of the saved state. The frame around it (tag "TLDs", format version, GUID,
//! phase, flags, time and experiment, checksum) is the shared layer's (`fmi2_slave::frame`);
//! the whole layout of format version 1:
//!
//! ```text
//! "TLDs" | format version u16 | reserved u16 | GUID length u16 | GUID bytes
//!        | payload length u32 | payload | FNV-1a 64 checksum of everything before it
//! payload: phase u8 | flags u8 (bit 0: solver.tolerance set by the user) | time, tolerance,
//!          start, stop f64
//!        | derivatives of base.a for the next step (orders 1, 2) f64
//!        | number of variables u32 | their values f64... (the 54 of the first version-1
//!          build, then those added since up to the last one away from its start value; the
//!          slot of the output impact.impulse holds S^2's impulse per unit impact mass, when
//!          not 0, beyond the model's pinned part below)
//!        | number of simulation values u32 (0: not initialised) | the values f64...
//! simulation values: the model's own part (`Model::save`: its state, then three numbers the
//!        integrator carries, 0 for the exact models) | the damper's frame (amplitude, mean-force
//!        flag and value, amplitude estimator: `Damper::snapshot`)
//! ```
//! tests/golden/ holds a state of this version for every model: the layout cannot change
//! without a test failing (tests/golden_state.rs).
//! All numbers little-endian.

use fmi2_slave::Context;
use fmi2_slave::frame::{Reader, put_f64, put_f64_list};

use super::params::{Configuration, Values};
use super::slave::Tld;
use super::vars::{index_of, vr};
use crate::model::Damper;

/// The slot of the values that carries [`Damper::extra`]: impact.impulse's.
const EXTRA_SLOT: usize = match index_of(vr::IMPACT_IMPULSE) {
    Some(i) => i,
    None => panic!("impact.impulse is in the model description"),
};

impl Tld {
    /// TLD's part of the saved state: input derivatives, values, simulation.
    pub(super) fn save_part(&self, out: &mut Vec<u8>) {
        for d in self.a_derivatives {
            put_f64(out, d);
        }
        // S^2's impulse handed over so far (impact.impulse over the impact mass) rides in the
        // output's own slot of the values, which is otherwise unused (NaN): listed only when
        // not 0, so every other state keeps the bytes of the earlier builds.
        match self.sim.as_ref().map_or(0.0, Damper::extra) {
            0.0 => put_f64_list(out, self.values.to_saved()),
            extra => {
                let mut values = self.values.clone();
                values.set_at(EXTRA_SLOT, extra);
                put_f64_list(out, values.to_saved());
            }
        }
        let simulation = self.sim.as_ref().map(Damper::snapshot).unwrap_or_default();
        put_f64_list(out, &simulation);
    }

    /// The slave a saved part describes, checked completely.
    pub(super) fn load_part(
        context: &Context,
        user_tolerance: bool,
        part: &mut Reader,
    ) -> Result<Self, String> {
        let a_derivatives = [part.f64()?, part.f64()?];
        let saved_values = part.f64_list()?;
        let simulation = part.f64_list()?;
        if !a_derivatives.iter().all(|d| d.is_finite()) {
            return Err("non-finite input derivatives".into());
        }
        let values = Values::from_saved(&saved_values)?;
        let initialised = context.phase.initialised();
        let sim = if initialised {
            let configuration = Configuration {
                values: &values,
                tolerance: context.experiment.tolerance,
                user_tolerance,
            };
            let mut sim = Damper::restore(&configuration, &simulation)?;
            // Absent, or NaN (the slot's start): 0.
            let extra = saved_values
                .get(EXTRA_SLOT)
                .copied()
                .filter(|x| !x.is_nan())
                .unwrap_or(0.0);
            sim.load_extra(extra)?;
            Some(sim)
        } else if simulation.is_empty() {
            None
        } else {
            return Err("simulation values in a state before initialisation".into());
        };
        Ok(Tld {
            // A state is saved between events: the model had taken the input's value.
            v_jump_taken: values.get(crate::description::vr::BASE_V_JUMP),
            values,
            user_tolerance,
            a_derivatives,
            sim,
        })
    }
}
