//! The damper in Model Exchange: the model's continuous states (see `model::continuous`) with
//! what the damper adds around them, the energy at the start (counted as input) and the damping
//! law. A fixed amplitude keeps the damping ratio constant. A tracked one (amplitude = Tracked)
//! is the Co-Simulation filter sampled at time events instead of communication steps:
//! [`SAMPLES_PER_PERIOD`] samples of base.a and base.v per natural sloshing period, each
//! setting the damping ratio until the next (constant between events, so the states'
//! equations and their Jacobian are those of a fixed amplitude).

use super::{Damper, per_step};
use crate::model::continuous::{BANK, Direction, IMPACT_V, IMPACT_Z, STATES, Tangent};
use crate::model::{Inputs, Output};

/// Model Exchange samples a tracked amplitude this many times per natural sloshing period
/// (the period of omega_f): about the Co-Simulation's default 10 ms step for the lab tank
/// (T = 1.11 s), and as many samples per period for any tank.
pub const SAMPLES_PER_PERIOD: f64 = 100.0;

/// A host's event time is the time it was told within rounding: a sample is due from this
/// fraction of a sample period before its time.
const DUE_WITHIN: f64 = 1e-9;

/// What a directional derivative asks for: a state's derivative (in state order) or an output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unknown {
    Derivative(usize),
    Output(Output),
}

impl Damper {
    /// Ok if a host's solver can integrate this damper; Err: why not.
    pub fn offers_model_exchange(&self) -> Result<(), String> {
        self.model.offers_model_exchange()
    }

    /// The tracked amplitude's sample period in Model Exchange [s]; None for a fixed one.
    pub fn amplitude_sample_period(&self) -> Option<f64> {
        self.tracker
            .as_ref()
            .map(|_| std::f64::consts::TAU / (self.derived.omega_f * SAMPLES_PER_PERIOD))
    }

    /// The event at time `t` of a run that started at `start`: if a sample of the tracked
    /// amplitude is due, the tracker takes in the inputs now (as a Co-Simulation step from `t`
    /// of one sample period would) and the damping ratio follows its estimate until the next.
    /// Returns the time of the next sample; None for a fixed amplitude (no time events). A host
    /// that stepped over due samples gets one sample now and the next after `t`.
    pub fn amplitude_event(&mut self, start: f64, t: f64, inputs: &Inputs) -> Option<f64> {
        let h = self.amplitude_sample_period()?;
        let due = |k: u64| start + k as f64 * h;
        if t >= due(self.samples) - DUE_WITHIN * h {
            if let Some(tracker) = self.tracker.as_mut() {
                tracker.update(h, inputs.a, inputs.v);
            }
            // Samples whose times lie at or before t: the one just taken and any skipped.
            let at_or_before = ((t - start) / h + DUE_WITHIN).floor().max(0.0) as u64 + 1;
            self.samples = at_or_before.max(self.samples + 1);
            if self.damping_reads_amplitude {
                self.zeta = self.common.zeta(self.amplitude());
                self.model.set_damping(self.zeta);
            }
        }
        Some(due(self.samples))
    }

    /// After a restore at time `t` (the samples are not saved: the time says how many were
    /// due): every sample before `t` taken, and the one at `t`, if `t` is a sample time, only
    /// if `taken_at_t` (a state saved in continuous-time mode, after the event).
    pub fn resume_amplitude_samples(&mut self, start: f64, t: f64, taken_at_t: bool) {
        let Some(h) = self.amplitude_sample_period() else {
            return;
        };
        let position = (t - start) / h;
        let last = (position + DUE_WITHIN).floor();
        if last < 0.0 {
            self.samples = 0;
            return;
        }
        // last = floor(position + DUE_WITHIN): position - last lies in [-DUE_WITHIN, 1).
        let at_sample = position - last < DUE_WITHIN;
        self.samples = last as u64 + u64::from(!at_sample || taken_at_t);
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
    /// (the damping ratio changes at events only, not with them), into `out`. Err, and
    /// `out` untouched, for a damper not offered in Model Exchange or an unknown out of range.
    pub fn directional_derivatives(
        &self,
        inputs: &Inputs,
        d: &Direction,
        unknowns: &[Unknown],
        out: &mut [f64],
    ) -> Result<(), String> {
        self.offers_model_exchange()?;
        let t = self.model.continuous_tangent(inputs.a, d)?;
        let mut values = Vec::with_capacity(unknowns.len());
        for &unknown in unknowns {
            values.push(match unknown {
                Unknown::Derivative(k) => *t.derivatives.get(k).ok_or_else(|| {
                    format!("there are {STATES} state derivatives, not {}", k + 1)
                })?,
                Unknown::Output(which) => self.output_tangent(which, d, &t)?,
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
            // Amplitude and damping change at events only, not with the states; so does the
            // count of impacts.
            Output::Amplitude | Output::Zeta | Output::Impacts => 0.0,
            Output::SurfaceLeft | Output::SurfaceRight => {
                if self.model.surface().is_some() {
                    return Err(format!("{which:?} of a model that resolves the surface"));
                }
                self.mode_surface(usize::from(which == Output::SurfaceRight)) * d.states[0]
            }
        })
    }
}
