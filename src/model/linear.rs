//! model = Linear: `modes` linear sloshing modes (seed Eqs 2.1, 2.2), each advanced by its exact
//! solution, so no step size makes an integration error.

use super::check_runaway;
use super::rates::{self, Oscillator};
use super::{Common, Interval, Model, Observable, Output, Parameters, Start, StepError, Stepped};
use crate::description::{limits, vr};
use crate::physics::geometry::NaturalMode;
use crate::physics::linear::{ModalOscillator, ModeState};

mod continuous;
pub use continuous::ME_MODES;

/// Numbers saved after the modes' states: the integrator memory of the state format, unused.
const CARRIED: usize = 3;

/// One linear mode: its propagator, its modal mass (all tanks) and its state.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearMode {
    pub mode: ModalOscillator,
    pub mass: f64,
    pub state: ModeState,
}

impl LinearMode {
    /// This mode advanced exactly over `step`, and the impulse of its force on the tank over
    /// the step: v' = -a_b - f, so integral f = -dv - integral a_b (per unit mass).
    pub fn advanced(&self, step: &Interval) -> (Self, f64) {
        let (h, base) = (step.h, &step.base);
        let mut next = self.clone();
        next.mode.zeta = step.zeta;
        next.mode.advance(&mut next.state, h, base);
        let impulse = next.mass * (-(next.state.v - self.state.v) - base.integral(h));
        (next, impulse)
    }

    pub fn force(&self) -> f64 {
        self.mass * self.mode.tank_force(&self.state)
    }

    pub fn stored_energy(&self) -> f64 {
        self.mass * self.mode.stored_energy(&self.state)
    }

    /// The mode as an oscillator for the output rates.
    pub fn oscillator(&self) -> Oscillator {
        let (w, s) = (self.mode.omega, &self.state);
        let w2 = w * w;
        Oscillator {
            mass: self.mass,
            v: s.v,
            c: 2.0 * self.mode.zeta * w,
            c_per_zeta: 2.0 * w,
            restoring: w2 * s.x,
            slope: w2,
        }
    }

    pub fn save(&self, out: &mut Vec<f64>) {
        let s = &self.state;
        out.extend_from_slice(&[s.x, s.v, s.work_in, s.dissipated]);
    }

    pub fn load(&mut self, v: &[f64]) {
        self.state = ModeState {
            x: v[0],
            v: v[1],
            work_in: v[2],
            dissipated: v[3],
        };
    }
}

/// Numbers of [`LinearMode::save`].
pub const MODE_STATE: usize = 4;

/// The linear multi-mode model; the first mode is the fundamental.
#[derive(Clone, Debug, PartialEq)]
pub struct Linear {
    modes: Vec<LinearMode>,
    /// Sum of the modal masses, all tanks.
    sloshing_mass: f64,
}

impl Linear {
    /// The modes, the fundamental first.
    pub(super) fn modes(&self) -> &[LinearMode] {
        &self.modes
    }
}

impl Model for Linear {
    fn configure(p: &dyn Parameters, common: &Common, start: Start) -> Result<Self, String> {
        let modes = p.count(vr::MODES);
        let most = limits::MODES_MAX as u32;
        if !(1..=most).contains(&modes) {
            return Err(format!(
                "modes = {modes}: the linear model carries 1 to {most} modes"
            ));
        }
        let tanks = f64::from(common.tanks);
        let natural: Vec<NaturalMode> = (1..=modes).map(|k| common.tank.mode(k)).collect();
        let modes: Vec<LinearMode> = (1..)
            .zip(&natural)
            .map(|(k, m)| {
                // The initial condition belongs to the fundamental mode.
                let (x, v) = if k == 1 {
                    (common.x0, common.v0)
                } else {
                    (0.0, 0.0)
                };
                LinearMode {
                    mode: ModalOscillator::new(m.omega, start.zeta),
                    mass: m.mass * tanks,
                    state: ModeState {
                        x,
                        v,
                        ..ModeState::default()
                    },
                }
            })
            .collect();
        // The modal masses summed, then scaled to all tanks (as the calculated parameter
        // mass.slosh has always been formed).
        let sum = natural.iter().map(|m| m.mass).sum::<f64>();
        Ok(Linear {
            modes,
            sloshing_mass: sum * tanks,
        })
    }

    fn sloshing_mass(&self) -> f64 {
        self.sloshing_mass
    }

    /// Out of line: the steps of the other models stay small. Exact propagation cannot fail; only the fundamental mode can run away (the higher ones
    /// respond less), so it is checked before anything changes.
    #[inline(never)]
    fn step(&mut self, step: &Interval) -> Result<Stepped, StepError> {
        let (first, mut impulse) = self.modes[0].advanced(step);
        check_runaway(first.state.x, step.limit)?;
        self.modes[0] = first;
        for mode in self.modes.iter_mut().skip(1) {
            let (next, i) = mode.advanced(step);
            *mode = next;
            impulse += i;
        }
        Ok(Stepped::exact(impulse, self.force(), self.sloshing()))
    }

    #[inline(always)]
    fn sloshing(&self) -> (f64, f64) {
        // There is always a first mode.
        self.modes
            .first()
            .map_or((0.0, 0.0), |m| (m.state.x, m.state.v))
    }

    fn force(&self) -> f64 {
        self.modes.iter().map(LinearMode::force).sum()
    }

    fn observe(&self, which: Observable) -> f64 {
        let each = |f: fn(&LinearMode) -> f64| self.modes.iter().map(f).sum();
        match which {
            Observable::WorkIn => each(|m| m.mass * m.state.work_in),
            Observable::Dissipated => each(|m| m.mass * m.state.dissipated),
            Observable::Stored => each(LinearMode::stored_energy),
            Observable::ImpactZ | Observable::Impacts | Observable::ImpactImpulse => 0.0,
        }
    }

    fn rate(&self, which: Output, a: f64, _a_rate: f64) -> f64 {
        let oscillators: Vec<Oscillator> = self.modes.iter().map(LinearMode::oscillator).collect();
        rates::rate(which, &oscillators, &[], a)
    }

    fn set_damping(&mut self, zeta: f64) {
        self.modes.iter_mut().for_each(|m| m.mode.zeta = zeta);
    }

    fn state_len(&self) -> usize {
        MODE_STATE * self.modes.len() + CARRIED
    }

    fn save(&self, out: &mut Vec<f64>) {
        self.modes.iter().for_each(|m| m.save(out));
        out.extend_from_slice(&[0.0; CARRIED]);
    }

    fn load(&mut self, state: &[f64]) -> Result<(), String> {
        for (m, v) in self.modes.iter_mut().zip(state.chunks_exact(MODE_STATE)) {
            m.load(v);
        }
        Ok(())
    }
}
