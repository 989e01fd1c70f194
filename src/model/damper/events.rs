//! The damper's state events in Model Exchange (see `model::events`): the model's event
//! indicators and event handling under the inputs now, and the per-step outputs refreshed after
//! an event changed the state.

use super::{Damper, per_step};
use crate::model::continuous::ENERGY_INPUT;
use crate::model::events::EVENT_INDICATORS;
use crate::model::slamming::Event;
use crate::model::{Inputs, Observable};

impl Damper {
    /// The event indicators under the inputs now.
    pub fn event_indicators(&self, inputs: &Inputs) -> [f64; EVENT_INDICATORS] {
        self.model.event_indicators(inputs.a)
    }

    /// Handle an event under the inputs now: what it did to the state.
    pub fn event(&mut self, inputs: &Inputs) -> Event {
        let event = self.model.event(inputs.a);
        if event != Event::None {
            self.per_step = per_step(&self.model);
        }
        event
    }

    /// The tank's velocity jumped by `dv` at an event (an impulse on the structure, handed
    /// over by the host): the liquid keeps its absolute velocity, so each velocity relative to
    /// the tank drops by `dv`, and the base's work in the tank frame (energy.input) takes the
    /// change of the stored energy this makes. False if nothing changed.
    pub fn base_velocity_jump(&mut self, dv: f64) -> Result<bool, String> {
        if dv == 0.0 {
            return Ok(false);
        }
        let before = self.model.observe(Observable::Stored);
        let mut s = self.continuous_states();
        for k in self.model.relative_velocities() {
            s[k] -= dv;
        }
        self.set_continuous_states(&s)?;
        let mut s = self.continuous_states();
        s[ENERGY_INPUT] += self.model.observe(Observable::Stored) - before;
        self.set_continuous_states(&s)?;
        Ok(true)
    }
}
