//! The restoring characteristic Phi of Eq 2.13 (seed, as corrected in MODEL.md section 2):
//! Phi(x) = omega_f^2 x [1 + phi |2x/a|^(2 eta - 2)], with the exponent 2 eta - 2 sorted into
//! kinds so that the usual ones cost multiplications rather than a powf.

/// |x|^(2 eta - 2) for one kind of exponent, integer exponents by multiplications rather than
/// a powf. [`Power`] holds any kind and dispatches at run time; the fixed kinds of [`exponent`]
/// let an integrator be compiled for one exponent
/// ([`NonlinearTld::with_exponent`](super::nonlinear::NonlinearTld::with_exponent)), so that no
/// dispatch sits in its stages: one there costs its jump and, worse, spills the stage values
/// around it onto the stack, on the path from x to x''.
pub trait Exponent: Copy {
    fn abs_pow(self, x: f64) -> f64;
}

/// The kinds of exponent 2 eta - 2, each with its own evaluation.
pub mod exponent {
    use super::Exponent;

    /// |x|^0 = 1: eta = 1 (a constant extra stiffness phi), or phi = 0 (no hardening at all,
    /// whatever eta; then without a powf).
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct Zero;
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct One;
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct Two;
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct Three;
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct Four;
    /// Any other integer exponent n = odd 2^squarings (odd odd): the squarings first, one
    /// multiplication each, then the odd power.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct Int {
        squarings: u32,
        odd: u32,
    }

    impl Int {
        /// |x|^n.
        pub fn new(n: u32) -> Self {
            // n = 0 leaves odd = 0, answered as |x|^0 = 1.
            let squarings = if n == 0 { 0 } else { n.trailing_zeros() };
            Int {
                squarings,
                odd: n >> squarings,
            }
        }
    }
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct Real(pub f64);

    impl Exponent for Zero {
        #[inline(always)]
        fn abs_pow(self, _x: f64) -> f64 {
            1.0
        }
    }
    impl Exponent for One {
        #[inline(always)]
        fn abs_pow(self, x: f64) -> f64 {
            x.abs()
        }
    }
    impl Exponent for Two {
        #[inline(always)]
        fn abs_pow(self, x: f64) -> f64 {
            x * x
        }
    }
    impl Exponent for Three {
        #[inline(always)]
        fn abs_pow(self, x: f64) -> f64 {
            let ax = x.abs();
            ax * ax * ax
        }
    }
    impl Exponent for Four {
        #[inline(always)]
        fn abs_pow(self, x: f64) -> f64 {
            let s = x * x;
            s * s
        }
    }
    impl Exponent for Int {
        /// `powi` with an exponent known only at run time would become a call to a generic
        /// routine several times slower.
        #[inline(always)]
        fn abs_pow(self, x: f64) -> f64 {
            let mut base = x.abs();
            // The usual counts unrolled: no loop (its counter and exit) on the path from x to
            // x'' in every stage (eta = 5: n = 8, three squarings).
            match self.squarings {
                0 => {}
                1 => base *= base,
                2 => {
                    base *= base;
                    base *= base;
                }
                3 => {
                    base *= base;
                    base *= base;
                    base *= base;
                }
                k => {
                    for _ in 0..k {
                        base *= base;
                    }
                }
            }
            match self.odd {
                0 => 1.0,
                1 => base,
                3 => base * base * base,
                n => {
                    // By squaring.
                    let (mut out, mut n) = (base, n >> 1);
                    while n > 0 {
                        base *= base;
                        if n & 1 == 1 {
                            out *= base;
                        }
                        n >>= 1;
                    }
                    out
                }
            }
        }
    }
    impl Exponent for Real {
        #[inline(always)]
        fn abs_pow(self, x: f64) -> f64 {
            x.abs().powf(self.0)
        }
    }
}

/// The exponent of a power law, of whichever kind (the usual eta = 1.5, 2, 2.5, 3 have a kind
/// each).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Power {
    Zero,
    One,
    Two,
    Three,
    Four,
    Int(exponent::Int),
    Real(f64),
}

/// Work on an exponent whose kind is chosen at run time ([`Power::dispatch`]).
pub(super) trait KindJob {
    type Output;
    fn run<E: Exponent>(self, exponent: E) -> Self::Output;
}

impl Power {
    /// Run `job` on this exponent as its kind: the one place where a Power becomes a kind.
    #[inline(always)]
    pub(super) fn dispatch<J: KindJob>(self, job: J) -> J::Output {
        match self {
            Power::Zero => job.run(exponent::Zero),
            Power::One => job.run(exponent::One),
            Power::Two => job.run(exponent::Two),
            Power::Three => job.run(exponent::Three),
            Power::Four => job.run(exponent::Four),
            Power::Int(n) => job.run(n),
            Power::Real(p) => job.run(exponent::Real(p)),
        }
    }
}

impl Exponent for Power {
    #[inline]
    fn abs_pow(self, x: f64) -> f64 {
        struct At(f64);
        impl KindJob for At {
            type Output = f64;
            #[inline(always)]
            fn run<E: Exponent>(self, exponent: E) -> f64 {
                exponent.abs_pow(self.0)
            }
        }
        self.dispatch(At(x))
    }
}

/// The restoring characteristic Phi of Eq 2.13 (per unit sloshing mass), xi = 2x/a so that
/// the walls sit at xi = +-1 and the wall force omega_f^2 (1 + phi) a/2 is the same for every eta.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PowerLaw {
    pub(super) omega2: f64,
    eta: f64,
    /// phi (2/a)^(2 eta - 2): the hardening is q |x|^(2 eta - 2), one multiplication and no
    /// scaling of x on the path of every evaluation.
    q: f64,
    /// omega_f^2 q, so that Phi = omega_f^2 x + (omega_f^2 q x) |x|^(2 eta - 2): the power and
    /// the scaled x are formed side by side, then one multiplication and one addition.
    omega2_q: f64,
    pub(super) power: Power,
}

impl PowerLaw {
    /// `eta` >= 1 (real), `phi` >= 0, `length` = a.
    pub fn new(omega_f: f64, phi: f64, eta: f64, length: f64) -> Self {
        let p = 2.0 * eta - 2.0;
        let (power, q) = if phi == 0.0 || p == 0.0 {
            (Power::Zero, phi)
        } else if p.fract() == 0.0 && p <= 64.0 {
            let power = match p as u32 {
                1 => Power::One,
                2 => Power::Two,
                3 => Power::Three,
                4 => Power::Four,
                n => Power::Int(exponent::Int::new(n)),
            };
            (power, phi * (2.0 / length).powf(p))
        } else {
            (Power::Real(p), phi * (2.0 / length).powf(p))
        };
        let omega2 = omega_f * omega_f;
        PowerLaw {
            omega2,
            eta,
            q,
            omega2_q: omega2 * q,
            power,
        }
    }

    /// omega_f^2, the linear stiffness per unit mass.
    pub fn linear_stiffness(&self) -> f64 {
        self.omega2
    }

    /// The exponent eta of Eq 2.13.
    pub fn eta(&self) -> f64 {
        self.eta
    }

    /// phi |xi|^(2 eta - 2): the hardening of the stiffness relative to the linear one.
    #[inline]
    pub fn hardening(&self, x: f64) -> f64 {
        self.q * self.power.abs_pow(x)
    }

    /// Phi(x), odd in x.
    #[inline]
    pub fn force(&self, x: f64) -> f64 {
        self.force_with(self.power, x)
    }

    /// Phi(x) with the exponent `e`, which must be of this law's kind.
    #[inline(always)]
    pub(super) fn force_with<E: Exponent>(&self, e: E, x: f64) -> f64 {
        self.omega2 * x + self.hardening_force_with(e, x)
    }

    /// Phi(x) - omega_f^2 x, the hardening alone, with the exponent `e`.
    #[inline(always)]
    pub(super) fn hardening_force_with<E: Exponent>(&self, e: E, x: f64) -> f64 {
        (self.omega2_q * x) * e.abs_pow(x)
    }

    /// dPhi/dx = omega_f^2 [1 + (2 eta - 1) phi |xi|^(2eta-2)]: the local stiffness.
    pub fn slope(&self, x: f64) -> f64 {
        self.omega2 * (1.0 + (2.0 * self.eta - 1.0) * self.hardening(x))
    }

    /// U(x) = integral of Phi from 0 to x = omega_f^2 x^2/2 [1 + phi |xi|^(2eta-2) / eta].
    pub fn potential(&self, x: f64) -> f64 {
        0.5 * self.omega2 * x * x * (1.0 + self.hardening(x) / self.eta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn direct(x: f64, w: f64, phi: f64, eta: f64, a: f64) -> f64 {
        w * w * x * (1.0 + phi * (2.0 * x / a).abs().powf(2.0 * eta - 2.0))
    }

    #[test]
    fn phi_is_odd_and_matches_eq_2_13() {
        for eta in [1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 5.0, 7.3, 10.0] {
            let law = PowerLaw::new(5.6389, 1.3, eta, 0.25);
            for x in [0.0, 1e-4, 0.01, 0.05, 0.125, 0.2] {
                let f = law.force(x);
                assert_eq!(law.force(-x), -f, "odd at eta {eta}, x {x}");
                let want = direct(x, 5.6389, 1.3, eta, 0.25);
                assert!(
                    (f - want).abs() <= 1e-13 * want.abs().max(1e-300),
                    "eta {eta} x {x}: {f} vs {want}"
                );
            }
            // At the wall (xi = 1) the stiffness is (1 + phi) times linear, for every eta.
            let wall = law.force(0.125) / (5.6389f64.powi(2) * 0.125);
            assert!((wall - 2.3).abs() < 1e-12, "eta {eta}: {wall}");
        }
    }

    #[test]
    fn potential_is_the_integral_of_phi() {
        for eta in [1.0, 2.0, 3.5, 10.0] {
            let law = PowerLaw::new(4.0, 0.7, eta, 0.5);
            for x in [-0.3, -0.1, 0.02, 0.2, 0.26] {
                let d = 1e-6;
                let slope = (law.potential(x + d) - law.potential(x - d)) / (2.0 * d);
                assert!(
                    (slope - law.force(x)).abs() < 1e-6 * law.force(x).abs().max(1e-3),
                    "eta {eta} x {x}"
                );
            }
            assert_eq!(law.potential(0.0), 0.0);
        }
    }

    #[test]
    fn slope_is_the_derivative_of_phi() {
        for eta in [1.0, 2.0, 3.5, 10.0] {
            let law = PowerLaw::new(4.0, 0.7, eta, 0.5);
            for x in [-0.3, -0.1, 0.02, 0.2, 0.26] {
                let d = 1e-6;
                let fd = (law.force(x + d) - law.force(x - d)) / (2.0 * d);
                assert!(
                    (fd - law.slope(x)).abs() < 1e-6 * law.slope(x),
                    "eta {eta} x {x}: {fd} {}",
                    law.slope(x)
                );
            }
        }
    }

    #[test]
    fn integer_powers_by_squaring() {
        for n in 0..=64 {
            for x in [-1.7, -0.93, -1e-3, 0.0, 2e-4, 0.31, 0.999, 1.0, 1.25] {
                let got = exponent::Int::new(n).abs_pow(x);
                let want = f64::abs(x).powi(n as i32);
                assert!(
                    (got - want).abs() <= 1e-15 * f64::from(n) * want,
                    "|{x}|^{n}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn linear_when_phi_is_zero_or_eta_is_one() {
        // phi = 0: the linear oscillator whatever eta.
        assert_eq!(PowerLaw::new(2.0, 0.0, 3.0, 1.0).force(0.3), 4.0 * 0.3);
        // eta = 1: |xi|^0 = 1, so Phi = omega^2 (1 + phi) x, still linear.
        assert!((PowerLaw::new(2.0, 2.0, 1.0, 1.0).force(0.3) - 4.0 * 3.0 * 0.3).abs() < 1e-15);
    }
}
