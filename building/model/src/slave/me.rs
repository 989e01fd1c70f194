//! Building.fmu in Model Exchange: the first-order system z' = A z + B p of the exact step
//! (structure.rs), its state z = [u, u', x_g, v_g, h, v_h] padded to MAX_STOREYS storeys (the
//! model description declares a fixed number of states; those of storeys above `storeys` stay
//! 0), and its derivatives. The same A and B the exact propagator exponentiates: no equation is
//! written twice.

use fmi2_slave::{Context, Continuous, EventUpdate, Refusal, Reply, Status, refuse};
use nalgebra::DVector;

use super::{Building, Simulation};
use crate::description::{Causality, TABLE, VARIABLES, VarType, index_of, vr};
use crate::structure::MAX_STOREYS;

/// Declared states: 2 MAX_STOREYS floor states and the ground's four.
pub const STATES: usize = 2 * MAX_STOREYS + 4;

/// Position in the padded vector of entry `k` of the state z of an `n`-storey building.
fn padded(k: usize, n: usize) -> usize {
    if k < n {
        k
    } else if k < 2 * n {
        MAX_STOREYS + (k - n)
    } else {
        2 * MAX_STOREYS + (k - 2 * n)
    }
}

impl Building {
    fn running(&self, function: &str) -> Result<&Simulation, Refusal> {
        self.sim
            .as_ref()
            .ok_or_else(|| refuse(format!("{function}: no simulation (not initialised)")))
    }

    /// dz/dt now, with the inputs the host set.
    fn rates(&self, s: &Simulation) -> DVector<f64> {
        let p = DVector::from_vec(self.channels(s, 0));
        &s.a * DVector::from_column_slice(&s.z) + &s.b * p
    }

    /// The position in the padded state vector of the state variable `r`, if it is one.
    fn state_position(r: u32) -> Option<usize> {
        let m = MAX_STOREYS as u32;
        let at = |first: u32, len: u32, base: usize| {
            (first..first + len)
                .contains(&r)
                .then(|| base + (r - first) as usize)
        };
        at(vr::FLOOR_1__X, m, 0)
            .or_else(|| at(vr::FLOOR_1__V, m, MAX_STOREYS))
            .or_else(|| at(vr::GROUND_X, 4, 2 * MAX_STOREYS))
    }

    /// The system is linear and homogeneous in its states and inputs (every derivative and
    /// output is a sum of terms each proportional to one of them): J d is the system evaluated
    /// at states and inputs d, with the other states and inputs 0. Exact, no differencing.
    fn linearised(&self, s: &Simulation, knowns: &[u32], dv: &[f64]) -> Result<Self, Refusal> {
        let n = s.building.n;
        let mut values = self.values.clone();
        for (k, var) in VARIABLES.iter().enumerate() {
            if var.causality == Causality::Input {
                values[k] = 0.0;
            }
        }
        let mut padded_z = [0.0; STATES];
        for (&r, &d) in knowns.iter().zip(dv) {
            if let Some(p) = Self::state_position(r) {
                padded_z[p] += d;
                continue;
            }
            match index_of(r).map(|k| (k, VARIABLES[k].causality)) {
                Some((k, Causality::Input)) => values[k] += d,
                _ => {
                    return Err(refuse(format!(
                        "fmi2GetDirectionalDerivative: value reference {r} is neither a continuous state nor an input"
                    )));
                }
            }
        }
        let mut sim = s.clone();
        for k in 0..sim.z.len() {
            sim.z[k] = padded_z[padded(k, n)];
        }
        Ok(Building {
            values,
            derivatives: self.derivatives.clone(),
            sim: Some(sim),
        })
    }

    /// The value of a state or derivative variable (Model Exchange's locals), if `r` is one.
    pub(super) fn local(&self, r: u32) -> Option<Result<f64, Refusal>> {
        let m = MAX_STOREYS;
        let within = |first: u32, len: usize| {
            (first..first + len as u32)
                .contains(&r)
                .then(|| (r - first) as usize)
        };
        let (state, p) = if let Some(k) = within(vr::FLOOR_1__V, m) {
            (true, m + k)
        } else if let Some(k) = within(vr::GROUND_X, 4) {
            (true, 2 * m + k)
        } else if let Some(k) = within(vr::DER_FLOOR_1__X_, m) {
            (false, k)
        } else if let Some(k) = within(vr::DER_FLOOR_1__V_, m) {
            (false, m + k)
        } else {
            (false, 2 * m + within(vr::DER_GROUND_X_, 4)?)
        };
        // Before initialisation (the host reads the initial unknowns in initialisation mode):
        // from the simulation the parameters set so far would start.
        let s = match self.simulation() {
            Ok(s) => s,
            Err(e) => return Some(Err(e)),
        };
        let n = s.building.n;
        let values: Vec<f64> = if state {
            s.z.to_vec()
        } else {
            self.rates(&s).iter().copied().collect()
        };
        let mut out = [0.0; STATES];
        for (k, v) in values.iter().enumerate() {
            out[padded(k, n)] = *v;
        }
        Some(Ok(out[p]))
    }
}

impl Continuous for Building {
    const STATES: usize = STATES;
    const MODEL_EXCHANGE_NOTE: Option<&'static str> = Some(
        "Model Exchange: 44 continuous states, floor[i].x and floor[i].v for 20 storeys (those \
         above 'storeys' stay 0), ground.x, ground.v and the built-in motion's ground.motion.x, \
         ground.motion.v; see docs/MODEL_EXCHANGE.md",
    );

    fn offers_model_exchange(&self) -> Result<(), String> {
        self.running("fmi2ExitInitializationMode")
            .map(|_| ())
            .map_err(|r| *r.message)
    }

    fn states(&self, x: &mut [f64]) -> Reply {
        let s = self.running("fmi2GetContinuousStates")?;
        x.fill(0.0);
        for (k, z) in s.z.iter().enumerate() {
            x[padded(k, s.building.n)] = *z;
        }
        Ok(Status::Ok)
    }

    fn set_states(&mut self, _: &Context, x: &[f64]) -> Reply {
        let s = self
            .sim
            .as_mut()
            .ok_or_else(|| refuse("fmi2SetContinuousStates: no simulation (not initialised)"))?;
        let n = s.building.n;
        for k in 0..s.z.len() {
            s.z[k] = x[padded(k, n)];
        }
        Ok(Status::Ok)
    }

    fn derivatives(&self, context: &Context, dx: &mut [f64]) -> Reply {
        let s = self.running("fmi2GetDerivatives")?;
        let rates = self.rates(s);
        if let Some(k) = rates.iter().position(|v| !v.is_finite()) {
            return Err(refuse(format!(
                "fmi2GetDerivatives at t = {}: derivative {k} is not finite (inputs too large?)",
                context.time
            )));
        }
        dx.fill(0.0);
        for (k, r) in rates.iter().enumerate() {
            dx[padded(k, s.building.n)] = *r;
        }
        Ok(Status::Ok)
    }

    fn directional_derivative(
        &self,
        _: &Context,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Reply {
        const F: &str = "fmi2GetDirectionalDerivative";
        let s = self.running(F)?;
        let linear = self.linearised(s, knowns, dv_known)?;
        let mut out = Vec::with_capacity(unknowns.len());
        for &r in unknowns {
            let (_, var) = TABLE.variable(r, F)?;
            let derivative = var.name.starts_with("der(");
            if !(derivative || var.causality == Causality::Output) {
                return Err(refuse(format!(
                    "{F}: {} is neither a state derivative nor an output",
                    var.name
                )));
            }
            out.push(linear.value_of(r, VarType::Real, F)?);
        }
        dv_unknown.copy_from_slice(&out);
        Ok(Status::Ok)
    }

    /// An impulse on the damper's floor (tld.impulse changed, in event mode): the state jumps
    /// by B's force column times the change, the velocity jump an impulse makes (its momentum
    /// goes to the floor whole).
    fn event_update(&mut self, _: &Context) -> Result<EventUpdate, Refusal> {
        let input = self.values[index_of(vr::TLD_IMPULSE)
            .unwrap_or_else(|| unreachable!("the model description declares tld.impulse"))];
        let s = self
            .sim
            .as_mut()
            .ok_or_else(|| refuse("fmi2NewDiscreteStates: no simulation (not initialised)"))?;
        let change = input - s.impulse_taken;
        if change != 0.0 {
            let jump = s.impulse_response();
            for (z, j) in s.z.iter_mut().zip(jump) {
                *z += j * change;
            }
            s.impulse_taken = input;
        }
        Ok(EventUpdate {
            states_changed: change != 0.0,
            next_event: None,
        })
    }

    /// Floors: the static drift of the first storey under 1 g of its own mass, and its velocity
    /// at the first mode's frequency; the ground's: 1 m, 1 m/s.
    fn nominals(&self, out: &mut [f64]) -> Reply {
        let s = self.running("fmi2GetNominalsOfContinuousStates")?;
        let b = &s.building;
        let x = (b.mass.sum() * 9.81 / b.storeys[0]).clamp(1e-6, 1.0);
        let v = (x * b.omega[0]).clamp(1e-6, 1.0);
        out[..MAX_STOREYS].fill(x);
        out[MAX_STOREYS..2 * MAX_STOREYS].fill(v);
        out[2 * MAX_STOREYS..].fill(1.0);
        Ok(Status::Ok)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn padding_keeps_each_block_in_its_place() {
        let n = 3;
        let got: Vec<usize> = (0..2 * n + 4).map(|k| padded(k, n)).collect();
        let m = MAX_STOREYS;
        assert_eq!(
            got,
            [
                0,
                1,
                2,
                m,
                m + 1,
                m + 2,
                2 * m,
                2 * m + 1,
                2 * m + 2,
                2 * m + 3
            ]
        );
    }
}
