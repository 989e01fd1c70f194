//! The damper in Model Exchange, the cells of model = ShallowWater (`shallow_water::continuous`):
//! the bank of cell states beside the four states every offered model has, set together, all
//! or nothing.

use super::{Damper, per_step};
use crate::model::Inputs;
use crate::model::continuous::STATES;
use crate::model::shallow_water::continuous::{CELL_STATES, CellRefusal};

impl Damper {
    /// The bank's states (0 where the model has no cells).
    pub fn cell_states(&self, out: &mut [f64; CELL_STATES]) {
        self.model.cell_states(out);
    }

    /// The bank's derivatives under the inputs now (0 where the model has no cells).
    pub fn cell_derivatives(&self, inputs: &Inputs, out: &mut [f64; CELL_STATES]) {
        self.model.cell_derivatives(inputs.a, out);
    }

    /// The bank's nominal magnitudes.
    pub fn cell_nominals(&self, out: &mut [f64; CELL_STATES]) {
        self.model.cell_nominals(out);
    }

    /// Take all continuous states: the four of [`Damper::continuous_states`] and the bank;
    /// all or nothing. A model with cells reads the bank and energy.input; the others the four.
    pub fn set_all_continuous_states(
        &mut self,
        s: &[f64; STATES],
        cells: &[f64; CELL_STATES],
    ) -> Result<(), CellRefusal> {
        // All or nothing already: the cells are checked before any is taken.
        if self
            .model
            .set_cell_states(cells, s[2], self.initial_energy)?
        {
            self.per_step = per_step(&self.model);
            Ok(())
        } else {
            self.set_continuous_states(s).map_err(CellRefusal::Invalid)
        }
    }
}
