//! Steady-state response of a structure (one mode: mass M, damping C, stiffness K) carrying a
//! linear sloshing mode (mass m, omega, zeta; force on the tank m (2 zeta omega x' + omega^2 x))
//! and liquid moving rigidly with it (m_rigid), under ground motion x_g = A sin(w t). Exact for
//! linear sloshing; for the S^2 model it is the response with the impacts left out.
//!
//! ```text
//! [K - w^2 (M + m_rigid) + i w C] X - m (omega^2 + 2 i zeta omega w) x = w^2 (M + m_rigid) A
//! -w^2 X + (omega^2 - w^2 + 2 i zeta omega w) x                       = w^2 A
//! ```

/// The structure and its damper.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coupled {
    pub structure_mass: f64,
    pub structure_damping: f64,
    pub structure_stiffness: f64,
    /// Liquid moving rigidly with the structure [kg].
    pub rigid_mass: f64,
    /// The sloshing mode: mass [kg], circular frequency [rad/s], damping ratio.
    pub mode_mass: f64,
    pub mode_omega: f64,
    pub mode_zeta: f64,
}

/// (re, im) arithmetic for the 2x2 solve.
type C = (f64, f64);
fn mul(a: C, b: C) -> C {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}
fn sub(a: C, b: C) -> C {
    (a.0 - b.0, a.1 - b.1)
}
fn div(a: C, b: C) -> C {
    let d = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}

impl Coupled {
    /// |X| / A at ground frequency `w`: structure displacement relative to the ground.
    pub fn structure_gain(&self, w: f64) -> f64 {
        let mass = self.structure_mass + self.rigid_mass;
        let (om, z, m) = (self.mode_omega, self.mode_zeta, self.mode_mass);
        let a11 = (
            self.structure_stiffness - w * w * mass,
            w * self.structure_damping,
        );
        let a12 = (-m * om * om, -m * 2.0 * z * om * w);
        let a21 = (-w * w, 0.0);
        let a22 = (om * om - w * w, 2.0 * z * om * w);
        let (b1, b2) = ((w * w * mass, 0.0), (w * w, 0.0));
        // Cramer's rule.
        let det = sub(mul(a11, a22), mul(a12, a21));
        let x = div(sub(mul(b1, a22), mul(a12, b2)), det);
        x.0.hypot(x.1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without the mode the structure is a base-excited oscillator: |X|/A = w^2 / |w_s^2 - w^2 + 2 i zeta w_s w|.
    #[test]
    fn bare_structure_closed_form() {
        let (m, ws, zs) = (168.0, 5.636, 0.0032);
        let c = Coupled {
            structure_mass: m,
            structure_damping: 2.0 * zs * m * ws,
            structure_stiffness: m * ws * ws,
            rigid_mass: 0.0,
            mode_mass: 0.0,
            mode_omega: 5.6,
            mode_zeta: 0.05,
        };
        for w in [4.0, 5.6, 5.636, 7.0] {
            let want = w * w / ((ws * ws - w * w).powi(2) + (2.0 * zs * ws * w).powi(2)).sqrt();
            assert!((c.structure_gain(w) / want - 1.0).abs() < 1e-12, "w {w}");
        }
    }

    /// The tuned damper of `a_tuned_mode_gives_two_lower_peaks`, with mode damping `zeta`.
    fn tuned(zeta: f64) -> Coupled {
        let (m, ws) = (168.0, 5.636);
        Coupled {
            structure_mass: m,
            structure_damping: 2.0 * 0.0032 * m * ws,
            structure_stiffness: m * ws * ws,
            rigid_mass: 0.35,
            mode_mass: 1.33,
            mode_omega: 5.6389,
            mode_zeta: zeta,
        }
    }

    /// Guards the solve (the complex products, differences and quotient) against the two
    /// equations of the module's header solved another way, in nalgebra's complex numbers:
    /// the mode's gives x = w^2 (A + X) / D2, D2 = omega^2 - w^2 + 2 i zeta omega w, which put
    /// into the structure's gives X = w^2 A (M' + m P / D2) / (K - w^2 M' + i w C - m w^2 P / D2),
    /// P = omega^2 + 2 i zeta omega w. A few complex operations on terms of ~1e4 whose
    /// result is at least ~1e-2 of them (the peaks are below 1 / (2 zeta_s) ~ 160 and the
    /// structure's terms cancel at most that much): rounding ~1e-14 relative, allowed 1e-12.
    #[test]
    fn structure_gain_solves_the_coupled_equations() {
        use nalgebra::Complex;
        for zeta in [0.01, 0.1] {
            let c = tuned(zeta);
            let mass = c.structure_mass + c.rigid_mass;
            let (om, m) = (c.mode_omega, c.mode_mass);
            for w in [3.0, 5.3, 5.6389, 5.9, 8.0] {
                let p = Complex::new(om * om, 2.0 * zeta * om * w);
                let d2 = Complex::new(om * om - w * w, 2.0 * zeta * om * w);
                let num = (Complex::from(mass) + p * m / d2) * (w * w);
                let den = Complex::new(
                    c.structure_stiffness - w * w * mass,
                    w * c.structure_damping,
                ) - p * (m * w * w) / d2;
                let want = (num / den).norm();
                assert!(
                    (c.structure_gain(w) / want - 1.0).abs() < 1e-12,
                    "zeta {zeta} w {w}: {} vs {want}",
                    c.structure_gain(w)
                );
            }
        }
    }

    /// An undamped mode is a vibration absorber: at its own frequency it holds the structure
    /// still in absolute terms (X = -x_g, |X| / A = 1), whatever the structure.
    #[test]
    fn an_undamped_mode_holds_the_structure_still_at_its_frequency() {
        let c = tuned(0.0);
        assert!((c.structure_gain(c.mode_omega) - 1.0).abs() < 1e-14);
    }

    /// A tuned mode splits the resonance in two (the double peak of a tuned damper) and cuts it.
    #[test]
    fn a_tuned_mode_gives_two_lower_peaks() {
        let ws = 5.636;
        let c = tuned(0.01);
        let ws_grid: Vec<f64> = (0..2001)
            .map(|k| ws * (0.8 + 0.4 * k as f64 / 2000.0))
            .collect();
        let g: Vec<f64> = ws_grid.iter().map(|&w| c.structure_gain(w)).collect();
        let peaks = (1..g.len() - 1)
            .filter(|&i| g[i] > g[i - 1] && g[i] > g[i + 1])
            .count();
        assert_eq!(peaks, 2);
        let bare = 1.0 / (2.0 * 0.0032);
        assert!(g.iter().cloned().fold(0.0, f64::max) < 0.5 * bare);
    }
}
