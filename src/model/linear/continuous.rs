//! The Linear model with more than one mode in Model Exchange, the model's side (knows no FMI):
//! the fundamental mode's x and v are the states every offered model shares; the modes 2 to
//! [`ME_MODES`] add a bank of (x, v) pairs, each an oscillator of Eq 2.1's modal mass and
//! frequency with the same damping ratio. The bank's size is fixed (FMI 2.0 declares the number
//! of states in the model description): a model of fewer modes keeps the pairs it has not at 0,
//! their derivatives 0. The energies are the totals over the modes, as the outputs.

use super::Linear;
use crate::model::Output;
use crate::model::rates::{self, Change};

/// The most modes Model Exchange declares states for. Mode n's modal mass falls as
/// tanh((2n - 1) pi h/a)/(2n - 1)^3: the 10th carries 5.7e-4 of the fundamental's (in the lab
/// tank, less for deeper ones), and the bank's value references must fit the model
/// description's range 100-199 (four a mode: x, v and their derivatives).
pub const ME_MODES: usize = 10;

/// The bank's part of J d: of the modes' derivatives (pairs, mode 2 first), of the base's power
/// and the dissipation summed over them, of their force and stored energy.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BankTangent {
    pub derivatives: Vec<f64>,
    pub power: f64,
    pub dissipation: f64,
    pub force: f64,
    pub stored: f64,
}

impl Linear {
    /// The higher modes' (x, v) pairs into `out` (modes 2.., as many as there are; the rest
    /// of `out` untouched).
    pub fn bank_states(&self, out: &mut [f64]) {
        for (pair, m) in out.chunks_exact_mut(2).zip(self.modes.iter().skip(1)) {
            pair.copy_from_slice(&[m.state.x, m.state.v]);
        }
    }

    /// Take the continuous states: the fundamental's x and v, the totals of the work done by
    /// the base and of the dissipated energy [J] (the higher modes keep their own shares, the
    /// rest is the fundamental's), the higher modes' (x, v) pairs (those beyond the model's
    /// modes ignored).
    pub fn set_continuous(&mut self, x: f64, v: f64, work_in: f64, dissipated: f64, bank: &[f64]) {
        for (m, pair) in self.modes.iter_mut().skip(1).zip(bank.chunks_exact(2)) {
            m.state.x = pair[0];
            m.state.v = pair[1];
        }
        let others =
            |f: fn(&super::LinearMode) -> f64| -> f64 { self.modes.iter().skip(1).map(f).sum() };
        let work = work_in - others(|m| m.mass * m.state.work_in);
        let lost = dissipated - others(|m| m.mass * m.state.dissipated);
        let first = &mut self.modes[0];
        first.state.x = x;
        first.state.v = v;
        first.state.work_in = work / first.mass;
        first.state.dissipated = lost / first.mass;
    }

    /// The higher modes' rates (x' = v, Eq 2.1's v' = -a - 2 zeta w v - w^2 x), pairs into
    /// `out` under base acceleration `a`.
    pub fn bank_rates(&self, a: f64, out: &mut [f64]) {
        for (pair, m) in out.chunks_exact_mut(2).zip(self.modes.iter().skip(1)) {
            let o = [m.oscillator()];
            pair[0] = rates::rate(Output::X, &o, &[], a);
            pair[1] = rates::rate(Output::V, &o, &[], a);
        }
    }

    /// J d of the higher modes under base acceleration `a`, for the changes `bank` of their
    /// (x, v) pairs, `da` of the base acceleration and `dzeta` of the damping ratio (the
    /// modes share it).
    pub fn bank_tangent(&self, a: f64, bank: &[f64], da: f64, dzeta: f64) -> BankTangent {
        let mut t = BankTangent::default();
        for (m, pair) in self.modes.iter().skip(1).zip(bank.chunks_exact(2)) {
            let o = m.oscillator();
            let change = Change {
                dx: pair[0],
                dv: pair[1],
                da,
                dzeta,
            };
            let rate = |which| o.rate_tangent(which, a, change).unwrap_or(0.0);
            t.derivatives.extend([rate(Output::X), rate(Output::V)]);
            t.power += rate(Output::EnergyInput);
            t.dissipation += rate(Output::EnergyDissipated);
            t.force += o.force_tangent(change);
            t.stored += o.stored_tangent(change);
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::{ModelKindItem, vr};
    use crate::model::continuous::{BANK, Direction, STATES};
    use crate::model::{AnyModel, Common, Observable, Start, StartValues};

    fn linear(modes: f64) -> AnyModel {
        let p = StartValues::default().with(vr::MODES, modes);
        let (common, _) = Common::read(&p).expect("start values are consistent");
        let start = Start {
            zeta: 0.03,
            amplitude: 0.005,
        };
        AnyModel::configure(ModelKindItem::Linear, &p, &common, start).expect("configures")
    }

    fn state(modes: usize) -> [f64; STATES] {
        let mut s = [0.0; STATES];
        for (k, v) in s.iter_mut().enumerate() {
            *v = 0.01 * (k as f64 + 1.0) * if k % 3 == 0 { -1.0 } else { 1.0 };
        }
        // Nothing beyond the model's modes (they read back 0).
        s[BANK + 2 * (modes - 1)..].fill(0.0);
        (s[4], s[5]) = (0.0, 0.0);
        s
    }

    /// The bank round-trips (the modes beyond the model's read 0, whatever the host set), and
    /// its derivatives are Eq 2.1's oscillators written out here: x' = v,
    /// v' = -a - 2 zeta w_n v - w_n^2 x, each mode's power and dissipation in the energies'.
    #[test]
    fn the_bank_round_trips_and_its_rates_are_the_modes() {
        for modes in [1, 2, 4, ME_MODES] {
            let mut m = linear(modes as f64);
            let mut s = state(modes);
            m.set_continuous_states(&s, 0.5).expect("takes them");
            assert_eq!(m.continuous_states(0.5)[BANK..], s[BANK..], "{modes}");
            let back = m.continuous_states(0.5);
            assert!((back[2] - s[2]).abs() < 1e-15 && (back[3] - s[3]).abs() < 1e-15);
            // A host's values for modes the model has not: ignored.
            if modes < ME_MODES {
                let mut t = s;
                t[STATES - 1] = 0.7;
                m.set_continuous_states(&t, 0.5).expect("takes them");
                assert_eq!(m.continuous_states(0.5)[STATES - 1], 0.0);
            }
            let a = 0.4;
            let d = m.continuous_derivatives(a);
            let AnyModel::Linear(l) = &m else {
                panic!("Linear")
            };
            let (mut power, mut lost) = (0.0, 0.0);
            for (n, mode) in l.modes.iter().enumerate() {
                let (w, zeta) = (mode.mode.omega, mode.mode.zeta);
                let (x, v) = if n == 0 {
                    (s[0], s[1])
                } else {
                    (s[BANK + 2 * n - 2], s[BANK + 2 * n - 1])
                };
                let want = -a - 2.0 * zeta * w * v - w * w * x;
                let (dx, dv) = if n == 0 {
                    (d[0], d[1])
                } else {
                    (d[BANK + 2 * n - 2], d[BANK + 2 * n - 1])
                };
                assert_eq!(dx, v, "mode {}", n + 1);
                assert!((dv - want).abs() < 1e-13 * want.abs(), "mode {}", n + 1);
                power -= mode.mass * a * v;
                lost += mode.mass * 2.0 * zeta * w * v * v;
            }
            assert!((d[2] - power).abs() < 1e-14 * power.abs(), "{modes}");
            assert!((d[3] - lost).abs() < 1e-14 * lost.abs(), "{modes}");
            assert!(d[BANK + 2 * (modes - 1)..].iter().all(|v| *v == 0.0));
            s.fill(0.0);
        }
    }

    /// The energy states are the totals over the modes: with the higher modes carrying shares of
    /// their own (as after Co-Simulation steps, or restored), the totals set are the totals
    /// read back and observed, the higher modes' shares kept, the rest the fundamental's.
    #[test]
    fn the_energy_states_are_totals_whatever_the_higher_modes_carry() {
        let mut m = linear(3.0);
        let AnyModel::Linear(l) = &mut m else {
            panic!("Linear")
        };
        let shares = [(0.2, 0.05), (-0.1, 0.3)];
        for (mode, (w, d)) in l.modes.iter_mut().skip(1).zip(shares) {
            mode.state.work_in = w;
            mode.state.dissipated = d;
        }
        let mut s = state(3);
        (s[2], s[3]) = (0.75, 0.125);
        m.set_continuous_states(&s, 0.25).expect("takes them");
        let back = m.continuous_states(0.25);
        assert!((back[2] - 0.75).abs() < 1e-15, "{}", back[2]);
        assert!((back[3] - 0.125).abs() < 1e-15, "{}", back[3]);
        assert!((m.observe(Observable::WorkIn) - 0.5).abs() < 1e-15);
        assert!((m.observe(Observable::Dissipated) - 0.125).abs() < 1e-15);
        let AnyModel::Linear(l) = &m else {
            panic!("Linear")
        };
        for (mode, (w, d)) in l.modes.iter().skip(1).zip(shares) {
            assert_eq!((mode.state.work_in, mode.state.dissipated), (w, d));
        }
    }

    /// J d of every state and the base acceleration, for the derivatives, the force and the
    /// stored energy, against central differences (exact but for rounding: linear system).
    #[test]
    fn the_bank_tangent_is_the_differences() {
        let m = linear(ME_MODES as f64);
        let mut m0 = m.clone();
        let s = state(ME_MODES);
        m0.set_continuous_states(&s, 0.0).expect("takes them");
        let a = -0.3;
        let h = 1e-6;
        for k in 0..=STATES {
            let (mut p, mut q) = (m0.clone(), m0.clone());
            let mut d = Direction::default();
            let (ap, aq) = if k == STATES {
                d.a = 1.0;
                (a + h, a - h)
            } else {
                d.states[k] = 1.0;
                let (mut sp, mut sq) = (s, s);
                sp[k] += h;
                sq[k] -= h;
                p.set_continuous_states(&sp, 0.0).expect("p");
                q.set_continuous_states(&sq, 0.0).expect("q");
                (a, a)
            };
            let t = m0.continuous_tangent(a, &d).expect("offered");
            let (dp, dq) = (p.continuous_derivatives(ap), q.continuous_derivatives(aq));
            let close = |j: f64, fd: f64, what: &str| {
                assert!(
                    (j - fd).abs() < 1e-7 * (1.0 + fd.abs()),
                    "{what} by {k}: {j} vs {fd}"
                );
            };
            for i in 0..STATES {
                close(
                    t.derivatives[i],
                    (dp[i] - dq[i]) / (2.0 * h),
                    &format!("der {i}"),
                );
            }
            close(t.force, (p.force() - q.force()) / (2.0 * h), "force");
            let stored = |m: &AnyModel| m.observe(Observable::Stored);
            close(t.stored, (stored(&p) - stored(&q)) / (2.0 * h), "stored");
        }
    }
}
