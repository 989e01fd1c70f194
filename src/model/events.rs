//! Model Exchange's state events, the models' side (knows no FMI): S^2's impacts on the walls
//! and its impact mass resting on and leaving a wall ([`SloshingSlamming::event`]). The number
//! of event indicators is fixed for every model (the model description declares it): the
//! models without events report indicators that never cross (constant 1).
//!
//! [`SloshingSlamming::event`]: super::slamming::SloshingSlamming::event

use super::continuous::{BANK, IMPACT_V};
use super::registry::AnyModel;
use super::slamming::Event;

/// Event indicators: S^2's contact functions of the walls +d/2 and -d/2.
pub const EVENT_INDICATORS: usize = 2;

impl AnyModel {
    /// The event indicators under base acceleration `a`; a state event where one reaches 0.
    pub fn event_indicators(&self, a: f64) -> [f64; EVENT_INDICATORS] {
        match self {
            AnyModel::SloshingSlamming(m) => m.contact_functions(a),
            _ => [1.0; EVENT_INDICATORS],
        }
    }

    /// Handle a state event (or an input or time event) under base acceleration `a`.
    pub fn event(&mut self, a: f64) -> Event {
        match self {
            AnyModel::SloshingSlamming(m) => m.event(a),
            _ => Event::None,
        }
    }

    /// The continuous states (in [`AnyModel::continuous_states`]' order) that are velocities
    /// relative to the tank: slosh.v, the flying impact mass's impact.v, the modes' mode[n].v.
    /// (At rest on a wall the impact mass moves with the tank.)
    pub fn relative_velocities(&self) -> Vec<usize> {
        let mut out = vec![1];
        match self {
            AnyModel::SloshingSlamming(m) if m.flying() => out.push(IMPACT_V),
            AnyModel::Linear(m) => out.extend((1..m.modes().len()).map(|k| BANK + 2 * k - 1)),
            _ => {}
        }
        out
    }
}
