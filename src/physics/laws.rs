//! Damping laws: the amplitude-dependent NSD fits of Yu, Wakahara & Reed (1999) as parameters,
//! with Lambda = A_e / a clamped to the fitted range (MODEL.md section 2), and the laminar
//! boundary layers' amplitude-independent damping (MODEL.md section 8), and the damping screens'
//! amplitude-dependent equivalent damping on top of it (MODEL.md section 9).

/// Clamp range of the non-dimensional excitation amplitude Lambda = A_e / a.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LambdaRange {
    pub min: f64,
    pub max: f64,
}

impl LambdaRange {
    pub fn clamp(&self, lambda: f64) -> f64 {
        if lambda.is_nan() {
            self.min
        } else {
            lambda.clamp(self.min, self.max)
        }
    }
}

/// How the damping ratio of the sloshing mode is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DampingLaw {
    /// zeta fixed.
    Constant(f64),
    /// zeta = c Lambda^p (NSD fit: c = 0.5, p = 0.35).
    Nsd { c: f64, p: f64 },
    /// The boundary layers' zeta ([`boundary_layer_zeta`]), fixed by the tank and the liquid.
    BoundaryLayer(f64),
    /// Damping screens (MODEL.md 9): the boundary layers' zeta plus the screens' equivalent
    /// damping zeta_s = per_response X at the resonant response X = A_e/(2 zeta)
    /// ([`crate::physics::screens::resonant_zeta`]); `random`: in random response of standard
    /// deviation A_e instead ([`crate::physics::screens::random_zeta`]).
    Screens {
        boundary: f64,
        per_response: f64,
        random: bool,
    },
}

/// Damping ratio of the fundamental mode by the laminar boundary layers on the bottom and the
/// side walls (Miles 1967, as used by Sun et al. 1992; MODEL.md section 8):
/// zeta = (1/(2 omega_1 h)) sqrt(nu omega_1/2) (1 + 2h/b + S), for natural frequency
/// `omega_1`, still depth `depth`, breadth `breadth`, kinematic viscosity `nu` and surface
/// contamination factor `s` (about 1 for tap water).
pub fn boundary_layer_zeta(omega_1: f64, depth: f64, breadth: f64, nu: f64, s: f64) -> f64 {
    (nu * omega_1 / 2.0).sqrt() * (1.0 + 2.0 * depth / breadth + s) / (2.0 * omega_1 * depth)
}

impl DampingLaw {
    /// Whether [`DampingLaw::zeta`] depends on the amplitude (only then must a tracked
    /// amplitude be known before each step).
    pub fn reads_amplitude(&self) -> bool {
        matches!(self, DampingLaw::Nsd { .. } | DampingLaw::Screens { .. })
    }

    /// Damping ratio for the excitation amplitude `a_e` in a tank of length `length`.
    pub fn zeta(&self, a_e: f64, length: f64, range: LambdaRange) -> f64 {
        match *self {
            DampingLaw::Constant(z) => z,
            DampingLaw::Nsd { c, p } => c * range.clamp(a_e / length).powf(p),
            DampingLaw::BoundaryLayer(z) => z,
            DampingLaw::Screens {
                boundary,
                per_response,
                random: false,
            } => crate::physics::screens::resonant_zeta(boundary, per_response, a_e),
            DampingLaw::Screens {
                boundary,
                per_response,
                random: true,
            } => crate::physics::screens::random_zeta(boundary, per_response, a_e),
        }
    }
}

impl DampingLaw {
    /// d zeta / d a_e of [`DampingLaw::zeta`] at `a_e`: 0 for the laws that ignore the
    /// amplitude and where Lambda is clamped (at the clamp's ends, the clamped side's 0).
    pub fn zeta_slope(&self, a_e: f64, length: f64, range: LambdaRange) -> f64 {
        match *self {
            DampingLaw::Constant(_) | DampingLaw::BoundaryLayer(_) => 0.0,
            DampingLaw::Nsd { c, p } => {
                let lambda = a_e / length;
                if range.min < lambda && lambda < range.max {
                    c * p * lambda.powf(p - 1.0) / length
                } else {
                    0.0
                }
            }
            DampingLaw::Screens {
                boundary,
                per_response,
                random: false,
            } => crate::physics::screens::resonant_zeta_slope(boundary, per_response, a_e),
            DampingLaw::Screens {
                per_response,
                random: true,
                ..
            } => crate::physics::screens::random_zeta_slope(per_response, a_e),
        }
    }
}

/// Frequency hardening ratio kappa(Lambda) of the NSD fit (the two branches meet at 0.03).
pub fn nsd_kappa(lambda: f64) -> f64 {
    if lambda < 0.03 {
        1.075 * lambda.powf(0.007)
    } else {
        2.52 * lambda.powf(0.25)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RANGE: LambdaRange = LambdaRange {
        min: 1e-3,
        max: 0.1,
    };

    #[test]
    fn nsd_damping_law_and_clamp() {
        let law = DampingLaw::Nsd { c: 0.5, p: 0.35 };
        // Lambda = 0.005/0.25 = 0.02: 0.5 * 0.02^0.35.
        let z = law.zeta(0.005, 0.25, RANGE);
        assert!((z - 0.5 * (0.02f64).ln().mul_add(0.35, 0.0).exp()).abs() < 1e-15);
        assert!((z - 0.127_154).abs() < 1e-6, "{z}");
        // Below and above the fitted range the law is held at the ends.
        assert_eq!(law.zeta(0.0, 0.25, RANGE), 0.5 * 1e-3f64.powf(0.35));
        assert_eq!(law.zeta(10.0, 0.25, RANGE), 0.5 * 0.1f64.powf(0.35));
        assert_eq!(law.zeta(f64::NAN, 0.25, RANGE), law.zeta(0.0, 0.25, RANGE));
        assert_eq!(DampingLaw::Constant(0.02).zeta(1.0, 0.25, RANGE), 0.02);
        assert!(law.reads_amplitude() && !DampingLaw::Constant(0.02).reads_amplitude());
    }

    /// MODEL.md section 8's check value: the lab tank with water (nu = 1e-6 m^2/s, S = 1).
    #[test]
    fn boundary_layer_damping_of_the_lab_tank() {
        let t = crate::physics::geometry::Tank::TABLE_2_1;
        let z = boundary_layer_zeta(t.fundamental().omega, t.depth, t.breadth, 1e-6, 1.0);
        assert!((z - 0.0151).abs() < 5e-5, "{z}");
        let law = DampingLaw::BoundaryLayer(z);
        assert_eq!(law.zeta(0.0, 0.25, RANGE), law.zeta(1.0, 0.25, RANGE));
        assert!(!law.reads_amplitude());
    }

    #[test]
    fn kappa_branches_meet_at_three_percent() {
        assert!((nsd_kappa(0.03 - 1e-12) - 1.0489).abs() < 1e-4);
        assert!((nsd_kappa(0.03) - 1.0488).abs() < 1e-4);
        // Extrapolated far below the fitted range the fit would soften (kappa < 1): why Lambda is clamped.
        assert!(nsd_kappa(1e-5) < 1.0 && nsd_kappa(1e-3) > 1.0);
    }
    /// The laws' slopes by the amplitude against central differences of the laws: NSD inside
    /// the clamp and 0 outside it, Screens (resonant and random), 0 for the constant laws.
    #[test]
    fn zeta_slopes_are_the_laws_changes() {
        let laws = [
            DampingLaw::Nsd { c: 0.5, p: 0.35 },
            DampingLaw::Screens {
                boundary: 0.015,
                per_response: 2.5,
                random: false,
            },
            DampingLaw::Screens {
                boundary: 0.015,
                per_response: 2.5,
                random: true,
            },
            DampingLaw::Constant(0.02),
            DampingLaw::BoundaryLayer(0.015),
        ];
        for law in laws {
            for a_e in [1e-5, 0.002, 0.01, 0.05] {
                let h = 1e-6 * a_e;
                let fd =
                    (law.zeta(a_e + h, 0.25, RANGE) - law.zeta(a_e - h, 0.25, RANGE)) / (2.0 * h);
                let got = law.zeta_slope(a_e, 0.25, RANGE);
                assert!(
                    (got - fd).abs() <= 1e-6 * fd.abs().max(1e-9),
                    "{law:?} at {a_e}: {got} vs {fd}"
                );
            }
        }
        // Lambda = 1e-5/0.25 below the clamp, 0.05/0.25 above: the NSD law is flat there.
        let nsd = laws[0];
        assert_eq!(nsd.zeta_slope(1e-5, 0.25, RANGE), 0.0);
        assert_eq!(nsd.zeta_slope(0.05, 0.25, RANGE), 0.0);
    }
}
