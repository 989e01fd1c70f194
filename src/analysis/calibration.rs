//! Calibration of the impact characteristic (phi, eta of Eq 2.13) and of the damping law
//! (zeta = c Lambda^p) to measured amplitude dependence: the frequency-hardening ratio
//! kappa(Lambda) (the jump frequency of a slow up-sweep over omega_f) and zeta(Lambda).
//!
//! zeta: least squares on log zeta = log c + p log Lambda (exact for the NSD form). kappa: the
//! harmonic-balance peak of Eq 2.11 at A_e = Lambda a with that damping, fitted over (phi, eta)
//! by Nelder-Mead on the squared relative residuals.

use super::harmonic::HarmonicBalance;
use crate::physics::power::PowerLaw;

/// One measured point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub lambda: f64,
    pub kappa: f64,
    pub zeta: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    pub phi: f64,
    pub eta: f64,
    pub nsd_c: f64,
    pub nsd_p: f64,
    /// kappa_model / kappa_data - 1 at each sample.
    pub kappa_residuals: Vec<f64>,
    /// zeta_model / zeta_data - 1 at each sample.
    pub zeta_residuals: Vec<f64>,
}

/// zeta = c Lambda^p by least squares in logs.
pub fn fit_damping(samples: &[Sample]) -> (f64, f64) {
    let n = samples.len() as f64;
    let (mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0);
    for s in samples {
        let (x, y) = (s.lambda.ln(), s.zeta.ln());
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    let p = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    let c = ((sy - p * sx) / n).exp();
    (c, p)
}

/// The hardening ratio harmonic balance predicts for (phi, eta) at Lambda, with damping zeta.
pub fn kappa_model(
    omega_f: f64,
    length: f64,
    phi: f64,
    eta: f64,
    lambda: f64,
    zeta: f64,
) -> Option<f64> {
    let hb = HarmonicBalance {
        law: PowerLaw::new(omega_f, phi, eta, length),
        damping: 2.0 * zeta * omega_f,
        base_amplitude: lambda * length,
    };
    hb.peak(3.0 * length).map(|p| p.w / omega_f)
}

/// Minimise `f` over two variables from `start` with initial steps `scale` (Nelder-Mead).
fn nelder_mead(f: impl Fn([f64; 2]) -> f64, start: [f64; 2], scale: [f64; 2]) -> [f64; 2] {
    let mut pts = [
        start,
        [start[0] + scale[0], start[1]],
        [start[0], start[1] + scale[1]],
    ];
    let mut val = pts.map(&f);
    for _ in 0..400 {
        let mut idx = [0, 1, 2];
        idx.sort_by(|&i, &j| val[i].total_cmp(&val[j]));
        let (b, m, w) = (idx[0], idx[1], idx[2]);
        if (val[w] - val[b]).abs() <= 1e-14 * val[b].abs().max(1e-300) {
            break;
        }
        let c = [(pts[b][0] + pts[m][0]) / 2.0, (pts[b][1] + pts[m][1]) / 2.0];
        let along = |t: f64| [c[0] + t * (pts[w][0] - c[0]), c[1] + t * (pts[w][1] - c[1])];
        let r = along(-1.0);
        let fr = f(r);
        if fr < val[b] {
            let e = along(-2.0);
            let fe = f(e);
            (pts[w], val[w]) = if fe < fr { (e, fe) } else { (r, fr) };
        } else if fr < val[m] {
            (pts[w], val[w]) = (r, fr);
        } else {
            let k = along(0.5);
            let fk = f(k);
            if fk < val[w] {
                (pts[w], val[w]) = (k, fk);
            } else {
                for i in [m, w] {
                    pts[i] = [(pts[i][0] + pts[b][0]) / 2.0, (pts[i][1] + pts[b][1]) / 2.0];
                    val[i] = f(pts[i]);
                }
            }
        }
    }
    let best = (0..3)
        .min_by(|&i, &j| val[i].total_cmp(&val[j]))
        .unwrap_or(0);
    pts[best]
}

/// Fit the damping law, then (phi, eta) with eta >= 1 and phi >= 0, starting from (1, 2).
pub fn calibrate(omega_f: f64, length: f64, samples: &[Sample]) -> Fit {
    let (nsd_c, nsd_p) = fit_damping(samples);
    let zeta = |s: &Sample| nsd_c * s.lambda.powf(nsd_p);
    let cost = |q: [f64; 2]| {
        let (phi, eta) = (q[0].abs(), 1.0 + q[1].abs());
        samples
            .iter()
            .map(
                |s| match kappa_model(omega_f, length, phi, eta, s.lambda, zeta(s)) {
                    Some(k) => (k / s.kappa - 1.0).powi(2),
                    None => 1.0,
                },
            )
            .sum::<f64>()
    };
    // Search in (phi, eta - 1) with the signs folded away, so the constraints always hold.
    let q = nelder_mead(cost, [1.0, 1.0], [0.5, 0.5]);
    let (phi, eta) = (q[0].abs(), 1.0 + q[1].abs());
    let kappa_residuals = samples
        .iter()
        .map(|s| {
            kappa_model(omega_f, length, phi, eta, s.lambda, zeta(s))
                .map_or(f64::NAN, |k| k / s.kappa - 1.0)
        })
        .collect();
    let zeta_residuals = samples.iter().map(|s| zeta(s) / s.zeta - 1.0).collect();
    Fit {
        phi,
        eta,
        nsd_c,
        nsd_p,
        kappa_residuals,
        zeta_residuals,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Data made by the model itself (phi = 0.6, eta = 2.5, zeta = 0.3 Lambda^0.3) must be
    /// recovered, and the residuals vanish.
    #[test]
    fn recovers_known_parameters() {
        let (wf, a) = (5.6389, 0.25);
        let samples: Vec<Sample> = [0.004, 0.008, 0.015, 0.03, 0.06]
            .iter()
            .map(|&l| {
                let zeta = 0.3 * f64::powf(l, 0.3);
                Sample {
                    lambda: l,
                    kappa: kappa_model(wf, a, 0.6, 2.5, l, zeta).expect("peak"),
                    zeta,
                }
            })
            .collect();
        let fit = calibrate(wf, a, &samples);
        assert!((fit.nsd_c - 0.3).abs() < 1e-12 && (fit.nsd_p - 0.3).abs() < 1e-12);
        assert!(
            (fit.phi - 0.6).abs() < 1e-3 && (fit.eta - 2.5).abs() < 1e-3,
            "{fit:?}"
        );
        assert!(
            fit.kappa_residuals.iter().all(|r| r.abs() < 1e-5),
            "{fit:?}"
        );
        // The damping law is fitted exactly (logs of a power law): its residuals vanish to
        // rounding, and there is one per sample.
        assert_eq!(fit.zeta_residuals.len(), samples.len());
        assert!(
            fit.zeta_residuals.iter().all(|r| r.abs() < 1e-12),
            "{fit:?}"
        );
    }

    /// Guards `nelder_mead` on a quadratic with a known minimum (1, -2) of value 3, where it
    /// stops once the simplex values agree to 1e-14 relative, so the point is within
    /// sqrt(3e-14 / smallest curvature) ~ 3e-7 of the minimum: allowed 1e-6.
    #[test]
    fn nelder_mead_finds_a_quadratics_minimum() {
        let f = |q: [f64; 2]| {
            let (x, y) = (q[0] - 1.0, q[1] + 2.0);
            3.0 + x * x + 10.0 * y * y + x * y
        };
        let q = nelder_mead(f, [0.0, 0.0], [0.5, 0.5]);
        assert!(
            (q[0] - 1.0).abs() < 1e-6 && (q[1] + 2.0).abs() < 1e-6,
            "{q:?}"
        );
    }

    /// Guards `nelder_mead` on Rosenbrock's valley from the classic start (-1.2, 1): the
    /// minimum (1, 1) has value 0, so only the 400 iterations stop it.
    #[test]
    fn nelder_mead_follows_the_rosenbrock_valley() {
        let f = |q: [f64; 2]| (1.0 - q[0]).powi(2) + 100.0 * (q[1] - q[0] * q[0]).powi(2);
        let q = nelder_mead(f, [-1.2, 1.0], [0.5, 0.5]);
        assert!(
            (q[0] - 1.0).abs() < 1e-6 && (q[1] - 1.0).abs() < 1e-6,
            "{q:?}"
        );
    }

    /// Runs `nelder_mead` from the simplex (1, 2), (2, 2), (1, 3) (start (1, 2), steps (1, 1))
    /// on a function given by a table of exact values (10 anywhere else) and returns the
    /// first `n` points it evaluates. With f = 0, 1, 2 at the three corners, the centroid of
    /// the best two is c = (1.5, 2) and the points along the worst's line are the reflection
    /// r = (2, 1), the expansion e = (2.5, 0) and the inside contraction k = (1.25, 2.5), all
    /// exact in binary.
    fn first_evaluations(table: &[([f64; 2], f64)], n: usize) -> Vec<[f64; 2]> {
        let seen = std::cell::RefCell::new(Vec::new());
        let corners = [([1.0, 2.0], 0.0), ([2.0, 2.0], 1.0), ([1.0, 3.0], 2.0)];
        let f = |q: [f64; 2]| {
            seen.borrow_mut().push(q);
            corners
                .iter()
                .chain(table)
                .find(|(p, _)| *p == q)
                .map_or(10.0, |&(_, v)| v)
        };
        nelder_mead(f, [1.0, 2.0], [1.0, 1.0]);
        seen.into_inner().into_iter().take(n).collect()
    }

    /// Guards the decisions of `nelder_mead` against the standard rules (Lagarias, Reeds,
    /// Wright & Wright 1998, with the inside contraction only), worked by hand on exact values:
    /// expand iff f(r) < f(best), keep the expansion iff f(e) < f(r), accept the reflection iff
    /// f(best) <= f(r) < f(middle), else contract, keep the contraction iff f(k) < f(worst),
    /// else shrink the other two halfway to the best. Ties go to the rule's side of `<`; the
    /// next point evaluated shows which branch ran.
    #[test]
    fn nelder_mead_takes_the_standard_step_at_each_branch_and_tie() {
        let (r, e, k) = ([2.0, 1.0], [2.5, 0.0], [1.25, 2.5]);
        let start = vec![[1.0, 2.0], [2.0, 2.0], [1.0, 3.0]];
        let then = |more: &[[f64; 2]]| [start.clone(), more.to_vec()].concat();
        // f(r) = f(best): a reflection, no expansion; the next simplex (1, 2), (2, 1), (2, 2)
        // reflects (2, 2) through (1.5, 1.5) to (1, 1).
        assert_eq!(first_evaluations(&[(r, 0.0)], 5), then(&[r, [1.0, 1.0]]));
        // f(e) = f(r) < f(best): the reflection is kept; (2, 1), (1, 2), (2, 2) next gives (1, 1).
        assert_eq!(
            first_evaluations(&[(r, -1.0), (e, -1.0)], 6),
            then(&[r, e, [1.0, 1.0]])
        );
        // f(best) < f(r) < f(middle): the reflection, as in the first case.
        assert_eq!(first_evaluations(&[(r, 0.5)], 5), then(&[r, [1.0, 1.0]]));
        // f(r) = f(middle): a contraction.
        assert_eq!(first_evaluations(&[(r, 1.0), (k, 0.5)], 5), then(&[r, k]));
        // f(k) < f(worst): the contraction is kept; (1, 2), (2, 2), (1.25, 2.5) next reflects
        // (1.25, 2.5) through (1.5, 2) to (1.75, 1.5).
        assert_eq!(
            first_evaluations(&[(r, 3.0), (k, 1.5)], 6),
            then(&[r, k, [1.75, 1.5]])
        );
        // f(k) = f(worst): a shrink, (2, 2) and (1, 3) halfway to (1, 2).
        assert_eq!(
            first_evaluations(&[(r, 3.0), (k, 2.0)], 7),
            then(&[r, k, [1.5, 2.0], [1.0, 2.5]])
        );
    }

    /// Guards the stopping test of `nelder_mead`: on a constant the three values agree, so it
    /// stops after evaluating the first simplex and returns the start.
    #[test]
    fn nelder_mead_stops_at_once_on_a_constant() {
        let count = std::cell::Cell::new(0);
        let q = nelder_mead(
            |_| {
                count.set(count.get() + 1);
                1.0
            },
            [1.0, 2.0],
            [1.0, 1.0],
        );
        assert_eq!((q, count.get()), ([1.0, 2.0], 3));
    }

    /// Guards `kappa_model` on the linear law (phi = 0): the peak of the base-excited
    /// response w^2 A / |w_f^2 - w^2 + i D w| lies at w^2 = w_f^2 / (1 - 2 zeta^2), whatever
    /// Lambda. The peak's frequency is the mean of the two merging roots, within ~eps of the
    /// double root: 1e-9 is wide.
    #[test]
    fn kappa_model_of_the_linear_law_is_the_exact_peak() {
        // The last case, a 10 m tank with its peak X = A / (2 zeta) at 2.5 tank lengths, checks
        // that the peak is searched up to 3 tank lengths (3 + length or 3 / length is short).
        for (length, lambda, zeta) in [
            (0.25, 0.004, 0.02),
            (0.25, 0.03, 0.08),
            (0.25, 0.1, 0.2),
            (10.0, 0.1, 0.02),
        ] {
            let k = kappa_model(5.6389, length, 0.0, 2.0, lambda, zeta).expect("peak");
            let want = 1.0 / (1.0 - 2.0 * zeta * zeta).sqrt();
            assert!(
                (k / want - 1.0).abs() < 1e-9,
                "{lambda} {zeta}: {k} vs {want}"
            );
        }
    }
}
