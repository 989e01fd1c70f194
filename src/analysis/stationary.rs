//! Stationary random response of a damper in the time domain, through the model contract (so it
//! works for every model): the standard deviations of slosh.x and slosh.v and the mean power
//! dissipated, under a given base-acceleration record. What the random form of the Screens
//! law (MODEL.md 11) is checked with against the shallow-water model.
//!
//! Equivalent damping from the energy balance: the linear oscillator
//! x'' + 2 zeta omega_f x' + omega_f^2 x = -a_b of modal mass m_1 dissipates on average
//! P = 2 zeta omega_f m_1 E[v^2], so zeta_eq = P / (2 omega_f m_1 sigma_v^2), with P the mean
//! rate of energy.dissipated (whatever dissipates it: screens, drag, bores) and m_1 the
//! fundamental modal mass of Eq 2.1 (all tanks).

use crate::model::{Common, Damper, Inputs, Output, Parameters};

/// Statistics of a stationary run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stationary {
    /// Standard deviation of slosh.x [m] and of slosh.v [m/s] (about their means).
    pub sigma_x: f64,
    pub sigma_v: f64,
    /// Mean power dissipated [W].
    pub power: f64,
    /// Energy-equivalent damping ratio (module docs).
    pub zeta_eq: f64,
    /// omega_f [rad/s] and m_1 [kg] it was formed with.
    pub omega_f: f64,
    pub m1: f64,
}

/// Run the damper `p` configures through the base acceleration `accel` (sampled every `h`,
/// held over each step) and take the statistics over the samples after the first `skip`.
pub fn stationary_response(
    p: &dyn Parameters,
    accel: &[f64],
    h: f64,
    skip: usize,
) -> Result<Stationary, String> {
    if !(h.is_finite() && h > 0.0) || skip + 2 > accel.len() {
        return Err(format!(
            "a positive step and more than {skip} samples to skip are needed ({} given)",
            accel.len()
        ));
    }
    let (common, _) = Common::read(p)?;
    let (mut damper, _) = Damper::configure(p)?;
    let fundamental = common.tank.fundamental();
    let m1 = fundamental.mass * f64::from(common.tanks);
    let none = Inputs::default();
    let (mut n, mut sx, mut sxx, mut sv, mut svv) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut e0 = 0.0;
    for (k, &a) in accel.iter().enumerate() {
        let inputs = Inputs {
            a,
            ..Inputs::default()
        };
        let t = h * k as f64;
        damper
            .step(t, h, &inputs)
            .map_err(|e| format!("at t = {t:.3} s: {e}"))?;
        if k + 1 == skip {
            e0 = damper.output(Output::EnergyDissipated, &none);
        }
        if k >= skip {
            let (x, v) = (
                damper.output(Output::X, &none),
                damper.output(Output::V, &none),
            );
            n += 1.0;
            sx += x;
            sxx += x * x;
            sv += v;
            svv += v * v;
        }
    }
    let energy = damper.output(Output::EnergyDissipated, &none) - e0;
    let sigma_x = (sxx / n - (sx / n).powi(2)).max(0.0).sqrt();
    let sigma_v = (svv / n - (sv / n).powi(2)).max(0.0).sqrt();
    let power = energy / (n * h);
    Ok(Stationary {
        sigma_x,
        sigma_v,
        power,
        zeta_eq: power / (2.0 * fundamental.omega * m1 * sigma_v * sigma_v),
        omega_f: fundamental.omega,
        m1,
    })
}

/// The standard deviation of a linear oscillator's displacement under white-noise base
/// acceleration of two-sided spectral density `s0` [(m/s^2)^2 s/rad] when its damping is the
/// random Screens law zeta = boundary + 1.880 K sigma (MODEL.md 11): the root of
/// sigma^2 = pi s0 / (2 zeta(sigma) omega^3), found by bisection (the right-hand side falls as
/// sigma grows, the left rises).
pub fn random_screens_sigma(boundary: f64, per_response: f64, omega: f64, s0: f64) -> f64 {
    let g = |s: f64| {
        let zeta = crate::physics::screens::random_zeta(boundary, per_response, s);
        s * s * 2.0 * zeta * omega.powi(3) - std::f64::consts::PI * s0
    };
    let mut hi = 1.0;
    while g(hi) < 0.0 {
        hi *= 2.0;
    }
    let mut lo = 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid) < 0.0 { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests;
