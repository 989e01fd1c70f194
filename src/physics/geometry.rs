//! Rectangular tank geometry -> linear sloshing modes (seed Eqs 2.1 and 2.2).

use std::f64::consts::PI;

/// A rigid rectangular tank, partly filled. Lengths in m, density in kg/m^3, g in m/s^2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tank {
    /// a: inner length along the excitation.
    pub length: f64,
    /// b: inner breadth across the excitation.
    pub breadth: f64,
    /// h: still-water depth.
    pub depth: f64,
    /// rho.
    pub density: f64,
    /// gravity.
    pub g: f64,
}

/// One linear sloshing mode: the mass that takes part in it and its natural circular frequency.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mode {
    pub mass: f64,
    pub omega: f64,
}

impl Tank {
    /// The table 2.1 laboratory tank of the seed.
    pub const TABLE_2_1: Tank = Tank {
        length: 0.25,
        breadth: 0.32,
        depth: 0.021,
        density: 1000.0,
        g: 9.81,
    };

    /// Depth ratio r = h/a (shallow water: r < 0.15).
    pub fn depth_ratio(&self) -> f64 {
        self.depth / self.length
    }

    /// Total liquid mass M_l = rho a b h.
    pub fn liquid_mass(&self) -> f64 {
        self.density * self.length * self.breadth * self.depth
    }

    /// Mode n = 1, 2, ... (Eq 2.1 for the mass, Eq 2.2 for the frequency).
    pub fn mode(&self, n: u32) -> Mode {
        let k = f64::from(2 * n.max(1) - 1) * PI; // (2n-1) pi
        let r = self.depth_ratio();
        let th = (k * r).tanh();
        Mode {
            mass: self.liquid_mass() * 8.0 * th / (k.powi(3) * r),
            omega: (self.g * k * th / self.length).sqrt(),
        }
    }

    /// The fundamental mode, the one the nonlinear model lumps the sloshing into.
    pub fn fundamental(&self) -> Mode {
        self.mode(1)
    }
}
