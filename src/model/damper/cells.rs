//! The damper in Model Exchange, the cells of model = ShallowWater (`shallow_water::continuous`):
//! the bank of cell states beside the four states every offered model has, set together, all
//! or nothing.

use super::{Damper, per_step};
use crate::model::Inputs;
use crate::model::continuous::STATES;
use crate::model::shallow_water::continuous::{CELL_STATES, StatesRefused};
use crate::physics::amplitude::TRACKER_CONTINUOUS;

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

    /// Take all continuous states: the four of [`Damper::continuous_states`], the amplitude
    /// estimator's and the bank; all or nothing. A model with cells reads the bank and
    /// energy.input, the others the four; with amplitude = Tracked the damping ratio follows
    /// the estimate of the estimator's states.
    pub fn set_all_continuous_states(
        &mut self,
        s: &[f64; STATES],
        tracker: &[f64; TRACKER_CONTINUOUS],
        cells: &[f64; CELL_STATES],
    ) -> Result<(), StatesRefused> {
        let estimator = match &self.tracker {
            Some(t) => {
                let mut t = t.clone();
                // Any finite trial state is taken (a mean square slightly below 0 included).
                t.set_continuous_state(tracker)
                    .map_err(StatesRefused::Invalid)?;
                Some(t)
            }
            None => None,
        };
        // All or nothing already: the cells are checked before any is taken.
        if !self
            .model
            .set_cell_states(cells, s[2], self.initial_energy)?
        {
            self.set_continuous_states(s)
                .map_err(StatesRefused::Invalid)?;
        }
        if estimator.is_some() {
            self.tracker = estimator;
            self.apply_tracked_damping();
        }
        self.per_step = per_step(&self.model);
        Ok(())
    }
}
