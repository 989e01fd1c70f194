//! Stepped-sine frequency sweeps of a damper in the time domain, through the model contract,
//! so they work for every model: the steady first-harmonic response, the energy-equivalent
//! damping, and the jumps of slow up and down sweeps. What the calibration from physics
//! (kappa(Lambda), zeta(Lambda) of the shallow-water model) is measured with.
//!
//! Base motion x_b = A sin(w tau), tau restarting at each frequency after whole cycles (so
//! a_b = -w^2 A sin(w tau) is continuous across the change), passed with its first two
//! derivatives. Each frequency is run cycle by cycle from the state the last one left until the
//! first-harmonic amplitude of `slosh.x` settles, then measured over whole cycles.
//!
//! Equivalent damping: the viscous ratio of Eq 2.11's form (c = 2 zeta omega_f) that dissipates
//! the same energy per cycle at the measured first-harmonic amplitude X,
//! zeta_eq = E_cycle / (2 pi m_1 omega_f w X^2), m_1 the fundamental modal mass of Eq 2.1 (over
//! all tanks): for the Nonlinear model with constant zeta and a harmonic response it is that
//! zeta.

use std::f64::consts::PI;

use crate::model::{Common, Damper, Inputs, Output, Parameters};

/// How each frequency of a sweep is run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settling {
    /// Communication steps per cycle of the excitation.
    pub steps_per_cycle: u32,
    /// Settled: the first-harmonic amplitude stayed within this (relative) over the last
    /// window of cycles (`Sweeper::respond`).
    pub tolerance: f64,
    /// Cycles run at most before measuring anyway (the point is then marked unsettled).
    pub max_cycles: u32,
    /// Cycles averaged in the measurement.
    pub measure_cycles: u32,
}

impl Default for Settling {
    fn default() -> Self {
        Settling {
            steps_per_cycle: 128,
            tolerance: 1e-3,
            max_cycles: 300,
            measure_cycles: 2,
        }
    }
}

/// The steady response at one frequency.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response {
    /// w / omega_f.
    pub ratio: f64,
    /// First-harmonic amplitude of slosh.x [m].
    pub x: f64,
    /// Its phase lag behind the excitation of Eq 2.11's right-hand side, -a_b [rad]: 0 far
    /// below resonance, pi/2 at it, towards pi above.
    pub phase: f64,
    /// Largest abs(slosh.x) over the measured cycles [m].
    pub x_peak: f64,
    /// Energy dissipated per cycle [J].
    pub energy_per_cycle: f64,
    /// Energy-equivalent damping ratio (module docs).
    pub zeta_eq: f64,
    /// Cycles run before measuring.
    pub cycles: u32,
    pub settled: bool,
}

/// A damper under harmonic base motion, swept in frequency.
pub struct Sweeper {
    damper: Damper,
    /// omega_f [rad/s] and the fundamental modal mass of Eq 2.1 over all tanks [kg].
    omega_f: f64,
    m1: f64,
    /// Base displacement amplitude A [m].
    amplitude: f64,
    settling: Settling,
    time: f64,
}

/// What one cycle measured.
struct Cycle {
    x: f64,
    phase: f64,
    x_peak: f64,
    energy: f64,
}

impl Sweeper {
    /// The damper `p` configures, from its start, under base motion of amplitude `amplitude`.
    pub fn new(p: &dyn Parameters, amplitude: f64, settling: Settling) -> Result<Self, String> {
        if !(amplitude.is_finite() && amplitude > 0.0) {
            return Err(format!("the base amplitude {amplitude} m must be positive"));
        }
        if settling.steps_per_cycle < 8 || settling.measure_cycles == 0 || settling.max_cycles < 8 {
            return Err(
                "at least 8 steps per cycle, one measured cycle and 8 cycles to settle in".into(),
            );
        }
        let (common, _) = Common::read(p)?;
        let (damper, _) = Damper::configure(p)?;
        let fundamental = common.tank.fundamental();
        Ok(Sweeper {
            damper,
            omega_f: fundamental.omega,
            m1: fundamental.mass * f64::from(common.tanks),
            amplitude,
            settling,
            time: 0.0,
        })
    }

    pub fn omega_f(&self) -> f64 {
        self.omega_f
    }

    /// Simulated time run so far [s].
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Run one cycle at `w` [rad/s] from the current state.
    fn cycle(&mut self, w: f64) -> Result<Cycle, String> {
        let n = self.settling.steps_per_cycle;
        let h = 2.0 * PI / w / f64::from(n);
        let a = self.amplitude;
        let none = Inputs::default();
        let e0 = self.damper.output(Output::EnergyDissipated, &none);
        let (mut s, mut c, mut peak) = (0.0, 0.0, 0.0f64);
        for k in 0..n {
            let phase = w * h * f64::from(k);
            let (sin, cos) = phase.sin_cos();
            let inputs = Inputs {
                a: -w * w * a * sin,
                v: 0.0,
                a_derivatives: [-w * w * w * a * cos, w * w * w * w * a * sin],
            };
            self.damper
                .step(self.time, h, &inputs)
                .map_err(|e| format!("at t = {:.3} s, w = {w:.4} rad/s: {e}", self.time))?;
            self.time += h;
            let x = self.damper.output(Output::X, &none);
            let end = w * h * f64::from(k + 1);
            s += x * end.sin();
            c += x * end.cos();
            peak = peak.max(x.abs());
        }
        // x = X sin(w t - phase) gives s = X cos(phase) n/2, c = -X sin(phase) n/2.
        Ok(Cycle {
            x: 2.0 * s.hypot(c) / f64::from(n),
            phase: (-c).atan2(s),
            x_peak: peak,
            energy: self.damper.output(Output::EnergyDissipated, &none) - e0,
        })
    }

    /// The energy-equivalent damping ratio of dissipating `energy` per cycle at amplitude `x` and
    /// frequency `w` (module docs).
    fn zeta_eq(&self, energy: f64, w: f64, x: f64) -> f64 {
        energy / (2.0 * PI * self.m1 * self.omega_f * w * x * x)
    }

    /// The steady response at `ratio` = w/omega_f, from the state the last frequency left.
    pub fn respond(&mut self, ratio: f64) -> Result<Response, String> {
        let w = ratio * self.omega_f;
        let tol = self.settling.tolerance;
        // Settled when the amplitude has stayed within the tolerance over a window long enough
        // for any transient to show: one e-fold of its decay (1/(2 pi zeta) cycles, zeta from
        // the cycle's own dissipation) and one and a half beats of the free motion against the
        // forcing (1/abs(1 - w/omega_f) cycles per beat). Over one e-fold a decaying transient
        // moves by 63 % of what is left of it.
        let mut history = Vec::new();
        let settled = loop {
            let cycle = self.cycle(w)?;
            history.push(cycle.x);
            let zeta = self.zeta_eq(cycle.energy, w, cycle.x);
            let window = settling_window(zeta, ratio, self.settling.max_cycles);
            if history.len() >= window {
                let recent = &history[history.len() - window..];
                let (lo, hi) = recent.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| {
                    (lo.min(x), hi.max(x))
                });
                if hi - lo <= tol * cycle.x {
                    break true;
                }
            }
            if history.len() >= self.settling.max_cycles as usize {
                break false;
            }
        };
        let cycles = history.len() as u32;
        let m = self.settling.measure_cycles;
        let (mut x, mut x_peak, mut energy, mut phase) = (0.0, 0.0f64, 0.0, 0.0);
        for _ in 0..m {
            let cycle = self.cycle(w)?;
            x += cycle.x;
            phase += cycle.phase;
            x_peak = x_peak.max(cycle.x_peak);
            energy += cycle.energy;
        }
        let (x, energy) = (x / f64::from(m), energy / f64::from(m));
        Ok(Response {
            ratio,
            x,
            phase: phase / f64::from(m),
            x_peak,
            energy_per_cycle: energy,
            zeta_eq: self.zeta_eq(energy, w, x),
            cycles,
            settled,
        })
    }

    /// The steady responses at `ratios`, in that order (a slow sweep: each frequency starts from
    /// the state the previous one left).
    pub fn sweep(&mut self, ratios: &[f64]) -> Result<Vec<Response>, String> {
        ratios.iter().map(|&r| self.respond(r)).collect()
    }
}

/// What slow sweeps up and down show of a damper's amplitude dependence at one excitation
/// amplitude, as the NSD model's two numbers: kappa, the frequency over omega_f where the
/// up-sweep's response is in quadrature with the excitation (the equivalent linear oscillator's
/// resonance, where its stiffness is w^2; at the top of the upper branch where an up-sweep
/// jumps, within one harmonic's accuracy), and zeta, the energy-equivalent damping there (both
/// interpolated linearly in the phase between the two frequencies around pi/2). The frequency
/// of the largest response is no such measure once the damping is large: above zeta = 0.71 a
/// linear oscillator's relative displacement grows monotonically with frequency.
#[derive(Clone, Debug, PartialEq)]
pub struct Characteristic {
    /// Base amplitude over tank length, A/a.
    pub lambda: f64,
    /// (kappa, zeta), None if the up-sweep never passes quadrature.
    pub quadrature: Option<(f64, f64)>,
    /// Up-sweep: the largest response, and the jump down (before, after) if there is one.
    pub peak: Response,
    pub jump_down: Option<(Response, Response)>,
    /// Down-sweep: the jump up (before, after) if there is one.
    pub jump_up: Option<(Response, Response)>,
    pub up: Vec<Response>,
    pub down: Vec<Response>,
}

/// How [`characterise`] sweeps: frequency ratios from `from` up to at most `to` in steps of
/// `step`, and back down to `from`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plan {
    pub from: f64,
    pub to: f64,
    pub step: f64,
    pub settling: Settling,
}

/// A jump: the amplitude changes by more than this factor between neighbouring frequencies.
pub const JUMP_FACTOR: f64 = 1.5;

/// Sweep the damper `p` configures up and down at base amplitude `lambda` times its tank length.
/// The up-sweep stops once the response has been below half its largest value (past the peak,
/// on the lower branch) or lagged by more than 3 pi/4 (well past quadrature) for three
/// frequencies; the down-sweep starts where it stopped.
pub fn characterise(
    p: &dyn Parameters,
    lambda: f64,
    plan: &Plan,
) -> Result<Characteristic, String> {
    if !(plan.step > 0.0 && plan.from > 0.0 && plan.to > plan.from) {
        return Err(format!(
            "a sweep from {} to {} in steps of {}",
            plan.from, plan.to, plan.step
        ));
    }
    let (common, _) = Common::read(p)?;
    let amplitude = lambda * common.tank.length;
    let mut sweeper = Sweeper::new(p, amplitude, plan.settling)?;
    let n = ((plan.to - plan.from) / plan.step).round() as usize;
    let mut up = Vec::new();
    let mut below = 0;
    for k in 0..=n {
        let r = sweeper.respond(plan.from + plan.step * k as f64)?;
        up.push(r);
        let top = peak(&up).map_or(0.0, |p| p.x);
        below = if past_peak(&r, top) { below + 1 } else { 0 };
        if below == 3 {
            break;
        }
    }
    let top = up.last().map_or(plan.from, |r| r.ratio);
    let mut sweeper = Sweeper::new(p, amplitude, plan.settling)?;
    let m = ((top - plan.from) / plan.step).round() as usize;
    let down = sweeper.sweep(
        &(0..=m)
            .map(|k| top - plan.step * k as f64)
            .collect::<Vec<_>>(),
    )?;
    let Some(peak) = peak(&up) else {
        return Err("an empty sweep".into());
    };
    Ok(Characteristic {
        lambda,
        quadrature: quadrature(&up),
        peak,
        jump_down: jump(&up, true, JUMP_FACTOR),
        jump_up: jump(&down, false, JUMP_FACTOR),
        up,
        down,
    })
}

/// The cycles over which a response must stay within the tolerance to count as settled at
/// damping `zeta` and frequency ratio `ratio`: one e-fold of a transient's decay,
/// 1/(2 pi zeta) cycles, or one and a half beats of the free motion against the forcing,
/// 1.5/abs(1 - ratio) cycles (at most 40), whichever is longer, rounded up; at least 4, at most
/// half of `max_cycles`.
pub fn settling_window(zeta: f64, ratio: f64, max_cycles: u32) -> usize {
    let decay = (1.0 / (2.0 * PI * zeta)).ceil();
    let beat = (1.5 / (1.0 - ratio).abs()).ceil().min(40.0);
    decay.max(beat).clamp(4.0, f64::from(max_cycles / 2)) as usize
}

/// Whether an up-sweep's response `r` is past the peak `top` (the largest amplitude so far): its
/// amplitude below half of it (on the lower branch) or its lag beyond 3 pi/4 (well past
/// quadrature).
pub fn past_peak(r: &Response, top: f64) -> bool {
    r.x < 0.5 * top || r.phase > 0.75 * PI
}

/// `n` ratios from `from` to `to`, evenly spaced, both included (n >= 2).
pub fn ratios(from: f64, to: f64, n: usize) -> Vec<f64> {
    let n = n.max(2);
    (0..n)
        .map(|k| from + (to - from) * k as f64 / (n - 1) as f64)
        .collect()
}

/// The jump of a sweep: the neighbours (before, after) with the largest relative change of the
/// first-harmonic amplitude in the direction given (`down`: a drop, as an up-sweep falls off its
/// upper branch; otherwise a rise, as a down-sweep jumps onto it), if it exceeds `factor`.
pub fn jump(responses: &[Response], down: bool, factor: f64) -> Option<(Response, Response)> {
    responses
        .windows(2)
        .map(|p| {
            let change = if down {
                p[0].x / p[1].x
            } else {
                p[1].x / p[0].x
            };
            (change, p[0], p[1])
        })
        .filter(|(change, _, _)| *change > factor)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, before, after)| (before, after))
}

/// The ratio and the equivalent damping where the phase of a sweep first passes pi/2,
/// interpolated linearly in the phase.
pub fn quadrature(responses: &[Response]) -> Option<(f64, f64)> {
    let half = 0.5 * PI;
    responses.windows(2).find_map(|p| {
        let (a, b) = (p[0], p[1]);
        if (a.phase - half) * (b.phase - half) > 0.0 || a.phase == b.phase {
            return None;
        }
        let t = (half - a.phase) / (b.phase - a.phase);
        Some((
            a.ratio + t * (b.ratio - a.ratio),
            a.zeta_eq + t * (b.zeta_eq - a.zeta_eq),
        ))
    })
}

/// The response with the largest first-harmonic amplitude.
pub fn peak(responses: &[Response]) -> Option<Response> {
    responses.iter().copied().max_by(|a, b| a.x.total_cmp(&b.x))
}

#[cfg(test)]
mod tests;
