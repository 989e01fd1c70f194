//! The base (tank) motion that drives every model over one communication step.

/// Base (tank) acceleration over one communication step: a Taylor polynomial about the step's
/// start t0, a(t) = a0 + a1 (t - t0) + a2 (t - t0)^2 / 2. Held input: a1 = a2 = 0.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BaseAcceleration {
    pub t0: f64,
    pub a: [f64; 3],
}

impl BaseAcceleration {
    pub fn held(a0: f64) -> Self {
        BaseAcceleration {
            t0: 0.0,
            a: [a0, 0.0, 0.0],
        }
    }

    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        // Held input, the usual case, by a predictable branch: no polynomial on the path of
        // every stage (the value is the same: a0 + s (0 + 0.5 s 0) = a0 for finite s).
        if let Some(a0) = self.held_value() {
            return a0;
        }
        let s = t - self.t0;
        self.a[0] + s * (self.a[1] + 0.5 * s * self.a[2])
    }

    /// The value of a held input (a1 = a2 = 0), which [`BaseAcceleration::at`] gives at every
    /// time; None for any other.
    #[inline(always)]
    pub fn held_value(&self) -> Option<f64> {
        (self.a[1] == 0.0 && self.a[2] == 0.0).then_some(self.a[0])
    }

    /// Integral of a from t0 to t0 + h.
    pub fn integral(&self, h: f64) -> f64 {
        h * (self.a[0] + h * (0.5 * self.a[1] + h * self.a[2] * (1.0 / 6.0)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The polynomial about t0, for every kind of input: held, a ramp, a parabola, with the
    /// step starting at t0 != 0; and its integral, against the closed forms.
    #[test]
    fn the_input_is_its_taylor_polynomial_about_the_steps_start() {
        for (t0, a) in [
            (0.0, [0.7, 0.0, 0.0]),
            (0.0, [0.7, -3.0, 0.0]),
            (2.5, [0.7, -3.0, 0.0]),
            (2.5, [0.7, -3.0, 8.0]),
            (2.5, [0.0, 0.0, 8.0]),
        ] {
            let base = BaseAcceleration { t0, a };
            for s in [0.0, 0.1, 0.37, 1.0] {
                let exact = a[0] + a[1] * s + 0.5 * a[2] * s * s;
                let got = base.at(t0 + s);
                assert!(
                    (got - exact).abs() <= 1e-15 * (1.0 + exact.abs()),
                    "{t0} {a:?} {s}"
                );
                let integral = a[0] * s + 0.5 * a[1] * s * s + a[2] * s * s * s / 6.0;
                let got = base.integral(s);
                assert!((got - integral).abs() <= 1e-15 * (1.0 + integral.abs()));
            }
        }
        assert_eq!(BaseAcceleration::held(0.3).at(7.0), 0.3);
    }
}
