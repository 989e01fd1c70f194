//! The damper in Model Exchange: the model's continuous states (see `model::continuous`) with
//! what the damper adds around them, the energy at the start (counted as input) and the damping
//! law. The damping ratio is constant in Model Exchange: amplitude = Fixed. The online amplitude
//! estimate (amplitude = Tracked) is a sampled filter of the host's communication steps, and a
//! host's solver has none; it is refused with that reason.

use super::{Damper, per_step};
use crate::model::continuous::STATES;
use crate::model::{AmplitudeSource, Inputs};

impl Damper {
    /// Ok if a host's solver can integrate this damper; Err: why not.
    pub fn offers_model_exchange(&self) -> Result<(), String> {
        self.model.offers_model_exchange()?;
        if let AmplitudeSource::Tracked { .. } = self.common.amplitude {
            return Err(
                "amplitude = Tracked estimates A_e by a filter sampled at the communication \
                 steps, which Model Exchange does not have: set amplitude = Fixed (the damping \
                 law then uses A_e), or use Co-Simulation"
                    .into(),
            );
        }
        Ok(())
    }

    /// The continuous states [slosh.x, slosh.v, energy.input, energy.dissipated].
    pub fn continuous_states(&self) -> [f64; STATES] {
        self.model.continuous_states(self.initial_energy)
    }

    /// Take the continuous states (finite); all or nothing.
    pub fn set_continuous_states(&mut self, s: &[f64; STATES]) -> Result<(), String> {
        let limit = 100.0 * self.common.tank.length;
        if s[0].abs() > limit {
            return Err(format!(
                "slosh.x = {:e} m ran away beyond {limit} m (100 tank lengths): the host's step \
                 is too large, or the input is not in m/s^2",
                s[0]
            ));
        }
        let mut model = self.model.clone();
        model.set_continuous_states(s, self.initial_energy)?;
        self.model = model;
        self.per_step = per_step(&self.model);
        Ok(())
    }

    /// The states' time derivatives under the inputs now.
    pub fn continuous_derivatives(&self, inputs: &Inputs) -> [f64; STATES] {
        self.model.continuous_derivatives(inputs.a)
    }

    /// Nominal magnitudes of the states: half a tank length, the velocity of that amplitude at
    /// the sloshing frequency, and the energy of that motion.
    pub fn continuous_nominals(&self) -> [f64; STATES] {
        let x = 0.5 * self.common.tank.length;
        let v = self.derived.omega_f * x;
        let energy = (0.5 * self.derived.mass_slosh * v * v).max(f64::MIN_POSITIVE);
        [x, v, energy, energy]
    }
}
