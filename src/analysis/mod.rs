//! Frequency-domain answers without time stepping (MODEL.md section 4, the seed's Eqs
//! 2.14-2.28 with their errors corrected): equivalent linearisation of the power law, harmonic
//! balance of Eq 2.11 with every branch of the response, and the exact stationary response to
//! white noise. Pure functions, shared by the command-line tool and the tests.

pub mod calibration;
pub mod coupled;
pub mod design;
pub mod excitation;
pub mod harmonic;
pub mod linearisation;
pub mod random;
pub mod stationary;
pub mod sweep;

/// ln Gamma(x) for x > 0 (Lanczos, g = 7, 9 terms: about 1e-15 relative).
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection keeps the series in its accurate range.
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln_gamma_matches_known_values() {
        let pi = std::f64::consts::PI;
        for (x, want) in [
            (1.0, 0.0),
            (2.0, 0.0),
            (5.0, 24f64.ln()),
            (0.5, pi.sqrt().ln()),
            (10.5, 1_133_278.388_7f64.ln()),
        ] {
            assert!(
                (ln_gamma(x) - want).abs() < 1e-9 * want.abs().max(1.0),
                "{x}: {} vs {want}",
                ln_gamma(x)
            );
        }
    }

    /// Below 1/2 the reflection formula Gamma(x) Gamma(1 - x) = pi / sin(pi x) is used:
    /// against the known constants Gamma(1/4) = 3.62560990822190831, Gamma(1/3) =
    /// 2.67893853470774763 (OEIS A068466, A073005) and Gamma(1/10) = 9.51350769866873184,
    /// whose logarithms are about 1, so the series' 1e-15 relative allows 1e-14.
    #[test]
    fn ln_gamma_below_one_half_reflects() {
        for (x, gamma) in [
            (0.25, 3.625_609_908_221_908),
            (1.0 / 3.0, 2.678_938_534_707_747_6),
            (0.1, 9.513_507_698_668_732),
        ] {
            let want = f64::ln(gamma);
            assert!(
                (ln_gamma(x) - want).abs() < 1e-14,
                "{x}: {} vs {want}",
                ln_gamma(x)
            );
        }
    }
}
