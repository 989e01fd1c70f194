//! S^2 in Model Exchange, the model's side (knows no FMI). Between impacts the host's solver
//! integrates the sloshing mode (an oscillator like every offered model's) and the impact mass
//! relative to the tank, z' = v, v' = -a_b in flight, z' = v' = 0 at rest on a wall. The impacts
//! are state events: each wall has a contact function, the gap d/2 -+ z while the mass flies
//! (an impact where it reaches 0), or while the mass rests on that wall the acceleration that
//! presses it there, -a_b w (it leaves where that reaches 0). At the event the same impact law
//! as Co-Simulation's ([`Slamming::hit`], Eq 2.5 with the tank infinitely heavy) reverses the
//! velocity with restitution e; a rebound slower than the rest speed while the base presses the
//! mass on the wall leaves it resting there, so chattering ends in a finite number of events.
//!
//! [`Slamming::hit`]: crate::physics::slamming::Slamming::hit

use super::SloshingSlamming;
use crate::model::rates::Oscillator;
use crate::physics::slamming::pressed;

/// How close to a wall [fraction of d/2] the mass counts as having reached it at an event.
pub const REACH: f64 = 1e-9;

/// What an event did to the impact mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// Nothing: no contact function has reached 0.
    None,
    /// An impact on `wall` (+1 or -1); `impulse` is what the tank took [N s]; `rests`: the mass
    /// came to rest on the wall.
    Impact { wall: i8, impulse: f64, rests: bool },
    /// The mass left the wall it rested on.
    Release { wall: i8 },
}

/// J d of the impact mass's part: of its two rates, of the base's power on it, of its kinetic
/// energy, for the change dv of its velocity and da of the base acceleration.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImpactTangent {
    pub z_rate: f64,
    pub v_rate: f64,
    pub power: f64,
    pub kinetic: f64,
}

impl SloshingSlamming {
    pub(crate) fn flying(&self) -> bool {
        self.state.contact == 0
    }

    /// The sloshing mode now (the part every offered model shares).
    pub fn oscillator(&self) -> Oscillator {
        self.sloshing.oscillator()
    }

    /// The impact mass's position and velocity relative to the tank.
    pub fn impact_state(&self) -> (f64, f64) {
        (self.state.z, self.state.v)
    }

    /// Their rates under base acceleration `a`: (v, -a) in flight, (0, 0) resting on a wall.
    pub fn impact_rates(&self, a: f64) -> (f64, f64) {
        if self.flying() {
            (self.state.v, -a)
        } else {
            (0.0, 0.0)
        }
    }

    /// J d of the impact mass's part under base acceleration `a` (the rates' all 0 at rest on
    /// a wall). Neither rate reads z: the tangent has no dz.
    pub fn impact_tangent(&self, a: f64, dv: f64, da: f64) -> ImpactTangent {
        let (m, v) = (self.impact_mass, self.state.v);
        // d(m v^2/2): the stored energy reads the velocity in either mode.
        let kinetic = m * v * dv;
        if !self.flying() {
            return ImpactTangent {
                kinetic,
                ..ImpactTangent::default()
            };
        }
        ImpactTangent {
            z_rate: dv,
            v_rate: -da,
            // d(-m a v).
            power: -m * (a * dv + v * da),
            kinetic,
        }
    }

    /// Take the continuous states: the sloshing mode's x, v, the totals of the work done by the
    /// base and of the dissipated energy [J] (less the impact mass's own share, which changes
    /// at the events only, the rest is the mode's), the impact mass's z, v. A host's trial
    /// state may lie beyond a wall (before its solver has located the impact).
    pub fn set_continuous(
        &mut self,
        x: f64,
        v: f64,
        work_in: f64,
        dissipated: f64,
        z: f64,
        vz: f64,
    ) {
        let (mi, i) = (self.impact_mass, &mut self.state);
        let s = &mut self.sloshing;
        s.state.x = x;
        s.state.v = v;
        s.state.work_in = (work_in - mi * i.work_in) / s.mass;
        s.state.dissipated = (dissipated - mi * i.dissipated) / s.mass;
        i.z = z;
        i.v = vz;
    }

    /// The contact functions of the walls +d/2 and -d/2 under base acceleration `a`: while the
    /// mass flies, the gap to the wall [m] while it moves towards that wall, and the gap plus d
    /// while it does not; d for the wall opposite the one it rests on, and for that wall the
    /// acceleration pressing it there [m/s^2]. An event where one reaches 0. The d added while
    /// the mass moves away keeps the function of the wall just left (gap 0) off 0 when a host
    /// restarts after the impact: a rebound too slow for the host to see the gap open (a gap
    /// of 1e-18 m at the wall rounds to 0) is still located when the mass comes back; it jumps
    /// from one positive value to another where the flight turns, which no host takes for an
    /// event.
    pub fn contact_functions(&self, a: f64) -> [f64; 2] {
        let (half, z, v) = (0.5 * self.impact.clearance, self.state.z, self.state.v);
        let d = self.impact.clearance;
        let away = |wall: f64| if v * wall > 0.0 { 0.0 } else { d };
        match self.state.contact {
            0 => [half - z + away(1.0), half + z + away(-1.0)],
            wall => {
                let press = -a * f64::from(wall);
                if wall > 0 { [press, d] } else { [d, press] }
            }
        }
    }

    /// Handle the event at base acceleration `a`: the impact on a wall the flying mass has
    /// reached while moving into it (Eq 2.5 via [`Slamming::hit`]), or its release from the
    /// wall it rests on once the base pulls it away.
    ///
    /// [`Slamming::hit`]: crate::physics::slamming::Slamming::hit
    pub fn event(&mut self, a: f64) -> Event {
        let half = 0.5 * self.impact.clearance;
        let st = &mut self.state;
        if st.contact != 0 {
            let wall = st.contact;
            if pressed(wall, a) {
                return Event::None;
            }
            st.contact = 0;
            return Event::Release { wall };
        }
        let wall: i8 = if st.z >= 0.0 { 1 } else { -1 };
        let w = f64::from(wall);
        // A host locates the event to its own tolerance, possibly just before the wall.
        let reached = st.z * w >= half * (1.0 - REACH);
        let into = st.v * w > 0.0 || (st.v == 0.0 && pressed(wall, a));
        if !(reached && into) {
            return Event::None;
        }
        let v_hit = st.v;
        let per_mass = self.impact.hit(st, wall, v_hit, a);
        Event::Impact {
            wall,
            impulse: self.impact_mass * per_mass,
            rests: st.contact != 0,
        }
    }
}

#[cfg(test)]
mod tests;
