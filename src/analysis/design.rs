//! Preliminary design of a TLD with damping screens for a structural mode under harmonic
//! excitation at resonance (after Tait 2008's procedure, with Warburton's optimum), and its
//! check by co-simulation with the shallow-water model (screens resolved).
//!
//! 1. The effective mass ratio mu = m_1/M (m_1 the fundamental sloshing mass of all tanks, Eq
//!    2.1, from the water mass ratio and the depth ratio) gives Warburton's optimum for a
//!    harmonic force on an undamped structure: frequency ratio gamma = 1/(1 + mu), damping
//!    zeta_opt = sqrt(3 mu / (8 (1 + mu))).
//! 2. The design amplitude: the controlled structure's resonant response to the force,
//!    X = (P/K) sqrt(1 + 2/mu) (Den Hartog's fixed points), is the tank's base amplitude A_e.
//! 3. The tank: length from Eq 2.2 at the depth ratio for the linear frequency
//!    gamma omega_s / kappa(Lambda), kappa the NSD hardening at Lambda = A_e/a (iterated: a
//!    depends on the frequency, Lambda on a); shortened to the footprint by a shallower depth
//!    ratio if needed; breadth and count from the water mass and the largest breadth.
//! 4. The screens: the Screens law's K that makes zeta(A_e) = zeta_opt,
//!    K = 2 zeta_opt (zeta_opt - zeta_BL)/A_e, then the loss coefficient
//!    C_l = K a / ((2/3)(m_1/M_l) sum |sin(pi x_j/a)|^3) and the solidity with that C_l.

use std::f64::consts::PI;

use crate::description::{AmplitudeModeItem, DampingLawItem, ModelKindItem, vr};
use crate::model::{Damper, Inputs, Output, StartValues};
use crate::physics::geometry::Tank;
use crate::physics::laws::{boundary_layer_zeta, nsd_kappa};
use crate::physics::screens::{Arrangement, loss_coefficient};

/// The structural mode and its excitation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Structure {
    /// Modal mass [kg], natural frequency [Hz], damping ratio.
    pub mass: f64,
    pub frequency: f64,
    pub damping: f64,
    /// Amplitude of the harmonic design force at resonance [N].
    pub force: f64,
}

impl Structure {
    pub fn omega(&self) -> f64 {
        2.0 * PI * self.frequency
    }

    pub fn stiffness(&self) -> f64 {
        self.mass * self.omega() * self.omega()
    }
}

/// What the designer allows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Water mass over the modal mass.
    pub mass_ratio: f64,
    /// Largest tank length along the motion and breadth across it [m].
    pub length: f64,
    pub breadth: f64,
    /// Preferred depth ratio h/a (shallower if the footprint needs it).
    pub depth_ratio: f64,
    /// Screens per tank (evenly spread: Tait's 0.4 a and 0.6 a for two).
    pub screens: u32,
}

/// The design.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Design {
    /// One tank (length, breadth, depth) and the count.
    pub tank: Tank,
    pub tanks: u32,
    pub screens: Arrangement,
    /// Effective mass ratio m_1/M, Warburton's frequency ratio and damping.
    pub mu: f64,
    pub gamma: f64,
    pub zeta_opt: f64,
    /// The boundary layers' zeta and the design amplitude A_e [m] (Lambda = A_e/a).
    pub zeta_bl: f64,
    pub amplitude: f64,
    /// NSD hardening at the design amplitude.
    pub kappa: f64,
    /// The loss coefficient the screens need.
    pub loss: f64,
}

/// Water at 20 C.
const NU: f64 = 1e-6;
const RHO: f64 = 1000.0;
const G: f64 = 9.81;

/// The tank of depth ratio `r` whose fundamental is at `omega` [rad/s] (Eq 2.2 solved for a).
fn length_for(omega: f64, r: f64) -> f64 {
    G * PI * (PI * r).tanh() / (omega * omega)
}

/// The solidity of a slat screen with loss coefficient `c_l` (C_l(S) inverted by bisection on
/// [0, 0.95]; None beyond).
pub fn solidity_for(c_l: f64) -> Option<f64> {
    if c_l.is_nan() || c_l < 0.0 || c_l > loss_coefficient(0.95) {
        return None;
    }
    let (mut lo, mut hi) = (0.0, 0.95);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if loss_coefficient(mid) < c_l {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// The preliminary design (module docs); Err with the reason if the limits cannot be met.
pub fn design(s: &Structure, l: &Limits) -> Result<Design, String> {
    let positive = [
        s.mass,
        s.frequency,
        s.force,
        l.mass_ratio,
        l.length,
        l.breadth,
    ];
    if !positive.iter().all(|v| v.is_finite() && *v > 0.0) || !(0.0..1.0).contains(&s.damping) {
        return Err("mass, frequency, force, mass ratio and footprint must be positive".into());
    }
    if !(0.02..=0.15).contains(&l.depth_ratio) {
        return Err(format!(
            "depth ratio {} outside the shallow-water range 0.02-0.15",
            l.depth_ratio
        ));
    }
    let water = l.mass_ratio * s.mass;
    let (mut r, mut kappa, mut a) = (l.depth_ratio, 1.0, 0.0);
    let (mut mu, mut gamma, mut zeta_opt, mut amplitude) = (0.0, 1.0, 0.0, 0.0);
    // Fixed point: the mass fraction m_1/M_l depends on r, the length on the frequency and r,
    // kappa on Lambda = A_e/a.
    for _ in 0..50 {
        let fraction = Tank {
            length: 1.0,
            breadth: 1.0,
            depth: r,
            density: RHO,
            g: G,
        }
        .fundamental()
        .mass
            / r
            / RHO;
        mu = water * fraction / s.mass;
        gamma = 1.0 / (1.0 + mu);
        zeta_opt = (3.0 * mu / (8.0 * (1.0 + mu))).sqrt();
        amplitude = s.force / s.stiffness() * (1.0 + 2.0 / mu).sqrt();
        let omega_1 = gamma * s.omega() / kappa;
        a = length_for(omega_1, r);
        if a > l.length {
            // Shallower: tanh(pi r) = a_max omega^2/(g pi).
            let t = l.length * omega_1 * omega_1 / (G * PI);
            r = t.atanh() / PI;
            if r.is_nan() || r < 0.02 {
                return Err(format!(
                    "a tank tuned to {:.3} Hz needs a length of {a:.2} m even at h/a = 0.02: \
                     the footprint ({} m) is too short",
                    omega_1 / (2.0 * PI),
                    l.length
                ));
            }
            a = l.length;
        }
        let next = nsd_kappa((amplitude / a).clamp(1e-3, 0.1));
        if (next - kappa).abs() < 1e-12 {
            break;
        }
        kappa = next;
    }
    let depth = r * a;
    let tanks = (water / (RHO * a * depth * l.breadth)).ceil().max(1.0);
    let breadth = water / (RHO * a * depth * tanks);
    let tank = Tank {
        length: a,
        breadth,
        depth,
        density: RHO,
        g: G,
    };
    let omega_1 = tank.fundamental().omega;
    let zeta_bl = boundary_layer_zeta(omega_1, depth, breadth, NU, 1.0);
    let mut screens = Arrangement {
        count: l.screens,
        solidity: 0.0,
        spacing: if l.screens == 2 { 0.2 * a } else { 0.0 },
        loss: 0.0,
    };
    let mass_fraction = tank.fundamental().mass / tank.liquid_mass();
    let loss = if zeta_opt > zeta_bl && l.screens > 0 {
        let k = 2.0 * zeta_opt * (zeta_opt - zeta_bl) / amplitude;
        k * a / (2.0 / 3.0 * mass_fraction * screens.velocity_cubes(a))
    } else {
        0.0
    };
    screens.solidity = solidity_for(loss).ok_or_else(|| {
        format!(
            "the screens would need a loss coefficient of {loss:.1} (solidity above 0.95): \
             use more screens"
        )
    })?;
    Ok(Design {
        tank,
        tanks: tanks as u32,
        screens,
        mu,
        gamma,
        zeta_opt,
        zeta_bl,
        amplitude,
        kappa,
        loss,
    })
}

impl Design {
    /// The FMU's parameters for these tanks as model = ShallowWater (damping = Screens: the
    /// boundary layers' drag, the screens resolved) on `cells` cells.
    pub fn parameters(&self, cells: u32) -> StartValues {
        let item = |i: i64| i as f64;
        StartValues::default()
            .with(vr::MODEL, item(ModelKindItem::ShallowWater as i64))
            .with(vr::DAMPING, item(DampingLawItem::Screens as i64))
            .with(vr::AMPLITUDE, item(AmplitudeModeItem::Fixed as i64))
            .with(vr::A_E, self.amplitude)
            .with(vr::TANK_LENGTH, self.tank.length)
            .with(vr::TANK_BREADTH, self.tank.breadth)
            .with(vr::TANK_DEPTH, self.tank.depth)
            .with(vr::TANKS, f64::from(self.tanks))
            .with(vr::SCREENS_COUNT, f64::from(self.screens.count))
            .with(vr::SCREENS_SOLIDITY, self.screens.solidity)
            .with(vr::SCREENS_SPACING, self.screens.spacing)
            .with(vr::SWE_CELLS, f64::from(cells))
            .with(vr::SLOSH_X0, 0.0)
            .with(vr::SLOSH_V0, 0.0)
    }
}

/// The structure (Newmark's average acceleration) carrying `damper` (None: bare) under the
/// harmonic force `force` sin(w t), swept slowly over `ratios` of its frequency: the steady
/// displacement amplitude at each (the largest over the last `measure` of `periods` periods
/// per frequency, `steps` steps per period). The damper is driven by the structure's
/// acceleration at the start of each step and pushes back with its force.mean over the step
/// (explicit coupling: stable while the liquid mass is below the structure's).
pub fn response(
    s: &Structure,
    mut damper: Option<Damper>,
    ratios: &[f64],
    periods: u32,
    steps: u32,
) -> Result<Vec<f64>, String> {
    let (m, k) = (s.mass, s.stiffness());
    let c = 2.0 * s.damping * m * s.omega();
    let (mut x, mut v, mut acc, mut t) = (0.0, 0.0, 0.0, 0.0);
    let measure = (periods / 4).max(1);
    let mut out = Vec::with_capacity(ratios.len());
    for &ratio in ratios {
        let w = ratio * s.omega();
        let h = 2.0 * PI / w / f64::from(steps);
        let mut largest: f64 = 0.0;
        // The phase restarts at each frequency after whole periods: the force stays smooth.
        for n in 0..periods * steps {
            let inputs = Inputs {
                a: acc,
                v,
                a_derivatives: [0.0; 2],
            };
            let push = match damper.as_mut() {
                Some(d) => {
                    d.step(t, h, &inputs)
                        .map_err(|e| format!("at t = {t:.2} s: {e}"))?;
                    d.output(Output::ForceMean, &inputs)
                }
                None => 0.0,
            };
            let p = s.force * (w * h * f64::from(n % steps + 1)).sin() + push;
            let lhs = m + 0.5 * h * c + 0.25 * h * h * k;
            let next = (p - c * (v + 0.5 * h * acc) - k * (x + h * v + 0.25 * h * h * acc)) / lhs;
            x += h * v + 0.25 * h * h * (acc + next);
            v += 0.5 * h * (acc + next);
            acc = next;
            t += h;
            if n >= (periods - measure) * steps {
                largest = largest.max(x.abs());
            }
        }
        out.push(largest);
    }
    Ok(out)
}

/// Configure the shallow-water damper of `design` on `cells` cells.
pub fn damper(design: &Design, cells: u32) -> Result<Damper, String> {
    Damper::configure(&design.parameters(cells)).map(|(d, _)| d)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn building() -> (Structure, Limits) {
        (
            Structure {
                mass: 1.0e6,
                frequency: 0.25,
                damping: 0.01,
                force: 1.0e4,
            },
            Limits {
                mass_ratio: 0.02,
                length: 20.0,
                breadth: 5.0,
                depth_ratio: 0.12,
                screens: 2,
            },
        )
    }

    /// The design meets its own equations: the tank's hardened frequency is Warburton's, the
    /// water mass is the allowed one, the screens' law gives zeta_opt at the design amplitude.
    #[test]
    fn design_meets_its_targets() {
        let (s, l) = building();
        let d = design(&s, &l).expect("design");
        let w1 = d.tank.fundamental().omega;
        let target = d.gamma * s.omega();
        assert!((w1 * d.kappa / target - 1.0).abs() < 1e-9, "{w1} {target}");
        let water = d.tank.liquid_mass() * f64::from(d.tanks);
        assert!((water / (l.mass_ratio * s.mass) - 1.0).abs() < 1e-12);
        assert!(d.tank.breadth <= l.breadth && d.tank.length <= l.length);
        let k = d.screens.zeta_per_response(
            d.tank.length,
            d.tank.fundamental().mass / d.tank.liquid_mass(),
        );
        let zeta = crate::physics::screens::resonant_zeta(d.zeta_bl, k, d.amplitude);
        assert!(
            (zeta / d.zeta_opt - 1.0).abs() < 1e-9,
            "{zeta} {}",
            d.zeta_opt
        );
        assert!((loss_coefficient(d.screens.solidity) / d.loss - 1.0).abs() < 1e-9);
        // A short footprint makes the tank shallower, not longer.
        let short = design(
            &s,
            &Limits {
                length: 0.8 * d.tank.length,
                ..l
            },
        )
        .expect("design");
        assert!(short.tank.length <= 0.8 * d.tank.length * (1.0 + 1e-12));
        assert!(short.tank.depth_ratio() < d.tank.depth_ratio());
    }

    /// The designed tanks, co-simulated as the shallow-water model with the screens resolved
    /// (coarse: 24 cells, 30 periods at 9 frequencies), hold the structure's peak to the
    /// design's prediction (P/K) sqrt(1 + 2/mu) within 10 % (the tool's 100-cell run: -2 %),
    /// a fifth of the bare structure's.
    #[test]
    fn designed_tanks_hold_the_peak_to_the_prediction() {
        let (s, l) = building();
        let d = design(&s, &l).expect("design");
        let ratios: Vec<f64> = (0..9).map(|k| 0.92 + 0.02 * f64::from(k)).collect();
        let x = response(&s, Some(damper(&d, 24).expect("damper")), &ratios, 30, 64).expect("run");
        let peak = x.iter().copied().fold(0.0, f64::max);
        let predicted = s.force / s.stiffness() * (1.0 + 2.0 / d.mu).sqrt();
        let bare = s.force / (2.0 * s.damping * s.stiffness());
        eprintln!("design: peak {peak:.4e} m, predicted {predicted:.4e} m, bare {bare:.4e} m");
        assert!(
            (peak / predicted - 1.0).abs() < 0.1,
            "{peak} vs {predicted}"
        );
        assert!(peak < 0.3 * bare);
    }

    /// The bare structure's steady resonant amplitude is P/(2 zeta K) (the slow sweep settles).
    #[test]
    fn bare_response_is_the_closed_form() {
        let (s, _) = building();
        let x = response(&s, None, &[1.0], 400, 64).expect("run")[0];
        let want = s.force / (2.0 * s.damping * s.stiffness());
        assert!((x / want - 1.0).abs() < 0.01, "{x} vs {want}");
    }
}
