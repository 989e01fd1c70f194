//! The nonlinear impact-characteristic model (seed Eq 2.11, as corrected in MODEL.md
//! section 2): x'' + 2 omega_f zeta x' + Phi(x) = -a_b(t), with the power law Phi of Eq 2.13
//! ([`super::power`]).

use super::base::BaseAcceleration;
use super::linear::free_motion_change;
use super::power::{Exponent, KindJob, PowerLaw};
use crate::solver::{OscillatorSplit, Rhs};

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
    /// The components an integrator controls the error of, x and x'; the energies after them
    /// are quadratures.
    pub const CONTROLLED: usize = 2;
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
}

impl NonlinearTld {
    /// The right-hand side with the exponent `e`, which must be of the law's kind, and the base
    /// acceleration `a_b` at the time of the evaluation.
    #[inline(always)]
    fn eval_with<E: Exponent>(
        &self,
        e: E,
        a_b: f64,
        y: &[f64; state::DIM],
        dy: &mut [f64; state::DIM],
    ) {
        let (x, v) = (y[state::X], y[state::V]);
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
        a_b: f64,
        y: &[f64; state::DIM],
        dy: &mut [f64; state::DIM],
    ) {
        let (x, v) = (y[state::X], y[state::V]);
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

    /// Run `job` on this model as a right-hand side compiled for its kind of exponent and
    /// for a held input or not: the same values as the model itself, without a dispatch per
    /// evaluation (a held input, the usual case, then costs no test and no polynomial in any
    /// stage). Inlined into the caller: behind a call, the integrator's state would pass
    /// through memory both ways.
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
                let model = self.model;
                match model.base.held_value() {
                    Some(a0) => self.job.run(&Fixed {
                        model,
                        exponent,
                        input: Held(a0),
                    }),
                    None => self.job.run(&Fixed {
                        model,
                        exponent,
                        input: Polynomial,
                    }),
                }
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

impl<E: Exponent, B: Input> CompiledTld for Fixed<'_, E, B> {
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

/// How a compiled right-hand side reads the base acceleration at time t.
trait Input: Copy {
    fn at(self, base: &BaseAcceleration, t: f64) -> f64;
}

/// A held input, its value known: [`BaseAcceleration::at`]'s at every time.
#[derive(Clone, Copy)]
struct Held(f64);

/// Any input: its polynomial.
#[derive(Clone, Copy)]
struct Polynomial;

impl Input for Held {
    #[inline(always)]
    fn at(self, _: &BaseAcceleration, _: f64) -> f64 {
        self.0
    }
}

impl Input for Polynomial {
    #[inline(always)]
    fn at(self, base: &BaseAcceleration, t: f64) -> f64 {
        base.at(t)
    }
}

/// The model with its kind of exponent and of input fixed at compile time.
struct Fixed<'a, E, B> {
    model: &'a NonlinearTld,
    exponent: E,
    input: B,
}

impl<E: Exponent, B: Input> Rhs<{ state::DIM }> for Fixed<'_, E, B> {
    const CONTROLLED: usize = state::CONTROLLED;

    #[inline]
    fn eval(&self, t: f64, y: &[f64; state::DIM], dy: &mut [f64; state::DIM]) {
        let a_b = self.input.at(&self.model.base, t);
        self.model.eval_with(self.exponent, a_b, y, dy);
    }

    fn jacobian(&self, t: f64, y: &[f64; state::DIM], jac: &mut [[f64; state::DIM]; state::DIM]) {
        self.model.jacobian(t, y, jac);
    }

    fn stiffness(&self, t: f64, y: &[f64; state::DIM]) -> f64 {
        Rhs::stiffness(self.model, t, y)
    }
}

impl<E: Exponent, B: Input> OscillatorSplit<{ state::DIM }> for Fixed<'_, E, B> {
    fn oscillator(&self) -> (f64, f64) {
        self.model.oscillator()
    }

    fn flow_change(&self, tau: f64) -> [[f64; 2]; 2] {
        self.model.flow_change(tau)
    }

    #[inline]
    fn remainder(&self, t: f64, y: &[f64; state::DIM], dy: &mut [f64; state::DIM]) {
        let a_b = self.input.at(&self.model.base, t);
        self.model.remainder_with(self.exponent, a_b, y, dy);
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
        self.remainder_with(self.stiffness.power, self.base.at(t), y, dy);
    }
}

impl Rhs<{ state::DIM }> for NonlinearTld {
    const CONTROLLED: usize = state::CONTROLLED;

    #[inline]
    fn eval(&self, t: f64, y: &[f64; state::DIM], dy: &mut [f64; state::DIM]) {
        self.eval_with(self.stiffness.power, self.base.at(t), y, dy);
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

    /// The energies are the quadratures past Rhs::CONTROLLED: nothing in f depends on them
    /// (an integrator need not error-control them), for the model and for it compiled.
    #[test]
    fn the_energies_are_quadratures_nothing_depends_on() {
        use crate::solver::Rhs;
        fn ride_along<F: Rhs<{ state::DIM }>>(f: &F) {
            assert_eq!(F::CONTROLLED, state::WORK_IN);
            let y = [0.03, -0.2, 0.0, 0.0];
            let mut other = y;
            other[F::CONTROLLED..].fill(7.5e3);
            let (mut a, mut b) = ([0.0; state::DIM], [0.0; state::DIM]);
            f.eval(0.1, &y, &mut a);
            f.eval(0.1, &other, &mut b);
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
        }
        struct Check;
        impl RhsJob for Check {
            type Output = ();
            fn run<F: CompiledTld>(self, f: &F) {
                ride_along(f);
            }
        }
        for base in [
            BaseAcceleration::held(0.4),
            BaseAcceleration {
                t0: 0.0,
                a: [0.4, 1.0, -2.0],
            },
        ] {
            for eta in [3.0, 2.5] {
                let m = NonlinearTld {
                    stiffness: PowerLaw::new(5.6, 1.0, eta, 0.25),
                    c: 0.3,
                    base,
                };
                ride_along(&m);
                m.with_exponent(Check);
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
        // One eta per kind of exponent (2 eta - 2 = 0, 1, 2, 3, 4, 8, 3.4), and phi = 0; a
        // held input (compiled with its value) and the inputs that are not held (their
        // polynomial), a ramp or a parabola alone among them.
        for (eta, phi) in [(1.0, 1.0), (1.5, 1.0), (2.0, 1.0), (2.5, 0.7), (3.0, 1.0)]
            .into_iter()
            .chain([(5.0, 1.0), (2.7, 1.0), (3.0, 0.0)])
        {
            for a in [
                [0.4, 1.0, -2.0],
                [0.4, 0.0, 0.0],
                [0.4, 1.0, 0.0],
                [0.4, 0.0, -2.0],
            ] {
                let m = NonlinearTld {
                    stiffness: PowerLaw::new(5.6, phi, eta, 0.25),
                    c: 0.3,
                    base: BaseAcceleration { t0: 0.0, a },
                };
                let states: Vec<[f64; state::DIM]> =
                    [-0.3, -0.11, -1e-3, 0.0, 2e-4, 0.07, 0.124, 0.4]
                        .iter()
                        .map(|&x| [x, 0.5 - x, 0.1, 0.2])
                        .collect();
                let compiled = m.with_exponent(Evaluate(states.clone()));
                let direct = Evaluate(states).run(&m);
                assert_eq!(compiled, direct, "eta {eta} phi {phi} input {a:?}");
            }
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

    /// The stiffness estimate the stiffness-switching solver reads is the largest |eigenvalue|
    /// of the (x, v) block of the model's own Jacobian, here from the block's trace and
    /// determinant: underdamped and overdamped, inside the walls and beyond them.
    #[test]
    fn stiffness_is_the_largest_eigenvalue_of_the_oscillator_block() {
        for (c, x) in [
            (0.1, 0.0),
            (0.1, 0.05),
            (0.3, 0.2),
            (40.0, 0.0),
            (40.0, 0.15),
        ] {
            let model = NonlinearTld {
                stiffness: PowerLaw::new(5.6, 1.0, 3.0, 0.25),
                c,
                base: BaseAcceleration::held(0.4),
            };
            let y = [x, 0.3, 0.0, 0.0];
            let mut jac = [[0.0; state::DIM]; state::DIM];
            model.jacobian(0.0, &y, &mut jac);
            let (a, b) = (jac[state::X][state::X], jac[state::X][state::V]);
            let (cc, d) = (jac[state::V][state::X], jac[state::V][state::V]);
            let (half_trace, det) = (0.5 * (a + d), a * d - b * cc);
            let disc = half_trace * half_trace - det;
            let largest = if disc < 0.0 {
                det.sqrt()
            } else {
                (half_trace.abs() + disc.sqrt()).max((half_trace.abs() - disc.sqrt()).abs())
            };
            let got = model.stiffness(0.0, &y);
            assert!(
                (got - largest).abs() <= 1e-12 * largest,
                "c {c} x {x}: {got} vs {largest}"
            );
        }
    }
}
