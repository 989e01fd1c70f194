//! Model Exchange, the models' side: which models a host's own solver can integrate, and their
//! continuous states. The offered models are one oscillator of Eq 2.11 (Linear with one mode,
//! Nonlinear, Auto, the sloshing mode of SloshingSlamming), whose states are the sloshing
//! mass's relative displacement and velocity and the two energy integrals, [x, v,
//! energy.input, energy.dissipated], and S^2's impact mass, [impact.z, impact.v] (the other
//! models keep these two at 0, their derivatives 0); their time derivatives are the exact
//! output rates every model already provides ([`Model::rate`]), so no equation is written
//! twice. S^2's impacts are state events (`model::events`). Knows no FMI.
//!
//! The Linear model's modes 2 to [`ME_MODES`] are a bank of (x, v) pairs after these
//! (`linear::continuous`); the other models keep them at 0, their derivatives 0.
//!
//! ShallowWater is offered with swe.cells up to the bank of cells the model description
//! declares after all these (`shallow_water::continuous`): its cells are states of their own,
//! and x, v and dissipated are functions of them.
//!
//! Not offered, with its reason: ShallowWater with more cells than the bank; Linear with more
//! than [`ME_MODES`] modes.
//!
//! Directional derivatives (J d, for a host's implicit solver): the exact derivatives of the
//! same rates in the states, the base acceleration and the damping ratio (which amplitude =
//! Tracked moves with the estimator's states: the damper gives its change), from the
//! oscillator's restoring force f(x) and its slope f'(x) (Phi of Eq 2.13 and dPhi/dx; finite at
//! x = 0 for every eta >= 1).
//!
//! [`Model::rate`]: super::Model::rate

use super::linear::ME_MODES;
use super::rates::{Change, Oscillator};
use super::registry::AnyModel;
use super::{Observable, Output};

/// Numbers of continuous states: x, v, energy.input, energy.dissipated, impact.z, impact.v,
/// then the bank of the Linear model's modes 2 to ME_MODES, (x, v) each.
pub const STATES: usize = BANK + 2 * (ME_MODES - 1);
/// Where S^2's impact mass's position and velocity are among the states.
pub const IMPACT_Z: usize = 4;
pub const IMPACT_V: usize = 5;
/// Where the base's work (energy.input) is among the states.
pub const ENERGY_INPUT: usize = 2;
/// Where the bank of higher modes begins.
pub const BANK: usize = 6;

/// All the continuous states the model description declares: those, the amplitude
/// estimator's (amplitude = Tracked) and the ShallowWater cell bank, in that order.
pub const ALL_STATES: usize = STATES
    + crate::physics::amplitude::TRACKER_CONTINUOUS
    + super::shallow_water::continuous::CELL_STATES;

/// The outputs whose rates are the states' derivatives, in state order.
pub const RATES: [Output; 4] = [
    Output::X,
    Output::V,
    Output::EnergyInput,
    Output::EnergyDissipated,
];

/// A direction d in the continuous states and the inputs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Direction {
    /// Changes of [x, v, energy.input, energy.dissipated].
    pub states: [f64; STATES],
    /// Changes of the inputs base.a [m/s^2], base.v [m/s], base.x [m]. No equation reads
    /// base.x, and base.v only the estimator's once it measures the velocity: their columns
    /// of J are 0 otherwise.
    pub a: f64,
    pub v: f64,
    pub x: f64,
    /// Changes of the amplitude estimator's states (amplitude = Tracked).
    pub tracker: [f64; crate::physics::amplitude::TRACKER_CONTINUOUS],
    /// The change of the damping ratio they make (through the estimate and the damping law;
    /// the damper sets it, 0 with a fixed amplitude).
    pub zeta: f64,
}

/// J d of the offered models' continuous part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tangent {
    /// Of the states' derivatives, in state order.
    pub derivatives: [f64; STATES],
    /// Of the force on the tanks [N], of the stored energy [J] and of impact.z [m].
    pub force: f64,
    pub stored: f64,
    pub impact_z: f64,
}

impl AnyModel {
    /// The model's one oscillator, if it is one of those offered in Model Exchange.
    fn oscillator(&self) -> Option<Oscillator> {
        match self {
            AnyModel::Linear(m) => m.modes().first().map(|first| first.oscillator()),
            AnyModel::Nonlinear(m) => Some(m.oscillator()),
            AnyModel::Auto(m) => Some(m.oscillator()),
            AnyModel::SloshingSlamming(m) => Some(m.oscillator()),
            AnyModel::ShallowWater(_) => None,
        }
    }

    /// J d under base acceleration `a`: the exact change of the states' derivatives, the force
    /// and the stored energy for the direction `d`. Err for a model not offered in Model
    /// Exchange.
    pub fn continuous_tangent(&self, a: f64, d: &Direction) -> Result<Tangent, String> {
        self.offers_model_exchange()?;
        let o = self
            .oscillator()
            .ok_or("this model has no directional derivatives")?;
        let change = Change {
            dx: d.states[0],
            dv: d.states[1],
            da: d.a,
            dzeta: d.zeta,
        };
        // The energies' derivatives do not read the energies: their columns are 0.
        let mut t = Tangent {
            derivatives: [0.0; STATES],
            force: o.force_tangent(change),
            stored: o.stored_tangent(change),
            impact_z: 0.0,
        };
        for (k, which) in RATES.into_iter().enumerate() {
            t.derivatives[k] = o.rate_tangent(which, a, change).unwrap_or(0.0);
        }
        // S^2's impact mass: a free mass in flight (no spring, no damper), still on a wall.
        if let AnyModel::SloshingSlamming(m) = self {
            let i = m.impact_tangent(a, d.states[IMPACT_V], d.a);
            t.derivatives[2] += i.power;
            t.derivatives[IMPACT_Z] = i.z_rate;
            t.derivatives[IMPACT_V] = i.v_rate;
            t.stored += i.kinetic;
            t.impact_z = d.states[IMPACT_Z];
        }
        if let AnyModel::Linear(m) = self {
            let bank = m.bank_tangent(a, &d.states[BANK..], d.a, d.zeta);
            t.derivatives[BANK..BANK + bank.derivatives.len()].copy_from_slice(&bank.derivatives);
            t.derivatives[2] += bank.power;
            t.derivatives[3] += bank.dissipation;
            t.force += bank.force;
            t.stored += bank.stored;
        }
        Ok(t)
    }

    /// Ok if the host's solver can integrate this model; Err: why not.
    pub fn offers_model_exchange(&self) -> Result<(), String> {
        match self {
            AnyModel::Linear(m) if m.modes().len() > ME_MODES => Err(format!(
                "model = Linear with modes = {}: Model Exchange declares the states of at most \
                 {ME_MODES} modes (the model description's number of states is fixed); use \
                 modes <= {ME_MODES}, or Co-Simulation for more modes",
                m.modes().len()
            )),
            AnyModel::Linear(_)
            | AnyModel::Nonlinear(_)
            | AnyModel::Auto(_)
            | AnyModel::SloshingSlamming(_) => Ok(()),
            AnyModel::ShallowWater(m) => m.fits_model_exchange(),
        }
    }

    /// The continuous states [x, v, work in, dissipated, impact.z, impact.v]; `initial_energy`
    /// is counted as input (as the output energy.input does).
    pub fn continuous_states(&self, initial_energy: f64) -> [f64; STATES] {
        let (x, v) = self.sloshing();
        let mut s = [0.0; STATES];
        s[..4].copy_from_slice(&[
            x,
            v,
            initial_energy + self.observe(Observable::WorkIn),
            self.observe(Observable::Dissipated),
        ]);
        match self {
            AnyModel::SloshingSlamming(m) => (s[IMPACT_Z], s[IMPACT_V]) = m.impact_state(),
            AnyModel::Linear(m) => m.bank_states(&mut s[BANK..]),
            _ => {}
        }
        s
    }

    /// Take the continuous states `s` (as [`AnyModel::continuous_states`] gives them).
    pub fn set_continuous_states(
        &mut self,
        s: &[f64; STATES],
        initial_energy: f64,
    ) -> Result<(), String> {
        if let AnyModel::SloshingSlamming(m) = self {
            let (z, vz) = (s[IMPACT_Z], s[IMPACT_V]);
            m.set_continuous(s[0], s[1], s[2] - initial_energy, s[3], z, vz);
            return Ok(());
        }
        if let AnyModel::Linear(m) = self {
            m.set_continuous(s[0], s[1], s[2] - initial_energy, s[3], &s[BANK..]);
            return Ok(());
        }
        // Nonlinear's and Auto's saved numbers begin with the oscillator's state per unit
        // sloshing mass: x, v, work in, dissipated (the tests check it). The impact mass's and
        // the bank's states: unused here (kept at 0 and read back as 0).
        let mass = self.sloshing_mass();
        let mut saved = Vec::with_capacity(self.state_len());
        self.save(&mut saved);
        saved[0] = s[0];
        saved[1] = s[1];
        saved[2] = (s[2] - initial_energy) / mass;
        saved[3] = s[3] / mass;
        self.load(&saved)
    }

    /// The states' time derivatives under base acceleration `a`.
    pub fn continuous_derivatives(&self, a: f64) -> [f64; STATES] {
        let mut d = [0.0; STATES];
        for (k, which) in RATES.into_iter().enumerate() {
            d[k] = self.rate(which, a, 0.0);
        }
        match self {
            AnyModel::SloshingSlamming(m) => (d[IMPACT_Z], d[IMPACT_V]) = m.impact_rates(a),
            AnyModel::Linear(m) => m.bank_rates(a, &mut d[BANK..]),
            _ => {}
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::{ModelKindItem, vr};
    use crate::model::{Common, Start, StartValues};

    fn model(item: ModelKindItem, modes: f64) -> AnyModel {
        let p = StartValues::default().with(vr::MODES, modes);
        let (common, _) = Common::read(&p).expect("start values are consistent");
        let start = Start {
            zeta: 0.02,
            amplitude: 0.005,
        };
        AnyModel::configure(item, &p, &common, start).expect("configures")
    }

    /// Every offered model takes its continuous states back (so the saved layout they are
    /// written into is the one its outputs read), and its derivatives are x' = v and the
    /// energies' rates.
    #[test]
    fn offered_models_take_their_states_and_report_them() {
        for item in [
            ModelKindItem::Linear,
            ModelKindItem::Nonlinear,
            ModelKindItem::Auto,
        ] {
            let mut m = model(item, 1.0);
            assert!(m.offers_model_exchange().is_ok(), "{item:?}");
            let mut s = [0.0; STATES];
            s[..4].copy_from_slice(&[0.0123, -0.045, 0.75, 0.125]);
            // The impact mass's states, which these models have not: ignored, read as 0,
            // their derivatives 0.
            (s[IMPACT_Z], s[IMPACT_V]) = (0.01, 0.2);
            m.set_continuous_states(&s, 0.25).expect("takes them");
            let back = m.continuous_states(0.25);
            assert_eq!((back[IMPACT_Z], back[IMPACT_V]), (0.0, 0.0), "{item:?}");
            for k in 0..4 {
                assert!(
                    (back[k] - s[k]).abs() <= 1e-14 * s[k].abs().max(1.0),
                    "{item:?} state {k}: {} vs {}",
                    back[k],
                    s[k]
                );
            }
            assert_eq!(m.sloshing(), (s[0], s[1]));
            let d = m.continuous_derivatives(0.3);
            assert_eq!(d[0], s[1], "{item:?}");
            assert_eq!((d[IMPACT_Z], d[IMPACT_V]), (0.0, 0.0), "{item:?}");
            // The base's power on the sloshing mass, -m a v.
            let want = -m.sloshing_mass() * 0.3 * s[1];
            assert!((d[2] - want).abs() <= 1e-14 * want.abs(), "{item:?}");
        }
    }

    /// The models that are not offered say why.
    #[test]
    fn models_not_offered_say_why() {
        let why = |m: AnyModel| m.offers_model_exchange().err().unwrap_or_default();
        assert!(why(model(ModelKindItem::Linear, 11.0)).contains("modes <= 10"));
        let swe = why(shallow_water(150.0));
        assert!(swe.contains("not offered in Model Exchange") && swe.contains("use Co-Simulation"));
    }

    /// Nor have they a Jacobian: refused with the same reason, never numbers.
    #[test]
    fn models_not_offered_have_no_tangent() {
        let m = model(ModelKindItem::Linear, 11.0);
        let got = m.continuous_tangent(0.1, &Direction::default());
        assert_eq!(got.err(), m.offers_model_exchange().err());
        let m = shallow_water(150.0);
        let got = m.continuous_tangent(0.1, &Direction::default());
        assert_eq!(got.err(), m.offers_model_exchange().err());
    }

    fn shallow_water(cells: f64) -> AnyModel {
        let p = StartValues::default().with(vr::SWE_CELLS, cells);
        let (common, _) = Common::read(&p).expect("start values are consistent");
        let start = Start {
            zeta: 0.02,
            amplitude: 0.005,
        };
        AnyModel::configure(ModelKindItem::ShallowWater, &p, &common, start).expect("configures")
    }
}
