//! Preliminary design of a TLD with damping screens for a structural mode under a design
//! excitation (a harmonic force at resonance, wind as a white-noise force, a ground-motion
//! record), after Tait 2008's procedure with Warburton's optima (analysis::excitation), and its
//! check by co-simulation with the shallow-water model (screens resolved). docs/DESIGN.md.
//!
//! 1. The effective mass ratio mu = m_1/M (m_1 the fundamental sloshing mass of all tanks, Eq
//!    2.1, from the water mass ratio and the depth ratio) gives Warburton's optimum frequency
//!    ratio gamma and damping zeta_opt for the excitation.
//! 2. The design response: the tuned mass's response X in the Screens law zeta_s = K X, with the
//!    optimal linear damper on the structure (harmonic: A_e/(2 zeta_opt), A_e the structure's
//!    resonant amplitude (P/K) sqrt(1 + 2/mu); wind: 1.880 sigma of the tuned mass; record: its
//!    peak); the equivalent base amplitude A_e = 2 zeta_opt X.
//! 3. The tank: length from Eq 2.2 at the depth ratio for the linear frequency
//!    gamma omega_s / kappa(Lambda), kappa the NSD hardening at Lambda = A_e/a (iterated: a
//!    depends on the frequency, Lambda on a); shortened to the footprint by a shallower depth
//!    ratio if needed; breadth and count from the water mass and the largest breadth.
//! 4. The screens: K = (zeta_opt - zeta_BL)/X, then the loss coefficient
//!    C_l = K a / ((2/3)(m_1/M_l) sum |sin(pi x_j/a)|^3) and the solidity with that C_l.

use std::f64::consts::PI;

use crate::analysis::excitation::{Optimum, TwoDof, warburton};
use crate::description::{AmplitudeModeItem, DampingLawItem, ModelKindItem, vr};
use crate::model::{Damper, Inputs, Output, StartValues};
use crate::physics::geometry::Tank;
use crate::physics::laws::{boundary_layer_zeta, nsd_kappa};
use crate::physics::screens::RANDOM_SCREENS;
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

/// The design excitation (docs/DESIGN.md): what sets Warburton's optimum and the design
/// amplitude.
#[derive(Clone, Debug, PartialEq)]
pub enum Excitation {
    /// The harmonic force `Structure::force` at resonance.
    Harmonic,
    /// Wind: a white-noise modal force of two-sided spectral density `s0` [N^2 s/rad].
    Wind { s0: f64 },
    /// A ground-motion record: accelerations [m/s^2] every `step` s; the modal force is
    /// -`participation` a_g.
    Record {
        step: f64,
        accel: Vec<f64>,
        participation: f64,
    },
}

impl Excitation {
    /// The wind whose resonant response gives the bare structure the rms acceleration
    /// `sigma_a` [m/s^2] at the damper's floor: sigma_X = sigma_a/omega^2 (narrow band) and
    /// sigma_X^2 = pi s0/(K C).
    pub fn wind_from_rms_accel(s: &Structure, sigma_a: f64) -> Self {
        let sigma_x = sigma_a / (s.omega() * s.omega());
        let c = 2.0 * s.damping * s.mass * s.omega();
        Excitation::Wind {
            s0: sigma_x * sigma_x * s.stiffness() * c / PI,
        }
    }

    fn optimum(&self) -> Optimum {
        match self {
            Excitation::Harmonic => Optimum::HarmonicForce,
            Excitation::Wind { .. } => Optimum::WhiteNoiseForce,
            Excitation::Record { .. } => Optimum::HarmonicGround,
        }
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
    /// The sloshing mass's response measure X in zeta_s = K X (harmonic: the amplitude
    /// A_e/(2 zeta_opt); wind: 1.880 sigma of the tuned mass; record: its peak) [m].
    pub sloshing: f64,
    /// The structure's predicted response with the optimal linear damper (harmonic: resonant
    /// amplitude; wind: rms displacement; record: peak displacement) [m].
    pub predicted: f64,
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

/// The preliminary design for the harmonic force at resonance.
pub fn design(s: &Structure, l: &Limits) -> Result<Design, String> {
    design_for(s, &Excitation::Harmonic, l)
}

/// The preliminary design (module docs) for the excitation `e`; Err with the reason if the
/// limits cannot be met.
pub fn design_for(s: &Structure, e: &Excitation, l: &Limits) -> Result<Design, String> {
    let force = match e {
        Excitation::Harmonic => s.force,
        Excitation::Wind { s0 } => *s0,
        Excitation::Record { step, accel, .. } => {
            if accel.len() < 2 || accel.iter().any(|a| !a.is_finite()) {
                return Err("the record needs at least two finite accelerations".into());
            }
            *step
        }
    };
    let positive = [
        s.mass,
        s.frequency,
        force,
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
    let (mut sloshing, mut predicted) = (0.0, 0.0);
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
        (gamma, zeta_opt) = warburton(e.optimum(), mu);
        (sloshing, predicted) = response_measures(s, e, mu, gamma, zeta_opt)?;
        // The equivalent harmonic base amplitude: the Screens law's A_e with X = A_e/(2 zeta).
        amplitude = 2.0 * zeta_opt * sloshing;
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
        sloshing,
        predicted,
    })
}

/// The sloshing mass's response measure X (zeta_s = K X) and the structure's predicted
/// response, with the optimal linear damper (mu, gamma, zeta_d) on the structure.
fn response_measures(
    s: &Structure,
    e: &Excitation,
    mu: f64,
    gamma: f64,
    zeta_d: f64,
) -> Result<(f64, f64), String> {
    let two = TwoDof {
        mass: s.mass,
        omega: s.omega(),
        zeta: s.damping,
        mu,
        gamma,
        zeta_d,
    };
    Ok(match e {
        Excitation::Harmonic => {
            // Den Hartog's fixed points: the structure's resonant amplitude is the tank's A_e.
            let x = s.force / s.stiffness() * (1.0 + 2.0 / mu).sqrt();
            (x / (2.0 * zeta_d), x)
        }
        Excitation::Wind { s0 } => {
            let (sx, sd) = two.white_noise_rms(*s0)?;
            // The random Screens law: zeta_s = 1.880 K sigma (MODEL.md 11).
            (RANDOM_SCREENS * sd, sx)
        }
        Excitation::Record {
            step,
            accel,
            participation,
        } => {
            let (px, pd) = two.record_peaks(*participation, *step, accel);
            (pd, px)
        }
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

/// The structure's mode (Newmark's average acceleration) carrying a damper on its floor. The
/// damper is driven by the floor's absolute acceleration at the start of each step and pushes
/// back with its force.mean over the step (explicit coupling: stable while the liquid mass is
/// below the structure's).
struct Carrier {
    m: f64,
    c: f64,
    k: f64,
    damper: Option<Damper>,
    /// Relative displacement, velocity, acceleration; the ground's velocity; the time.
    x: f64,
    v: f64,
    acc: f64,
    v_g: f64,
    t: f64,
}

impl Carrier {
    fn new(s: &Structure, damper: Option<Damper>) -> Self {
        Carrier {
            m: s.mass,
            c: 2.0 * s.damping * s.mass * s.omega(),
            k: s.stiffness(),
            damper,
            x: 0.0,
            v: 0.0,
            acc: 0.0,
            v_g: 0.0,
            t: 0.0,
        }
    }

    /// One step of `h`: `p` the modal force at its end (external force and -L a_g), the ground
    /// acceleration `a_g` at its start and `a_g_next` at its end.
    fn step(&mut self, h: f64, p: f64, a_g: f64, a_g_next: f64) -> Result<(), String> {
        let inputs = Inputs {
            a: self.acc + a_g,
            v: self.v + self.v_g,
            a_derivatives: [0.0; 2],
        };
        let push = match self.damper.as_mut() {
            Some(d) => {
                d.step(self.t, h, &inputs)
                    .map_err(|e| format!("at t = {:.2} s: {e}", self.t))?;
                d.output(Output::ForceMean, &inputs)
            }
            None => 0.0,
        };
        let (m, c, k, x, v, acc) = (self.m, self.c, self.k, self.x, self.v, self.acc);
        let lhs = m + 0.5 * h * c + 0.25 * h * h * k;
        let next =
            (p + push - c * (v + 0.5 * h * acc) - k * (x + h * v + 0.25 * h * h * acc)) / lhs;
        self.x += h * v + 0.25 * h * h * (acc + next);
        self.v += 0.5 * h * (acc + next);
        self.acc = next;
        self.v_g += 0.5 * h * (a_g + a_g_next);
        self.t += h;
        Ok(())
    }
}

/// The structure carrying `damper` (None: bare) under the harmonic force `force` sin(w t),
/// swept slowly over `ratios` of its frequency: the steady displacement amplitude at each (the
/// largest over the last quarter of `periods` periods per frequency, `steps` steps per period).
pub fn response(
    s: &Structure,
    damper: Option<Damper>,
    ratios: &[f64],
    periods: u32,
    steps: u32,
) -> Result<Vec<f64>, String> {
    let mut carrier = Carrier::new(s, damper);
    let measure = (periods / 4).max(1);
    let mut out = Vec::with_capacity(ratios.len());
    for &ratio in ratios {
        let w = ratio * s.omega();
        let h = 2.0 * PI / w / f64::from(steps);
        let mut largest: f64 = 0.0;
        // The phase restarts at each frequency after whole periods: the force stays smooth.
        for n in 0..periods * steps {
            let p = s.force * (w * h * f64::from(n % steps + 1)).sin();
            carrier.step(h, p, 0.0, 0.0)?;
            if n >= (periods - measure) * steps {
                largest = largest.max(carrier.x.abs());
            }
        }
        out.push(largest);
    }
    Ok(out)
}

/// The structure carrying `damper` (None: bare) under the modal force `force[n]` and the
/// ground acceleration `a_g[n]` (modal force -`participation` a_g) at t = n h: its relative
/// displacement at each t (the same length as the inputs).
pub fn history(
    s: &Structure,
    damper: Option<Damper>,
    h: f64,
    force: &[f64],
    a_g: &[f64],
    participation: f64,
) -> Result<Vec<f64>, String> {
    if force.len() != a_g.len() || h.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err("force and ground acceleration on the same grid, h > 0".into());
    }
    let mut carrier = Carrier::new(s, damper);
    let mut out = Vec::with_capacity(force.len());
    out.push(0.0);
    for n in 1..force.len() {
        let p = force[n] - participation * a_g[n];
        carrier.step(h, p, a_g[n - 1], a_g[n])?;
        out.push(carrier.x);
    }
    Ok(out)
}

/// A realisation of a band-limited white-noise force of two-sided spectral density `s0`
/// [N^2 s/rad] between `band` [rad/s] on t = n h, n < `count`: a sum of cosines at the
/// multiples of 2 pi/(count h) in the band, amplitudes sqrt(4 s0 dw) (one-sided density
/// 2 s0), phases uniform from `seed` (SplitMix64).
pub fn wind_force(s0: f64, band: (f64, f64), h: f64, count: usize, seed: u64) -> Vec<f64> {
    let dw = 2.0 * PI / (count as f64 * h);
    let mut state = seed;
    let mut uniform = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) as f64 / u64::MAX as f64
    };
    let first = (band.0 / dw).ceil().max(1.0) as usize;
    let last = (band.1 / dw).floor() as usize;
    let amplitude = (4.0 * s0 * dw).sqrt();
    let mut out = vec![0.0; count];
    for j in first..=last {
        let (w, phase) = (j as f64 * dw, 2.0 * PI * uniform());
        for (n, f) in out.iter_mut().enumerate() {
            *f += amplitude * (w * h * n as f64 + phase).cos();
        }
    }
    out
}

/// Configure the shallow-water damper of `design` on `cells` cells.
pub fn damper(design: &Design, cells: u32) -> Result<Damper, String> {
    Damper::configure(&design.parameters(cells)).map(|(d, _)| d)
}

#[cfg(test)]
mod tests;
