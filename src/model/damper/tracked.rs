//! The damper in Model Exchange with amplitude = Tracked: the amplitude estimator's filters and
//! velocity rebuild as continuous states (`AmplitudeTracker::continuous_state`), so that the
//! estimate, and the damping ratio the law makes of it, follow the host's solution whatever
//! steps it takes. The velocity source (rebuilt from base.a until the host sets a base.v other
//! than 0, then base.v) is a discrete state: its switch is an event, asked for at
//! fmi2CompletedIntegratorStep and made at fmi2NewDiscreteStates.

use super::Damper;
use crate::model::Inputs;
use crate::model::continuous::Direction;
use crate::physics::amplitude::TRACKER_CONTINUOUS;

/// The estimator's part of J d (all 0 with a fixed amplitude).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrackerTangent {
    /// Of the estimator's state derivatives.
    pub rates: [f64; TRACKER_CONTINUOUS],
    /// Of the estimate (A_e.estimate) and of the damping ratio the law makes of it.
    pub estimate: f64,
    pub zeta: f64,
}

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

    /// Their nominal magnitudes: the rebuilt velocity's is slosh.v's (both integrate base.a,
    /// so a host's error control sees the same input changes in both: with the prior's
    /// velocity, 25 times smaller by default, fmpy's CVode needed more steps than its mxstep
    /// at rtol 1e-10 under an input it sets at every internal step); for base motion of the
    /// prior amplitude at the sloshing frequency, the squares of its velocity and
    /// acceleration (the prior's share of the mean squares, PRIOR_WEIGHT of them, stays far
    /// above the solver's absolute tolerance); the weight 1.
    pub fn tracker_nominals(&self, out: &mut [f64; TRACKER_CONTINUOUS]) {
        let w = self.derived.omega_f;
        let v = (self.amplitude * w).max(f64::MIN_POSITIVE);
        let a = v * w;
        let rebuilt = self.continuous_nominals()[1];
        *out = [rebuilt, v * v, v * v, a * a, a * a, 1.0, 1.0];
    }

    /// J d of the estimator under the inputs now for the direction `d` (its states', base.a's
    /// and base.v's changes): of its rates, of the estimate (by its gradient) and of the
    /// damping ratio (the law's slope at the estimate times that).
    pub fn tracker_tangent(&self, inputs: &Inputs, d: &Direction) -> TrackerTangent {
        let Some(t) = &self.tracker else {
            return TrackerTangent::default();
        };
        let (estimate, gradient) = t.continuous_estimate();
        let d_estimate: f64 = gradient.iter().zip(&d.tracker).map(|(g, s)| g * s).sum();
        TrackerTangent {
            rates: t.rates_tangent(inputs.a, inputs.v, &d.tracker, d.a, d.v),
            estimate: d_estimate,
            zeta: self.common.zeta_slope(estimate) * d_estimate,
        }
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
