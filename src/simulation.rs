//! The small interface between the FMI layer and the physics: a configured damper that steps
//! over communication intervals with held inputs and reports its outputs. Knows no FMI.

use crate::physics::amplitude::{AmplitudeTracker, TRACKER_STATE};
use crate::physics::geometry::Tank;
use crate::physics::laws::nsd_kappa;
use crate::physics::laws::{DampingLaw, LambdaRange};
use crate::physics::linear::{Mode, ModeState};
use crate::physics::nonlinear::{
    BaseAcceleration, CompiledTld, NonlinearTld, PowerLaw, RhsJob, state,
};
use crate::physics::slamming::{SlamState, Slamming};
use crate::solver::{
    Auto, Dop853, Dopri5, ExpRk4, OscillatorSplit, Rk4, Rk5, Rk8, Sdirk4, SolveError, SolveStats,
};

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
    /// An explicit formula with equal internal steps <= `step`, no error control.
    Fixed { formula: FixedFormula, step: f64 },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FixedFormula {
    /// Classical fourth-order Runge-Kutta (4 evaluations per step).
    Rk4,
    /// The fifth-order solution of Dormand-Prince 5(4) (6 evaluations).
    Rk5,
    /// The eighth-order solution of DOP853 (12 evaluations).
    Rk8,
    /// Exponential (Lawson) RK4: the linear oscillator by its exact flow, RK4 on the rest
    /// (4 evaluations).
    ExpRk4,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AdaptiveKind {
    /// Explicit Dormand-Prince 5(4).
    DormandPrince,
    /// Explicit Dormand-Prince 8(5,3), for tight tolerances.
    DormandPrince853,
    /// L-stable implicit SDIRK4.
    Sdirk4,
    /// Per interval, whichever of the two the local stiffness calls for.
    Auto,
}

/// Most modes the linear model carries (their masses fall as 1/(2n-1)^3).
pub const MAX_MODES: u32 = 50;

/// Which model of the seed's ladder the damper runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ModelKind {
    /// `modes` linear sloshing modes (Eqs 2.1, 2.2), advanced exactly.
    Linear { modes: u32 },
    /// The impact-characteristic model (Eq 2.11 with Eq 2.13).
    Nonlinear,
    /// The same, stepped by the exact linear propagator while the hardening term stays below
    /// `threshold` over the step (0: the solver tolerance), by the integrator otherwise.
    NonlinearAuto { threshold: f64 },
    /// Sloshing-slamming (S^2, Eqs 2.5-2.8): the fundamental mode with mass Omega m_1 on its
    /// unchanged spring (frequency omega_1 / sqrt(Omega)) and an impact mass
    /// (mass_ratio + 1 - Omega) m_1 slamming on the walls across the clearance.
    SloshingSlamming(SlammingParams),
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlammingParams {
    /// Mass exchange Omega in (0, 1]; 0: from the NSD hardening law, Omega = 1/kappa(Lambda)^2.
    pub omega: f64,
    pub restitution: f64,
    /// d [m].
    pub clearance: f64,
    /// Impact mass before the exchange over m_1 (the seed: 0.01).
    pub mass_ratio: f64,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    pub model: ModelKind,
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
    /// Number of sloshing modes the model carries.
    fn mode_count(&self) -> u32 {
        match self.model {
            ModelKind::Linear { modes } => modes.max(1),
            ModelKind::Nonlinear
            | ModelKind::NonlinearAuto { .. }
            | ModelKind::SloshingSlamming(_) => 1,
        }
    }

    /// The S^2 mass exchange Omega in use.
    fn mass_exchange(&self, params: &SlammingParams, amplitude: f64) -> f64 {
        if params.omega > 0.0 {
            return params.omega.min(1.0);
        }
        let kappa = nsd_kappa(self.lambda.clamp(amplitude / self.tank.length));
        (1.0 / (kappa * kappa)).clamp(1e-3, 1.0)
    }

    pub fn derived(&self) -> Derived {
        let n = f64::from(self.tanks);
        let liquid = self.tank.liquid_mass() * n;
        let modes = (1..=self.mode_count())
            .map(|k| self.tank.mode(k).mass)
            .sum::<f64>();
        // S^2: the impact mass before the exchange comes out of the liquid at rest.
        let extra = match self.model {
            ModelKind::SloshingSlamming(p) => p.mass_ratio * self.tank.fundamental().mass,
            _ => 0.0,
        };
        let slosh = (modes + extra) * n;
        Derived {
            omega_f: self.tank.fundamental().omega,
            mass_liquid: liquid,
            mass_slosh: slosh,
            mass_inactive: liquid - slosh,
        }
    }

    /// The damping ratio of the sloshing modes for the excitation amplitude `amplitude`.
    fn zeta(&self, amplitude: f64) -> f64 {
        self.damping.zeta(amplitude, self.tank.length, self.lambda)
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
        if let ModelKind::Linear { modes } = self.model
            && !(1..=MAX_MODES).contains(&modes)
        {
            return Err(format!(
                "modes = {modes}: the linear model carries 1 to {MAX_MODES} modes"
            ));
        }
        if let ModelKind::SloshingSlamming(p) = self.model {
            if p.clearance > self.tank.length {
                return Err(format!(
                    "slamming.clearance ({} m) exceeds the tank length ({} m)",
                    p.clearance, self.tank.length
                ));
            }
            if self.derived().mass_inactive < 0.0 {
                return Err(format!(
                    "slamming.mass_ratio ({}) takes more liquid than the tank holds",
                    p.mass_ratio
                ));
            }
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
    /// S^2: position of the impact mass relative to the tank centre [m], and impacts so far.
    ImpactZ,
    Impacts,
}

/// Why a communication step was refused. The simulation is left as it was before the step.
#[derive(Clone, Debug, PartialEq)]
pub enum StepError {
    /// The integrator could not finish the step within its bounds; a smaller step may work.
    Solver(SolveError),
    /// The sloshing displacement left any physical range: the model is meaningless there.
    Runaway { x: f64, limit: f64 },
    /// S^2 impacts did not come to rest within the step's bound.
    Chattering(String),
}

impl std::fmt::Display for StepError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StepError::Solver(e) => write!(f, "{e}"),
            StepError::Runaway { x, limit } => write!(
                f,
                "the sloshing displacement ran away to {x:e} m (limit {limit} m, 100 tank lengths)"
            ),
            StepError::Chattering(why) => write!(f, "{why}"),
        }
    }
}

/// Numbers in [`Simulation::snapshot`] besides the model's state: the integrator's memory,
/// amplitude, mean force (flag and value), amplitude estimator.
const SNAPSHOT_EXTRA: usize = 6 + TRACKER_STATE;

#[derive(Clone, Debug, PartialEq)]
enum Integrator {
    DormandPrince(Dopri5<{ state::DIM }>),
    DormandPrince853(Dop853<{ state::DIM }>),
    Sdirk4(Sdirk4<{ state::DIM }>),
    Auto(Auto<{ state::DIM }>),
    Rk4(Rk4),
    Rk5(Rk5),
    Rk8(Rk8),
    ExpRk4(ExpRk4),
}

impl Integrator {
    /// Advance `y` over (0, h), the interval that starts at time `t`, refusing a state whose
    /// displacement leaves `limit` (a runaway). On error `y` and the integrator are unchanged.
    #[inline]
    fn integrate<F: OscillatorSplit<{ state::DIM }>>(
        &mut self,
        model: &F,
        t: f64,
        h: f64,
        y: &mut [f64; state::DIM],
        limit: f64,
    ) -> Result<SolveStats, StepError> {
        match self {
            // The cheapest steps, inline. They carry nothing from one interval to the next
            // (ExpRK4's flows are derived from the configuration): nothing to put back.
            Integrator::Rk4(m) => checked(y, t, limit, |z| m.integrate(model, 0.0, h, z)),
            Integrator::ExpRk4(m) => checked(y, t, limit, |z| m.integrate(model, 0.0, h, z)),
            other => other.integrate_any(model, t, h, y, limit),
        }
    }

    /// Any integrator, out of line. The error-controlled ones, inlined into the step for every
    /// kind of exponent, made it a function of some 60 kB whose stack traffic slowed the
    /// cheapest steps (RK4, one substep: 5 % of the whole doStep).
    #[inline(never)]
    fn integrate_any<F: OscillatorSplit<{ state::DIM }>>(
        &mut self,
        model: &F,
        t: f64,
        h: f64,
        y: &mut [f64; state::DIM],
        limit: f64,
    ) -> Result<SolveStats, StepError> {
        // The integrators change nothing of themselves when they fail; a runaway found after
        // a successful integration puts their carried step sizes back.
        let carried = self.memory();
        let outcome = checked(y, t, limit, |z| match self {
            Integrator::DormandPrince(m) => m.integrate(model, 0.0, h, z),
            Integrator::DormandPrince853(m) => m.integrate(model, 0.0, h, z),
            Integrator::Sdirk4(m) => m.integrate(model, 0.0, h, z),
            Integrator::Auto(m) => m.integrate(model, 0.0, h, z),
            Integrator::Rk5(m) => m.integrate(model, 0.0, h, z),
            Integrator::Rk8(m) => m.integrate(model, 0.0, h, z),
            // Taken directly by `integrate`; here only to keep the match whole.
            Integrator::Rk4(m) => m.integrate(model, 0.0, h, z),
            Integrator::ExpRk4(m) => m.integrate(model, 0.0, h, z),
        });
        if outcome.is_err() {
            self.set_memory(carried);
        }
        outcome
    }

    /// What is carried between intervals (what the configuration does not determine).
    fn memory(&self) -> [f64; 3] {
        match self {
            Integrator::DormandPrince(m) => [m.carried_step(), 0.0, 0.0],
            Integrator::DormandPrince853(m) => [m.carried_step(), 0.0, 0.0],
            Integrator::Sdirk4(m) => [m.carried_step(), 0.0, 0.0],
            Integrator::Auto(m) => m.memory(),
            Integrator::Rk4(_)
            | Integrator::Rk5(_)
            | Integrator::Rk8(_)
            | Integrator::ExpRk4(_) => [0.0; 3],
        }
    }

    fn set_memory(&mut self, h: [f64; 3]) {
        match self {
            Integrator::DormandPrince(m) => m.set_carried_step(h[0]),
            Integrator::DormandPrince853(m) => m.set_carried_step(h[0]),
            Integrator::Sdirk4(m) => m.set_carried_step(h[0]),
            Integrator::Auto(m) => m.set_memory(h),
            Integrator::Rk4(_)
            | Integrator::Rk5(_)
            | Integrator::Rk8(_)
            | Integrator::ExpRk4(_) => {}
        }
    }
}

/// `run` on a copy of the state `y` (of the interval starting at time `t`), committed if it
/// succeeds and the displacement stays within `limit`.
#[inline(always)]
fn checked(
    y: &mut [f64; state::DIM],
    t: f64,
    limit: f64,
    run: impl FnOnce(&mut [f64; state::DIM]) -> Result<SolveStats, SolveError>,
) -> Result<SolveStats, StepError> {
    let mut next = *y;
    let stats = run(&mut next).map_err(|e| StepError::Solver(e.shifted(t)))?;
    check_runaway(next[state::X], limit)?;
    *y = next;
    Ok(stats)
}

/// One interval of the nonlinear model (see [`Integrator::integrate`]), handed the model
/// compiled for its exponent.
struct Interval<'a> {
    integrator: &'a mut Integrator,
    t: f64,
    h: f64,
    y: &'a mut [f64; state::DIM],
    limit: f64,
}

impl RhsJob for Interval<'_> {
    /// The step's statistics and the force per unit sloshing mass at its end.
    type Output = Result<(SolveStats, f64), StepError>;
    fn run<F: CompiledTld>(self, f: &F) -> Self::Output {
        let stats = self
            .integrator
            .integrate(f, self.t, self.h, self.y, self.limit)?;
        Ok((stats, f.tank_force(self.y[state::X], self.y[state::V])))
    }
}

/// One linear mode (mode, mass, state) advanced exactly by `h`, and the impulse of its force
/// on the tank over the step (-dv - integral of a_b, per unit mass, times the mass). The mode
/// given is not changed.
fn advance_mode(
    mode: &(Mode, f64, ModeState),
    zeta: f64,
    h: f64,
    base: &BaseAcceleration,
) -> ((Mode, f64, ModeState), f64) {
    let mut next = *mode;
    next.0.zeta = zeta;
    next.0.advance(&mut next.2, h, base);
    let impulse = next.1 * (-(next.2.v - mode.2.v) - base.integral(h));
    (next, impulse)
}

/// model = Auto: the nonlinear state advanced by the exact linear solution, if the hardening
/// phi |2x/a|^(2eta-2) stays below `threshold` over the whole step (Eq 2.11 is then linear to
/// that tolerance and its exact solution is cheaper than any integrator); None if it may not;
/// a runaway error (nothing changed) if the displacement leaves `limit`.
/// The bound on |x| over the step: the free amplitude now, plus twice the static deflection
/// and the growth of one step under the largest base acceleration of the step.
#[inline(never)]
fn linear_step(
    model: &NonlinearTld,
    (threshold, mode): &mut (f64, Mode),
    zeta: f64,
    y: &[f64; state::DIM],
    h: f64,
    base: &BaseAcceleration,
    limit: f64,
) -> Option<Result<[f64; state::DIM], StepError>> {
    let omega_f = mode.omega;
    let (x, v) = (y[state::X], y[state::V]);
    let a_max = base.a[0].abs() + h * (base.a[1].abs() + 0.5 * h * base.a[2].abs());
    let bound =
        (x * x + (v / omega_f).powi(2)).sqrt() + a_max * (2.0 / (omega_f * omega_f) + h / omega_f);
    if model.stiffness.hardening(bound) >= *threshold {
        return None;
    }
    let mut next_mode = *mode;
    next_mode.zeta = zeta;
    let mut s = ModeState {
        x,
        v,
        work_in: y[state::WORK_IN],
        dissipated: y[state::DISSIPATED],
    };
    next_mode.advance(&mut s, h, base);
    // Without hardening (phi = 0) nothing else bounds the motion: checked as every step is.
    Some(check_runaway(s.x, limit).map(|()| {
        *mode = next_mode;
        [s.x, s.v, s.work_in, s.dissipated]
    }))
}

/// model = Linear: every mode advanced exactly; the statistics of the step and the impulse of
/// the modes' forces on the tank. Exact propagation cannot fail; only the fundamental mode can
/// run away (the higher ones respond less), so it is checked before anything changes.
fn step_linear(
    modes: &mut [(Mode, f64, ModeState)],
    zeta: f64,
    h: f64,
    base: &BaseAcceleration,
    limit: f64,
) -> Result<(SolveStats, f64), StepError> {
    let (first, mut impulse) = advance_mode(&modes[0], zeta, h, base);
    check_runaway(first.2.x, limit)?;
    modes[0] = first;
    for mode in modes.iter_mut().skip(1) {
        let (next, i) = advance_mode(mode, zeta, h, base);
        *mode = next;
        impulse += i;
    }
    Ok((
        SolveStats {
            accepted: 1,
            ..SolveStats::default()
        },
        impulse,
    ))
}

/// model = SloshingSlamming: the sloshing mode exactly, the impact mass event by event.
fn step_slamming(
    mode: &mut (Mode, f64, ModeState),
    impact: &mut (Slamming, f64, SlamState),
    zeta: f64,
    h: f64,
    base: &BaseAcceleration,
    limit: f64,
) -> Result<(SolveStats, f64), StepError> {
    let (sloshing, slosh_impulse) = advance_mode(mode, zeta, h, base);
    check_runaway(sloshing.2.x, limit)?;
    let mut slam = impact.2;
    let per_mass = impact
        .0
        .advance(&mut slam, h, base)
        .map_err(StepError::Chattering)?;
    let impulse = slosh_impulse + impact.1 * per_mass;
    *mode = sloshing;
    impact.2 = slam;
    Ok((
        SolveStats {
            accepted: 1,
            ..SolveStats::default()
        },
        impulse,
    ))
}

/// Refuse a step whose sloshing displacement left any physical range.
fn check_runaway(x: f64, limit: f64) -> Result<(), StepError> {
    if x.is_nan() || x.abs() > limit {
        Err(StepError::Runaway { x, limit })
    } else {
        Ok(())
    }
}

/// What evolves, by model.
// One per instance: the size difference costs nothing, boxing would add an indirection to
// every step.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
enum Dynamics {
    Nonlinear {
        model: NonlinearTld,
        integrator: Integrator,
        /// State per unit sloshing mass, see `physics::nonlinear::state`.
        y: [f64; state::DIM],
        /// model = Auto: the hardening below which a step is taken by the linear propagator, and
        /// that propagator (kept for its cached coefficients).
        linear_below: Option<(f64, Mode)>,
    },
    /// Each mode with its total modal mass and state; the first is the fundamental.
    Linear { modes: Vec<(Mode, f64, ModeState)> },
    /// S^2: the sloshing mode (mode, mass, state) and the impact mass (law, mass, state).
    Slamming {
        mode: (Mode, f64, ModeState),
        impact: (Slamming, f64, SlamState),
    },
}

impl Dynamics {
    /// Numbers of the model's state in a snapshot.
    fn state_len(&self) -> usize {
        match self {
            Dynamics::Nonlinear { .. } => state::DIM,
            Dynamics::Linear { modes } => 4 * modes.len(),
            Dynamics::Slamming { .. } => 4 + 6,
        }
    }
}

/// A configured damper and its state.
#[derive(Clone, Debug, PartialEq)]
pub struct Simulation {
    config: Config,
    derived: Derived,
    dynamics: Dynamics,
    tracker: Option<AmplitudeTracker>,
    /// Stored energy at the start [J]: counted as input.
    initial_energy: f64,
    amplitude: f64,
    /// Damping ratio in use.
    zeta: f64,
    last_mean_force: Option<f64>,
    /// Force of the liquid on the tanks at the current state [N] ([`Simulation::tank_force`]),
    /// kept with the state: a master reads it after every step, where it is a load.
    force: f64,
}

impl Simulation {
    pub fn new(config: Config) -> Result<(Self, Vec<String>), String> {
        let warnings = config.check()?;
        let derived = config.derived();
        let omega_f = derived.omega_f;
        let length = config.tank.length;
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
        let zeta = config.zeta(amplitude);
        let tanks = f64::from(config.tanks);
        let (dynamics, initial_energy) = match config.model {
            ModelKind::Nonlinear | ModelKind::NonlinearAuto { .. } => {
                let stiffness = PowerLaw::new(omega_f, config.phi, config.eta, length);
                let model = NonlinearTld {
                    stiffness,
                    c: 2.0 * zeta * omega_f,
                    base: BaseAcceleration::held(0.0),
                };
                let mut y = [0.0; state::DIM];
                y[state::X] = config.x0;
                y[state::V] = config.v0;
                let energy = derived.mass_slosh * model.stored_energy(config.x0, config.v0);
                (
                    Dynamics::Nonlinear {
                        model,
                        integrator: Self::integrator(&config, omega_f),
                        y,
                        linear_below: match config.model {
                            ModelKind::NonlinearAuto { threshold } => {
                                let tolerance = match config.method {
                                    Method::Adaptive { rtol, .. } => rtol,
                                    Method::Fixed { .. } => 1e-10,
                                };
                                let threshold = if threshold > 0.0 {
                                    threshold
                                } else {
                                    tolerance
                                };
                                Some((threshold, Mode::new(omega_f, zeta)))
                            }
                            _ => None,
                        },
                    },
                    energy,
                )
            }
            ModelKind::SloshingSlamming(p) => {
                let m1 = config.tank.fundamental();
                let omega = config.mass_exchange(&p, amplitude);
                let mode = Mode::new(m1.omega / omega.sqrt(), zeta);
                let sloshing = omega * m1.mass * tanks;
                let state = ModeState {
                    x: config.x0,
                    v: config.v0,
                    ..ModeState::default()
                };
                let slam = Slamming {
                    clearance: p.clearance,
                    restitution: p.restitution,
                    // A rebound slower than 1e-6 of the clearance crossed per sloshing period.
                    rest_speed: 1e-6 * p.clearance * m1.omega,
                };
                let impact_mass = (p.mass_ratio + 1.0 - omega) * m1.mass * tanks;
                let energy = sloshing * mode.stored_energy(&state);
                (
                    Dynamics::Slamming {
                        mode: (mode, sloshing, state),
                        impact: (slam, impact_mass, SlamState::default()),
                    },
                    energy,
                )
            }
            ModelKind::Linear { .. } => {
                let modes: Vec<(Mode, f64, ModeState)> = (1..=config.mode_count())
                    .map(|k| {
                        let m = config.tank.mode(k);
                        // The initial conditions belong to the fundamental mode.
                        let (x, v) = if k == 1 {
                            (config.x0, config.v0)
                        } else {
                            (0.0, 0.0)
                        };
                        (
                            Mode::new(m.omega, zeta),
                            m.mass * tanks,
                            ModeState {
                                x,
                                v,
                                ..ModeState::default()
                            },
                        )
                    })
                    .collect();
                let energy = modes
                    .iter()
                    .map(|(mode, mass, s)| mass * mode.stored_energy(s))
                    .sum();
                (Dynamics::Linear { modes }, energy)
            }
        };
        let mut sim = Simulation {
            config,
            derived,
            dynamics,
            tracker,
            initial_energy,
            amplitude,
            zeta,
            last_mean_force: None,
            force: 0.0,
        };
        sim.force = sim.tank_force();
        Ok((sim, warnings))
    }

    fn integrator(config: &Config, omega_f: f64) -> Integrator {
        let half = 0.5 * config.tank.length;
        match config.method {
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
                    AdaptiveKind::DormandPrince853 => {
                        Integrator::DormandPrince853(Dop853::new(rtol, scale, max_step, n))
                    }
                    AdaptiveKind::DormandPrince => {
                        Integrator::DormandPrince(Dopri5::new(rtol, scale, max_step, n))
                    }
                    AdaptiveKind::Sdirk4 => {
                        Integrator::Sdirk4(Sdirk4::new(rtol, scale, max_step, n))
                    }
                    AdaptiveKind::Auto => Integrator::Auto(Auto::new(rtol, scale, max_step, n)),
                }
            }
            Method::Fixed { formula, step } => {
                let n = config.max_substeps;
                match formula {
                    FixedFormula::Rk4 => Integrator::Rk4(Rk4::new(step, n)),
                    FixedFormula::Rk5 => Integrator::Rk5(Rk5::new(step, n)),
                    FixedFormula::Rk8 => Integrator::Rk8(Rk8::new(step, n)),
                    FixedFormula::ExpRk4 => Integrator::ExpRk4(ExpRk4::new(step, n)),
                }
            }
        }
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
    #[inline]
    pub fn step(&mut self, t: f64, h: f64, inputs: &Inputs) -> Result<SolveStats, StepError> {
        // Only a tracked amplitude moves the damping; a fixed one was applied in new().
        match &self.tracker {
            None => self.advance(self.zeta, t, h, inputs),
            Some(tracker) => {
                let mut tracker = tracker.clone();
                tracker.update(h, inputs.a, inputs.v);
                self.step_tracked(tracker, t, h, inputs)
            }
        }
    }

    /// [`Simulation::step`] with the amplitude tracker as it will be after the step.
    #[inline(never)]
    fn step_tracked(
        &mut self,
        tracker: AmplitudeTracker,
        t: f64,
        h: f64,
        inputs: &Inputs,
    ) -> Result<SolveStats, StepError> {
        let stats = self.advance(self.config.zeta(tracker.estimate()), t, h, inputs)?;
        self.amplitude = tracker.estimate();
        self.tracker = Some(tracker);
        Ok(stats)
    }

    /// [`Simulation::step`] with the damping ratio `zeta`: all but the amplitude tracker.
    /// Out of line: one copy for both kinds of amplitude.
    #[inline(never)]
    fn advance(
        &mut self,
        zeta: f64,
        t: f64,
        h: f64,
        inputs: &Inputs,
    ) -> Result<SolveStats, StepError> {
        let [a1, a2] = inputs.a_derivatives;
        // Each step is integrated in its own time, 0 to h: the model is autonomous but for the
        // input, and (t + h) - t is not h in floating point (at t = 3600 s and h = 1 ms, a
        // relative error of 1e-9 in every step's length).
        let base = BaseAcceleration {
            t0: 0.0,
            a: [inputs.a, a1, a2],
        };
        // The mean force divides the step's impulse by h: a division at the end of the step's
        // dependency chain costs its full latency; 1/h is ready long before.
        let inv_h = 1.0 / h;
        let limit = 100.0 * self.config.tank.length;
        let mass = self.derived.mass_slosh;
        let omega_f = self.derived.omega_f;
        // The impulse of each mode's force on the tank over the step follows from its velocity
        // change, v' = -a_b - f: integral f = -dv - integral a_b (for a Runge-Kutta step too:
        // h sum b_i f_i = -dv - h sum b_i a_b(t_i), the input's quadrature being exact).
        let (stats, impulse, force) = match &mut self.dynamics {
            Dynamics::Nonlinear {
                model,
                integrator,
                y,
                linear_below,
            } => {
                // The model takes this step's damping and input in place (field by field: a
                // whole-struct copy here stalls on store forwarding) and gets its previous ones
                // back if the step fails.
                let previous = (model.c, model.base);
                model.c = 2.0 * zeta * omega_f;
                model.base.t0 = 0.0;
                model.base.a = [inputs.a, a1, a2];
                let v0 = y[state::V];
                // model = Auto: the exact linear solution while the hardening is below the
                // threshold; otherwise the integrator.
                let linear = linear_below
                    .as_mut()
                    .and_then(|below| linear_step(model, below, zeta, y, h, &base, limit));
                let outcome = match linear {
                    Some(next) => next.map(|next| {
                        *y = next;
                        let stats = SolveStats {
                            accepted: 1,
                            ..SolveStats::default()
                        };
                        (stats, model.tank_force(y[state::X], y[state::V]))
                    }),
                    None => model.with_exponent(Interval {
                        integrator,
                        t,
                        h,
                        y,
                        limit,
                    }),
                };
                let (stats, force) = match outcome {
                    Ok(done) => done,
                    Err(e) => {
                        (model.c, model.base) = previous;
                        return Err(e);
                    }
                };
                let impulse = mass * (-(y[state::V] - v0) - base.integral(h));
                (stats, impulse, Some(mass * force))
            }
            Dynamics::Linear { modes } => {
                let (stats, impulse) = step_linear(modes, zeta, h, &base, limit)?;
                (stats, impulse, None)
            }
            Dynamics::Slamming { mode, impact } => {
                let (stats, impulse) = step_slamming(mode, impact, zeta, h, &base, limit)?;
                (stats, impulse, None)
            }
        };
        self.force = force.unwrap_or_else(|| self.tank_force());
        // 1/h overflows for a subnormal h (and 0 x inf is NaN): over so short a step the mean
        // force is the force.
        let mean_force = impulse * inv_h;
        self.last_mean_force = Some(if mean_force.is_finite() {
            mean_force
        } else {
            self.force
        });
        self.zeta = zeta;
        Ok(stats)
    }

    /// Everything that evolves, as a flat list of numbers (what the configuration does not
    /// determine). Restore with [`Simulation::restore`] and the same configuration.
    pub fn snapshot(&self) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.dynamics.state_len() + SNAPSHOT_EXTRA);
        let carried = match &self.dynamics {
            Dynamics::Nonlinear { integrator, y, .. } => {
                out.extend_from_slice(y);
                integrator.memory()
            }
            Dynamics::Linear { modes } => {
                for (_, _, s) in modes {
                    out.extend_from_slice(&[s.x, s.v, s.work_in, s.dissipated]);
                }
                [0.0; 3]
            }
            Dynamics::Slamming {
                mode: (_, _, s),
                impact: (_, _, i),
            } => {
                out.extend_from_slice(&[s.x, s.v, s.work_in, s.dissipated]);
                out.extend_from_slice(&[
                    i.z,
                    i.v,
                    f64::from(i.contact),
                    i.impacts as f64,
                    i.work_in,
                    i.dissipated,
                ]);
                [0.0; 3]
            }
        };
        out.extend_from_slice(&carried);
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
        let n = sim.dynamics.state_len();
        if snapshot.len() != n + SNAPSHOT_EXTRA {
            return Err(format!(
                "a state of this model has {} numbers, this one {}",
                n + SNAPSHOT_EXTRA,
                snapshot.len()
            ));
        }
        if snapshot.iter().any(|v| !v.is_finite()) {
            return Err("the state holds non-finite numbers".into());
        }
        let (model_state, rest) = snapshot.split_at(n);
        match &mut sim.dynamics {
            Dynamics::Nonlinear { integrator, y, .. } => {
                y.copy_from_slice(model_state);
                integrator.set_memory([rest[0], rest[1], rest[2]]);
            }
            Dynamics::Linear { modes } => {
                for ((_, _, s), v) in modes.iter_mut().zip(model_state.chunks_exact(4)) {
                    *s = ModeState {
                        x: v[0],
                        v: v[1],
                        work_in: v[2],
                        dissipated: v[3],
                    };
                }
            }
            Dynamics::Slamming { mode, impact } => {
                let (m, i) = model_state.split_at(4);
                mode.2 = ModeState {
                    x: m[0],
                    v: m[1],
                    work_in: m[2],
                    dissipated: m[3],
                };
                let contact = match i[2] {
                    0.0 => 0,
                    1.0 => 1,
                    -1.0 => -1,
                    _ => return Err("the state's wall-contact flag is not -1, 0 or 1".into()),
                };
                if i[0].abs() > 0.5 * impact.0.clearance || i[3] < 0.0 || i[3].fract() != 0.0 {
                    return Err("the impact mass's state is out of range".into());
                }
                impact.2 = SlamState {
                    z: i[0],
                    v: i[1],
                    contact,
                    impacts: i[3] as u64,
                    work_in: i[4],
                    dissipated: i[5],
                };
            }
        }
        let rest = &rest[3..];
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
        sim.zeta = sim.config.zeta(sim.amplitude);
        // The damping the last step used, where the model keeps it (the output derivatives
        // read it before the next step).
        let (zeta, omega_f) = (sim.zeta, sim.derived.omega_f);
        match &mut sim.dynamics {
            Dynamics::Nonlinear { model, .. } => model.c = 2.0 * zeta * omega_f,
            Dynamics::Linear { modes } => modes.iter_mut().for_each(|m| m.0.zeta = zeta),
            Dynamics::Slamming { mode, .. } => mode.0.zeta = zeta,
        }
        sim.force = sim.tank_force();
        Ok(sim)
    }

    /// The linear modes: all of them (Linear), the sloshing mode (SloshingSlamming).
    fn linear_modes(&self) -> &[(Mode, f64, ModeState)] {
        match &self.dynamics {
            Dynamics::Linear { modes } => modes,
            Dynamics::Slamming { mode, .. } => std::slice::from_ref(mode),
            Dynamics::Nonlinear { .. } => &[],
        }
    }

    /// The impact mass of the S^2 model: its mass and state.
    fn impact(&self) -> Option<(f64, &SlamState)> {
        match &self.dynamics {
            Dynamics::Slamming { impact, .. } => Some((impact.1, &impact.2)),
            _ => None,
        }
    }

    /// The output `which` now.
    #[inline]
    pub fn output(&self, which: Output, inputs: &Inputs) -> f64 {
        self.per_step_output(which)
            .unwrap_or_else(|| self.other_output(which, inputs))
    }

    /// The output `which` if it is one of the three a master reads after every step: loads,
    /// with no call and nothing that can panic (the FMI layer's per-step read then needs no
    /// stack frame). None for the others.
    #[inline(always)]
    pub fn per_step_output(&self, which: Output) -> Option<f64> {
        match which {
            Output::X => Some(self.x()),
            Output::V => Some(self.v()),
            Output::Force => Some(self.force),
            _ => None,
        }
    }

    /// The nonlinear model and its state, if that is the model.
    #[inline]
    fn nonlinear(&self) -> Option<(&NonlinearTld, &[f64; state::DIM])> {
        match &self.dynamics {
            Dynamics::Nonlinear { model, y, .. } => Some((model, y)),
            _ => None,
        }
    }

    /// The (fundamental) sloshing mass's state: its relative displacement and velocity.
    #[inline(always)]
    fn fundamental(&self) -> (f64, f64) {
        match &self.dynamics {
            Dynamics::Nonlinear { y, .. } => (y[state::X], y[state::V]),
            Dynamics::Slamming { mode, .. } => (mode.2.x, mode.2.v),
            // There is always a first mode.
            Dynamics::Linear { modes } => modes.first().map_or((0.0, 0.0), |m| (m.2.x, m.2.v)),
        }
    }

    /// Relative displacement of the (fundamental) sloshing mass.
    #[inline(always)]
    fn x(&self) -> f64 {
        self.fundamental().0
    }

    /// Relative velocity of the (fundamental) sloshing mass.
    #[inline(always)]
    fn v(&self) -> f64 {
        self.fundamental().1
    }

    /// Force of the liquid on the tanks, from the state (kept in [`Simulation::force`]).
    fn tank_force(&self) -> f64 {
        match self.nonlinear() {
            Some((model, y)) => {
                self.derived.mass_slosh * model.tank_force(y[state::X], y[state::V])
            }
            None => self
                .linear_modes()
                .iter()
                .map(|(mode, m, s)| m * mode.tank_force(s))
                .sum(),
        }
    }

    /// Every output but the three of [`Simulation::output`]'s direct branches (which it also
    /// answers).
    #[inline(never)]
    fn other_output(&self, which: Output, inputs: &Inputs) -> f64 {
        let m = self.derived.mass_slosh;
        let nonlinear = self.nonlinear();
        // Sums over the linear modes and the impact mass, formed only where an output needs them.
        let over_modes = |f: &dyn Fn(&Mode, &ModeState) -> f64| {
            self.linear_modes()
                .iter()
                .map(|(mode, m, s)| m * f(mode, s))
                .sum::<f64>()
        };
        let over_impact =
            |f: &dyn Fn(&SlamState) -> f64| self.impact().map_or(0.0, |(m, s)| m * f(s));
        match which {
            Output::X => self.x(),
            Output::V => self.v(),
            Output::Force => self.force,
            Output::ForceMean => self.last_mean_force.unwrap_or(self.force),
            // The impact mass resting on a wall moves with the tank, like the inactive liquid.
            Output::BaseShear => {
                self.force
                    - self.derived.mass_inactive * inputs.a
                    - over_impact(&|s| if s.contact != 0 { inputs.a } else { 0.0 })
            }
            Output::EnergyInput => {
                self.initial_energy
                    + nonlinear.map_or(0.0, |(_, y)| m * y[state::WORK_IN])
                    + over_modes(&|_, s| s.work_in)
                    + over_impact(&|s| s.work_in)
            }
            Output::EnergyDissipated => {
                nonlinear.map_or(0.0, |(_, y)| m * y[state::DISSIPATED])
                    + over_modes(&|_, s| s.dissipated)
                    + over_impact(&|s| s.dissipated)
            }
            Output::EnergyStored => {
                nonlinear.map_or(0.0, |(model, y)| {
                    m * model.stored_energy(y[state::X], y[state::V])
                }) + over_modes(&|mode, s| mode.stored_energy(s))
                    + over_impact(&|s| 0.5 * s.v * s.v)
            }
            Output::Amplitude => self.amplitude,
            Output::Zeta => self.zeta,
            Output::ImpactZ => self.impact().map_or(0.0, |(_, s)| s.z),
            Output::Impacts => self.impact().map_or(0.0, |(_, s)| s.impacts as f64),
        }
    }

    /// The exact first time derivative of the output `which` now (0 for quantities constant
    /// between communication points; the impacts themselves are instants, not rates).
    pub fn output_derivative(&self, which: Output, inputs: &Inputs) -> f64 {
        let a = inputs.a;
        // Per oscillator: mass, x, v, damping c, restoring force per mass and its slope.
        let mut terms: Vec<(f64, f64, f64, f64, f64, f64)> = match &self.dynamics {
            Dynamics::Nonlinear { model, y, .. } => {
                let (x, v) = (y[state::X], y[state::V]);
                vec![(
                    self.derived.mass_slosh,
                    x,
                    v,
                    model.c,
                    model.stiffness.force(x),
                    model.stiffness.slope(x),
                )]
            }
            _ => self
                .linear_modes()
                .iter()
                .map(|(mode, m, s)| {
                    let w2 = mode.omega * mode.omega;
                    (*m, s.x, s.v, 2.0 * mode.zeta * mode.omega, w2 * s.x, w2)
                })
                .collect(),
        };
        let acc = |&(_, _, v, c, f, _): &(f64, f64, f64, f64, f64, f64)| -a - c * v - f;
        let force: f64 = terms.iter().map(|t| t.0 * (t.3 * acc(t) + t.5 * t.2)).sum();
        let (x, v) = (terms[0].2, acc(&terms[0]));
        // The impact mass in flight: a free mass (no spring, no damper); at rest, still.
        let in_flight = self.impact().filter(|(_, s)| s.contact == 0);
        terms.extend(in_flight.map(|(m, s)| (m, s.z, s.v, 0.0, 0.0, 0.0)));
        match which {
            Output::Force => force,
            Output::BaseShear => {
                let resting = self
                    .impact()
                    .filter(|(_, s)| s.contact != 0)
                    .map_or(0.0, |(m, _)| m);
                force - (self.derived.mass_inactive + resting) * inputs.a_derivatives[0]
            }
            Output::X => x,
            Output::V => v,
            Output::EnergyInput => terms.iter().map(|t| -t.0 * a * t.2).sum(),
            Output::EnergyDissipated => terms.iter().map(|t| t.0 * t.3 * t.2 * t.2).sum(),
            Output::EnergyStored => terms.iter().map(|t| t.0 * t.2 * (acc(t) + t.4)).sum(),
            Output::ForceMean
            | Output::Amplitude
            | Output::Zeta
            | Output::ImpactZ
            | Output::Impacts => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config() -> Config {
        Config {
            model: ModelKind::Nonlinear,
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

    /// The S^2 model the tests run: Omega 0.9, a 0.1 m clearance.
    fn slamming() -> ModelKind {
        ModelKind::SloshingSlamming(SlammingParams {
            omega: 0.9,
            restitution: 0.4,
            clearance: 0.1,
            mass_ratio: 0.01,
        })
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

    /// A step whose displacement leaves every physical range is refused after a successful
    /// integration, or the exact linear step of model = Auto; the state and the integrator's
    /// carried step size stay as they were.
    #[test]
    fn a_runaway_step_changes_nothing() {
        let adaptive = |kind| Method::Adaptive {
            kind,
            rtol: 1e-8,
            max_step: 0.0,
        };
        for (model, method) in [
            adaptive(AdaptiveKind::DormandPrince),
            adaptive(AdaptiveKind::DormandPrince853),
            adaptive(AdaptiveKind::Sdirk4),
            adaptive(AdaptiveKind::Auto),
            Method::Fixed {
                formula: FixedFormula::Rk4,
                step: 0.01,
            },
            Method::Fixed {
                formula: FixedFormula::Rk5,
                step: 0.01,
            },
            Method::Fixed {
                formula: FixedFormula::Rk8,
                step: 0.01,
            },
            Method::Fixed {
                formula: FixedFormula::ExpRk4,
                step: 0.01,
            },
        ]
        .into_iter()
        .flat_map(|method| {
            // With phi = 0 the Auto model never leaves its exact linear step.
            [
                ModelKind::Nonlinear,
                ModelKind::NonlinearAuto { threshold: 0.0 },
            ]
            .map(|model| (model, method))
        }) {
            // Linear (phi = 0), so that a huge input is integrated without trouble.
            let cfg = Config {
                model,
                phi: 0.0,
                method,
                ..config()
            };
            let (mut sim, _) = Simulation::new(cfg).expect("config");
            let push = |a| Inputs {
                a,
                ..Inputs::default()
            };
            sim.step(0.0, 0.013, &push(0.3)).expect("an ordinary step");
            let before = sim.clone();
            let r = sim.step(0.013, 0.1, &push(-1e9));
            assert!(
                matches!(r, Err(StepError::Runaway { .. })),
                "{model:?} {method:?}: {r:?}"
            );
            assert_eq!(sim, before, "{model:?} {method:?}");
            sim.step(0.013, 0.01, &push(0.3)).expect("usable after");
        }
    }

    /// The force kept with the state is the state's force, bit for bit: from the start, after
    /// every step (the damping moving with a tracked amplitude), a refused step and a restore,
    /// for every model, kind of exponent and path through the step.
    #[test]
    fn the_force_kept_with_the_state_is_the_states_force() {
        let fixed = |formula| Method::Fixed {
            formula,
            step: 0.004,
        };
        let dp45 = config().method;
        let mut cases = vec![];
        for eta in [1.0, 1.5, 2.0, 2.5, 3.0, 5.0] {
            cases.push((ModelKind::Nonlinear, eta, dp45));
        }
        for method in [fixed(FixedFormula::Rk4), fixed(FixedFormula::ExpRk4)] {
            cases.push((ModelKind::Nonlinear, 2.0, method));
        }
        // Below the threshold (the exact linear step) while the motion is small, above it later.
        let auto = ModelKind::NonlinearAuto { threshold: 0.1 };
        cases.push((auto, 2.0, dp45));
        cases.push((ModelKind::Linear { modes: 3 }, 2.0, dp45));
        cases.push((slamming(), 2.0, dp45));
        for (model, eta, method) in cases {
            let cfg = Config {
                model,
                eta,
                method,
                x0: 0.02,
                amplitude: AmplitudeSource::Tracked {
                    tau: 0.0,
                    prior: 0.005,
                },
                ..config()
            };
            let same = |sim: &Simulation, when: &str| {
                let kept = sim.output(Output::Force, &Inputs::default());
                assert_eq!(
                    kept.to_bits(),
                    sim.tank_force().to_bits(),
                    "{model:?} eta {eta} {method:?}, {when}: {kept} vs {}",
                    sim.tank_force()
                );
                assert_ne!(kept, 0.0, "{model:?}: a state with a force");
                // x and v: the (first) sloshing mode's, first in the snapshot.
                let snapshot = sim.snapshot();
                for (which, k) in [(Output::X, 0), (Output::V, 1)] {
                    let got = sim.output(which, &Inputs::default());
                    assert_eq!(got.to_bits(), snapshot[k].to_bits(), "{model:?} {which:?}");
                }
            };
            let (mut sim, _) = Simulation::new(cfg).expect("config");
            same(&sim, "start");
            let mut zetas = vec![];
            let mut linear_steps = 0;
            for k in 0..300 {
                let t = f64::from(k) * 0.01;
                let inputs = Inputs {
                    a: 0.3 * (5.6 * t).sin(),
                    v: -0.3 / 5.6 * (5.6 * t).cos(),
                    ..Inputs::default()
                };
                let stats = sim.step(t, 0.01, &inputs).expect("step");
                same(&sim, &format!("step {k}"));
                zetas.push(sim.zeta);
                // The exact linear step of model = Auto evaluates nothing.
                linear_steps += usize::from(stats.evaluations == 0);
            }
            if matches!(model, ModelKind::NonlinearAuto { .. }) {
                assert!(
                    linear_steps > 0 && linear_steps < 300,
                    "{model:?}: both kinds of step ({linear_steps} linear)"
                );
            }
            assert_ne!(zetas[299], zetas[298], "{model:?}: the damping moves");
            let refused = sim.step(
                3.0,
                0.1,
                &Inputs {
                    a: -1e300,
                    ..Inputs::default()
                },
            );
            assert!(
                refused.is_err(),
                "{model:?} eta {eta} {method:?}: {refused:?} x {}",
                sim.x()
            );
            same(&sim, "a refused step");
            let restored = Simulation::restore(cfg, &sim.snapshot()).expect("restore");
            same(&restored, "restored");
            assert_eq!(restored.force.to_bits(), sim.force.to_bits());
        }
    }

    /// The shortest step there is (h = 5e-324, 1/h = inf) is taken, every output stays finite,
    /// and the simulation goes on; for every model.
    #[test]
    fn a_subnormal_step_gives_finite_outputs() {
        let rk4 = Method::Fixed {
            formula: FixedFormula::Rk4,
            step: 0.01,
        };
        for (model, method) in [
            (ModelKind::Nonlinear, config().method),
            (ModelKind::Nonlinear, rk4),
            (ModelKind::NonlinearAuto { threshold: 0.0 }, config().method),
            (ModelKind::Linear { modes: 2 }, config().method),
            (slamming(), config().method),
        ] {
            let cfg = Config {
                model,
                method,
                x0: 0.02,
                v0: 0.1,
                ..config()
            };
            let (mut sim, _) = Simulation::new(cfg).expect("config");
            let inputs = Inputs {
                a: 0.3,
                ..Inputs::default()
            };
            sim.step(0.0, 5e-324, &inputs).expect("a subnormal step");
            for which in [
                Output::Force,
                Output::ForceMean,
                Output::BaseShear,
                Output::X,
                Output::V,
                Output::EnergyInput,
                Output::EnergyDissipated,
                Output::EnergyStored,
                Output::Amplitude,
                Output::Zeta,
                Output::ImpactZ,
                Output::Impacts,
            ] {
                let value = sim.output(which, &inputs);
                assert!(value.is_finite(), "{model:?} {method:?} {which:?}: {value}");
            }
            sim.step(5e-324, 0.01, &inputs)
                .expect("an ordinary step after");
        }
    }

    #[test]
    fn a_restored_state_has_the_damping_of_its_last_step() {
        // Tracked amplitude: the damping moves with every step, and the output derivatives read
        // it from the model; a restored simulation must give the same ones as the original.
        for model in [
            ModelKind::Nonlinear,
            ModelKind::Linear { modes: 2 },
            slamming(),
        ] {
            let cfg = Config {
                model,
                amplitude: AmplitudeSource::Tracked {
                    tau: 0.0,
                    prior: 0.005,
                },
                ..config()
            };
            let (mut sim, _) = Simulation::new(cfg).expect("config");
            let zeta0 = sim.zeta;
            for k in 0..400 {
                let t = f64::from(k) * 0.01;
                let inputs = Inputs {
                    a: 0.5 * (5.6 * t).sin(),
                    v: -0.5 / 5.6 * (5.6 * t).cos(),
                    ..Inputs::default()
                };
                sim.step(t, 0.01, &inputs).expect("step");
            }
            assert!(
                (sim.zeta - zeta0).abs() > 1e-4 * zeta0,
                "{model:?}: the damping moved"
            );
            let restored = Simulation::restore(cfg, &sim.snapshot()).expect("restore");
            let inputs = Inputs {
                a: 0.3,
                ..Inputs::default()
            };
            for which in [Output::Force, Output::BaseShear] {
                assert_eq!(
                    restored.output_derivative(which, &inputs),
                    sim.output_derivative(which, &inputs),
                    "{model:?} {which:?}"
                );
            }
        }
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
