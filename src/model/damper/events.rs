//! The damper's state events in Model Exchange (see `model::events`): the model's event
//! indicators and event handling under the inputs now, and the per-step outputs refreshed after
//! an event changed the state.

use super::{Damper, per_step};
use crate::model::Inputs;
use crate::model::events::EVENT_INDICATORS;
use crate::model::slamming::Event;

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
}
