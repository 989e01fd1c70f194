//! The damper an instance runs: the chosen model and what every model shares around it, the
//! damping law and its amplitude (fixed or tracked online), the mean force of the last step, the
//! energy at the start, and the frame of the saved state.

use super::{
    AmplitudeSource, AnyModel, Common, Derived, InputAt, Inputs, Observable, Output, Parameters,
    Start, StepError, choice,
};
use crate::description::vr;
use crate::physics::amplitude::{AmplitudeTracker, TRACKER_STATE};
use crate::solver::SolveStats;

/// How many outputs [`Damper::per_step`] keeps: the `Output`s with discriminants below. Its
/// array has one slot more, infinite: a read there finds no value (fmi2GetReal's quick path
/// reads it for "none", with no branch). Infinite, not NaN: the damper still equals itself.
pub const PER_STEP: usize = 3;

/// Numbers of a saved state after the model's own: amplitude, mean force (flag and value),
/// amplitude estimator.
const FRAME: usize = 3 + TRACKER_STATE;

#[derive(Clone, Debug, PartialEq)]
pub struct Damper {
    common: Common,
    derived: Derived,
    model: AnyModel,
    tracker: Option<AmplitudeTracker>,
    /// Whether the amplitude is tracked and the damping law reads it: only then is the
    /// amplitude estimated before each step. Otherwise a tracker takes in the step's input
    /// after the step, on the fixed amplitude's path ([`Damper::step`]), and forms its estimate
    /// only when something reads it (A_e.estimate, a saved state). One flag: one load and
    /// branch before every step.
    estimates_first: bool,
    /// Stored energy at the start [J]: counted as input.
    initial_energy: f64,
    /// The fixed amplitude, or a tracked one's prior (see [`Damper::amplitude`]).
    amplitude: f64,
    /// Damping ratio in use.
    zeta: f64,
    /// The last step's impulse and length, the mean force formed when read
    /// ([`MeanForce::get`]).
    last_mean_force: MeanForce,
    /// Force of the liquid on the tanks [N] and the sloshing's displacement and velocity at the
    /// current state, kept with the state and indexed by their `Output` discriminants: a master
    /// reads them after every step, where they are loads. Then infinity ([`PER_STEP`]).
    per_step: [f64; PER_STEP + 1],
    /// Whether the run has been told of implausible motion.
    noticed: bool,
}

/// What a step of the damper reports besides its new state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Report {
    pub stats: SolveStats,
    /// The motion is implausible for a building (likely a unit mistake): [`Damper::notice`]
    /// says why.
    pub implausible: bool,
}

impl Damper {
    /// The damper the parameters describe, and warnings about them; Err: they cannot be
    /// simulated, with the reason.
    pub fn configure(p: &dyn Parameters) -> Result<(Self, Vec<String>), String> {
        let (common, warnings) = Common::read(p)?;
        let omega_f = common.tank.fundamental().omega;
        let (amplitude, tracker) = match common.amplitude {
            AmplitudeSource::Fixed(a_e) => (a_e, None),
            AmplitudeSource::Tracked { tau, prior } => {
                let period = 2.0 * std::f64::consts::PI / omega_f;
                let tau = if tau > 0.0 { tau } else { 2.0 * period };
                // The velocity rebuild leaks at w_f/20: 0.5 % gain error at w_f/2, undone exactly.
                (
                    prior,
                    Some(AmplitudeTracker::new(tau, 0.05 * omega_f, prior, omega_f)),
                )
            }
        };
        let zeta = common.zeta(amplitude);
        let model =
            AnyModel::configure(choice(p, vr::MODEL)?, p, &common, Start { zeta, amplitude })?;
        let mass_liquid = common.liquid_mass();
        let mass_slosh = model.sloshing_mass();
        let derived = Derived {
            omega_f,
            mass_liquid,
            mass_slosh,
            mass_inactive: mass_liquid - mass_slosh,
        };
        let estimates_first = tracker.is_some() && common.damping.reads_amplitude();
        let damper = Damper {
            common,
            derived,
            initial_energy: model.observe(Observable::Stored),
            per_step: per_step(&model),
            model,
            tracker,
            estimates_first,
            amplitude,
            zeta,
            last_mean_force: MeanForce::NONE,
            noticed: false,
        };
        Ok((damper, warnings))
    }

    pub fn derived(&self) -> Derived {
        self.derived
    }

    /// Advance by `h` > 0 from time `t`, the base acceleration following its Taylor polynomial
    /// from `inputs` (held when the derivatives are 0). All or nothing: on error the damper is
    /// unchanged. Inlined into fmi2DoStep: the models' steps are out of line, and the call
    /// this would add costs more than its body.
    #[inline(always)]
    pub fn step(&mut self, t: f64, h: f64, inputs: &Inputs) -> Result<Report, StepError> {
        let input = InputAt {
            a: &inputs.a,
            v: &inputs.v,
        };
        self.step_at(t, h, inputs.a_derivatives, input)
    }

    /// [`Damper::step`] with base.a and base.v where they are (the host's values): nothing is
    /// copied to memory for the step, and base.v is not read unless the amplitude tracker
    /// takes it in.
    #[inline(always)]
    pub fn step_at(
        &mut self,
        t: f64,
        h: f64,
        a_derivatives: [f64; 2],
        input: InputAt,
    ) -> Result<Report, StepError> {
        // A fixed amplitude was applied in configure. A tracked amplitude that the damping law
        // reads is estimated before the step, out of line; otherwise the tracker takes in the
        // step's input once the step has succeeded (all or nothing), on the same code as a
        // fixed amplitude, its rare cases (a new interval length, the host's base.v appearing)
        // out of line in the update itself.
        if self.estimates_first {
            return self.step_aside(t, h, a_derivatives, input);
        }
        self.advance(self.zeta, t, h, a_derivatives, input, true)
    }

    /// [`Damper::step`] for a damping law that reads a tracked amplitude: the step's input is
    /// taken in before the step, which uses the tracker as it will be after it.
    #[inline(never)]
    fn step_aside(
        &mut self,
        t: f64,
        h: f64,
        a_derivatives: [f64; 2],
        input: InputAt,
    ) -> Result<Report, StepError> {
        let Some(tracker) = self.tracker.as_mut() else {
            return self.advance(self.zeta, t, h, a_derivatives, input, false);
        };
        // Updated in place, the copy kept for a refused step: an update of a fresh copy would
        // load what the copy has just stored, in other widths (a stall per load the processor
        // cannot forward; NSD's defaults +12 % with the filters' gain as one vector load).
        let before = tracker.clone();
        tracker.update(h, *input.a, *input.v);
        let zeta = self.common.zeta(tracker.estimate());
        match self.advance(zeta, t, h, a_derivatives, input, false) {
            Ok(report) => {
                // Only here does the damping ratio change (stored on the other paths, the
                // same value stored on every step).
                self.zeta = zeta;
                Ok(report)
            }
            Err(e) => {
                self.tracker = Some(before);
                Err(e)
            }
        }
    }

    /// The excitation amplitude the damping law is given (A_e.estimate): the fixed one, or
    /// the tracker's estimate from the input so far (its prior before the first step).
    pub fn amplitude(&self) -> f64 {
        self.tracker
            .as_ref()
            .map_or(self.amplitude, AmplitudeTracker::estimate)
    }

    /// [`Damper::step`] with the damping ratio `zeta`; the amplitude tracker, if `take_in`,
    /// takes in the step's input once the step has succeeded. Small (the models' steps are out
    /// of line), so inlined.
    #[inline(always)]
    fn advance(
        &mut self,
        zeta: f64,
        t: f64,
        h: f64,
        a_derivatives: [f64; 2],
        input: InputAt,
        take_in: bool,
    ) -> Result<Report, StepError> {
        // Each step is integrated in its own time, 0 to h: the model is autonomous but for the
        // input, and (t + h) - t is not h in floating point.
        let a = [*input.a, a_derivatives[0], a_derivatives[1]];
        let limit = 100.0 * self.common.tank.length;
        let stepped = self.model.step(t, h, zeta, a, limit)?;
        // The tracker's part, the input read back from where it is (volatile reads: the compiler
        // may not keep it in registers across the model's step, where it would be spilled,
        // stored on the fixed amplitude's path too, and a store before the step costs that path
        // time; docs/ARCHITECTURE.md).
        if take_in && let Some(tracker) = self.tracker.as_mut() {
            // SAFETY: reads through valid references, as plain reads are.
            let (a, v) = unsafe {
                (
                    std::ptr::read_volatile(input.a),
                    std::ptr::read_volatile(input.v),
                )
            };
            tracker.take_in(h, a, v);
        }
        // (The three, not the infinity after them: no store for it.)
        let [force, x, v, _] = &mut self.per_step;
        (*force, *x, *v) = (stepped.force, stepped.sloshing.0, stepped.sloshing.1);
        // The mean force is formed when read: a division and a check on every step otherwise,
        // whose result most hosts never ask for.
        self.last_mean_force = MeanForce {
            impulse: stepped.impulse,
            h,
        };
        // Far beyond the walls (twice their distance): most likely a unit mistake, in the input
        // or the tank, which `notice` explains. An implausible input drives the sloshing there
        // within a step or two.
        let implausible = stepped.sloshing.0.abs() > self.common.tank.length;
        Ok(Report {
            stats: stepped.stats,
            implausible,
        })
    }

    /// Why the last step's motion is implausible, under base acceleration `a`: the first time
    /// in a run; None after that.
    #[cold]
    #[inline(never)]
    pub fn notice(&mut self, a: f64) -> Option<String> {
        // More than any floor of a building moves: 10 g.
        const IMPLAUSIBLE_ACCELERATION: f64 = 10.0 * 9.81;
        if self.noticed {
            return None;
        }
        self.noticed = true;
        let length = self.common.tank.length;
        let x = self.x();
        Some(if a.abs() > IMPLAUSIBLE_ACCELERATION {
            format!(
                "base.a = {a} m/s^2 is {:.0} g, implausible for a building floor: is it given in \
                 mm/s^2 or in g instead of m/s^2?",
                a.abs() / 9.81
            )
        } else {
            format!(
                "slosh.x = {x:.3} m in a tank {length} m long (walls at +-{:.3} m): the sloshing \
                 is far beyond the walls, where no model of this FMU holds. Is base.a in m/s^2 \
                 (not mm/s^2 or g), and are the tank's lengths in metres?",
                0.5 * length
            )
        })
    }

    /// The output `which` now.
    #[inline]
    pub fn output(&self, which: Output, inputs: &Inputs) -> f64 {
        self.per_step_output(which)
            .unwrap_or_else(|| self.other_output(which, inputs))
    }

    /// The output `which` if it is one of the three a master reads after every step: loads,
    /// with no call and nothing that can panic. None for the others.
    #[inline(always)]
    pub fn per_step_output(&self, which: Output) -> Option<f64> {
        self.per_step[..PER_STEP].get(which as usize).copied()
    }

    /// The outputs of [`Damper::per_step_output`], indexed by their `Output` discriminants
    /// (those below [`PER_STEP`]), and infinity.
    #[inline(always)]
    pub fn per_step(&self) -> &[f64; PER_STEP + 1] {
        &self.per_step
    }

    fn force(&self) -> f64 {
        self.per_step[Output::Force as usize]
    }

    fn x(&self) -> f64 {
        self.per_step[Output::X as usize]
    }

    /// Every output but those of [`Damper::per_step_output`].
    #[inline(never)]
    fn other_output(&self, which: Output, inputs: &Inputs) -> f64 {
        let observe = |o| self.model.observe(o);
        match which {
            Output::X | Output::V | Output::Force => self.per_step_output(which).unwrap_or(0.0),
            Output::ForceMean => self
                .last_mean_force
                .get(self.force())
                .unwrap_or(self.force()),
            Output::BaseShear => {
                self.force()
                    - self.derived.mass_inactive * inputs.a
                    - self.model.rigid_mass() * inputs.a
            }
            Output::EnergyInput => self.initial_energy + observe(Observable::WorkIn),
            Output::EnergyDissipated => observe(Observable::Dissipated),
            Output::EnergyStored => observe(Observable::Stored),
            Output::Amplitude => self.amplitude(),
            Output::Zeta => self.zeta,
            Output::ImpactZ => observe(Observable::ImpactZ),
            Output::Impacts => observe(Observable::Impacts),
            Output::ImpactImpulse => observe(Observable::ImpactImpulse),
            Output::SurfaceLeft | Output::SurfaceRight => {
                let k = usize::from(which == Output::SurfaceRight);
                self.model
                    .surface()
                    .map_or(self.mode_surface(k) * self.x(), |s| s[k])
            }
        }
    }

    /// Wave height at wall `k` (0: x = 0, 1: x = a) per metre of slosh.x for the models that do
    /// not resolve the surface: the fundamental shallow-water mode cos(pi x/a) with the first
    /// moment m_1 x (integral of rho b eta (x - a/2) dx = -2 rho b a^2 eta(0)/pi^2), so
    /// eta(0) = -pi^2 m_1 x/(2 rho b a^2) and eta(a) = -eta(0).
    fn mode_surface(&self, k: usize) -> f64 {
        let t = &self.common.tank;
        let left = -std::f64::consts::PI.powi(2) * t.fundamental().mass
            / (2.0 * t.density * t.breadth * t.length * t.length);
        if k == 0 { left } else { -left }
    }

    /// The exact first time derivative of the output `which` now (0 for quantities constant
    /// between communication points; the impacts themselves are instants, not rates).
    pub fn output_derivative(&self, which: Output, inputs: &Inputs) -> f64 {
        let (a, a_rate) = (inputs.a, inputs.a_derivatives[0]);
        match which {
            Output::BaseShear => {
                self.model.rate(Output::Force, a, a_rate)
                    - (self.derived.mass_inactive + self.model.rigid_mass()) * a_rate
            }
            Output::SurfaceLeft | Output::SurfaceRight if self.model.surface().is_none() => {
                let k = usize::from(which == Output::SurfaceRight);
                self.mode_surface(k) * self.model.rate(Output::X, a, a_rate)
            }
            _ => self.model.rate(which, a, a_rate),
        }
    }

    /// Everything that evolves, as a flat list of numbers (what the parameters do not
    /// determine): the model's part, then the frame. Restore with [`Damper::restore`] and the
    /// same parameters.
    pub fn snapshot(&self) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.model.state_len() + FRAME);
        self.model.save(&mut out);
        out.push(self.amplitude());
        let mean_force = self.last_mean_force.get(self.force());
        out.push(f64::from(u8::from(mean_force.is_some())));
        out.push(mean_force.unwrap_or(0.0));
        out.extend_from_slice(
            &self
                .tracker
                .as_ref()
                .map_or([0.0; TRACKER_STATE], |t| t.state()),
        );
        out
    }

    /// What the model carries beyond the snapshot's pinned layout ([`Model::extra`]: S^2's
    /// impact impulse, per unit impact mass); 0 for most.
    pub fn extra(&self) -> f64 {
        self.model.extra()
    }

    /// Take [`Damper::extra`] back after [`Damper::restore`].
    pub fn load_extra(&mut self, x: f64) -> Result<(), String> {
        self.model.load_extra(x)
    }

    /// The damper the parameters `p` describe, in the state `snapshot` recorded.
    pub fn restore(p: &dyn Parameters, snapshot: &[f64]) -> Result<Self, String> {
        let (mut damper, _) = Damper::configure(p)?;
        let n = damper.model.state_len();
        if snapshot.len() != n + FRAME {
            return Err(format!(
                "a state of this model has {} numbers, this one {}",
                n + FRAME,
                snapshot.len()
            ));
        }
        if snapshot.iter().any(|v| !v.is_finite()) {
            return Err("the state holds non-finite numbers".into());
        }
        let (model_state, frame) = snapshot.split_at(n);
        damper.model.load(model_state)?;
        // A tracked amplitude is the tracker's estimate (frame[0] holds it as saved); a fixed
        // one is the state's.
        if damper.tracker.is_none() {
            damper.amplitude = frame[0];
        }
        damper.last_mean_force = match frame[1] {
            0.0 => MeanForce::NONE,
            1.0 => MeanForce::of(frame[2]),
            _ => return Err("the state's mean-force flag is neither 0 nor 1".into()),
        };
        if let Some(tracker) = damper.tracker.as_mut() {
            let mut t = [0.0; TRACKER_STATE];
            t.copy_from_slice(&frame[3..]);
            tracker.set_state(&t)?;
        }
        // The damping the last step used, which the model keeps for the output rates.
        damper.zeta = damper.common.zeta(damper.amplitude());
        damper.model.set_damping(damper.zeta);
        damper.per_step = per_step(&damper.model);
        Ok(damper)
    }
}

/// The last step's impulse on the tanks and its length: force.mean is their ratio, formed when
/// read. No step yet: h = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
struct MeanForce {
    impulse: f64,
    h: f64,
}

impl MeanForce {
    const NONE: MeanForce = MeanForce {
        impulse: 0.0,
        h: 0.0,
    };

    /// The mean force `f` as a step of length 1 with the impulse `f` (f x 1/1 is f).
    fn of(f: f64) -> Self {
        MeanForce { impulse: f, h: 1.0 }
    }

    /// Whether a step has been taken.
    fn is_some(&self) -> bool {
        self.h != 0.0
    }

    /// The mean force over the last step, whose end has the force `force`; None before the
    /// first step. Where impulse/h is not finite (1/h overflows for a subnormal h, and 0 x inf
    /// is NaN) the step was too short for a mean: `force`.
    fn get(&self, force: f64) -> Option<f64> {
        if !self.is_some() {
            return None;
        }
        let mean = self.impulse * (1.0 / self.h);
        Some(if mean.is_finite() { mean } else { force })
    }
}

/// The outputs a master reads after every step, at the model's state, in `Output` order, and
/// infinity.
fn per_step(model: &AnyModel) -> [f64; PER_STEP + 1] {
    let (x, v) = model.sloshing();
    [model.force(), x, v, f64::INFINITY]
}

mod cells;
mod continuous;
mod events;
mod tracked;
pub use continuous::Unknown;

#[cfg(test)]
mod me_tests;
#[cfg(test)]
mod tests;
