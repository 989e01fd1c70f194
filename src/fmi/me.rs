//! TLD.fmu in Model Exchange: the damper's continuous states, derivatives and nominals through
//! the shared layer's [`Continuous`] contract. The layer has checked the phase (the simulation
//! exists), the array lengths (the model description's four states) and that the states are
//! finite.

use fmi2_slave::{Context, Continuous, Refusal, Reply, Status, refuse};

use super::slave::Tld;
use super::vars::vr;
use crate::model::Damper;
use crate::model::continuous::STATES;

impl Tld {
    fn running(&self, function: &str) -> Result<&Damper, Refusal> {
        self.sim
            .as_ref()
            .ok_or_else(|| refuse(format!("{function}: no simulation (not initialised)")))
    }
}

impl Tld {
    /// The value of a state derivative variable (der(slosh.x), ...), if `r` names one.
    pub(super) fn derivative_value(
        &self,
        context: &Context,
        r: u32,
    ) -> Option<Result<f64, Refusal>> {
        let k = [
            vr::DER_SLOSH_X_,
            vr::DER_SLOSH_V_,
            vr::DER_ENERGY_INPUT_,
            vr::DER_ENERGY_DISSIPATED_,
        ]
        .iter()
        .position(|&d| d == r)?;
        // Before initialisation (hosts read the initial unknowns in initialisation mode): from
        // the simulation the parameters set so far would start.
        let mut provisional = None;
        let inputs = self.values.inputs([0.0; 2]);
        Some(
            self.simulation(context, &mut provisional)
                .map(|sim| sim.continuous_derivatives(&inputs)[k]),
        )
    }
}

impl Continuous for Tld {
    const STATES: usize = STATES;
    const MODEL_EXCHANGE_NOTE: Option<&'static str> = Some(
        "Model Exchange offers model = Linear (modes = 1), Nonlinear and Auto with amplitude = \
         Fixed; the states are slosh.x, slosh.v, energy.input, energy.dissipated. \
         SloshingSlamming, ShallowWater and amplitude = Tracked are Co-Simulation only \
         (fmi2ExitInitializationMode says why); see docs/MODEL_EXCHANGE.md",
    );

    fn offers_model_exchange(&self) -> Result<(), String> {
        self.sim
            .as_ref()
            .map_or(Err("no simulation".into()), Damper::offers_model_exchange)
    }

    fn states(&self, x: &mut [f64]) -> Reply {
        x.copy_from_slice(&self.running("fmi2GetContinuousStates")?.continuous_states());
        Ok(Status::Ok)
    }

    fn set_states(&mut self, _: &Context, x: &[f64]) -> Reply {
        let mut s = [0.0; STATES];
        s.copy_from_slice(x);
        let sim = self
            .sim
            .as_mut()
            .ok_or_else(|| refuse("fmi2SetContinuousStates: no simulation (not initialised)"))?;
        sim.set_continuous_states(&s).map_err(|why| {
            refuse(format!(
                "fmi2SetContinuousStates: {why}; the states are left as they were"
            ))
        })?;
        Ok(Status::Ok)
    }

    fn derivatives(&self, context: &Context, dx: &mut [f64]) -> Reply {
        let inputs = self.values.inputs([0.0; 2]);
        let d = self
            .running("fmi2GetDerivatives")?
            .continuous_derivatives(&inputs);
        if let Some(k) = d.iter().position(|v| !v.is_finite()) {
            return Err(refuse(format!(
                "fmi2GetDerivatives at t = {}: derivative {k} is not finite (base.a = {})",
                context.time, inputs.a
            )));
        }
        dx.copy_from_slice(&d);
        Ok(Status::Ok)
    }

    fn nominals(&self, out: &mut [f64]) -> Reply {
        out.copy_from_slice(
            &self
                .running("fmi2GetNominalsOfContinuousStates")?
                .continuous_nominals(),
        );
        Ok(Status::Ok)
    }
}
