//! model = SloshingSlamming (S^2, seed Eqs 2.5-2.8 as corrected in MODEL.md section 3): the
//! fundamental mode with mass Omega m_1 on its unchanged spring (frequency omega_1 / sqrt(Omega)),
//! advanced exactly, and an impact mass (mass_ratio + 1 - Omega) m_1 that slams on the walls
//! across the clearance, event by event.

use super::check_runaway;
use super::linear::{LinearMode, MODE_STATE};
use super::rates::{self, Oscillator};
use super::{Common, Interval, Model, Observable, Output, Parameters, Start, StepError, Stepped};
use crate::description::vr;
use crate::physics::laws::nsd_kappa;
use crate::physics::linear::{ModalOscillator, ModeState};
use crate::physics::slamming::{SlamState, Slamming};

mod continuous;
pub use continuous::{Event, ImpactTangent, REACH};

/// Numbers of the impact mass's state in a saved state, and the unused integrator memory after.
const IMPACT_STATE: usize = 6;
const CARRIED: usize = 3;

#[derive(Clone, Debug, PartialEq)]
pub struct SloshingSlamming {
    sloshing: LinearMode,
    impact: Slamming,
    /// The impact mass, all tanks [kg].
    impact_mass: f64,
    state: SlamState,
    /// Sloshing plus impact mass before the exchange, all tanks [kg].
    sloshing_mass: f64,
}

impl Model for SloshingSlamming {
    fn configure(p: &dyn Parameters, common: &Common, start: Start) -> Result<Self, String> {
        let clearance = p.value(vr::SLAMMING_CLEARANCE);
        let restitution = p.value(vr::SLAMMING_RESTITUTION);
        // Impact mass before the exchange over m_1 (the seed: 0.01).
        let mass_ratio = p.value(vr::SLAMMING_MASS_RATIO);
        if clearance > common.tank.length {
            return Err(format!(
                "slamming.clearance ({clearance} m) exceeds the tank length ({} m)",
                common.tank.length
            ));
        }
        let tanks = f64::from(common.tanks);
        let m1 = common.tank.fundamental();
        let sloshing_mass = (m1.mass + mass_ratio * m1.mass) * tanks;
        if common.liquid_mass() - sloshing_mass < 0.0 {
            return Err(format!(
                "slamming.mass_ratio ({mass_ratio}) takes more liquid than the tank holds"
            ));
        }
        // Mass exchange Omega in (0, 1]; 0: from the NSD hardening law, Omega = 1/kappa^2.
        let omega = match p.value(vr::SLAMMING_OMEGA) {
            o if o > 0.0 => o.min(1.0),
            _ => {
                let kappa = nsd_kappa(common.lambda.clamp(start.amplitude / common.tank.length));
                (1.0 / (kappa * kappa)).clamp(1e-3, 1.0)
            }
        };
        Ok(SloshingSlamming {
            sloshing: LinearMode {
                mode: ModalOscillator::new(m1.omega / omega.sqrt(), start.zeta),
                mass: omega * m1.mass * tanks,
                state: ModeState {
                    x: common.x0,
                    v: common.v0,
                    ..ModeState::default()
                },
            },
            impact: Slamming {
                clearance,
                restitution,
                // A rebound slower than 1e-6 of the clearance crossed per sloshing period.
                rest_speed: 1e-6 * clearance * m1.omega,
            },
            impact_mass: (mass_ratio + 1.0 - omega) * m1.mass * tanks,
            state: SlamState::default(),
            sloshing_mass,
        })
    }

    fn sloshing_mass(&self) -> f64 {
        self.sloshing_mass
    }

    /// Out of line: the steps of the other models stay small.
    #[inline(never)]
    fn step(&mut self, step: &Interval) -> Result<Stepped, StepError> {
        let (sloshing, slosh_impulse) = self.sloshing.advanced(step);
        check_runaway(sloshing.state.x, step.limit)?;
        let mut slam = self.state;
        let per_mass = self
            .impact
            .advance(&mut slam, step.h, &step.base)
            .map_err(StepError::Chattering)?;
        self.sloshing = sloshing;
        self.state = slam;
        let impulse = slosh_impulse + self.impact_mass * per_mass;
        Ok(Stepped::exact(impulse, self.force(), self.sloshing()))
    }

    #[inline(always)]
    fn sloshing(&self) -> (f64, f64) {
        (self.sloshing.state.x, self.sloshing.state.v)
    }

    /// The sloshing mode's force; the impact mass's reaches the tank as impulses, in the mean
    /// force only.
    fn force(&self) -> f64 {
        self.sloshing.force()
    }

    /// The impact mass resting on a wall moves with the tank, like the inactive liquid.
    fn rigid_mass(&self) -> f64 {
        if self.state.contact != 0 {
            self.impact_mass
        } else {
            0.0
        }
    }

    fn observe(&self, which: Observable) -> f64 {
        let (m, s, i) = (self.impact_mass, &self.sloshing, &self.state);
        match which {
            Observable::WorkIn => s.mass * s.state.work_in + m * i.work_in,
            Observable::Dissipated => s.mass * s.state.dissipated + m * i.dissipated,
            Observable::Stored => s.stored_energy() + m * (0.5 * i.v * i.v),
            Observable::ImpactZ => i.z,
            Observable::Impacts => i.impacts as f64,
            Observable::ImpactImpulse => m * i.impulse,
        }
    }

    /// The impact mass in flight is a free mass (no spring, no damper); at rest, still.
    fn rate(&self, which: Output, a: f64, _a_rate: f64) -> f64 {
        let oscillators: [Oscillator; 1] = [self.sloshing.oscillator()];
        let in_flight = [(self.impact_mass, self.state.v)];
        let free = if self.state.contact == 0 {
            &in_flight[..]
        } else {
            &[]
        };
        rates::rate(which, &oscillators, free, a)
    }

    fn set_damping(&mut self, zeta: f64) {
        self.sloshing.mode.zeta = zeta;
    }

    fn state_len(&self) -> usize {
        MODE_STATE + IMPACT_STATE + CARRIED
    }

    fn save(&self, out: &mut Vec<f64>) {
        self.sloshing.save(out);
        let i = &self.state;
        out.extend_from_slice(&[
            i.z,
            i.v,
            f64::from(i.contact),
            i.impacts as f64,
            i.work_in,
            i.dissipated,
        ]);
        out.extend_from_slice(&[0.0; CARRIED]);
    }

    fn load(&mut self, state: &[f64]) -> Result<(), String> {
        let (m, i) = state.split_at(MODE_STATE);
        let contact = match i[2] {
            0.0 => 0,
            1.0 => 1,
            -1.0 => -1,
            _ => return Err("the state's wall-contact flag is not -1, 0 or 1".into()),
        };
        if i[0].abs() > 0.5 * self.impact.clearance || i[3] < 0.0 || i[3].fract() != 0.0 {
            return Err("the impact mass's state is out of range".into());
        }
        self.sloshing.load(m);
        self.state = SlamState {
            z: i[0],
            v: i[1],
            contact,
            impacts: i[3] as u64,
            work_in: i[4],
            dissipated: i[5],
            // Saved apart (`extra`): this layout is pinned by tests/golden.
            impulse: self.state.impulse,
        };
        Ok(())
    }

    fn extra(&self) -> f64 {
        self.state.impulse
    }

    fn load_extra(&mut self, x: f64) -> Result<(), String> {
        if !x.is_finite() {
            return Err(format!("the impact impulse {x} is not finite"));
        }
        self.state.impulse = x;
        Ok(())
    }
}
