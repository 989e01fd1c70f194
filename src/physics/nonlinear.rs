//! The nonlinear impact-characteristic model (seed Eqs 2.11 and 2.13, as corrected in
//! MODEL.md section 2): x'' + 2 omega_f zeta x' + Phi(x) = -a_b(t),
//! Phi(x) = omega_f^2 x [1 + phi |2x/a|^(2 eta - 2)].

use super::base::BaseAcceleration;
use super::linear::free_motion_change;
use crate::solver::{OscillatorSplit, Rhs};

/// |x|^(2 eta - 2) for one kind of exponent, integer exponents by multiplications rather than
/// a powf. [`Power`] holds any kind and dispatches at run time; the fixed kinds of [`exponent`]
/// let an integrator be compiled for one exponent ([`NonlinearTld::with_exponent`]), so that no
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
            for _ in 0..self.squarings {
                base *= base;
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
enum Power {
    Zero,
    One,
    Two,
    Three,
    Four,
    Int(exponent::Int),
    Real(f64),
}

/// Work on an exponent whose kind is chosen at run time ([`Power::dispatch`]).
trait KindJob {
    type Output;
    fn run<E: Exponent>(self, exponent: E) -> Self::Output;
}

impl Power {
    /// Run `job` on this exponent as its kind: the one place where a Power becomes a kind.
    #[inline(always)]
    fn dispatch<J: KindJob>(self, job: J) -> J::Output {
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
    omega2: f64,
    eta: f64,
    /// phi (2/a)^(2 eta - 2): the hardening is q |x|^(2 eta - 2), one multiplication and no
    /// scaling of x on the path of every evaluation.
    q: f64,
    /// omega_f^2 q, so that Phi = omega_f^2 x + (omega_f^2 q x) |x|^(2 eta - 2): the power and
    /// the scaled x are formed side by side, then one multiplication and one addition.
    omega2_q: f64,
    power: Power,
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
    fn force_with<E: Exponent>(&self, e: E, x: f64) -> f64 {
        self.omega2 * x + self.hardening_force_with(e, x)
    }

    /// Phi(x) - omega_f^2 x, the hardening alone, with the exponent `e`.
    #[inline(always)]
    fn hardening_force_with<E: Exponent>(&self, e: E, x: f64) -> f64 {
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

/// Indices of the state of [`NonlinearTld`]; every quantity is per unit sloshing mass.
pub mod state {
    /// Relative displacement x of the sloshing mass.
    pub const X: usize = 0;
    /// Relative velocity x'.
    pub const V: usize = 1;
    /// Work input, integral of -a_b x'.
    pub const WORK_IN: usize = 2;
    /// Dissipated energy, integral of c x'^2.
    pub const DISSIPATED: usize = 3;
    pub const DIM: usize = 4;
}

/// Eq 2.11 driven by a base acceleration given over the interval being integrated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NonlinearTld {
    pub stiffness: PowerLaw,
    /// Viscous coefficient c = 2 zeta omega_f.
    pub c: f64,
    pub base: BaseAcceleration,
}

impl NonlinearTld {
    /// Force of the liquid on the tank per unit sloshing mass, c x' + Phi(x).
    #[inline]
    pub fn tank_force(&self, x: f64, v: f64) -> f64 {
        self.c * v + self.stiffness.force(x)
    }

    /// Kinetic plus potential energy per unit sloshing mass.
    pub fn stored_energy(&self, x: f64, v: f64) -> f64 {
        0.5 * v * v + self.stiffness.potential(x)
    }

    /// Relative acceleration x'' at (x, v) under base acceleration `a_b`.
    #[inline]
    pub fn acceleration(&self, x: f64, v: f64, a_b: f64) -> f64 {
        -a_b - self.tank_force(x, v)
    }
}

impl NonlinearTld {
    /// The right-hand side with the exponent `e`, which must be of the law's kind.
    #[inline(always)]
    fn eval_with<E: Exponent>(
        &self,
        e: E,
        t: f64,
        y: &[f64; state::DIM],
        dy: &mut [f64; state::DIM],
    ) {
        let (x, v) = (y[state::X], y[state::V]);
        let a_b = self.base.at(t);
        dy[state::X] = v;
        // The restoring force last: it ends the longest chain (x to Phi), so one subtraction
        // follows it, not two.
        dy[state::V] = (-a_b - self.c * v) - self.stiffness.force_with(e, x);
        self.quadratures(a_b, v, dy);
    }

    /// The energy integrands: work input -a_b x' and dissipation c x'^2.
    #[inline(always)]
    fn quadratures(&self, a_b: f64, v: f64, dy: &mut [f64; state::DIM]) {
        dy[state::WORK_IN] = -a_b * v;
        dy[state::DISSIPATED] = self.c * v * v;
    }

    /// The right-hand side less the linear oscillator x'' + c x' + omega_f^2 x (see
    /// [`OscillatorSplit`]): the input and the hardening.
    #[inline(always)]
    fn remainder_with<E: Exponent>(
        &self,
        e: E,
        t: f64,
        y: &[f64; state::DIM],
        dy: &mut [f64; state::DIM],
    ) {
        let (x, v) = (y[state::X], y[state::V]);
        let a_b = self.base.at(t);
        dy[state::X] = 0.0;
        dy[state::V] = -a_b - self.stiffness.hardening_force_with(e, x);
        self.quadratures(a_b, v, dy);
    }

    /// (omega_f^2, c) of the linear oscillator in Eq 2.11.
    fn oscillator(&self) -> (f64, f64) {
        (self.stiffness.omega2, self.c)
    }

    /// The exact flow of x'' + c x' + omega_f^2 x = 0 over `tau`, less the identity.
    fn flow_change(&self, tau: f64) -> [[f64; 2]; 2] {
        let (w2, c) = self.oscillator();
        let sigma = 0.5 * c;
        let (cm1, sn) = free_motion_change(w2, sigma, tau);
        [[cm1 + sigma * sn, sn], [-w2 * sn, cm1 - sigma * sn]]
    }

    /// Run `job` on this model as a right-hand side compiled for its kind of exponent: the
    /// same values as the model itself, without a dispatch per evaluation. Inlined into the
    /// caller: behind a call, the integrator's state would pass through memory both ways.
    #[inline(always)]
    pub fn with_exponent<J: RhsJob>(&self, job: J) -> J::Output {
        struct Compiled<'a, J> {
            model: &'a NonlinearTld,
            job: J,
        }
        impl<J: RhsJob> KindJob for Compiled<'_, J> {
            type Output = J::Output;
            #[inline(always)]
            fn run<E: Exponent>(self, exponent: E) -> J::Output {
                self.job.run(&Fixed {
                    model: self.model,
                    exponent,
                })
            }
        }
        self.stiffness.power.dispatch(Compiled { model: self, job })
    }
}

/// Work on a right-hand side whose type is chosen at run time ([`NonlinearTld::with_exponent`]).
pub trait RhsJob {
    type Output;
    fn run<F: CompiledTld>(self, f: &F) -> Self::Output;
}

/// The model compiled for its kind of exponent, as [`RhsJob`]s get it.
pub trait CompiledTld: OscillatorSplit<{ state::DIM }> {
    /// [`NonlinearTld::tank_force`], with the exponent's kind known.
    fn tank_force(&self, x: f64, v: f64) -> f64;
}

impl<E: Exponent> CompiledTld for Fixed<'_, E> {
    #[inline(always)]
    fn tank_force(&self, x: f64, v: f64) -> f64 {
        self.model.c * v + self.model.stiffness.force_with(self.exponent, x)
    }
}

/// The model itself, its exponent's kind dispatched at every use.
impl CompiledTld for NonlinearTld {
    fn tank_force(&self, x: f64, v: f64) -> f64 {
        NonlinearTld::tank_force(self, x, v)
    }
}

/// The model with its kind of exponent fixed at compile time.
struct Fixed<'a, E> {
    model: &'a NonlinearTld,
    exponent: E,
}

impl<E: Exponent> Rhs<{ state::DIM }> for Fixed<'_, E> {
    #[inline]
    fn eval(&self, t: f64, y: &[f64; state::DIM], dy: &mut [f64; state::DIM]) {
        self.model.eval_with(self.exponent, t, y, dy);
    }

    fn jacobian(&self, t: f64, y: &[f64; state::DIM], jac: &mut [[f64; state::DIM]; state::DIM]) {
        self.model.jacobian(t, y, jac);
    }

    fn stiffness(&self, t: f64, y: &[f64; state::DIM]) -> f64 {
        Rhs::stiffness(self.model, t, y)
    }
}

impl<E: Exponent> OscillatorSplit<{ state::DIM }> for Fixed<'_, E> {
    fn oscillator(&self) -> (f64, f64) {
        self.model.oscillator()
    }

    fn flow_change(&self, tau: f64) -> [[f64; 2]; 2] {
        self.model.flow_change(tau)
    }

    #[inline]
    fn remainder(&self, t: f64, y: &[f64; state::DIM], dy: &mut [f64; state::DIM]) {
        self.model.remainder_with(self.exponent, t, y, dy);
    }
}

impl OscillatorSplit<{ state::DIM }> for NonlinearTld {
    fn oscillator(&self) -> (f64, f64) {
        NonlinearTld::oscillator(self)
    }

    fn flow_change(&self, tau: f64) -> [[f64; 2]; 2] {
        NonlinearTld::flow_change(self, tau)
    }

    fn remainder(&self, t: f64, y: &[f64; state::DIM], dy: &mut [f64; state::DIM]) {
        self.remainder_with(self.stiffness.power, t, y, dy);
    }
}

impl Rhs<{ state::DIM }> for NonlinearTld {
    #[inline]
    fn eval(&self, t: f64, y: &[f64; state::DIM], dy: &mut [f64; state::DIM]) {
        self.eval_with(self.stiffness.power, t, y, dy);
    }

    fn jacobian(&self, t: f64, y: &[f64; state::DIM], jac: &mut [[f64; state::DIM]; state::DIM]) {
        let (x, v) = (y[state::X], y[state::V]);
        let k = self.stiffness.slope(x);
        *jac = [[0.0; state::DIM]; state::DIM];
        jac[state::X][state::V] = 1.0;
        jac[state::V][state::X] = -k;
        jac[state::V][state::V] = -self.c;
        jac[state::WORK_IN][state::V] = -self.base.at(t);
        jac[state::DISSIPATED][state::V] = 2.0 * self.c * v;
    }

    /// The local oscillator x'' + c x' + k(x) x: |lambda| = sqrt(k) when underdamped, the
    /// larger real root otherwise.
    fn stiffness(&self, _t: f64, y: &[f64; state::DIM]) -> f64 {
        let k = self.stiffness.slope(y[state::X]).max(0.0);
        let disc = 0.25 * self.c * self.c - k;
        if disc <= 0.0 {
            k.sqrt()
        } else {
            0.5 * self.c + disc.sqrt()
        }
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
    fn analytic_jacobian_matches_differences() {
        use crate::solver::Rhs;
        let m = NonlinearTld {
            stiffness: PowerLaw::new(5.6, 1.0, 3.0, 0.25),
            c: 0.3,
            base: BaseAcceleration {
                t0: 0.0,
                a: [0.4, 1.0, -2.0],
            },
        };
        let y = [0.09, -0.3, 0.0, 0.0];
        let mut exact = [[0.0; state::DIM]; state::DIM];
        m.jacobian(0.2, &y, &mut exact);
        struct Fd(NonlinearTld);
        impl Rhs<{ state::DIM }> for Fd {
            fn eval(&self, t: f64, y: &[f64; state::DIM], dy: &mut [f64; state::DIM]) {
                self.0.eval(t, y, dy)
            }
        }
        let mut fd = [[0.0; state::DIM]; state::DIM];
        Fd(m).jacobian(0.2, &y, &mut fd);
        for i in 0..state::DIM {
            for j in 0..state::DIM {
                assert!(
                    (exact[i][j] - fd[i][j]).abs() < 1e-5 * exact[i][j].abs().max(1.0),
                    "{i},{j}"
                );
            }
        }
        // The local frequency at rest is omega_f.
        assert!((Rhs::stiffness(&m, 0.0, &[0.0; state::DIM]) - 5.6).abs() < 1e-12);
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
    fn the_compiled_exponent_gives_the_models_values() {
        struct Evaluate(Vec<[f64; state::DIM]>);
        impl RhsJob for Evaluate {
            type Output = Vec<[f64; state::DIM]>;
            fn run<F: CompiledTld>(self, f: &F) -> Self::Output {
                let mut jac = [[0.0; state::DIM]; state::DIM];
                let y = [0.03, 0.2, 0.0, 0.0];
                f.jacobian(0.1, &y, &mut jac);
                let mut out: Vec<_> = self
                    .0
                    .iter()
                    .flat_map(|y| {
                        let mut dy = [0.0; state::DIM];
                        f.eval(0.1, y, &mut dy);
                        let mut r = [0.0; state::DIM];
                        f.remainder(0.1, y, &mut r);
                        // The split adds up to the whole right-hand side.
                        let (w2, c) = f.oscillator();
                        let linear = -w2 * y[state::X] - c * y[state::V];
                        let whole = linear + r[state::V];
                        let scale = dy[state::V].abs().max(linear.abs()) + 1.0;
                        assert!((whole - dy[state::V]).abs() <= 1e-14 * scale, "{y:?}");
                        assert_eq!(r[state::WORK_IN..], dy[state::WORK_IN..]);
                        let force = f.tank_force(y[state::X], y[state::V]);
                        [dy, r, [force, 0.0, 0.0, 0.0]]
                    })
                    .collect();
                out.extend(jac);
                out.extend(f.flow_change(0.37).map(|row| [row[0], row[1], 0.0, 0.0]));
                out.push([f.stiffness(0.1, &y), 0.0, 0.0, 0.0]);
                out
            }
        }
        // One eta per kind of exponent (2 eta - 2 = 0, 1, 2, 3, 4, 8, 3.4), and phi = 0.
        for (eta, phi) in [(1.0, 1.0), (1.5, 1.0), (2.0, 1.0), (2.5, 0.7), (3.0, 1.0)]
            .into_iter()
            .chain([(5.0, 1.0), (2.7, 1.0), (3.0, 0.0)])
        {
            let m = NonlinearTld {
                stiffness: PowerLaw::new(5.6, phi, eta, 0.25),
                c: 0.3,
                base: BaseAcceleration {
                    t0: 0.0,
                    a: [0.4, 1.0, -2.0],
                },
            };
            let states: Vec<[f64; state::DIM]> = [-0.3, -0.11, -1e-3, 0.0, 2e-4, 0.07, 0.124, 0.4]
                .iter()
                .map(|&x| [x, 0.5 - x, 0.1, 0.2])
                .collect();
            let compiled = m.with_exponent(Evaluate(states.clone()));
            let direct = Evaluate(states).run(&m);
            assert_eq!(compiled, direct, "eta {eta} phi {phi}");
        }
    }

    /// The linear part's flow: its derivative at 0 is the linear part (entries of P - I over a
    /// short tau), and flows compose, P(a + b) = P(a) P(b); under-, critically and overdamped.
    #[test]
    fn the_linear_flow_is_the_oscillators() {
        for c in [0.0, 0.3, 2.0 * 5.6, 30.0] {
            let m = NonlinearTld {
                stiffness: PowerLaw::new(5.6, 1.0, 2.0, 0.25),
                c,
                base: BaseAcceleration::held(0.0),
            };
            let (w2, _) = m.oscillator();
            let tau = 1e-7;
            let d = m.flow_change(tau);
            let linear = [[0.0, 1.0], [-w2, -c]];
            for i in 0..2 {
                for j in 0..2 {
                    let rate = d[i][j] / tau;
                    assert!(
                        (rate - linear[i][j]).abs() < 1e-5 * (1.0 + w2),
                        "c {c} [{i}][{j}]: {rate}"
                    );
                }
            }
            let p = |t: f64| {
                let d = m.flow_change(t);
                [[1.0 + d[0][0], d[0][1]], [d[1][0], 1.0 + d[1][1]]]
            };
            let (pa, pb, pab) = (p(0.13), p(0.29), p(0.42));
            for i in 0..2 {
                for j in 0..2 {
                    let composed = pa[i][0] * pb[0][j] + pa[i][1] * pb[1][j];
                    assert!(
                        (composed - pab[i][j]).abs() < 1e-14 * (1.0 + w2),
                        "c {c} [{i}][{j}]"
                    );
                }
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
