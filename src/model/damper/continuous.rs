//! The damper in Model Exchange: the model's continuous states (see `model::continuous`) with
//! what the damper adds around them, the energy at the start (counted as input) and the damping
//! law. With amplitude = Tracked the damping ratio is the law's at the estimate of the
//! estimator's states (`tracked`), and J d carries their change through the estimate and the
//! law into the damping.

use super::{Damper, per_step};
use crate::model::continuous::{BANK, Direction, IMPACT_V, IMPACT_Z, STATES, Tangent};
use crate::model::{Inputs, Output};
use crate::physics::amplitude::TRACKER_CONTINUOUS;

/// What a directional derivative asks for: a state's derivative (in state order) or an output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unknown {
    Derivative(usize),
    /// The derivative of the amplitude estimator's state k (amplitude = Tracked; else 0).
    Tracker(usize),
    Output(Output),
    /// The derivative of a state this model does not have (identically 0).
    Frozen,
}

impl Damper {
    /// Ok if a host's solver can integrate this damper; Err: why not.
    pub fn offers_model_exchange(&self) -> Result<(), String> {
        self.model.offers_model_exchange()
    }

    /// The continuous states [slosh.x, slosh.v, energy.input, energy.dissipated, impact.z,
    /// impact.v].
    pub fn continuous_states(&self) -> [f64; STATES] {
        self.model.continuous_states(self.initial_energy)
    }

    /// Take the continuous states (finite); all or nothing.
    pub fn set_continuous_states(&mut self, s: &[f64; STATES]) -> Result<(), String> {
        let limit = 100.0 * self.common.tank.length;
        for (k, name) in [(0, "slosh.x"), (IMPACT_Z, "impact.z")] {
            if s[k].abs() > limit {
                return Err(format!(
                    "{name} = {:e} m ran away beyond {limit} m (100 tank lengths): the host's \
                     step is too large, or the input is not in m/s^2",
                    s[k]
                ));
            }
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
    /// the sloshing frequency, and the energy of that motion (the impact mass's as the
    /// sloshing mass's).
    pub fn continuous_nominals(&self) -> [f64; STATES] {
        let x = 0.5 * self.common.tank.length;
        let v = self.derived.omega_f * x;
        let energy = (0.5 * self.derived.mass_slosh * v * v).max(f64::MIN_POSITIVE);
        let mut n = [x; STATES];
        n[1] = v;
        n[2] = energy;
        n[3] = energy;
        n[IMPACT_Z] = x;
        n[IMPACT_V] = v;
        // The bank of higher modes: (x, v) pairs.
        for pair in n[BANK..].chunks_exact_mut(2) {
            pair[1] = v;
        }
        n
    }

    /// J d: the exact change of each of `unknowns` for the change `d` of the states and inputs
    /// (with amplitude = Tracked the estimator's too, which move the estimate and through the
    /// damping law the damping ratio; `d.zeta` is ignored, the damper sets it), into `out`.
    /// Err, and `out` untouched, for a damper not offered in Model Exchange or an unknown out of
    /// range.
    pub fn directional_derivatives(
        &self,
        inputs: &Inputs,
        d: &Direction,
        unknowns: &[Unknown],
        out: &mut [f64],
    ) -> Result<(), String> {
        self.offers_model_exchange()?;
        let tracked = self.tracker_tangent(inputs, d);
        let d = &Direction {
            zeta: tracked.zeta,
            ..*d
        };
        let t = self.model.continuous_tangent(inputs.a, d)?;
        let mut values = Vec::with_capacity(unknowns.len());
        for &unknown in unknowns {
            values.push(match unknown {
                Unknown::Derivative(k) => *t.derivatives.get(k).ok_or_else(|| {
                    format!("there are {STATES} state derivatives, not {}", k + 1)
                })?,
                Unknown::Tracker(k) => *tracked.rates.get(k).ok_or_else(|| {
                    format!(
                        "the estimator has {TRACKER_CONTINUOUS} states, not {}",
                        k + 1
                    )
                })?,
                Unknown::Output(Output::Amplitude) => tracked.estimate,
                Unknown::Output(Output::Zeta) => tracked.zeta,
                Unknown::Output(which) => self.output_tangent(which, d, &t)?,
                Unknown::Frozen => 0.0,
            });
        }
        out.copy_from_slice(&values);
        Ok(())
    }

    /// J d of the output `which` (as [`Damper::output`] forms it), given the model's tangent
    /// (of the force, the stored energy, impact.z).
    fn output_tangent(&self, which: Output, d: &Direction, t: &Tangent) -> Result<f64, String> {
        let (force, stored, impact_z) = (t.force, t.stored, t.impact_z);
        Ok(match which {
            Output::X => d.states[0],
            Output::V => d.states[1],
            Output::Force => force,
            // Until a step has been taken (none is in Model Exchange) the mean force is the force.
            Output::ForceMean => {
                if self.last_mean_force.is_some() {
                    0.0
                } else {
                    force
                }
            }
            Output::BaseShear => {
                force - (self.derived.mass_inactive + self.model.rigid_mass()) * d.a
            }
            Output::EnergyInput => d.states[2],
            Output::EnergyDissipated => d.states[3],
            Output::EnergyStored => stored,
            Output::ImpactZ => impact_z,
            // The amplitude and damping: the estimator's (above); the count of impacts and their
            // impulse change at events only.
            Output::Amplitude | Output::Zeta | Output::Impacts | Output::ImpactImpulse => 0.0,
            Output::SurfaceLeft | Output::SurfaceRight => {
                if self.model.surface().is_some() {
                    return Err(format!("{which:?} of a model that resolves the surface"));
                }
                self.mode_surface(usize::from(which == Output::SurfaceRight)) * d.states[0]
            }
        })
    }
}
