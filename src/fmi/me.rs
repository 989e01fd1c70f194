//! TLD.fmu in Model Exchange: the damper's continuous states, derivatives, nominals and
//! directional derivatives through the shared layer's [`Continuous`] contract. The layer has
//! checked the phase (the simulation exists), the array lengths (the model description's four
//! states) and that the states are finite. Value references become the model's states, inputs,
//! derivatives and outputs here; the model computes J d.

use fmi2_slave::{Context, Continuous, EventUpdate, Refusal, Reply, Status, refuse};

use super::params::output_of;
use super::slave::Tld;
use super::vars::{VARIABLES, VarType, index_of, vr};
use crate::model::continuous::{BANK, Direction, STATES};
use crate::model::events::EVENT_INDICATORS;
use crate::model::slamming::Event;
use crate::model::{Damper, Unknown};

/// The state derivative variables, in state order.
const DERIVATIVES: [u32; STATES] = with_bank(
    [
        vr::DER_SLOSH_X_,
        vr::DER_SLOSH_V_,
        vr::DER_ENERGY_INPUT_,
        vr::DER_ENERGY_DISSIPATED_,
        vr::DER_IMPACT_Z_,
        vr::DER_IMPACT_V_,
    ],
    2,
);

/// The continuous state variables, in state order.
const STATE_VARIABLES: [u32; STATES] = with_bank(
    [
        vr::SLOSH_X,
        vr::SLOSH_V,
        vr::ENERGY_INPUT,
        vr::ENERGY_DISSIPATED,
        vr::IMPACT_Z,
        vr::IMPACT_V,
    ],
    0,
);

/// `first`, then the Linear model's bank mode[n].x, mode[n].v (n = 2, 3, ...), whose value
/// references run four a mode from mode[2].x's (x, v, der(x), der(v)): `offset` 2 gives the
/// derivatives. The tests check every name.
const fn with_bank(first: [u32; BANK], offset: u32) -> [u32; STATES] {
    let mut out = [0; STATES];
    let mut k = 0;
    while k < STATES {
        out[k] = if k < BANK {
            first[k]
        } else {
            let (mode, which) = ((k - BANK) / 2, (k - BANK) % 2);
            vr::MODE_2__X + 4 * mode as u32 + which as u32 + offset
        };
        k += 1;
    }
    out
}

/// The direction the host gives as changes `dv` of the states and inputs `knowns`.
fn direction(knowns: &[u32], dv: &[f64]) -> Result<Direction, Refusal> {
    let mut d = Direction::default();
    for (&r, &change) in knowns.iter().zip(dv) {
        let slot = match r {
            vr::BASE_A => &mut d.a,
            vr::BASE_V => &mut d.v,
            vr::BASE_X => &mut d.x,
            _ => match STATE_VARIABLES.iter().position(|&s| s == r) {
                Some(k) => &mut d.states[k],
                None => {
                    return Err(refuse(format!(
                        "fmi2GetDirectionalDerivative: value reference {r} is neither a \
                         continuous state (slosh.x, slosh.v, energy.input, energy.dissipated, \
                         impact.z, impact.v, mode[n].x, mode[n].v) nor an input (base.a, base.v, \
                         base.x)"
                    )));
                }
            },
        };
        *slot += change;
    }
    Ok(d)
}

/// What the unknown `r` is: a state's derivative or a Real output.
fn unknown(r: u32) -> Result<Unknown, Refusal> {
    if let Some(k) = DERIVATIVES.iter().position(|&d| d == r) {
        return Ok(Unknown::Derivative(k));
    }
    let real = index_of(r).is_some_and(|k| VARIABLES[k].ty == VarType::Real);
    match output_of(r) {
        Some(which) if real => Ok(Unknown::Output(which)),
        _ => Err(refuse(format!(
            "fmi2GetDirectionalDerivative: value reference {r} is neither a state derivative \
             nor a Real output"
        ))),
    }
}

/// `values` into the host's `out` if all are finite; else refused, saying which `what` is not.
fn copy_finite(
    function: &str,
    what: &str,
    context: &Context,
    a: f64,
    values: &[f64],
    out: &mut [f64],
) -> Reply {
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Err(refuse(format!(
            "{function} at t = {}: {what} {k} is not finite (base.a = {a})",
            context.time
        )));
    }
    out.copy_from_slice(values);
    Ok(Status::Ok)
}

impl Tld {
    fn running(&self, function: &str) -> Result<&Damper, Refusal> {
        self.sim
            .as_ref()
            .ok_or_else(|| refuse(format!("{function}: no simulation (not initialised)")))
    }
}

impl Tld {
    /// The value of a state derivative variable (der(slosh.x), ...) or of a state that is no
    /// output (impact.v), if `r` names one.
    pub(super) fn derivative_value(
        &self,
        context: &Context,
        r: u32,
    ) -> Option<Result<f64, Refusal>> {
        // Ok(k): the derivative of state k; Err(k): state k.
        let which = match DERIVATIVES.iter().position(|&d| d == r) {
            Some(k) => Ok(k),
            None => Err(STATE_VARIABLES.iter().position(|&s| s == r)?),
        };
        // Before initialisation (hosts read the initial unknowns in initialisation mode): from
        // the simulation the parameters set so far would start.
        let mut provisional = None;
        let inputs = self.values.inputs([0.0; 2]);
        Some(
            self.simulation(context, &mut provisional)
                .map(|sim| match which {
                    Ok(k) => sim.continuous_derivatives(&inputs)[k],
                    Err(k) => sim.continuous_states()[k],
                }),
        )
    }
}

impl Continuous for Tld {
    const STATES: usize = STATES;
    const EVENT_INDICATORS: usize = EVENT_INDICATORS;
    const MODEL_EXCHANGE_NOTE: Option<&'static str> = Some(
        "Model Exchange offers model = Linear (modes <= 10), Nonlinear, Auto and \
         SloshingSlamming (impacts as state events) with amplitude = Fixed; the states are \
         slosh.x, slosh.v, energy.input, energy.dissipated, impact.z, impact.v and mode[n].x, \
         mode[n].v (n = 2..10, Linear's higher modes). ShallowWater, Linear with more modes and \
         amplitude = Tracked are Co-Simulation only (fmi2ExitInitializationMode says why); see \
         docs/MODEL_EXCHANGE.md",
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
        copy_finite(
            "fmi2GetDerivatives",
            "derivative",
            context,
            inputs.a,
            &d,
            dx,
        )
    }

    fn event_indicators(&self, context: &Context, out: &mut [f64]) -> Reply {
        let inputs = self.values.inputs([0.0; 2]);
        let z = self
            .running("fmi2GetEventIndicators")?
            .event_indicators(&inputs);
        copy_finite(
            "fmi2GetEventIndicators",
            "event indicator",
            context,
            inputs.a,
            &z,
            out,
        )
    }

    fn event_update(&mut self, _: &Context) -> Result<EventUpdate, Refusal> {
        let inputs = self.values.inputs([0.0; 2]);
        let sim = self
            .sim
            .as_mut()
            .ok_or_else(|| refuse("fmi2NewDiscreteStates: no simulation (not initialised)"))?;
        let event = sim.event(&inputs);
        Ok(EventUpdate {
            states_changed: matches!(event, Event::Impact { .. }),
            next_event: None,
        })
    }

    fn nominals(&self, out: &mut [f64]) -> Reply {
        out.copy_from_slice(
            &self
                .running("fmi2GetNominalsOfContinuousStates")?
                .continuous_nominals(),
        );
        Ok(Status::Ok)
    }

    fn directional_derivative(
        &self,
        context: &Context,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Reply {
        const F: &str = "fmi2GetDirectionalDerivative";
        let sim = self.running(F)?;
        let d = direction(knowns, dv_known)?;
        let unknowns = unknowns
            .iter()
            .map(|&r| unknown(r))
            .collect::<Result<Vec<_>, _>>()?;
        let inputs = self.values.inputs([0.0; 2]);
        let mut out = vec![0.0; unknowns.len()];
        sim.directional_derivatives(&inputs, &d, &unknowns, &mut out)
            .map_err(|why| refuse(format!("{F}: {why}")))?;
        copy_finite(F, "entry", context, inputs.a, &out, dv_unknown)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn name(r: u32) -> &'static str {
        index_of(r).map_or("?", |k| VARIABLES[k].name)
    }

    /// The bank's value references name mode[n].x, mode[n].v and their derivatives.
    #[test]
    fn the_bank_names_its_modes() {
        for k in BANK..STATES {
            let n = 2 + (k - BANK) / 2;
            let which = if (k - BANK).is_multiple_of(2) {
                "x"
            } else {
                "v"
            };
            let state = format!("mode[{n}].{which}");
            assert_eq!(name(STATE_VARIABLES[k]), state);
            assert_eq!(name(DERIVATIVES[k]), format!("der({state})"));
        }
        for k in 0..BANK {
            assert_eq!(
                name(DERIVATIVES[k]),
                format!("der({})", name(STATE_VARIABLES[k]))
            );
        }
    }
}
