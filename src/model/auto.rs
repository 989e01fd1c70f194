//! model = Auto: the nonlinear model, stepped by the exact linear solution while its hardening
//! phi |2x/a|^(2 eta - 2) stays below `auto.threshold` over the whole step (Eq 2.11 is then
//! linear to that tolerance, and its exact solution is cheaper than any integrator), by the
//! integrator otherwise.

use super::check_runaway;
use super::nonlinear::{Nonlinear, Shortcut};
use super::{Common, Interval, Model, Observable, Output, Parameters, Start, StepError, Stepped};
use crate::description::vr;
use crate::physics::linear::{ModalOscillator, ModeState};
use crate::physics::nonlinear::{NonlinearTld, state};

#[derive(Clone, Debug, PartialEq)]
pub struct NonlinearAuto {
    nonlinear: Nonlinear,
    linear: LinearBelow,
}

/// The exact linear step while the hardening stays below `threshold`.
#[derive(Clone, Debug, PartialEq)]
struct LinearBelow {
    threshold: f64,
    /// The linear propagator (kept for its cached coefficients).
    mode: ModalOscillator,
}

impl Shortcut for LinearBelow {
    fn step(
        &mut self,
        tld: &NonlinearTld,
        y: &[f64; state::DIM],
        step: &Interval,
    ) -> Option<Result<[f64; state::DIM], StepError>> {
        linear_step(tld, (self.threshold, &mut self.mode), y, step)
    }
}

/// The nonlinear state advanced by the exact linear solution, if the hardening stays below
/// `threshold` over the whole step; None if it may not; a runaway error if the displacement
/// leaves `limit`. The bound on |x| over the step: the free amplitude now, plus twice the static
/// deflection and the growth of one step under the largest base acceleration of the step.
#[inline(never)]
fn linear_step(
    tld: &NonlinearTld,
    (threshold, mode): (f64, &mut ModalOscillator),
    y: &[f64; state::DIM],
    step: &Interval,
) -> Option<Result<[f64; state::DIM], StepError>> {
    let (h, base) = (step.h, &step.base);
    let omega_f = mode.omega;
    let (x, v) = (y[state::X], y[state::V]);
    let a_max = base.a[0].abs() + h * (base.a[1].abs() + 0.5 * h * base.a[2].abs());
    let bound =
        (x * x + (v / omega_f).powi(2)).sqrt() + a_max * (2.0 / (omega_f * omega_f) + h / omega_f);
    if tld.stiffness.hardening(bound) >= threshold {
        return None;
    }
    let mut next_mode = *mode;
    next_mode.zeta = step.zeta;
    let mut s = ModeState {
        x,
        v,
        work_in: y[state::WORK_IN],
        dissipated: y[state::DISSIPATED],
    };
    next_mode.advance(&mut s, h, base);
    // Without hardening (phi = 0) nothing else bounds the motion: checked as every step is.
    Some(check_runaway(s.x, step.limit).map(|()| {
        *mode = next_mode;
        [s.x, s.v, s.work_in, s.dissipated]
    }))
}

impl NonlinearAuto {
    /// The nonlinear model's oscillator (Model Exchange integrates its equations).
    pub(super) fn oscillator(&self) -> super::rates::Oscillator {
        self.nonlinear.oscillator()
    }
}

impl Model for NonlinearAuto {
    fn configure(p: &dyn Parameters, common: &Common, start: Start) -> Result<Self, String> {
        let nonlinear = Nonlinear::configure(p, common, start)?;
        // 0: the solver's tolerance.
        let threshold = match p.value(vr::AUTO_THRESHOLD) {
            t if t > 0.0 => t,
            _ => nonlinear.method.tolerance(),
        };
        let mode = ModalOscillator::new(common.tank.fundamental().omega, start.zeta);
        Ok(NonlinearAuto {
            nonlinear,
            linear: LinearBelow { threshold, mode },
        })
    }

    fn sloshing_mass(&self) -> f64 {
        self.nonlinear.sloshing_mass()
    }

    #[inline(always)]
    fn step(&mut self, step: &Interval) -> Result<Stepped, StepError> {
        let a = step.base.a;
        self.nonlinear.step_with(
            step.t,
            step.h,
            step.zeta,
            a[0],
            a[1],
            a[2],
            step.limit,
            Some(&mut self.linear),
        )
    }

    #[inline(always)]
    fn sloshing(&self) -> (f64, f64) {
        self.nonlinear.sloshing()
    }

    fn force(&self) -> f64 {
        self.nonlinear.force()
    }

    fn observe(&self, which: Observable) -> f64 {
        self.nonlinear.observe(which)
    }

    fn rate(&self, which: Output, a: f64, a_rate: f64) -> f64 {
        self.nonlinear.rate(which, a, a_rate)
    }

    fn set_damping(&mut self, zeta: f64) {
        self.nonlinear.set_damping(zeta);
    }

    fn state_len(&self) -> usize {
        self.nonlinear.state_len()
    }

    fn save(&self, out: &mut Vec<f64>) {
        self.nonlinear.save(out);
    }

    fn load(&mut self, state: &[f64]) -> Result<(), String> {
        self.nonlinear.load(state)
    }
}
