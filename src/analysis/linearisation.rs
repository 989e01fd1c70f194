//! Equivalent linearisation of the power law (MODEL.md section 4: the seed's Eqs 2.14-2.28 give
//! wrong closed forms). For sign(x)|x|^(2eta-1): harmonic motion X cos(wt) gives the equivalent
//! stiffness c_H(eta) X^(2eta-2), Gaussian motion of standard deviation sigma gives
//! c_R(eta) sigma^(2eta-2); lambda = psi = 0 in both.

use super::ln_gamma;
use crate::physics::power::PowerLaw;

/// c_H(eta) = 2 Gamma(eta + 1/2) / (sqrt(pi) Gamma(eta + 1)); 2 C(2eta, eta)/4^eta for integers.
pub fn c_harmonic(eta: f64) -> f64 {
    2.0 * (ln_gamma(eta + 0.5) - ln_gamma(eta + 1.0)).exp() / std::f64::consts::PI.sqrt()
}

/// c_R(eta) = 2^eta Gamma(eta + 1/2) / sqrt(pi); (2eta - 1)!! for integers.
pub fn c_random(eta: f64) -> f64 {
    (eta * 2f64.ln() + ln_gamma(eta + 0.5)).exp() / std::f64::consts::PI.sqrt()
}

/// omega_eq^2 for harmonic motion of amplitude `x_amp` (Eq 2.13 linearised).
pub fn stiffness_harmonic(law: &PowerLaw, x_amp: f64) -> f64 {
    law.linear_stiffness() * (1.0 + c_harmonic(law.eta()) * law.hardening(x_amp))
}

/// omega_eq^2 for Gaussian motion of standard deviation `sigma`.
pub fn stiffness_random(law: &PowerLaw, sigma: f64) -> f64 {
    law.linear_stiffness() * (1.0 + c_random(law.eta()) * law.hardening(sigma))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficients_match_the_closed_forms() {
        // MODEL.md: c_H = 1, 0.8488, 0.75, 0.6791, 0.625 for eta = 1, 1.5, 2, 2.5, 3.
        for (eta, want) in [
            (1.0, 1.0),
            (1.5, 0.8488),
            (2.0, 0.75),
            (2.5, 0.6791),
            (3.0, 0.625),
        ] {
            assert!(
                (c_harmonic(eta) - want).abs() < 5e-5,
                "c_H({eta}) = {}",
                c_harmonic(eta)
            );
        }
        // (2 eta - 1)!!: 1, 3, 15, 105 for eta = 1..4.
        for (eta, want) in [(1.0, 1.0), (2.0, 3.0), (3.0, 15.0), (4.0, 105.0)] {
            assert!(
                (c_random(eta) - want).abs() < 1e-10 * want,
                "c_R({eta}) = {}",
                c_random(eta)
            );
        }
    }

    /// c_H is the first Fourier coefficient of the power law over a harmonic cycle: checked by
    /// quadrature, which shares nothing with the Gamma-function form.
    #[test]
    fn c_harmonic_is_the_fourier_coefficient() {
        for eta in [1.5, 2.0, 3.7, 7.0] {
            let n = 20000;
            let mut sum = 0.0;
            for k in 0..n {
                let th = (k as f64 + 0.5) / n as f64 * std::f64::consts::TAU;
                let c = th.cos();
                sum += c.abs().powf(2.0 * eta - 1.0).copysign(c) * c;
            }
            let coefficient = sum / n as f64 * 2.0;
            assert!(
                (coefficient - c_harmonic(eta)).abs() < 1e-6,
                "eta {eta}: {coefficient} vs {}",
                c_harmonic(eta)
            );
        }
    }
}
