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
pub struct NaturalMode {
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
    pub fn mode(&self, n: u32) -> NaturalMode {
        let k = f64::from(2 * n.max(1) - 1) * PI; // (2n-1) pi
        let r = self.depth_ratio();
        let th = (k * r).tanh();
        NaturalMode {
            mass: self.liquid_mass() * 8.0 * th / (k.powi(3) * r),
            omega: (self.g * k * th / self.length).sqrt(),
        }
    }

    /// The fundamental mode, the one the nonlinear model lumps the sloshing into.
    pub fn fundamental(&self) -> NaturalMode {
        self.mode(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// MODEL.md section 1 check values for the seed's Table 2.1 tank.
    #[test]
    fn table_2_1_check_values() {
        let t = Tank::TABLE_2_1;
        assert!((t.liquid_mass() - 1.68).abs() < 1e-12);
        let m1 = t.mode(1);
        assert!(
            (m1.mass / t.liquid_mass() - 0.7923).abs() < 5e-5,
            "{}",
            m1.mass / t.liquid_mass()
        );
        assert!((m1.omega - 5.6389).abs() < 5e-5, "{}", m1.omega);
        assert!((m1.omega / (2.0 * PI) - 0.8975).abs() < 5e-5);
        let m2 = t.mode(2);
        assert!((m2.mass / t.liquid_mass() - 0.075).abs() < 5e-4);
        assert!((m2.omega - 15.62).abs() < 5e-3, "{}", m2.omega);
        let m3 = t.mode(3);
        assert!((m3.mass / t.liquid_mass() - 0.021).abs() < 5e-4);
        assert!((m3.omega - 23.11).abs() < 5e-3, "{}", m3.omega);
        let sum: f64 = (1..=200).map(|n| t.mode(n).mass).sum::<f64>() / t.liquid_mass();
        assert!((sum - 0.909).abs() < 1e-3, "{sum}");
    }

    /// MODEL.md section 6 sizing at h/a = 0.1.
    #[test]
    fn sizing_at_depth_ratio_one_tenth() {
        for (a, hz) in [(0.24, 1.0), (0.95, 0.5), (5.9, 0.2), (23.8, 0.1)] {
            let t = Tank {
                length: a,
                breadth: 1.0,
                depth: 0.1 * a,
                density: 1000.0,
                g: 9.81,
            };
            let f = t.fundamental().omega / (2.0 * PI);
            assert!((f / hz - 1.0).abs() < 0.01, "a = {a}: {f} Hz");
        }
    }
}
