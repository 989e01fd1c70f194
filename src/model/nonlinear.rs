//! model = Nonlinear: the impact-characteristic model (seed Eq 2.11 with the power law Phi of
//! Eq 2.13) in one sloshing mass, integrated by the method `solver` names.

use super::check_runaway;
use super::rates::{self, Oscillator};
use super::{
    Common, Interval, Model, Observable, Output, Parameters, Start, StepError, Stepped, choice,
};
use crate::description::{SolverMethodItem, vr};
use crate::physics::base::BaseAcceleration;
use crate::physics::nonlinear::{CompiledTld, NonlinearTld, RhsJob, state};
use crate::physics::power::PowerLaw;
use crate::solver::{
    Auto, Dop853, Dopri5, ExpRk4, OscillatorSplit, Rk4, Rk5, Rk8, Sdirk4, SolveError, SolveStats,
};

/// Integrator inside a communication step, as the `solver` parameters describe it.
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
    /// Exponential (Lawson) RK4: the linear oscillator by its exact flow, RK4 on the rest.
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
    /// Per interval, explicit or implicit as the local stiffness calls for (the solver item
    /// "Auto", not the model item of that name).
    StiffnessSwitching,
}

impl Method {
    /// The method the `solver` parameters describe.
    pub fn read(p: &dyn Parameters) -> Result<Self, String> {
        let adaptive = |kind| Method::Adaptive {
            kind,
            rtol: p.value(vr::SOLVER_TOLERANCE),
            max_step: p.value(vr::SOLVER_MAX_STEP),
        };
        let fixed = |formula| Method::Fixed {
            formula,
            step: p.value(vr::SOLVER_FIXED_STEP),
        };
        Ok(match choice(p, vr::SOLVER)? {
            SolverMethodItem::DormandPrince45 => adaptive(AdaptiveKind::DormandPrince),
            SolverMethodItem::RK4 => fixed(FixedFormula::Rk4),
            SolverMethodItem::SDIRK4 => adaptive(AdaptiveKind::Sdirk4),
            SolverMethodItem::Auto => adaptive(AdaptiveKind::StiffnessSwitching),
            SolverMethodItem::DormandPrince853 => adaptive(AdaptiveKind::DormandPrince853),
            SolverMethodItem::RK5 => fixed(FixedFormula::Rk5),
            SolverMethodItem::RK8 => fixed(FixedFormula::Rk8),
            SolverMethodItem::ExpRK4 => fixed(FixedFormula::ExpRk4),
        })
    }

    /// The relative tolerance the method works to (fixed steps: none; 1e-10 stands for it).
    pub fn tolerance(&self) -> f64 {
        match *self {
            Method::Adaptive { rtol, .. } => rtol,
            Method::Fixed { .. } => 1e-10,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Integrator {
    DormandPrince(Dopri5<{ state::DIM }>),
    DormandPrince853(Dop853<{ state::DIM }>),
    Sdirk4(Sdirk4<{ state::DIM }>),
    StiffnessSwitching(Auto<{ state::DIM }>),
    Rk4(Rk4),
    Rk5(Rk5),
    Rk8(Rk8),
    ExpRk4(ExpRk4),
}

/// Numbers an integrator carries from one interval to the next (its step sizes).
const CARRIED: usize = 3;

impl Integrator {
    /// The integrator for `method`, its error scaled to half a tank length (and the matching
    /// velocity) and bounded to `max_steps` internal steps per interval.
    fn new(method: Method, half_length: f64, omega_f: f64, max_steps: u64) -> Self {
        match method {
            Method::Adaptive {
                kind,
                rtol,
                max_step,
            } => {
                let mut scale = [0.0; state::DIM];
                scale[state::X] = half_length;
                scale[state::V] = omega_f * half_length;
                let max_step = if max_step > 0.0 {
                    max_step
                } else {
                    f64::INFINITY
                };
                let n = max_steps;
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
                    AdaptiveKind::StiffnessSwitching => {
                        Integrator::StiffnessSwitching(Auto::new(rtol, scale, max_step, n))
                    }
                }
            }
            Method::Fixed { formula, step } => match formula {
                FixedFormula::Rk4 => Integrator::Rk4(Rk4::new(step, max_steps)),
                FixedFormula::Rk5 => Integrator::Rk5(Rk5::new(step, max_steps)),
                FixedFormula::Rk8 => Integrator::Rk8(Rk8::new(step, max_steps)),
                FixedFormula::ExpRk4 => Integrator::ExpRk4(ExpRk4::new(step, max_steps)),
            },
        }
    }

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
            // The cheapest steps inline; they carry nothing from one interval to the next.
            Integrator::Rk4(m) => checked(y, t, limit, |z| m.integrate(model, 0.0, h, z)),
            Integrator::ExpRk4(m) => checked(y, t, limit, |z| m.integrate(model, 0.0, h, z)),
            other => other.integrate_any(model, t, h, y, limit),
        }
    }

    /// Any integrator, out of line: the error-controlled ones inlined for every kind of exponent
    /// would make the step too large a function for the cheap steps' sake.
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
        let outcome = match self {
            // The default method's driver and stages here, with the copy of the state: behind a
            // call, its state and slopes would pass through memory (defaults 7 % faster).
            Integrator::DormandPrince(m) => {
                checked(y, t, limit, |z| m.integrate_inlined(model, 0.0, h, z))
            }
            Integrator::DormandPrince853(m) => {
                checked(y, t, limit, |z| m.integrate(model, 0.0, h, z))
            }
            Integrator::Sdirk4(m) => checked(y, t, limit, |z| m.integrate(model, 0.0, h, z)),
            Integrator::StiffnessSwitching(m) => {
                checked(y, t, limit, |z| m.integrate(model, 0.0, h, z))
            }
            Integrator::Rk5(m) => checked(y, t, limit, |z| m.integrate(model, 0.0, h, z)),
            Integrator::Rk8(m) => checked(y, t, limit, |z| m.integrate(model, 0.0, h, z)),
            Integrator::Rk4(m) => checked(y, t, limit, |z| m.integrate(model, 0.0, h, z)),
            Integrator::ExpRk4(m) => checked(y, t, limit, |z| m.integrate(model, 0.0, h, z)),
        };
        if outcome.is_err() {
            self.set_memory(carried);
        }
        outcome
    }

    /// What is carried between intervals (what the configuration does not determine).
    fn memory(&self) -> [f64; CARRIED] {
        match self {
            Integrator::DormandPrince(m) => [m.carried_step(), 0.0, 0.0],
            Integrator::DormandPrince853(m) => [m.carried_step(), 0.0, 0.0],
            Integrator::Sdirk4(m) => [m.carried_step(), 0.0, 0.0],
            Integrator::StiffnessSwitching(m) => m.memory(),
            Integrator::Rk4(_)
            | Integrator::Rk5(_)
            | Integrator::Rk8(_)
            | Integrator::ExpRk4(_) => [0.0; CARRIED],
        }
    }

    fn set_memory(&mut self, h: [f64; CARRIED]) {
        match self {
            Integrator::DormandPrince(m) => m.set_carried_step(h[0]),
            Integrator::DormandPrince853(m) => m.set_carried_step(h[0]),
            Integrator::Sdirk4(m) => m.set_carried_step(h[0]),
            Integrator::StiffnessSwitching(m) => m.set_memory(h),
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

/// One interval of the integrator, handed the model compiled for its exponent.
struct Integration<'a> {
    integrator: &'a mut Integrator,
    t: f64,
    h: f64,
    y: &'a mut [f64; state::DIM],
    limit: f64,
}

impl RhsJob for Integration<'_> {
    /// The step's statistics and the force per unit sloshing mass at its end.
    type Output = Result<(SolveStats, f64), StepError>;
    fn run<F: CompiledTld>(self, f: &F) -> Self::Output {
        let stats = self
            .integrator
            .integrate(f, self.t, self.h, self.y, self.limit)?;
        Ok((stats, f.tank_force(self.y[state::X], self.y[state::V])))
    }
}

/// A way to take a step of the nonlinear model without its integrator (model = Auto's exact
/// linear step).
pub trait Shortcut {
    /// The state `y` of `tld` at the end of `step`, a runaway, or None: integrate.
    fn step(
        &mut self,
        tld: &NonlinearTld,
        y: &[f64; state::DIM],
        step: &Interval,
    ) -> Option<Result<[f64; state::DIM], StepError>>;
}

/// [`Shortcut::step`] over the interval of these parts, out of line: the interval is made in
/// memory only here. Made in the step, its stores (ten) were paid on every step of every
/// nonlinear model, and a step's stores, not its instructions, are what its time follows at RK4
/// one substep (docs/ARCHITECTURE.md, *Costs*).
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn take_shortcut(
    shortcut: &mut dyn Shortcut,
    tld: &NonlinearTld,
    y: &[f64; state::DIM],
    t: f64,
    h: f64,
    zeta: f64,
    a0: f64,
    a1: f64,
    a2: f64,
    limit: f64,
) -> Option<Result<[f64; state::DIM], StepError>> {
    let step = Interval {
        t,
        h,
        zeta,
        base: BaseAcceleration {
            t0: 0.0,
            a: [a0, a1, a2],
        },
        limit,
    };
    shortcut.step(tld, y, &step)
}

#[derive(Clone, Debug, PartialEq)]
pub struct Nonlinear {
    pub(super) tld: NonlinearTld,
    integrator: Integrator,
    /// State per unit sloshing mass, see `physics::nonlinear::state`.
    pub(super) y: [f64; state::DIM],
    /// The sloshing mass, all tanks [kg].
    mass: f64,
    omega_f: f64,
    pub(super) method: Method,
}

impl Nonlinear {
    /// [`Model::step`], taking the `shortcut` where it offers the step's end. One function for
    /// both nonlinear models: two copies of the integrators inlined for every kind of exponent
    /// would make the cheapest steps dearer. The interval comes in scalars, in registers: an
    /// [`Interval`] passed by reference would be read back from memory at the start of the
    /// step's dependency chain.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn step_with(
        &mut self,
        t: f64,
        h: f64,
        zeta: f64,
        a0: f64,
        a1: f64,
        a2: f64,
        limit: f64,
        shortcut: Option<&mut dyn Shortcut>,
    ) -> Result<Stepped, StepError> {
        let base = BaseAcceleration {
            t0: 0.0,
            a: [a0, a1, a2],
        };
        // The model takes this step's damping and input in place (field by field: a whole-struct
        // copy here stalls on store forwarding) and gets its previous ones back if the step fails.
        // Only what changed is stored: a held input under a constant damping ratio changes
        // base.a alone, and a store costs more on this path than a compare.
        let previous = (self.tld.c, self.tld.base);
        keep(&mut self.tld.c, 2.0 * zeta * self.omega_f);
        keep(&mut self.tld.base.t0, 0.0);
        self.tld.base.a[0] = a0;
        keep(&mut self.tld.base.a[1], a1);
        keep(&mut self.tld.base.a[2], a2);
        // The input's part of the impulse, formed before the step: one value kept across it
        // instead of the input and h.
        let input_impulse = base.integral(h);
        let v0 = self.y[state::V];
        // (No shortcut: straight to the integration, no answer of the shortcut's kept in memory.)
        let outcome = if let Some(s) = shortcut
            && let Some(next) = take_shortcut(s, &self.tld, &self.y, t, h, zeta, a0, a1, a2, limit)
        {
            next.map(|next| {
                self.y = next;
                let stats = SolveStats {
                    accepted: 1,
                    ..SolveStats::default()
                };
                (stats, self.tld.tank_force(next[state::X], next[state::V]))
            })
        } else {
            self.tld.with_exponent(Integration {
                integrator: &mut self.integrator,
                t,
                h,
                y: &mut self.y,
                limit,
            })
        };
        let (stats, force) = match outcome {
            Ok(done) => done,
            Err(e) => {
                (self.tld.c, self.tld.base) = previous;
                return Err(e);
            }
        };
        // The impulse on the tank follows from the velocity change, v' = -a_b - f:
        // integral f = -dv - integral a_b (for a Runge-Kutta step too, the input's quadrature
        // being exact).
        let impulse = self.mass * (-(self.y[state::V] - v0) - input_impulse);
        Ok(Stepped {
            stats,
            impulse,
            force: self.mass * force,
            sloshing: (self.y[state::X], self.y[state::V]),
        })
    }
}

/// `*slot = value`, storing only if the bits differ (the same bits in memory either way).
#[inline(always)]
fn keep(slot: &mut f64, value: f64) {
    if slot.to_bits() != value.to_bits() {
        *slot = value;
    }
}

impl Nonlinear {
    /// The sloshing mass as an oscillator now: Phi of Eq 2.13 and its slope at x.
    pub(super) fn oscillator(&self) -> Oscillator {
        let (x, v) = self.sloshing();
        Oscillator {
            mass: self.mass,
            v,
            c: self.tld.c,
            c_per_zeta: 2.0 * self.omega_f,
            restoring: self.tld.stiffness.force(x),
            slope: self.tld.stiffness.slope(x),
        }
    }
}

impl Model for Nonlinear {
    fn configure(p: &dyn Parameters, common: &Common, start: Start) -> Result<Self, String> {
        let fundamental = common.tank.fundamental();
        let omega_f = fundamental.omega;
        let length = common.tank.length;
        let method = Method::read(p)?;
        let tld = NonlinearTld {
            stiffness: PowerLaw::new(omega_f, p.value(vr::PHI), p.value(vr::ETA), length),
            c: 2.0 * start.zeta * omega_f,
            base: BaseAcceleration::held(0.0),
        };
        let mut y = [0.0; state::DIM];
        y[state::X] = common.x0;
        y[state::V] = common.v0;
        let max_steps = p.value(vr::SOLVER_MAX_SUBSTEPS) as u64;
        Ok(Nonlinear {
            tld,
            integrator: Integrator::new(method, 0.5 * length, omega_f, max_steps),
            y,
            mass: fundamental.mass * f64::from(common.tanks),
            omega_f,
            method,
        })
    }

    fn sloshing_mass(&self) -> f64 {
        self.mass
    }

    #[inline(always)]
    fn step(&mut self, step: &Interval) -> Result<Stepped, StepError> {
        let a = step.base.a;
        self.step_with(
            step.t, step.h, step.zeta, a[0], a[1], a[2], step.limit, None,
        )
    }

    #[inline(always)]
    fn sloshing(&self) -> (f64, f64) {
        (self.y[state::X], self.y[state::V])
    }

    fn force(&self) -> f64 {
        self.mass * self.tld.tank_force(self.y[state::X], self.y[state::V])
    }

    fn observe(&self, which: Observable) -> f64 {
        let (m, y) = (self.mass, &self.y);
        match which {
            Observable::WorkIn => m * y[state::WORK_IN],
            Observable::Dissipated => m * y[state::DISSIPATED],
            Observable::Stored => m * self.tld.stored_energy(y[state::X], y[state::V]),
            Observable::ImpactZ | Observable::Impacts | Observable::ImpactImpulse => 0.0,
        }
    }

    fn rate(&self, which: Output, a: f64, _a_rate: f64) -> f64 {
        rates::rate(which, &[self.oscillator()], &[], a)
    }

    fn set_damping(&mut self, zeta: f64) {
        self.tld.c = 2.0 * zeta * self.omega_f;
    }

    fn state_len(&self) -> usize {
        state::DIM + CARRIED
    }

    fn save(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(&self.y);
        out.extend_from_slice(&self.integrator.memory());
    }

    fn load(&mut self, s: &[f64]) -> Result<(), String> {
        let (y, carried) = s.split_at(state::DIM);
        self.y.copy_from_slice(y);
        self.integrator
            .set_memory([carried[0], carried[1], carried[2]]);
        Ok(())
    }
}
