//! TLD.fmu in Model Exchange: the damper's continuous states, derivatives, nominals and
//! directional derivatives through the shared layer's [`Continuous`] contract. The layer has
//! checked the phase (the simulation exists), the array lengths (the model description's four
//! states) and that the states are finite. Value references become the model's states, inputs,
//! derivatives and outputs here; the model computes J d.

use fmi2_slave::{Context, Continuous, EventUpdate, Refusal, Reply, Status, refuse};

use super::me_cells::{Cell, cell_of, tracker_of};

use super::params::output_of;
use super::slave::Tld;
use super::vars::{VARIABLES, VarType, index_of, vr};
use crate::model::continuous::{ALL_STATES, BANK, Direction, STATES};
use crate::model::events::EVENT_INDICATORS;
use crate::model::shallow_water::continuous::{CELL_STATES, StatesRefused};
use crate::model::slamming::Event;
use crate::model::{Damper, Unknown};
use crate::physics::amplitude::TRACKER_CONTINUOUS;

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
                // A cell: no equation of a model without cells reads it (and a model with cells
                // has no directional derivatives).
                None if matches!(cell_of(r), Some(Cell::State(_))) => continue,
                None => match tracker_of(r) {
                    // The estimator's (read by no equation with a fixed amplitude).
                    Some((k, false)) => &mut d.tracker[k],
                    _ => {
                        return Err(refuse(format!(
                            "fmi2GetDirectionalDerivative: value reference {r} is neither a \
                             continuous state (slosh.x, slosh.v, energy.input, \
                             energy.dissipated, impact.z, impact.v, mode[n].x, mode[n].v, \
                             A_e.tracker.*) nor an input (base.a, base.v, base.x)"
                        )));
                    }
                },
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
    if let Some((k, true)) = tracker_of(r) {
        return Ok(Unknown::Tracker(k));
    }
    if let Some(Cell::Derivative(_)) = cell_of(r) {
        return Ok(Unknown::Frozen);
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
    /// The simulation, for a Model Exchange function: refused before initialisation, and for
    /// parameters Model Exchange does not offer (a Co-Simulation instance of ShallowWater, which
    /// the call table lets ask for derivatives once terminated).
    fn running(&self, function: &str) -> Result<&Damper, Refusal> {
        let sim = self
            .sim
            .as_ref()
            .ok_or_else(|| refuse(format!("{function}: no simulation (not initialised)")))?;
        sim.offers_model_exchange()
            .map_err(|why| refuse(format!("{function}: {why}")))?;
        Ok(sim)
    }
}

impl Tld {
    /// The value of a state derivative variable (der(slosh.x), ...), of a state that is no
    /// output (impact.v), or of the amplitude estimator's or a cell's state or derivative, if
    /// `r` names one.
    pub(super) fn derivative_value(
        &self,
        context: &Context,
        r: u32,
    ) -> Option<Result<f64, Refusal>> {
        // Ok(k): the derivative of state k; Err(k): state k.
        let which = match DERIVATIVES.iter().position(|&d| d == r) {
            Some(k) => Ok(k),
            None => match STATE_VARIABLES.iter().position(|&s| s == r) {
                Some(k) => Err(k),
                None => {
                    if let Some((k, derivative)) = tracker_of(r) {
                        return Some(self.tracker_value(context, k, derivative));
                    }
                    return self.cell_value(context, cell_of(r)?);
                }
            },
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

impl Tld {
    /// The estimator's state or derivative `k` (0 with a fixed amplitude).
    fn tracker_value(&self, context: &Context, k: usize, derivative: bool) -> Result<f64, Refusal> {
        let mut provisional = None;
        let inputs = self.values.inputs([0.0; 2]);
        let mut out = [0.0; TRACKER_CONTINUOUS];
        let sim = self.simulation(context, &mut provisional)?;
        if derivative {
            sim.tracker_derivatives(&inputs, &mut out);
        } else {
            sim.tracker_states(&mut out);
        }
        Ok(out[k])
    }

    /// A cell's state or derivative (0 for a model without cells).
    fn cell_value(&self, context: &Context, cell: Cell) -> Option<Result<f64, Refusal>> {
        let mut provisional = None;
        let inputs = self.values.inputs([0.0; 2]);
        let mut bank = [0.0; CELL_STATES];
        Some(
            self.simulation(context, &mut provisional)
                .map(|sim| match cell {
                    Cell::State(k) => {
                        sim.cell_states(&mut bank);
                        bank[k]
                    }
                    Cell::Derivative(k) => {
                        sim.cell_derivatives(&inputs, &mut bank);
                        bank[k]
                    }
                }),
        )
    }
}

impl Continuous for Tld {
    const STATES: usize = ALL_STATES;
    const EVENT_INDICATORS: usize = EVENT_INDICATORS;
    const MODEL_EXCHANGE_NOTE: Option<&'static str> = Some(
        "Model Exchange offers model = Linear (modes <= 10), Nonlinear, Auto, \
         and SloshingSlamming (impacts as state events) with amplitude = Fixed or Tracked; the \
         states are slosh.x, slosh.v, energy.input, energy.dissipated, impact.z, impact.v, \
         mode[n].x, mode[n].v (n = 2..10, Linear's higher modes), then the amplitude \
         estimator's A_e.tracker.* (each frozen at 0 where the configuration has none). \
         Linear with more modes and ShallowWater (2 x swe.cells states) are Co-Simulation only \
         (fmi2ExitInitializationMode says why); see \
         docs/MODEL_EXCHANGE.md",
    );

    fn offers_model_exchange(&self) -> Result<(), String> {
        self.sim
            .as_ref()
            .map_or(Err("no simulation".into()), Damper::offers_model_exchange)
    }

    fn states(&self, x: &mut [f64]) -> Reply {
        let sim = self.running("fmi2GetContinuousStates")?;
        let (core, tracker, cells) = split(x);
        core.copy_from_slice(&sim.continuous_states());
        sim.tracker_states(tracker);
        sim.cell_states(cells);
        Ok(Status::Ok)
    }

    fn set_states(&mut self, _: &Context, x: &[f64]) -> Reply {
        let mut all = [0.0; ALL_STATES];
        all.copy_from_slice(x);
        let (s, tracker, bank) = split(&mut all);
        let s = <&[f64; STATES]>::try_from(&*s)
            .unwrap_or_else(|_| unreachable!("STATES long by construction"));
        let sim = self
            .sim
            .as_mut()
            .ok_or_else(|| refuse("fmi2SetContinuousStates: no simulation (not initialised)"))?;
        sim.offers_model_exchange()
            .map_err(|why| refuse(format!("fmi2SetContinuousStates: {why}")))?;
        sim.set_all_continuous_states(s, tracker, bank)
            .map_err(|why| {
                let (status, why) = match why {
                    // The host may retry with a shorter step.
                    StatesRefused::Step(why) => (Status::Discard, why),
                    StatesRefused::Invalid(why) => (Status::Error, why),
                };
                Refusal::new(
                    status,
                    format!("fmi2SetContinuousStates: {why}; the states are left as they were"),
                )
            })?;
        Ok(Status::Ok)
    }

    fn derivatives(&self, context: &Context, dx: &mut [f64]) -> Reply {
        let inputs = self.values.inputs([0.0; 2]);
        let sim = self.running("fmi2GetDerivatives")?;
        let mut d = [0.0; ALL_STATES];
        let (core, tracker, cells) = split(&mut d);
        core.copy_from_slice(&sim.continuous_derivatives(&inputs));
        sim.tracker_derivatives(&inputs, tracker);
        sim.cell_derivatives(&inputs, cells);
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
        // The host's impulse on the structure moved the tank (base.v.jump): first, then the
        // impacts at the velocities it leaves.
        let jump = self.values.get(vr::BASE_V_JUMP) - self.v_jump_taken;
        let jumped = sim
            .base_velocity_jump(jump)
            .map_err(|why| refuse(format!("fmi2NewDiscreteStates: base.v.jump: {why}")))?;
        self.v_jump_taken += jump;
        let event = sim.event(&inputs);
        // amplitude = Tracked: a base.v other than 0 switches the estimator (below).
        let switched = sim.tracker_event(&inputs);
        Ok(EventUpdate {
            states_changed: matches!(event, Event::Impact { .. }) || switched || jumped,
            next_event: None,
        })
    }

    fn nominals(&self, out: &mut [f64]) -> Reply {
        let sim = self.running("fmi2GetNominalsOfContinuousStates")?;
        let (core, tracker, cells) = split(out);
        core.copy_from_slice(&sim.continuous_nominals());
        sim.tracker_nominals(tracker);
        sim.cell_nominals(cells);
        // Nominals are scales, never numbers a host cannot use: one that overflows (the
        // estimator's squares of an extreme A_e or tank, say) is 1 (the FMI default).
        for n in out.iter_mut() {
            if !(n.is_finite() && *n > 0.0) {
                *n = 1.0;
            }
        }
        Ok(Status::Ok)
    }

    /// amplitude = Tracked: a base.v other than 0 switches the estimator to it (an event).
    fn completed_step(&mut self, _: &Context) -> Result<bool, Refusal> {
        let inputs = self.values.inputs([0.0; 2]);
        Ok(self
            .running("fmi2CompletedIntegratorStep")?
            .tracker_event_pending(&inputs))
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

/// The host's array of all states (the layer checked its length) as the four, the
/// estimator's and the bank.
#[allow(clippy::type_complexity)]
fn split(
    x: &mut [f64],
) -> (
    &mut [f64],
    &mut [f64; TRACKER_CONTINUOUS],
    &mut [f64; CELL_STATES],
) {
    let (core, rest) = x.split_at_mut(STATES);
    let (tracker, cells) = rest.split_at_mut(TRACKER_CONTINUOUS);
    (
        core,
        <&mut [f64; TRACKER_CONTINUOUS]>::try_from(tracker)
            .unwrap_or_else(|_| unreachable!("TRACKER_CONTINUOUS long by construction")),
        <&mut [f64; CELL_STATES]>::try_from(cells)
            .unwrap_or_else(|_| unreachable!("the layer checks the length")),
    )
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
