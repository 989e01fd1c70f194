//! Model Exchange, the models' side: which models a host's own solver can integrate, and their
//! continuous states. The offered models are one oscillator of Eq 2.11 (Linear with one mode,
//! Nonlinear, Auto), whose states are the sloshing mass's relative displacement and velocity
//! and the two energy integrals, [x, v, energy.input, energy.dissipated]; their time
//! derivatives are the exact output rates every model already provides ([`Model::rate`]), so
//! no equation is written twice. Knows no FMI.
//!
//! ShallowWater is offered with swe.cells up to the bank of cells the model description
//! declares (`shallow_water::continuous`): its cells are states of their own, and the four
//! above are functions of them (energy.input excepted, the work's integral).
//!
//! Not offered, each with its reason: SloshingSlamming (its impacts are instants that change
//! the velocity: state events with an event iteration, not yet written), ShallowWater with
//! more cells than the bank. A Linear model of more than one mode would need more states than
//! the model description declares.
//!
//! Directional derivatives (J d, for a host's implicit solver): the exact derivatives of the
//! same rates in the states and the base acceleration, the damping ratio fixed (amplitude =
//! Fixed), from the oscillator's restoring force f(x) and its slope f'(x) (Phi of Eq 2.13 and
//! dPhi/dx; finite at x = 0 for every eta >= 1).
//!
//! [`Model::rate`]: super::Model::rate

use super::rates::{Change, Oscillator};
use super::registry::AnyModel;
use super::{Observable, Output};

/// Numbers of continuous states: x, v, energy.input, energy.dissipated.
pub const STATES: usize = 4;

/// All the continuous states the model description declares: those four, the amplitude
/// estimator's (amplitude = Tracked) and the ShallowWater cell bank, in that order.
pub const ALL_STATES: usize = STATES
    + crate::physics::amplitude::TRACKER_CONTINUOUS
    + super::shallow_water::continuous::CELL_STATES;

/// The outputs whose rates are the states' derivatives, in state order.
pub const RATES: [Output; STATES] = [
    Output::X,
    Output::V,
    Output::EnergyInput,
    Output::EnergyDissipated,
];

/// The saved numbers of every offered model begin with the fundamental oscillator's state per
/// unit sloshing mass: x, v, work in, dissipated (Linear's first mode, Nonlinear's and Auto's
/// `y`); the tests check it for each.
const OSCILLATOR: usize = 4;

/// A direction d in the continuous states and the inputs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Direction {
    /// Changes of [x, v, energy.input, energy.dissipated].
    pub states: [f64; STATES],
    /// Changes of the inputs base.a [m/s^2], base.v [m/s], base.x [m]. With amplitude = Fixed
    /// no equation reads base.v or base.x: their columns of J are 0.
    pub a: f64,
    pub v: f64,
    pub x: f64,
}

/// J d of the offered models' continuous part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tangent {
    /// Of the states' derivatives, in state order.
    pub derivatives: [f64; STATES],
    /// Of the force on the tanks [N] and of the stored energy [J].
    pub force: f64,
    pub stored: f64,
}

impl AnyModel {
    /// The model's one oscillator, if it is one of those offered in Model Exchange.
    fn oscillator(&self) -> Option<Oscillator> {
        match self {
            AnyModel::Linear(m) => match m.modes() {
                [only] => Some(only.oscillator()),
                _ => None,
            },
            AnyModel::Nonlinear(m) => Some(m.oscillator()),
            AnyModel::Auto(m) => Some(m.oscillator()),
            AnyModel::SloshingSlamming(_) | AnyModel::ShallowWater(_) => None,
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
        };
        // The energies' derivatives do not read the energies: their columns are 0.
        Ok(Tangent {
            derivatives: RATES.map(|which| o.rate_tangent(which, a, change).unwrap_or(0.0)),
            force: o.force_tangent(change),
            stored: o.stored_tangent(change),
        })
    }

    /// Ok if the host's solver can integrate this model; Err: why not.
    pub fn offers_model_exchange(&self) -> Result<(), String> {
        match self {
            AnyModel::Linear(_) if self.state_len() != OSCILLATOR + 3 => Err(format!(
                "model = Linear with modes > 1: Model Exchange declares {STATES} continuous states \
                 (one mode); use modes = 1, or Co-Simulation for more modes"
            )),
            AnyModel::Linear(_) | AnyModel::Nonlinear(_) | AnyModel::Auto(_) => Ok(()),
            AnyModel::SloshingSlamming(_) => Err(
                "model = SloshingSlamming is Co-Simulation only for now: its impacts need state \
                 events (the gap to each wall as event indicator) that are not yet offered"
                    .into(),
            ),
            AnyModel::ShallowWater(m) => m.fits_model_exchange(),
        }
    }

    /// The continuous states [x, v, work in, dissipated]; `initial_energy` is counted as input
    /// (as the output energy.input does).
    pub fn continuous_states(&self, initial_energy: f64) -> [f64; STATES] {
        let (x, v) = self.sloshing();
        [
            x,
            v,
            initial_energy + self.observe(Observable::WorkIn),
            self.observe(Observable::Dissipated),
        ]
    }

    /// Take the continuous states `s` (as [`AnyModel::continuous_states`] gives them).
    pub fn set_continuous_states(
        &mut self,
        s: &[f64; STATES],
        initial_energy: f64,
    ) -> Result<(), String> {
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
        RATES.map(|which| self.rate(which, a, 0.0))
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
            let s = [0.0123, -0.045, 0.75, 0.125];
            m.set_continuous_states(&s, 0.25).expect("takes them");
            let back = m.continuous_states(0.25);
            for k in 0..STATES {
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
            // The base's power on the sloshing mass, -m a v.
            let want = -m.sloshing_mass() * 0.3 * s[1];
            assert!((d[2] - want).abs() <= 1e-14 * want.abs(), "{item:?}");
        }
    }

    /// The models that are not offered say why.
    #[test]
    fn models_not_offered_say_why() {
        let why = |m: AnyModel| m.offers_model_exchange().err().unwrap_or_default();
        assert!(why(model(ModelKindItem::Linear, 3.0)).contains("modes = 1"));
        assert!(why(model(ModelKindItem::SloshingSlamming, 1.0)).contains("state events"));
        assert!(why(shallow_water(201.0)).contains("swe.cells = 201"));
        assert!(shallow_water(200.0).offers_model_exchange().is_ok());
    }

    /// Nor have they a Jacobian: refused with the same reason, never numbers.
    #[test]
    fn models_not_offered_have_no_tangent() {
        for (item, modes) in [
            (ModelKindItem::Linear, 3.0),
            (ModelKindItem::SloshingSlamming, 1.0),
        ] {
            let m = model(item, modes);
            let got = m.continuous_tangent(0.1, &Direction::default());
            assert_eq!(got.err(), m.offers_model_exchange().err(), "{item:?}");
        }
        let m = shallow_water(201.0);
        let got = m.continuous_tangent(0.1, &Direction::default());
        assert_eq!(got.err(), m.offers_model_exchange().err());
        // Offered, but without directional derivatives (the limiter's kinks): said so.
        let got = shallow_water(150.0).continuous_tangent(0.1, &Direction::default());
        assert!(got.is_err_and(|why| why.contains("no directional derivatives")));
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
