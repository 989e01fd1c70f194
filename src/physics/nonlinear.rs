//! The nonlinear impact-characteristic model (seed Eqs 2.11 and 2.13, as corrected in
//! MODEL.md section 2): x'' + 2 omega_f zeta x' + Phi(x) = -a_b(t),
//! Phi(x) = omega_f^2 x [1 + phi |2x/a|^(2 eta - 2)].

use crate::solver::Rhs;

/// |xi|^(2 eta - 2), specialised so integer exponents cost a multiplication, not a powf.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Power {
    Zero,
    Int(i32),
    Real(f64),
}

/// The restoring characteristic Phi of Eq 2.13 (per unit sloshing mass), xi = 2x/a so that
/// the walls sit at xi = +-1 and the wall force omega_f^2 (1 + phi) a/2 is the same for every eta.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PowerLaw {
    omega2: f64,
    phi: f64,
    eta: f64,
    inv_half_length: f64,
    power: Power,
}

impl PowerLaw {
    /// `eta` >= 1 (real), `phi` >= 0, `length` = a.
    pub fn new(omega_f: f64, phi: f64, eta: f64, length: f64) -> Self {
        let p = 2.0 * eta - 2.0;
        let power = if phi == 0.0 || p == 0.0 {
            Power::Zero
        } else if p.fract() == 0.0 && p <= 64.0 {
            Power::Int(p as i32)
        } else {
            Power::Real(p)
        };
        PowerLaw {
            omega2: omega_f * omega_f,
            phi,
            eta,
            inv_half_length: 2.0 / length,
            power,
        }
    }

    /// phi |xi|^(2 eta - 2): the hardening of the stiffness relative to the linear one.
    #[inline]
    pub fn hardening(&self, x: f64) -> f64 {
        let xi = (x * self.inv_half_length).abs();
        match self.power {
            Power::Zero => 0.0,
            Power::Int(n) => self.phi * xi.powi(n),
            Power::Real(p) => self.phi * xi.powf(p),
        }
    }

    /// Phi(x), odd in x.
    #[inline]
    pub fn force(&self, x: f64) -> f64 {
        self.omega2 * x * (1.0 + self.hardening(x))
    }

    /// U(x) = integral of Phi from 0 to x = omega_f^2 x^2/2 [1 + phi |xi|^(2eta-2) / eta].
    pub fn potential(&self, x: f64) -> f64 {
        0.5 * self.omega2 * x * x * (1.0 + self.hardening(x) / self.eta)
    }
}

/// Indices of the state of [`NonlinearTld`]; every quantity is per unit sloshing mass.
pub mod state {
    /// Relative displacement x of the sloshing mass.
    pub const X: usize = 0;
    /// Relative velocity x'.
    pub const V: usize = 1;
    /// Work input, integral of -a_b x'.
    pub const WORK_IN: usize = 2;
    /// Dissipated energy, integral of c x'^2.
    pub const DISSIPATED: usize = 3;
    /// Impulse of the force on the tank, integral of c x' + Phi(x).
    pub const IMPULSE: usize = 4;
    pub const DIM: usize = 5;
}

/// Eq 2.11 driven by a base acceleration held over the interval being integrated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NonlinearTld {
    pub stiffness: PowerLaw,
    /// Viscous coefficient c = 2 zeta omega_f.
    pub c: f64,
    /// Base (tank) acceleration a_b.
    pub base_acceleration: f64,
}

impl NonlinearTld {
    /// Force of the liquid on the tank per unit sloshing mass, c x' + Phi(x).
    #[inline]
    pub fn tank_force(&self, x: f64, v: f64) -> f64 {
        self.c * v + self.stiffness.force(x)
    }

    /// Kinetic plus potential energy per unit sloshing mass.
    pub fn stored_energy(&self, x: f64, v: f64) -> f64 {
        0.5 * v * v + self.stiffness.potential(x)
    }
}

impl Rhs<{ state::DIM }> for NonlinearTld {
    #[inline]
    fn eval(&self, _t: f64, y: &[f64; state::DIM], dy: &mut [f64; state::DIM]) {
        let (x, v) = (y[state::X], y[state::V]);
        let f = self.tank_force(x, v);
        dy[state::X] = v;
        dy[state::V] = -self.base_acceleration - f;
        dy[state::WORK_IN] = -self.base_acceleration * v;
        dy[state::DISSIPATED] = self.c * v * v;
        dy[state::IMPULSE] = f;
    }
}
