//! The damper in Model Exchange with amplitude = Tracked: the amplitude estimator's filters and
//! velocity rebuild as continuous states (`AmplitudeTracker::continuous_state`), so that the
//! estimate, and the damping ratio the law makes of it, follow the host's solution whatever
//! steps it takes. The velocity source (rebuilt from base.a until the host sets a base.v other
//! than 0, then base.v) is a discrete state: its switch is an event, asked for at
//! fmi2CompletedIntegratorStep and made at fmi2NewDiscreteStates.

use super::Damper;
use crate::model::Inputs;
use crate::physics::amplitude::TRACKER_CONTINUOUS;

impl Damper {
    /// The estimator's continuous states (0 with a fixed amplitude).
    pub fn tracker_states(&self, out: &mut [f64; TRACKER_CONTINUOUS]) {
        *out = self
            .tracker
            .as_ref()
            .map_or([0.0; TRACKER_CONTINUOUS], |t| t.continuous_state());
    }

    /// Their derivatives under the inputs now (0 with a fixed amplitude).
    pub fn tracker_derivatives(&self, inputs: &Inputs, out: &mut [f64; TRACKER_CONTINUOUS]) {
        *out = self
            .tracker
            .as_ref()
            .map_or([0.0; TRACKER_CONTINUOUS], |t| {
                t.continuous_rates(inputs.a, inputs.v)
            });
    }

    /// Their nominal magnitudes: for base motion of the prior amplitude at the sloshing
    /// frequency, its velocity, the squares of its velocity and acceleration, and the weight 1.
    pub fn tracker_nominals(&self, out: &mut [f64; TRACKER_CONTINUOUS]) {
        let w = self.derived.omega_f;
        let v = (self.amplitude * w).max(f64::MIN_POSITIVE);
        let a = v * w;
        *out = [v, v * v, v * v, a * a, a * a, 1.0, 1.0];
    }

    /// Whether the inputs now switch the estimator's velocity source (an event).
    pub fn tracker_event_pending(&self, inputs: &Inputs) -> bool {
        self.tracker
            .as_ref()
            .is_some_and(|t| t.would_see_velocity(inputs.v))
    }

    /// Make that switch (the statistics restart): true if the states changed.
    pub fn tracker_event(&mut self, inputs: &Inputs) -> bool {
        let changed = self
            .tracker
            .as_mut()
            .is_some_and(|t| t.sees_velocity(inputs.v));
        if changed {
            self.apply_tracked_damping();
        }
        changed
    }

    /// The damping ratio of the tracked estimate now, into the model.
    pub(super) fn apply_tracked_damping(&mut self) {
        if let Some(t) = &self.tracker {
            self.zeta = self.common.zeta(t.estimate());
            self.model.set_damping(self.zeta);
        }
    }
}
