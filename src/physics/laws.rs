//! Amplitude-dependent properties (MODEL.md section 2): the NSD fits of Yu, Wakahara & Reed
//! (1999) as parameters, with Lambda = A_e / a clamped to the fitted range.

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
}

impl DampingLaw {
    /// Damping ratio for the excitation amplitude `a_e` in a tank of length `length`.
    pub fn zeta(&self, a_e: f64, length: f64, range: LambdaRange) -> f64 {
        match *self {
            DampingLaw::Constant(z) => z,
            DampingLaw::Nsd { c, p } => c * range.clamp(a_e / length).powf(p),
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
