//! The small interface between the FMI layer and the physics: a configured damper that steps
//! over communication intervals with held inputs and reports its outputs. Knows no FMI.

use crate::physics::amplitude::{AmplitudeTracker, TRACKER_STATE};
use crate::physics::geometry::Tank;
use crate::physics::laws::{DampingLaw, LambdaRange};
use crate::physics::nonlinear::{BaseAcceleration, NonlinearTld, PowerLaw, state};
use crate::solver::{Auto, Dopri5, Rk4, Sdirk4, SolveError, SolveStats};

/// Where the excitation amplitude of the amplitude laws comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AmplitudeSource {
    /// A design amplitude [m].
    Fixed(f64),
    /// Estimated online; `tau` [s] is the filter time constant (0: two sloshing periods),
    /// `prior` [m] the value used before the base has moved.
    Tracked { tau: f64, prior: f64 },
}

/// Integrator inside a communication step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// An error-controlled method at relative tolerance `rtol`, internal steps <= `max_step`
    /// (0: no bound beyond the communication step).
    Adaptive {
        kind: AdaptiveKind,
        rtol: f64,
        max_step: f64,
    },
    /// Classical RK4 with internal steps <= `step`.
    Rk4 { step: f64 },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AdaptiveKind {
    /// Explicit Dormand-Prince 5(4).
    DormandPrince,
    /// L-stable implicit SDIRK4.
    Sdirk4,
    /// Per interval, whichever of the two the local stiffness calls for.
    Auto,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    pub tank: Tank,
    /// Number of identical tanks acting together.
    pub tanks: u32,
    pub eta: f64,
    pub phi: f64,
    pub damping: DampingLaw,
    pub lambda: LambdaRange,
    pub amplitude: AmplitudeSource,
    /// Initial relative displacement [m] and velocity [m/s] of the sloshing mass.
    pub x0: f64,
    pub v0: f64,
    pub method: Method,
    /// Most internal steps per communication step.
    pub max_substeps: u64,
}

/// Quantities computed from the configuration (totals over all tanks).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Derived {
    pub omega_f: f64,
    pub mass_liquid: f64,
    pub mass_slosh: f64,
    pub mass_inactive: f64,
}

impl Config {
    pub fn derived(&self) -> Derived {
        let n = f64::from(self.tanks);
        let mode = self.tank.fundamental();
        let liquid = self.tank.liquid_mass() * n;
        let slosh = mode.mass * n;
        Derived {
            omega_f: mode.omega,
            mass_liquid: liquid,
            mass_slosh: slosh,
            mass_inactive: liquid - slosh,
        }
    }

    /// c = 2 zeta omega_f of Eq 2.11 for the excitation amplitude `amplitude`.
    fn viscous_coefficient(&self, omega_f: f64, amplitude: f64) -> f64 {
        2.0 * omega_f * self.damping.zeta(amplitude, self.tank.length, self.lambda)
    }

    /// Checks that involve several parameters. Err: the configuration cannot be simulated;
    /// Ok(warnings): it can, outside the model's stated validity where a warning says so.
    pub fn check(&self) -> Result<Vec<String>, String> {
        let mut warnings = Vec::new();
        if self.lambda.min > self.lambda.max {
            return Err(format!(
                "lambda.min ({}) must not exceed lambda.max ({})",
                self.lambda.min, self.lambda.max
            ));
        }
        if self.tank.depth >= self.tank.length {
            return Err(format!(
                "tank.depth ({} m) must be smaller than tank.length ({} m) for a sloshing tank",
                self.tank.depth, self.tank.length
            ));
        }
        let r = self.tank.depth_ratio();
        if r > 0.15 {
            warnings.push(format!(
                "depth ratio h/a = {r:.3} exceeds 0.15: the shallow-water model is outside its validity"
            ));
        }
        if self.x0.abs() > self.tank.length {
            return Err(format!(
                "|slosh.x0| = {} m exceeds the tank length {} m",
                self.x0.abs(),
                self.tank.length
            ));
        }
        Ok(warnings)
    }
}

/// Base motion held over a communication step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Inputs {
    pub a: f64,
    pub v: f64,
    pub x: f64,
    /// First and second time derivatives of `a` at the step's start (0: held).
    pub a_derivatives: [f64; 2],
}

/// The outputs of the damper.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    /// Force of the liquid on the tanks [N].
    Force,
    /// Impulse of `Force` over the last step / its length [N].
    ForceMean,
    /// `Force` minus the inactive mass's inertia [N].
    BaseShear,
    /// Relative displacement [m] and velocity [m/s] of the sloshing mass.
    X,
    V,
    /// Energies [J]: work input, dissipated, stored.
    EnergyInput,
    EnergyDissipated,
    EnergyStored,
    /// Excitation amplitude in use [m].
    Amplitude,
    /// Damping ratio in use.
    Zeta,
}

/// Why a communication step was refused. The simulation is left as it was before the step.
#[derive(Clone, Debug, PartialEq)]
pub enum StepError {
    /// The integrator could not finish the step within its bounds; a smaller step may work.
    Solver(SolveError),
    /// The sloshing displacement left any physical range: the model is meaningless there.
    Runaway { x: f64, limit: f64 },
}

impl std::fmt::Display for StepError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StepError::Solver(e) => write!(f, "{e}"),
            StepError::Runaway { x, limit } => write!(
                f,
                "the sloshing displacement ran away to {x:e} m (limit {limit} m, 100 tank lengths)"
            ),
        }
    }
}

/// Length of [`Simulation::snapshot`]: state, two carried steps, amplitude, mean force (flag
/// and value), amplitude estimator.
pub const SNAPSHOT_LEN: usize = state::DIM + 5 + TRACKER_STATE;

#[derive(Clone, Debug, PartialEq)]
enum Integrator {
    DormandPrince(Dopri5<{ state::DIM }>),
    Sdirk4(Sdirk4<{ state::DIM }>),
    Auto(Auto<{ state::DIM }>),
    Rk4(Rk4),
}

impl Integrator {
    fn integrate(
        &mut self,
        model: &NonlinearTld,
        t0: f64,
        t1: f64,
        y: &mut [f64; state::DIM],
    ) -> Result<SolveStats, SolveError> {
        match self {
            Integrator::DormandPrince(m) => m.integrate(model, t0, t1, y),
            Integrator::Sdirk4(m) => m.integrate(model, t0, t1, y),
            Integrator::Auto(m) => m.integrate(model, t0, t1, y),
            Integrator::Rk4(m) => m.integrate(model, t0, t1, y),
        }
    }

    /// Step sizes carried between intervals (what the configuration does not determine).
    fn carried_steps(&self) -> [f64; 2] {
        match self {
            Integrator::DormandPrince(m) => [m.carried_step(), 0.0],
            Integrator::Sdirk4(m) => [m.carried_step(), 0.0],
            Integrator::Auto(m) => m.carried_steps(),
            Integrator::Rk4(_) => [0.0; 2],
        }
    }

    fn set_carried_steps(&mut self, h: [f64; 2]) {
        match self {
            Integrator::DormandPrince(m) => m.set_carried_step(h[0]),
            Integrator::Sdirk4(m) => m.set_carried_step(h[0]),
            Integrator::Auto(m) => m.set_carried_steps(h),
            Integrator::Rk4(_) => {}
        }
    }
}

/// A configured damper and its state.
#[derive(Clone, Debug, PartialEq)]
pub struct Simulation {
    config: Config,
    derived: Derived,
    model: NonlinearTld,
    integrator: Integrator,
    tracker: Option<AmplitudeTracker>,
    /// State per unit sloshing mass, see `physics::nonlinear::state`.
    y: [f64; state::DIM],
    initial_energy: f64,
    amplitude: f64,
    last_mean_force: Option<f64>,
}

impl Simulation {
    pub fn new(config: Config) -> Result<(Self, Vec<String>), String> {
        let warnings = config.check()?;
        let derived = config.derived();
        let omega_f = derived.omega_f;
        let length = config.tank.length;
        let stiffness = PowerLaw::new(omega_f, config.phi, config.eta, length);
        let half = 0.5 * length;
        let integrator = match config.method {
            Method::Adaptive {
                kind,
                rtol,
                max_step,
            } => {
                let mut scale = [0.0; state::DIM];
                scale[state::X] = half;
                scale[state::V] = omega_f * half;
                let max_step = if max_step > 0.0 {
                    max_step
                } else {
                    f64::INFINITY
                };
                let n = config.max_substeps;
                match kind {
                    AdaptiveKind::DormandPrince => {
                        Integrator::DormandPrince(Dopri5::new(rtol, scale, max_step, n))
                    }
                    AdaptiveKind::Sdirk4 => {
                        Integrator::Sdirk4(Sdirk4::new(rtol, scale, max_step, n))
                    }
                    AdaptiveKind::Auto => Integrator::Auto(Auto::new(rtol, scale, max_step, n)),
                }
            }
            Method::Rk4 { step } => Integrator::Rk4(Rk4 {
                max_step: step,
                max_steps: config.max_substeps,
            }),
        };
        let (amplitude, tracker) = match config.amplitude {
            AmplitudeSource::Fixed(a_e) => (a_e, None),
            AmplitudeSource::Tracked { tau, prior } => {
                let period = 2.0 * std::f64::consts::PI / omega_f;
                let tau = if tau > 0.0 { tau } else { 2.0 * period };
                // The velocity rebuild leaks at w_f/20: 0.5 % gain error at w_f/2, undone exactly.
                (
                    prior,
                    Some(AmplitudeTracker::new(tau, 0.05 * omega_f, prior)),
                )
            }
        };
        let c = config.viscous_coefficient(omega_f, amplitude);
        let model = NonlinearTld {
            stiffness,
            c,
            base: BaseAcceleration::held(0.0),
        };
        let mut y = [0.0; state::DIM];
        y[state::X] = config.x0;
        y[state::V] = config.v0;
        let initial_energy = model.stored_energy(config.x0, config.v0);
        let sim = Simulation {
            config,
            derived,
            model,
            integrator,
            tracker,
            y,
            initial_energy,
            amplitude,
            last_mean_force: None,
        };
        Ok((sim, warnings))
    }

    pub fn config(&self) -> &Config {
        &self.config
    }

    pub fn derived(&self) -> Derived {
        self.derived
    }

    /// Advance by `h` > 0 from time `t`, the base acceleration following its Taylor polynomial
    /// from `inputs` (held when the derivatives are 0). All or nothing: on error the simulation
    /// is unchanged.
    pub fn step(&mut self, t: f64, h: f64, inputs: &Inputs) -> Result<SolveStats, StepError> {
        let mut model = self.model;
        let mut tracker = None;
        if let Some(tr) = &self.tracker {
            // Only a tracked amplitude moves the damping; a fixed one was applied in new().
            let mut tr = tr.clone();
            tr.update(h, inputs.a, inputs.v);
            model.c = self
                .config
                .viscous_coefficient(self.derived.omega_f, tr.estimate());
            tracker = Some(tr);
        }
        let [a1, a2] = inputs.a_derivatives;
        model.base = BaseAcceleration {
            t0: t,
            a: [inputs.a, a1, a2],
        };
        let mut y = self.y;
        // The integrators change nothing of themselves when they fail; a runaway found after a
        // successful integration puts their carried step sizes back.
        let carried = self.integrator.carried_steps();
        let stats = self
            .integrator
            .integrate(&model, t, t + h, &mut y)
            .map_err(StepError::Solver)?;
        let limit = 100.0 * self.config.tank.length;
        if y[state::X].abs() > limit {
            self.integrator.set_carried_steps(carried);
            return Err(StepError::Runaway {
                x: y[state::X],
                limit,
            });
        }
        // The impulse of the force on the tank over the step, from v' = -a_b - f: for a
        // Runge-Kutta step h sum b_i f_i = -dv - h sum b_i a_b(t_i), and the quadrature of the
        // (at most quadratic) input is exact, so this equals integrating f alongside.
        let impulse = -(y[state::V] - self.y[state::V]) - model.base.integral(h);
        self.last_mean_force = Some(self.derived.mass_slosh * impulse / h);
        self.y = y;
        self.model = model;
        if let Some(tr) = tracker {
            self.amplitude = tr.estimate();
            self.tracker = Some(tr);
        }
        Ok(stats)
    }

    /// Everything that evolves, as a flat list of numbers (what the configuration does not
    /// determine). Restore with [`Simulation::restore`] and the same configuration.
    pub fn snapshot(&self) -> Vec<f64> {
        let mut out = Vec::with_capacity(SNAPSHOT_LEN);
        out.extend_from_slice(&self.y);
        out.extend_from_slice(&self.integrator.carried_steps());
        out.push(self.amplitude);
        out.push(f64::from(u8::from(self.last_mean_force.is_some())));
        out.push(self.last_mean_force.unwrap_or(0.0));
        out.extend_from_slice(
            &self
                .tracker
                .as_ref()
                .map_or([0.0; TRACKER_STATE], |t| t.state()),
        );
        out
    }

    /// The simulation `config` describes, in the state `snapshot` recorded.
    pub fn restore(config: Config, snapshot: &[f64]) -> Result<Self, String> {
        let (mut sim, _) = Simulation::new(config)?;
        if snapshot.len() != SNAPSHOT_LEN {
            return Err(format!(
                "a state has {SNAPSHOT_LEN} numbers, this one {}",
                snapshot.len()
            ));
        }
        if snapshot.iter().any(|v| !v.is_finite()) {
            return Err("the state holds non-finite numbers".into());
        }
        let (y, rest) = snapshot.split_at(state::DIM);
        sim.y.copy_from_slice(y);
        sim.integrator.set_carried_steps([rest[0], rest[1]]);
        let rest = &rest[2..];
        sim.amplitude = rest[0];
        sim.last_mean_force = match rest[1] {
            0.0 => None,
            1.0 => Some(rest[2]),
            _ => return Err("the state's mean-force flag is neither 0 nor 1".into()),
        };
        if let Some(tracker) = sim.tracker.as_mut() {
            let mut t = [0.0; TRACKER_STATE];
            t.copy_from_slice(&rest[3..]);
            tracker.set_state(&t)?;
        }
        sim.model.c = sim
            .config
            .viscous_coefficient(sim.derived.omega_f, sim.amplitude);
        Ok(sim)
    }

    /// The output `which` now.
    pub fn output(&self, which: Output, inputs: &Inputs) -> f64 {
        let m = self.derived.mass_slosh;
        let (x, v) = (self.y[state::X], self.y[state::V]);
        match which {
            Output::Force => m * self.model.tank_force(x, v),
            Output::ForceMean => self
                .last_mean_force
                .unwrap_or_else(|| self.output(Output::Force, inputs)),
            Output::BaseShear => {
                self.output(Output::Force, inputs) - self.derived.mass_inactive * inputs.a
            }
            Output::X => x,
            Output::V => v,
            Output::EnergyInput => m * (self.initial_energy + self.y[state::WORK_IN]),
            Output::EnergyDissipated => m * self.y[state::DISSIPATED],
            Output::EnergyStored => m * self.model.stored_energy(x, v),
            Output::Amplitude => self.amplitude,
            Output::Zeta => self.model.c / (2.0 * self.derived.omega_f),
        }
    }

    /// The exact first time derivative of the output `which` now (0 for quantities constant
    /// between communication points).
    pub fn output_derivative(&self, which: Output, inputs: &Inputs) -> f64 {
        let m = self.derived.mass_slosh;
        let (x, v) = (self.y[state::X], self.y[state::V]);
        let acc = self.model.acceleration(x, v, inputs.a);
        let force = || m * (self.model.c * acc + self.model.stiffness.slope(x) * v);
        match which {
            Output::Force => force(),
            Output::BaseShear => force() - self.derived.mass_inactive * inputs.a_derivatives[0],
            Output::X => v,
            Output::V => acc,
            Output::EnergyInput => -m * inputs.a * v,
            Output::EnergyDissipated => m * self.model.c * v * v,
            Output::EnergyStored => m * v * (acc + self.model.stiffness.force(x)),
            Output::ForceMean | Output::Amplitude | Output::Zeta => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config() -> Config {
        Config {
            tank: Tank::TABLE_2_1,
            tanks: 1,
            eta: 2.0,
            phi: 1.0,
            damping: DampingLaw::Nsd { c: 0.5, p: 0.35 },
            lambda: LambdaRange {
                min: 1e-3,
                max: 0.1,
            },
            amplitude: AmplitudeSource::Fixed(0.005),
            x0: 0.0,
            v0: 0.0,
            method: Method::Adaptive {
                kind: AdaptiveKind::DormandPrince,
                rtol: 1e-10,
                max_step: 0.0,
            },
            max_substeps: 100_000,
        }
    }

    /// Free decay of the linear limit against the closed-form damped oscillation.
    #[test]
    fn linear_free_decay_matches_closed_form() {
        let cfg = Config {
            eta: 1.0,
            phi: 0.0,
            damping: DampingLaw::Constant(0.02),
            x0: 0.01,
            ..config()
        };
        let (mut sim, _) = Simulation::new(cfg).expect("config");
        let w = sim.derived().omega_f;
        let wd = w * (1.0 - 0.02f64 * 0.02).sqrt();
        let h = 0.01;
        let mut worst: f64 = 0.0;
        for k in 0..2000 {
            sim.step(k as f64 * h, h, &Inputs::default()).expect("step");
            let t = (k + 1) as f64 * h;
            let exact =
                0.01 * (-0.02 * w * t).exp() * ((wd * t).cos() + 0.02 * w / wd * (wd * t).sin());
            worst = worst.max((sim.output(Output::X, &Inputs::default()) - exact).abs());
        }
        assert!(worst < 1e-8 * 0.01, "worst error {worst}");
    }

    /// energy.input = energy.stored + energy.dissipated, and dissipation never decreases.
    #[test]
    fn energy_balance_under_harmonic_forcing() {
        let cfg = Config {
            x0: 0.02,
            ..config()
        };
        let (mut sim, _) = Simulation::new(cfg).expect("config");
        let w = 1.1 * sim.derived().omega_f;
        let mut last_dissipated = 0.0;
        let h = 0.005;
        for k in 0..4000 {
            let t = k as f64 * h;
            let inputs = Inputs {
                a: -w * w * 0.005 * (w * t).sin(),
                ..Inputs::default()
            };
            sim.step(t, h, &inputs).expect("step");
            let e = |w| sim.output(w, &inputs);
            let (input, stored, dissipated) = (
                e(Output::EnergyInput),
                e(Output::EnergyStored),
                e(Output::EnergyDissipated),
            );
            let residual = (input - stored - dissipated).abs();
            assert!(
                residual < 1e-8 * input.abs().max(1e-6),
                "step {k}: residual {residual}"
            );
            assert!(dissipated >= last_dissipated);
            last_dissipated = dissipated;
        }
        assert!(last_dissipated > 0.0);
    }

    #[test]
    fn a_refused_step_changes_nothing() {
        let cfg = Config {
            max_substeps: 3,
            x0: 0.05,
            ..config()
        };
        let (mut sim, _) = Simulation::new(cfg).expect("config");
        let before = sim.clone();
        let r = sim.step(
            0.0,
            50.0,
            &Inputs {
                a: 1.0,
                ..Inputs::default()
            },
        );
        assert!(
            matches!(r, Err(StepError::Solver(SolveError::TooManySteps { .. }))),
            "{r:?}"
        );
        assert_eq!(sim, before);
    }

    #[test]
    fn tracked_amplitude_settles_within_five_percent() {
        for rebuild in [false, true] {
            for ratio in [0.5, 1.0, 2.0] {
                let cfg = Config {
                    amplitude: AmplitudeSource::Tracked {
                        tau: 0.0,
                        prior: 0.001,
                    },
                    ..config()
                };
                let (mut sim, _) = Simulation::new(cfg).expect("config");
                let w = ratio * sim.derived().omega_f;
                let amp = 0.005;
                let h = 0.01;
                for k in 0..6000 {
                    let t = k as f64 * h;
                    let v = if rebuild {
                        0.0
                    } else {
                        w * amp * (w * t).cos()
                    };
                    let inputs = Inputs {
                        a: -w * w * amp * (w * t).sin(),
                        v,
                        x: amp * (w * t).sin(),
                        ..Inputs::default()
                    };
                    sim.step(t, h, &inputs).expect("step");
                    if k > 4000 {
                        let est = sim.output(Output::Amplitude, &inputs);
                        assert!(
                            (est / amp - 1.0).abs() < 0.05,
                            "w/wf {ratio} rebuild {rebuild}: {est}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn inconsistent_configurations_are_refused() {
        let bad = Config {
            lambda: LambdaRange { min: 0.2, max: 0.1 },
            ..config()
        };
        assert!(Simulation::new(bad).is_err());
        let deep = Config {
            tank: Tank {
                depth: 0.3,
                ..Tank::TABLE_2_1
            },
            ..config()
        };
        assert!(Simulation::new(deep).is_err());
        let (_, warnings) = Simulation::new(Config {
            tank: Tank {
                depth: 0.05,
                ..Tank::TABLE_2_1
            },
            ..config()
        })
        .expect("valid but deep");
        assert_eq!(warnings.len(), 1);
    }
}
