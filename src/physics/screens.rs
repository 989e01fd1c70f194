//! Damping screens (MODEL.md section 9): vertical slat screens across the tank, each taking a
//! pressure drop dp = (rho/2) C_l(S) u|u| from the depth-averaged velocity u through it.
//!
//! - The loss coefficient of a sharp-edged slat screen of solidity S (blocked area over total
//!   area) after Baines & Peterson (1951), as Tait and co-workers use it:
//!   C_l = (1/(C_c (1 - S)) - 1)^2 with the contraction coefficient
//!   C_c = 0.405 exp(-pi S) + 0.595 (a fit of the jet contraction through the slots, 1 for an
//!   open screen, 0.595 for a closed one).
//! - The arrangement a designer writes down: `count` screens of one solidity, symmetric about
//!   the tank centre, neighbours `spacing` apart (0: evenly spaced, a/(count + 1) apart).
//! - The equivalent linear damping of the screens in the fundamental shallow-water mode, from
//!   the energy they take per cycle ([`Arrangement::zeta_per_response`]).

use std::f64::consts::PI;

/// Most screens in one tank.
pub const MOST: usize = 16;

/// Contraction coefficient C_c(S) of a sharp-edged slat screen of solidity `s`.
pub fn contraction(s: f64) -> f64 {
    0.405 * (-PI * s).exp() + 0.595
}

/// Pressure-loss coefficient C_l(S) = (1/(C_c (1 - S)) - 1)^2 of a sharp-edged slat screen of
/// solidity `s` in [0, 1) (Baines & Peterson 1951): 0 for an open screen, growing without bound
/// as the screen closes.
pub fn loss_coefficient(s: f64) -> f64 {
    let r = 1.0 / (contraction(s) * (1.0 - s)) - 1.0;
    r * r
}

/// A screen arrangement as a designer writes it down.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arrangement {
    /// Number of screens (0: none).
    pub count: u32,
    /// Solidity S of every screen.
    pub solidity: f64,
    /// Distance between neighbouring screens [m]; 0: evenly spaced, a/(count + 1).
    pub spacing: f64,
    /// The loss coefficient if given (> 0), else 0: C_l from the solidity.
    pub loss: f64,
}

impl Arrangement {
    pub const NONE: Arrangement = Arrangement {
        count: 0,
        solidity: 0.0,
        spacing: 0.0,
        loss: 0.0,
    };

    /// The loss coefficient C_l of each screen.
    pub fn loss_coefficient(&self) -> f64 {
        if self.loss > 0.0 {
            self.loss
        } else {
            loss_coefficient(self.solidity)
        }
    }

    /// Positions of the screens from the left wall in a tank of length `length` [m]:
    /// x_j = a/2 + (j - (count - 1)/2) spacing, symmetric about the centre.
    pub fn positions(&self, length: f64) -> Vec<f64> {
        let n = self.count as usize;
        let spacing = if self.spacing > 0.0 {
            self.spacing
        } else {
            length / (n as f64 + 1.0)
        };
        (0..n)
            .map(|j| 0.5 * length + (j as f64 - 0.5 * (n as f64 - 1.0)) * spacing)
            .collect()
    }

    /// Err if the arrangement cannot be built in a tank of length `length`.
    pub fn check(&self, length: f64) -> Result<(), String> {
        if self.count == 0 {
            return Ok(());
        }
        if self.count as usize > MOST {
            return Err(format!(
                "screens.count = {}: at most {MOST} screens per tank",
                self.count
            ));
        }
        if !(0.0..1.0).contains(&self.solidity) {
            return Err(format!(
                "screens.solidity = {} must lie in [0, 1)",
                self.solidity
            ));
        }
        let x = self.positions(length);
        let (first, last) = (x[0], x[x.len() - 1]);
        if first <= 0.0 || last >= length {
            return Err(format!(
                "{} screens {} m apart span {:.4} m to {:.4} m: outside the tank (0 to {} m); \
                 reduce screens.spacing",
                self.count, self.spacing, first, last, length
            ));
        }
        Ok(())
    }

    /// Sum over the screens of |sin(pi x_j/a)|^3: the fundamental mode's velocity at each
    /// screen (relative to its largest, at the centre) cubed.
    pub fn velocity_cubes(&self, length: f64) -> f64 {
        self.positions(length)
            .iter()
            .map(|x| (PI * x / length).sin().abs().powi(3))
            .sum()
    }

    /// The screens' equivalent damping ratio per metre of response amplitude X of the
    /// sloshing mass (zeta_s = K X), in the fundamental shallow-water mode, for sinusoidal
    /// motion (MODEL.md 9):
    ///
    /// ```text
    /// K = (2/3) C_l (m_1/M_l) sum_j |sin(pi x_j/a)|^3 / a
    /// ```
    ///
    /// from the energy per cycle rho b h C_l U_j^3 4/(3 omega) of each screen (the time mean
    /// of |cos|^3 is 4/(3 pi)) over 4 pi times the mode's energy rho b g_e a eta^2/4, with the
    /// wave amplitude at the walls eta = pi^2 m_1 X/(2 rho b a^2) and the velocity
    /// U_j = eta omega a/(pi h) |sin(pi x_j/a)|. `mass_ratio` = m_1/M_l.
    pub fn zeta_per_response(&self, length: f64, mass_ratio: f64) -> f64 {
        if self.count == 0 {
            return 0.0;
        }
        2.0 / 3.0 * self.loss_coefficient() * mass_ratio * self.velocity_cubes(length) / length
    }
}

/// The damping ratio of a mode with amplitude-independent damping `boundary` and screens of
/// `per_response` (zeta_s = per_response X) under harmonic base motion of amplitude `a_e` at
/// resonance, where the response is X = A_e/(2 zeta): the root of
/// zeta^2 - boundary zeta - per_response A_e/2 = 0.
pub fn resonant_zeta(boundary: f64, per_response: f64, a_e: f64) -> f64 {
    let a_e = if a_e.is_finite() { a_e.abs() } else { 0.0 };
    0.5 * (boundary + (boundary * boundary + 2.0 * per_response * a_e).sqrt())
}

/// d zeta / d a_e of [`resonant_zeta`]: per_response / (2 sqrt(boundary^2 + 2 per_response
/// |a_e|)) times the sign of a_e (infinite at a_e = 0 without boundary damping, where the root
/// has a vertical tangent).
pub fn resonant_zeta_slope(boundary: f64, per_response: f64, a_e: f64) -> f64 {
    if !a_e.is_finite() {
        return 0.0;
    }
    let root = (boundary * boundary + 2.0 * per_response * a_e.abs()).sqrt();
    0.5 * per_response / root * a_e.signum()
}

/// The random form's factor (MODEL.md 11): zeta_s = K X for a sinusoid of amplitude X becomes
/// zeta_s = 3 sqrt(pi/8) K sigma = 1.880 K sigma for Gaussian narrow-band response of standard
/// deviation sigma (E|u|^3 / E[u^2] = 2 sqrt(2/pi) sigma against (8/(3 pi)) U).
pub const RANDOM_SCREENS: f64 = 1.879_971_205_973_250_3;

/// The damping ratio of a mode with amplitude-independent damping `boundary` and screens of
/// `per_response` (zeta_s = per_response X for a sinusoid) in stationary Gaussian narrow-band
/// response of standard deviation `sigma`: boundary + 1.880 per_response sigma.
pub fn random_zeta(boundary: f64, per_response: f64, sigma: f64) -> f64 {
    let sigma = if sigma.is_finite() { sigma.abs() } else { 0.0 };
    boundary + RANDOM_SCREENS * per_response * sigma
}

/// d zeta / d sigma of [`random_zeta`].
pub fn random_zeta_slope(per_response: f64, sigma: f64) -> f64 {
    if sigma.is_finite() {
        RANDOM_SCREENS * per_response * sigma.signum()
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// C_l against the formula worked by hand at a few solidities (C_c and C_l to 5 digits,
    /// computed separately: C_c(0.5) = 0.405 e^(-pi/2) + 0.595 = 0.67919, C_l(0.5) =
    /// (1/(0.67919 * 0.5) - 1)^2 = 3.7818, by a separate script).
    #[test]
    fn loss_coefficient_at_a_few_solidities() {
        assert_eq!(loss_coefficient(0.0), 0.0);
        assert!((contraction(0.0) - 1.0).abs() < 1e-15);
        assert!(
            (contraction(0.5) - 0.67919).abs() < 1e-5,
            "{}",
            contraction(0.5)
        );
        let cases = [
            (0.5, 3.78178),
            (0.25, 0.504325),
            (0.42, 2.10738),
            (0.7, 17.7159),
        ];
        for (s, expected) in cases {
            let c = loss_coefficient(s);
            assert!(
                (c / expected - 1.0).abs() < 2e-5,
                "C_l({s}) = {c}, not {expected}"
            );
        }
        // It grows with the solidity.
        let mut last = 0.0;
        for k in 1..95 {
            let c = loss_coefficient(k as f64 / 100.0);
            assert!(c > last, "{k}");
            last = c;
        }
    }

    #[test]
    fn positions_symmetric_or_even() {
        let pair = Arrangement {
            count: 2,
            solidity: 0.5,
            spacing: 0.2,
            loss: 0.0,
        };
        let x = pair.positions(1.0);
        assert!(
            (x[0] - 0.4).abs() < 1e-15 && (x[1] - 0.6).abs() < 1e-15,
            "{x:?}"
        );
        let even = Arrangement {
            count: 3,
            spacing: 0.0,
            ..pair
        };
        let x = even.positions(2.0);
        assert_eq!(x, vec![0.5, 1.0, 1.5]);
        assert!(
            Arrangement {
                spacing: 0.6,
                ..even
            }
            .check(1.0)
            .is_err()
        );
        assert!(even.check(1.0).is_ok());
        assert!(
            Arrangement {
                solidity: 1.0,
                ..even
            }
            .check(1.0)
            .is_err()
        );
        assert_eq!(Arrangement::NONE.zeta_per_response(1.0, 0.8), 0.0);
    }

    /// The resonant root solves its quadratic; without screens it is the boundary's zeta.
    #[test]
    fn resonant_zeta_solves_the_balance() {
        assert_eq!(resonant_zeta(0.015, 0.0, 0.01), 0.015);
        let (b, k, a) = (0.012, 3.0, 0.004);
        let z = resonant_zeta(b, k, a);
        assert!((z - (b + k * a / (2.0 * z))).abs() < 1e-15, "{z}");
    }
}
