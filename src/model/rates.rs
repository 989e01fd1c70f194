//! Exact output rates of models made of oscillators: each a mass on a spring and damper driven
//! by the base, x'' = -a - c x' - f(x), whose force on the tank is c x' + f(x).

use super::Output;

/// One oscillator now: mass [kg], v, damping c [1/s] and its change by the damping ratio
/// (c = 2 zeta omega: 2 omega), restoring force per unit mass f(x) and its slope f'(x).
#[derive(Clone, Copy, Debug)]
pub struct Oscillator {
    pub mass: f64,
    pub v: f64,
    pub c: f64,
    pub c_per_zeta: f64,
    pub restoring: f64,
    pub slope: f64,
}

/// A change of one oscillator's state, displacement `dx` and velocity `dv`, of the base
/// acceleration `da` and of the damping ratio `dzeta` (amplitude = Tracked: the estimate's
/// change through the damping law): the direction d of a directional derivative J d.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Change {
    pub dx: f64,
    pub dv: f64,
    pub da: f64,
    pub dzeta: f64,
}

impl Oscillator {
    /// x'' under base acceleration `a`.
    fn acceleration(&self, a: f64) -> f64 {
        -a - self.c * self.v - self.restoring
    }

    /// J d of [`rate`] for this oscillator alone (the fundamental one, no free masses) under
    /// base acceleration `a`: the exact change of the rates of x, v and of the two energies for
    /// the change `d`, the damping changing by dc = 2 omega dzeta. f(x) enters through its
    /// slope f'(x) only. None for the outputs whose rate is not a state's derivative.
    pub fn rate_tangent(&self, which: Output, a: f64, d: Change) -> Option<f64> {
        let (m, c, v) = (self.mass, self.c, self.v);
        let dc = self.c_per_zeta * d.dzeta;
        // d(x'') = -da - c dv - v dc - f'(x) dx.
        let acceleration = -d.da - c * d.dv - v * dc - self.slope * d.dx;
        Some(match which {
            Output::X => d.dv,
            Output::V => acceleration,
            // d(-m a v) = -m (a dv + v da).
            Output::EnergyInput => -m * (a * d.dv + v * d.da),
            // d(m c v^2) = m (2 c v dv + v^2 dc).
            Output::EnergyDissipated => m * v * (2.0 * c * d.dv + v * dc),
            _ => return None,
        })
    }

    /// J d of the force on the tank m (c v + f(x)): m (c dv + v dc + f'(x) dx).
    pub fn force_tangent(&self, d: Change) -> f64 {
        let dc = self.c_per_zeta * d.dzeta;
        self.mass * (self.c * d.dv + self.v * dc + self.slope * d.dx)
    }

    /// J d of the stored energy m (v^2/2 + U(x)), U' = f: m (v dv + f(x) dx).
    pub fn stored_tangent(&self, d: Change) -> f64 {
        self.mass * (self.v * d.dv + self.restoring * d.dx)
    }
}

/// The rate of `which` for `oscillators` (the first the fundamental one) and `free` masses that
/// move with no spring or damper (mass, velocity), under base acceleration `a`. Outputs that
/// are not made of these (mean force, base shear, amplitude, ...) are 0 here.
pub fn rate(which: Output, oscillators: &[Oscillator], free: &[(f64, f64)], a: f64) -> f64 {
    let each = |f: &dyn Fn(&Oscillator) -> f64| oscillators.iter().map(f).sum::<f64>();
    match which {
        // d/dt (c v + f(x)) = c v' + f'(x) v.
        Output::Force => each(&|o| o.mass * (o.c * o.acceleration(a) + o.slope * o.v)),
        Output::X => oscillators.first().map_or(0.0, |o| o.v),
        Output::V => oscillators.first().map_or(0.0, |o| o.acceleration(a)),
        // Power of the base on each mass, -m a v.
        Output::EnergyInput => {
            each(&|o| -o.mass * a * o.v) + free.iter().map(|(m, v)| -m * a * v).sum::<f64>()
        }
        Output::EnergyDissipated => each(&|o| o.mass * o.c * o.v * o.v),
        // d/dt (v^2/2 + V(x)) = v (v' + f(x)).
        Output::EnergyStored => {
            each(&|o| o.mass * o.v * (o.acceleration(a) + o.restoring))
                + free.iter().map(|(m, v)| m * v * -a).sum::<f64>()
        }
        Output::ForceMean
        | Output::BaseShear
        | Output::Amplitude
        | Output::Zeta
        | Output::ImpactZ
        | Output::Impacts
        | Output::ImpactImpulse
        | Output::SurfaceLeft
        | Output::SurfaceRight => 0.0,
    }
}
