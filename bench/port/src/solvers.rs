//! The C FMU's two integrators, `rk4` and `dp45` of bench/c/tld_c.c: true when the step failed.

#[cfg(feature = "energies")]
use super::energy_rates;
use super::{Tld, accel};

/// RK4 with n equal substeps over dt. `pe`: the energy integrals (feature energies).
pub(super) fn rk4(s: &Tld, dt: f64, px: &mut f64, pv: &mut f64, pe: &mut [f64; 2]) -> bool {
    let q = dt / s.fixed_step * (1.0 - 1e-12);
    if !(q <= f64::from(s.max_substeps)) {
        return true;
    }
    let mut n = q as i32;
    if f64::from(n) < q || n == 0 {
        n += 1;
    }
    let h = dt / f64::from(n);
    let (mut x, mut v, ab) = (*px, *pv, s.a_b);
    #[cfg(feature = "energies")]
    let (mut w, mut d) = (pe[0], pe[1]);
    #[cfg(not(feature = "energies"))]
    let _ = &pe;
    for _ in 0..n {
        let (k1x, k1v) = (v, accel(s, x, v, ab));
        let (x2, v2) = (x + 0.5 * h * k1x, v + 0.5 * h * k1v);
        let (k2x, k2v) = (v2, accel(s, x2, v2, ab));
        let (x3, v3) = (x + 0.5 * h * k2x, v + 0.5 * h * k2v);
        let (k3x, k3v) = (v3, accel(s, x3, v3, ab));
        let (x4, v4) = (x + h * k3x, v + h * k3v);
        let (k4x, k4v) = (v4, accel(s, x4, v4, ab));
        #[cfg(feature = "energies")]
        {
            let (k1w, k1d) = energy_rates(s, ab, v);
            let (k2w, k2d) = energy_rates(s, ab, v2);
            let (k3w, k3d) = energy_rates(s, ab, v3);
            let (k4w, k4d) = energy_rates(s, ab, v4);
            w += h / 6.0 * (k1w + 2.0 * (k2w + k3w) + k4w);
            d += h / 6.0 * (k1d + 2.0 * (k2d + k3d) + k4d);
        }
        x += h / 6.0 * (k1x + 2.0 * (k2x + k3x) + k4x);
        v += h / 6.0 * (k1v + 2.0 * (k2v + k3v) + k4v);
    }
    *px = x;
    *pv = v;
    #[cfg(feature = "energies")]
    {
        pe[0] = w;
        pe[1] = d;
    }
    false
}

// the C file's static constants: the tableau the plain-Rust baseline uses too
#[path = "../../native/src/dp45_tableau.rs"]
mod dp45_tableau;
use dp45_tableau::*;

/// Dormand & Prince (1980) 5(4), error per step against the mixed scales.
pub(super) fn dp45(s: &mut Tld, dt: f64, px: &mut f64, pv: &mut f64, pe: &mut [f64; 2]) -> bool {
    let (mut x, mut v, ab, mut t) = (*px, *pv, s.a_b, 0.0);
    #[cfg(feature = "energies")]
    let (mut w, mut d) = (pe[0], pe[1]);
    #[cfg(not(feature = "energies"))]
    let _ = &pe;
    let mut h = if s.h_carried > 0.0 {
        s.h_carried
    } else {
        (0.5 * s.tol.powf(0.2) / s.omega).min(dt)
    };
    let (mut k1x, mut k1v) = (v, accel(s, x, v, ab));
    let mut rejected = false;
    let mut steps = 1;
    loop {
        if steps > s.max_substeps {
            return true;
        }
        let rem = dt - t;
        let last = h >= rem;
        let hs = if last { rem } else { h };
        let (y2x, y2v) = (x + hs * A21 * k1x, v + hs * A21 * k1v);
        let (k2x, k2v) = (y2v, accel(s, y2x, y2v, ab));
        let y3x = x + hs * (A31 * k1x + A32 * k2x);
        let y3v = v + hs * (A31 * k1v + A32 * k2v);
        let (k3x, k3v) = (y3v, accel(s, y3x, y3v, ab));
        let y4x = x + hs * (A41 * k1x + A42 * k2x + A43 * k3x);
        let y4v = v + hs * (A41 * k1v + A42 * k2v + A43 * k3v);
        let (k4x, k4v) = (y4v, accel(s, y4x, y4v, ab));
        let y5x = x + hs * (A51 * k1x + A52 * k2x + A53 * k3x + A54 * k4x);
        let y5v = v + hs * (A51 * k1v + A52 * k2v + A53 * k3v + A54 * k4v);
        let (k5x, k5v) = (y5v, accel(s, y5x, y5v, ab));
        let y6x = x + hs * (A61 * k1x + A62 * k2x + A63 * k3x + A64 * k4x + A65 * k5x);
        let y6v = v + hs * (A61 * k1v + A62 * k2v + A63 * k3v + A64 * k4v + A65 * k5v);
        let (k6x, k6v) = (y6v, accel(s, y6x, y6v, ab));
        let xn = x + hs * (B1 * k1x + B3 * k3x + B4 * k4x + B5 * k5x + B6 * k6x);
        let vn = v + hs * (B1 * k1v + B3 * k3v + B4 * k4v + B5 * k5v + B6 * k6v);
        let (k7x, k7v) = (vn, accel(s, xn, vn, ab));
        let ex = hs * (E1 * k1x + E3 * k3x + E4 * k4x + E5 * k5x + E6 * k6x + E7 * k7x);
        let ev = hs * (E1 * k1v + E3 * k3v + E4 * k4v + E5 * k5v + E6 * k6v + E7 * k7v);
        let sx = s.tol * (s.scale_x + x.abs().max(xn.abs()));
        let sv = s.tol * (s.scale_v + v.abs().max(vn.abs()));
        let err = (0.5 * ((ex / sx) * (ex / sx) + (ev / sv) * (ev / sv))).sqrt();
        if err <= 1.0 {
            let mut fac = if err == 0.0 {
                5.0
            } else {
                (0.9 * err.powf(-0.2)).max(0.2).min(5.0)
            };
            if rejected {
                fac = fac.min(1.0);
            }
            rejected = false;
            #[cfg(feature = "energies")]
            {
                // the energies' stages: the integrands at the stage velocities (k_i x = v_i)
                let (q1w, q1d) = energy_rates(s, ab, k1x);
                let (q3w, q3d) = energy_rates(s, ab, k3x);
                let (q4w, q4d) = energy_rates(s, ab, k4x);
                let (q5w, q5d) = energy_rates(s, ab, k5x);
                let (q6w, q6d) = energy_rates(s, ab, k6x);
                w += hs * (B1 * q1w + B3 * q3w + B4 * q4w + B5 * q5w + B6 * q6w);
                d += hs * (B1 * q1d + B3 * q3d + B4 * q4d + B5 * q5d + B6 * q6d);
            }
            (x, v, k1x, k1v) = (xn, vn, k7x, k7v);
            let proposal = hs * fac;
            if last {
                // a step shortened to land on the communication point does not set the pace
                s.h_carried = if hs < h { h.max(proposal) } else { proposal };
                break;
            }
            t += hs;
            h = proposal;
        } else {
            rejected = true;
            h = hs
                * if err.is_finite() {
                    (0.9 * err.powf(-0.2)).max(0.2).min(1.0)
                } else {
                    0.25
                };
            if h < 1e-14 * dt {
                return true;
            }
        }
        steps += 1;
    }
    *px = x;
    *pv = v;
    #[cfg(feature = "energies")]
    {
        pe[0] = w;
        pe[1] = d;
    }
    false
}
