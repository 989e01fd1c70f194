//! Harmonic balance of Eq 2.11 under harmonic base motion x_b = A sin(wt) (a_b = -w^2 A sin wt):
//! with x = X cos(wt - theta) and the harmonic equivalent stiffness K(X),
//!
//! ```text
//! F(X, w) = X^2 [ (K(X) - w^2)^2 + (D w)^2 ] - w^4 A^2 = 0,   D = 2 zeta omega_f.
//! ```
//!
//! For given X it is a quadratic in s = w^2, (1 - A^2/X^2) s^2 + (D^2 - 2K) s + K^2 = 0, so the
//! whole response curve follows explicitly: a low-frequency root w_low(X), defined up to the
//! peak, and for X > A a high-frequency root w_high(X) that comes down from infinity, may turn
//! (the fold) and climbs back to meet w_low at the peak. Hardening bends the curve right: a slow
//! sweep up jumps down at the peak, a sweep down jumps up at the fold. At a fixed w the
//! amplitudes are the roots of F in X: the first, third, ... are stable (dF/dX > 0), the
//! others not; for large eta a detached branch may appear beyond the walls.

use super::linearisation::stiffness_harmonic;
use crate::physics::power::PowerLaw;

/// One point of a response curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Excitation frequency [rad/s].
    pub w: f64,
    /// Response amplitude [m].
    pub x: f64,
    /// Whether the periodic solution is stable.
    pub stable: bool,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HarmonicBalance {
    pub law: PowerLaw,
    /// D = 2 zeta omega_f [rad/s].
    pub damping: f64,
    /// Base displacement amplitude A [m].
    pub base_amplitude: f64,
}

impl HarmonicBalance {
    fn k(&self, x: f64) -> f64 {
        stiffness_harmonic(&self.law, x)
    }

    /// F(X, w); negative below the response, positive above.
    pub fn residual(&self, x: f64, w: f64) -> f64 {
        let (k, w2) = (self.k(x), w * w);
        x * x * ((k - w2).powi(2) + (self.damping * w).powi(2))
            - w2 * w2 * self.base_amplitude.powi(2)
    }

    /// The frequency along the backbone, sqrt(K(X)): free oscillation at amplitude X.
    pub fn backbone(&self, x: f64) -> f64 {
        self.k(x).sqrt()
    }

    /// The frequencies at which amplitude `x` solves the balance, ascending (none, one or two).
    pub fn frequencies(&self, x: f64) -> Vec<f64> {
        let k = self.k(x);
        let a = 1.0 - (self.base_amplitude / x).powi(2);
        let b = self.damping * self.damping - 2.0 * k;
        let c = k * k;
        let mut s: Vec<f64> = if a.abs() < 1e-14 {
            vec![-c / b]
        } else {
            let disc = b * b - 4.0 * a * c;
            if disc < 0.0 {
                vec![]
            } else {
                // Numerically stable roots of a s^2 + b s + c.
                let q = -0.5 * (b + b.signum() * disc.sqrt());
                vec![q / a, c / q]
            }
        };
        s.retain(|v| v.is_finite() && *v > 0.0);
        let mut w: Vec<f64> = s.into_iter().map(f64::sqrt).collect();
        w.sort_by(f64::total_cmp);
        w
    }

    /// Every amplitude at frequency `w` up to `x_max`, ascending, with its stability.
    pub fn amplitudes(&self, w: f64, x_max: f64) -> Vec<Point> {
        let n = 4000;
        let x_min = x_max * 1e-9;
        let grid = |i: usize| x_min * (x_max / x_min).powf(i as f64 / n as f64);
        let mut out = Vec::new();
        let (mut x0, mut f0) = (grid(0), self.residual(grid(0), w));
        for i in 1..=n {
            let x1 = grid(i);
            let f1 = self.residual(x1, w);
            if f0.signum() != f1.signum() {
                let (mut lo, mut hi) = (x0, x1);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if self.residual(mid, w).signum() == f0.signum() {
                        lo = mid
                    } else {
                        hi = mid
                    }
                    if hi - lo <= 1e-15 * hi {
                        break;
                    }
                }
                // Rising through zero: a stable solution; falling: unstable.
                out.push(Point {
                    w,
                    x: 0.5 * (lo + hi),
                    stable: f1 > f0,
                });
            }
            (x0, f0) = (x1, f1);
        }
        out
    }

    /// The resonance peak: the largest amplitude of the main response branch, where w_low and
    /// w_high meet; a slow up-sweep jumps down here. Searched up to `x_max`.
    pub fn peak(&self, x_max: f64) -> Option<Point> {
        let a = self.base_amplitude;
        let n = 4000;
        let grid = |i: usize| a * (x_max / a).powf(i as f64 / n as f64);
        // The first amplitude above A at which no frequency solves the balance any more.
        let mut last_ok = None;
        for i in 1..=n {
            let x = grid(i);
            if self.frequencies(x).len() == 2 {
                last_ok = Some(x);
            } else if let Some(lo) = last_ok {
                let (mut lo, mut hi) = (lo, x);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if self.frequencies(mid).len() == 2 {
                        lo = mid
                    } else {
                        hi = mid
                    }
                }
                let w = self.frequencies(lo);
                return Some(Point {
                    w: 0.5 * (w[0] + w[1]),
                    x: lo,
                    stable: true,
                });
            }
        }
        None
    }

    /// The fold of the high-frequency branch: the lowest w_high below the peak. A slow
    /// down-sweep jumps up here. None when w_high falls all the way to the peak (no jump).
    pub fn fold(&self, x_max: f64) -> Option<Point> {
        let peak = self.peak(x_max)?;
        let a = self.base_amplitude;
        let w_high = |x: f64| self.frequencies(x).last().copied().unwrap_or(f64::INFINITY);
        let n = 4000;
        let xs: Vec<f64> = (1..n)
            .map(|i| a * (peak.x / a).powf(i as f64 / n as f64))
            .collect();
        let (i_min, _) = xs
            .iter()
            .enumerate()
            .map(|(i, &x)| (i, w_high(x)))
            .min_by(|p, q| p.1.total_cmp(&q.1))?;
        if i_min + 2 >= xs.len() {
            return None;
        }
        // Golden-section refinement between the neighbours of the grid minimum.
        let (mut lo, mut hi) = (xs[i_min.saturating_sub(1)], xs[i_min + 1]);
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..100 {
            let (m1, m2) = (hi - g * (hi - lo), lo + g * (hi - lo));
            if w_high(m1) < w_high(m2) {
                hi = m2
            } else {
                lo = m1
            }
        }
        let x = 0.5 * (lo + hi);
        Some(Point {
            w: w_high(x),
            x,
            stable: true,
        })
    }

    /// The response curve for plotting, parameterised by amplitude: every (w, X) on both roots.
    pub fn curve(&self, x_max: f64, n: usize) -> Vec<Point> {
        let fold = self.fold(x_max);
        let mut out = Vec::new();
        for i in 0..=n {
            let x = x_max * 1e-4 * (1e4f64).powf(i as f64 / n as f64);
            let ws = self.frequencies(x);
            for (j, &w) in ws.iter().enumerate() {
                // The high root between the fold and the peak is the unstable middle branch.
                let unstable = ws.len() == 2 && j == 1 && fold.is_some_and(|f| x > f.x);
                out.push(Point {
                    w,
                    x,
                    stable: !unstable,
                });
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// VERIFY.md 4: a = 0.25, w_f = 5.6389, zeta = 0.02, eta = 2, phi = 1, A = 3 mm.
    fn example() -> HarmonicBalance {
        let wf = 5.6389;
        HarmonicBalance {
            law: PowerLaw::new(wf, 1.0, 2.0, 0.25),
            damping: 2.0 * 0.02 * wf,
            base_amplitude: 0.003,
        }
    }

    #[test]
    fn verify_example_peak_jumps_and_three_amplitudes() {
        let hb = example();
        let wf = 5.6389;
        let peak = hb.peak(1.0).expect("peak");
        assert!((peak.x - 0.0878).abs() < 5e-4, "peak X {}", peak.x);
        assert!(
            (peak.w / wf - 1.171).abs() < 1e-3,
            "peak at {}",
            peak.w / wf
        );
        let fold = hb.fold(1.0).expect("fold");
        assert!(
            fold.w / wf > 1.07 && fold.w / wf < 1.09,
            "fold at {}",
            fold.w / wf
        );
        let xs = hb.amplitudes(1.10 * wf, 0.25);
        let got: Vec<(f64, bool)> = xs.iter().map(|p| (p.x, p.stable)).collect();
        assert_eq!(got.len(), 3, "{got:?}");
        for ((x, stable), (want, want_stable)) in
            got.iter()
                .zip([(0.01825, true), (0.05898, false), (0.07028, true)])
        {
            assert!((x - want).abs() < 5e-5, "{got:?}");
            assert_eq!(*stable, want_stable);
        }
    }

    /// The linear limit: the peak is A / (2 zeta sqrt(1 - zeta^2)) (MODEL.md section 4).
    #[test]
    fn linear_limit_peak() {
        let zeta = 0.03;
        let hb = HarmonicBalance {
            law: PowerLaw::new(4.0, 0.0, 2.0, 1.0),
            damping: 2.0 * zeta * 4.0,
            base_amplitude: 0.002,
        };
        let peak = hb.peak(10.0).expect("peak");
        let want = 0.002 / (2.0 * zeta * (1.0 - zeta * zeta).sqrt());
        assert!((peak.x / want - 1.0).abs() < 1e-6, "{} vs {want}", peak.x);
        assert!(hb.fold(10.0).is_none(), "no jump for a linear oscillator");
    }

    /// Every point of the explicit curve solves F = 0.
    #[test]
    fn curve_points_solve_the_balance() {
        let hb = example();
        for p in hb.curve(0.2, 300) {
            let scale = (p.w * p.w * hb.base_amplitude).powi(2);
            assert!(hb.residual(p.x, p.w).abs() < 1e-9 * scale, "{p:?}");
        }
    }

    /// The linear oscillator's exact response to base motion A sin(w t):
    /// X(w) = w^2 A / sqrt((w_f^2 - w^2)^2 + (D w)^2).
    fn linear_case() -> (HarmonicBalance, impl Fn(f64) -> f64) {
        let (wf, d, a) = (4.0, 2.0 * 0.03 * 4.0, 0.002);
        let hb = HarmonicBalance {
            law: PowerLaw::new(wf, 0.0, 2.0, 1.0),
            damping: d,
            base_amplitude: a,
        };
        let exact = move |w: f64| w * w * a / ((wf * wf - w * w).powi(2) + (d * w).powi(2)).sqrt();
        (hb, exact)
    }

    /// Guards `frequencies` (both roots, the X = A case, the sorting) and `amplitudes` (the
    /// bracketing and the stability flag) with the linear oscillator, whose balance is the
    /// exact frequency response. Each root solves the balance to rounding (the quadratic in
    /// w^2 is well separated away from the peak, the bisection ends at 1e-15 X), so 1e-10
    /// relative is a wide margin; a wrong root is off by its whole distance to the other.
    #[test]
    fn linear_balance_is_the_exact_frequency_response() {
        let (hb, exact) = linear_case();
        for w in [0.5, 2.0, 3.7, 3.95, 4.0, 4.1, 5.0, 12.0] {
            let got = hb.amplitudes(w, 10.0);
            assert_eq!(got.len(), 1, "w {w}: {got:?}");
            assert!(got[0].stable && got[0].w == w, "w {w}: {got:?}");
            let want = exact(w);
            assert!(
                (got[0].x / want - 1.0).abs() < 1e-10,
                "w {w}: {got:?} vs {want}"
            );
        }
        let peak = hb.peak(10.0).expect("peak").x;
        // Below A one (high) frequency, A itself the degenerate quadratic, then two up to the peak.
        // Just above A (a = 1 - A^2/X^2 = 2e-9) the small root needs the stable form of the
        // quadratic formula: the textbook one loses b^2 / (4 a c) ~ 5e8 of its precision.
        for (x, count) in [
            (0.001, 1),
            (0.002, 1),
            (0.002 * (1.0 + 1e-9), 2),
            (0.003, 2),
            (0.02, 2),
            (0.99 * peak, 2),
        ] {
            let ws = hb.frequencies(x);
            assert_eq!(ws.len(), count, "X {x}: {ws:?}");
            assert!(ws.windows(2).all(|p| p[0] < p[1]), "X {x}: {ws:?}");
            for w in ws {
                assert!((exact(w) / x - 1.0).abs() < 1e-10, "X {x}: w {w}");
            }
        }
        assert!(hb.frequencies(1.01 * peak).is_empty());
    }

    /// Guards `backbone`: for eta = 2 Eq 2.13 is the cubic Duffing oscillator
    /// x'' + w_f^2 x + k3 x^3 with k3 = w_f^2 phi (2/a)^2, whose first-order harmonic balance
    /// backbone is w^2 = w_f^2 + (3/4) k3 X^2; for eta = 3 the quintic term gives (5/8) k5 X^4.
    /// Closed forms in a few operations: 1e-14 relative.
    #[test]
    fn duffing_backbone_is_the_first_order_formula() {
        let (wf, phi, a) = (5.6389f64, 0.7, 0.25);
        let duffing = HarmonicBalance {
            law: PowerLaw::new(wf, phi, 2.0, a),
            damping: 0.1,
            base_amplitude: 0.003,
        };
        let quintic = HarmonicBalance {
            law: PowerLaw::new(wf, phi, 3.0, a),
            ..duffing
        };
        let k3 = wf * wf * phi * (2.0 / a).powi(2);
        let k5 = wf * wf * phi * (2.0 / a).powi(4);
        for x in [0.0, 0.01, 0.05, 0.125, 0.2] {
            let want3 = (wf * wf + 0.75 * k3 * x * x).sqrt();
            let want5 = (wf * wf + 0.625 * k5 * x.powi(4)).sqrt();
            assert!((duffing.backbone(x) / want3 - 1.0).abs() < 1e-14, "X {x}");
            assert!((quintic.backbone(x) / want5 - 1.0).abs() < 1e-14, "X {x}");
        }
    }

    /// Guards `fold` and `peak` by what they are: at the fold the balance has a double root in
    /// X (F = 0 and dF/dX = 0, so F keeps its sign on both sides); at the peak the two
    /// frequencies merge (two just below, none just above). The golden section locates the
    /// fold's X to ~sqrt(eps) relative, far inside the 1e-3 offsets probed.
    #[test]
    fn fold_and_peak_are_where_solutions_merge() {
        let hb = example();
        let fold = hb.fold(1.0).expect("fold");
        let scale = (fold.w * fold.w * hb.base_amplitude).powi(2);
        assert!(hb.residual(fold.x, fold.w).abs() < 1e-9 * scale, "{fold:?}");
        let (below, above) = (
            hb.residual(fold.x * (1.0 - 1e-3), fold.w),
            hb.residual(fold.x * (1.0 + 1e-3), fold.w),
        );
        assert!(below * above > 0.0, "{fold:?}: {below} {above}");
        // And it is the lowest frequency of the high branch: just below it one amplitude,
        // just above three.
        assert_eq!(hb.amplitudes(fold.w * (1.0 - 1e-3), 0.25).len(), 1);
        assert_eq!(hb.amplitudes(fold.w * (1.0 + 1e-3), 0.25).len(), 3);
        let peak = hb.peak(1.0).expect("peak");
        let near = hb.frequencies(peak.x * (1.0 - 1e-9));
        assert_eq!(near.len(), 2, "{near:?}");
        assert!(
            near.iter().all(|w| (w / peak.w - 1.0).abs() < 1e-3),
            "{near:?} {peak:?}"
        );
        assert!(hb.frequencies(peak.x * (1.0 + 1e-9)).is_empty());
    }

    /// Guards `fold` against the fold solved another way: it is the lowest point of the high
    /// root s = w^2 of P(s, X) = a s^2 + b s + c (a = 1 - A^2/X^2, b = D^2 - 2K, c = K^2),
    /// so P = 0 and, as P_s ds/dX + P_X = 0, P_X = a' s^2 + b' s + c' = 0 there. For eta = 2
    /// K = w_f^2 + (3/4) k3 X^2 (see `duffing_backbone_is_the_first_order_formula`), and
    /// Newton's method on (P, P_X) with the exact derivatives converges to the last bits.
    /// Over several base amplitudes the fold lies in either neighbour cell of the search's
    /// grid minimum. The golden section ends where w_high no longer changes in its last
    /// bits, X within ~sqrt(eps) ~ 1e-8 relative of the minimum: 1e-6 allowed; w_high is flat
    /// there, so the frequency is right to ~1e-14: 1e-12 allowed.
    #[test]
    fn fold_is_the_lowest_point_of_the_high_branch() {
        let (wf, phi, len) = (5.6389f64, 1.0, 0.25f64);
        let k3 = wf * wf * phi * (2.0 / len).powi(2);
        for amp in [0.002, 0.0025, 0.003, 0.0035, 0.004] {
            let hb = HarmonicBalance {
                base_amplitude: amp,
                ..example()
            };
            let d2 = hb.damping * hb.damping;
            let fold = hb.fold(1.0).expect("fold");
            let (mut x, mut s) = (fold.x, fold.w * fold.w);
            for _ in 0..50 {
                let (k, k1, k2) = (wf * wf + 0.75 * k3 * x * x, 1.5 * k3 * x, 1.5 * k3);
                let (a, a1, a2) = (
                    1.0 - (amp / x).powi(2),
                    2.0 * amp * amp / x.powi(3),
                    -6.0 * amp * amp / x.powi(4),
                );
                let (b, b1, b2) = (d2 - 2.0 * k, -2.0 * k1, -2.0 * k2);
                let (c, c1, c2) = (k * k, 2.0 * k * k1, 2.0 * (k1 * k1 + k * k2));
                let p = a * s * s + b * s + c;
                let q = a1 * s * s + b1 * s + c1;
                let (p_x, p_s) = (q, 2.0 * a * s + b);
                let (q_x, q_s) = (a2 * s * s + b2 * s + c2, 2.0 * a1 * s + b1);
                let det = p_x * q_s - p_s * q_x;
                x -= (p * q_s - p_s * q) / det;
                s -= (p_x * q - p * q_x) / det;
            }
            assert!(
                (fold.x / x - 1.0).abs() < 1e-6 && (fold.w / s.sqrt() - 1.0).abs() < 1e-12,
                "A {amp}: {fold:?} vs X {x}, w {}",
                s.sqrt()
            );
        }
    }

    /// Guards the stability flags of `curve`: a periodic solution is stable where the
    /// balance rises through zero in X (dF/dX > 0), measured here by a central difference
    /// away from the fold and the peak, where dF/dX vanishes.
    #[test]
    fn curve_stability_is_the_sign_of_the_slope() {
        let hb = example();
        let (fold, peak) = (hb.fold(1.0).expect("fold"), hb.peak(1.0).expect("peak"));
        let mut unstable = 0;
        for p in hb.curve(0.2, 300) {
            if (p.x / fold.x - 1.0).abs() < 0.02 || (p.x / peak.x - 1.0).abs() < 0.02 {
                continue;
            }
            let dx = 1e-6 * p.x;
            let slope = hb.residual(p.x + dx, p.w) - hb.residual(p.x - dx, p.w);
            assert_eq!(p.stable, slope > 0.0, "{p:?}: {slope}");
            unstable += usize::from(!p.stable);
        }
        assert!(
            unstable > 5,
            "the middle branch must be sampled: {unstable}"
        );
    }
}
