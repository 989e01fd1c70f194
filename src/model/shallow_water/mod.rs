//! model = ShallowWater: the nonlinear shallow-water equations in the tank frame (MODEL.md
//! section 7) on `swe.cells` finite volumes per tank ([`crate::physics::shallow_water`]). The
//! whole liquid is resolved: no inactive mass, force = base shear, and the mean force is the
//! impulse of the wall pressures, the drag and the bed's friction on dry cells summed over
//! the substeps, so that h force.mean = -M_l a_b h - Delta(rho b integral q dx) per step.

use super::{Common, Interval, Model, Observable, Output, Parameters, Start, StepError, Stepped};
use crate::description::vr;
use crate::physics::laws::DampingLaw;
use crate::physics::shallow_water::scheme::velocity;
use crate::physics::shallow_water::{Channel, DRY, Flow, Scratch};
use crate::solver::SolveStats;
use std::f64::consts::PI;

/// Deepest tank the model takes, h/a: twice the shallow-water limit of MODEL.md (0.15). The
/// dispersion correction g_e keeps the fundamental right at any depth, but the higher modes
/// (3 omega_1 here, 2.77 omega_1 in potential theory already at h/a = 0.084) and the
/// hydrostatic bores drift further from the real liquid as it deepens.
pub const DEEPEST: f64 = 0.3;

/// Numbers saved after the depths and discharges: the work done on the liquid.
const CARRIED: usize = 1;

#[derive(Clone, Debug, PartialEq)]
pub struct ShallowWater {
    channel: Channel,
    flow: Flow,
    /// rho b tanks: turns the scheme's per-unit-breadth-and-density numbers into totals; rho b
    /// alone into one tank's.
    scale: f64,
    rho_b: f64,
    /// Eq 2.1's m_1 of one tank [kg] (slosh.x = M_l x_cm / m_1) and Eq 2.2's omega_1.
    m1: f64,
    omega_1: f64,
    /// Damping ratio of the last step: the drag is 2 zeta omega_1 q.
    zeta: f64,
    /// damping = Screens: its boundary layers' zeta, the drag's instead of the law's.
    boundary: Option<f64>,
    /// Work of the inertial force on the liquid since the start [J] and the energy stored at
    /// the start [J] (which the damper counts as input).
    work: f64,
    initial_energy: f64,
    /// Most substeps per communication step (solver.max_substeps).
    most: u64,
    /// The liquid of all tanks, rho a b h tanks [kg], as the damper computes mass.liquid.
    liquid: f64,
    storage: Storage,
}

/// Where a step is taken (the state stays as it was if the step is refused) and the substep's
/// storage: allocated once, not per step. It holds nothing from one step to the next: any two
/// are equal, and a clone is a new one.
#[derive(Debug)]
struct Storage {
    next: Flow,
    scratch: Scratch,
}

impl Storage {
    fn new(channel: &Channel) -> Self {
        Storage {
            next: channel.at_rest(),
            scratch: Scratch::new(channel.cells),
        }
    }
}

impl Clone for Storage {
    fn clone(&self) -> Self {
        Storage {
            next: self.next.clone(),
            scratch: Scratch::new(self.next.depth.len()),
        }
    }
}

impl PartialEq for Storage {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl ShallowWater {
    fn drag(&self) -> f64 {
        2.0 * self.linear_zeta(self.zeta) * self.omega_1
    }

    /// The damping ratio of the linear drag for the damping law's `zeta`: damping = Screens
    /// gives its boundary layers' part only (the screens are resolved, not averaged).
    fn linear_zeta(&self, zeta: f64) -> f64 {
        self.boundary.unwrap_or(zeta)
    }

    /// Cell averages of cos (odd = false) or sin (true) of pi x/a.
    fn fundamental_shape(ch: &Channel, odd: bool) -> Vec<f64> {
        let (dx, k) = (ch.dx(), PI / ch.length);
        (0..ch.cells)
            .map(|i| {
                let (x0, x1) = (i as f64 * dx, (i + 1) as f64 * dx);
                if odd {
                    ((k * x0).cos() - (k * x1).cos()) / (k * dx)
                } else {
                    ((k * x1).sin() - (k * x0).sin()) / (k * dx)
                }
            })
            .collect()
    }
}

impl Model for ShallowWater {
    fn configure(p: &dyn Parameters, common: &Common, start: Start) -> Result<Self, String> {
        let t = &common.tank;
        let cells = p.count(vr::SWE_CELLS) as usize;
        if cells < 2 {
            return Err(format!(
                "swe.cells = {cells}: the model needs 2 cells or more"
            ));
        }
        let r = t.depth_ratio();
        if r > DEEPEST {
            return Err(format!(
                "depth ratio h/a = {r:.3}: the shallow-water model takes tanks up to h/a = \
                 {DEEPEST} (twice the shallow-water limit 0.15)"
            ));
        }
        let mut channel = Channel::new(t.length, t.depth, t.g, cells);
        let screens = &common.screens;
        if screens.count > 0 {
            channel =
                channel.with_screens(&screens.positions(t.length), screens.loss_coefficient());
        }
        let m1 = t.fundamental().mass;
        let rho_b = t.density * t.breadth;
        // The initial condition of the mechanical models' sloshing mass as the fundamental
        // mode: the surface eta(0) cos(pi x/a) with the first moment m_1 x0
        // (rho b integral eta (x - a/2) dx = -2 rho b a^2 eta(0)/pi^2) and the discharge
        // Q sin(pi x/a) with the momentum m_1 v0 (rho b 2 a Q/pi).
        let eta = -PI * PI * m1 * common.x0 / (2.0 * rho_b * t.length * t.length);
        if eta.abs() >= t.depth {
            return Err(format!(
                "slosh.x0 = {} m raises the fundamental mode {:.4} m at the walls, more than the \
                 depth {} m: the tank would run dry at the start",
                common.x0,
                eta.abs(),
                t.depth
            ));
        }
        let discharge = PI * m1 * common.v0 / (2.0 * rho_b * t.length);
        let flow = Flow {
            depth: Self::fundamental_shape(&channel, false)
                .iter()
                .map(|c| t.depth + eta * c)
                .collect(),
            discharge: Self::fundamental_shape(&channel, true)
                .iter()
                .map(|s| discharge * s)
                .collect(),
        };
        let scale = rho_b * f64::from(common.tanks);
        Ok(ShallowWater {
            initial_energy: scale * channel.energy(&flow),
            channel,
            flow,
            scale,
            rho_b,
            m1,
            omega_1: t.fundamental().omega,
            zeta: start.zeta,
            boundary: match common.damping {
                DampingLaw::Screens { boundary, .. } => Some(boundary),
                _ => None,
            },
            work: 0.0,
            most: u64::from(p.count(vr::SOLVER_MAX_SUBSTEPS)),
            liquid: common.liquid_mass(),
            storage: Storage::new(&channel),
        })
    }

    /// The whole liquid: nothing moves rigidly with the tanks.
    fn sloshing_mass(&self) -> f64 {
        self.liquid
    }

    /// Out of line: the steps of the other models stay small.
    #[inline(never)]
    fn step(&mut self, step: &Interval) -> Result<Stepped, StepError> {
        let c = 2.0 * self.linear_zeta(step.zeta) * self.omega_1;
        let Storage { next, scratch } = &mut self.storage;
        next.clone_from(&self.flow);
        let done = self
            .channel
            .advance_in(scratch, next, step.h, &step.base, c, self.most)
            .map_err(|e| StepError::Solver(e.shifted(step.t)))?;
        std::mem::swap(&mut self.flow, next);
        self.zeta = step.zeta;
        self.work += self.scale * done.work;
        let stats = SolveStats {
            accepted: done.substeps,
            rejected: done.rejected,
            // One flux evaluation per substep, taken or not.
            evaluations: done.substeps + done.rejected,
        };
        Ok(Stepped {
            stats,
            impulse: self.scale * done.impulse,
            force: self.force(),
            sloshing: self.sloshing(),
        })
    }

    /// M_l x_cm / m_1 and its continuum rate rho b integral q dx / m_1 (per tank: the ratio
    /// is the same for all tanks).
    #[inline(always)]
    fn sloshing(&self) -> (f64, f64) {
        (
            self.rho_b * self.channel.moment(&self.flow) / self.m1,
            self.rho_b * self.channel.momentum(&self.flow) / self.m1,
        )
    }

    fn force(&self) -> f64 {
        self.scale * self.channel.force(&self.flow, self.drag())
    }

    fn surface(&self) -> Option<[f64; 2]> {
        let [l, r] = self.channel.wall_depths(&self.flow);
        let h = self.channel.depth;
        Some([l - h, r - h])
    }

    fn observe(&self, which: Observable) -> f64 {
        let stored = || self.scale * self.channel.energy(&self.flow);
        match which {
            Observable::WorkIn => self.work,
            // Drag, bores and the bed's friction on dry cells together (MODEL.md 7).
            Observable::Dissipated => self.initial_energy + self.work - stored(),
            Observable::Stored => stored(),
            Observable::ImpactZ | Observable::Impacts | Observable::ImpactImpulse => 0.0,
        }
    }

    /// The time derivatives of the outputs along the semi-discrete equations (the scheme's
    /// right-hand side at this state and base acceleration `a`, with the drag), exact for
    /// the outputs' definitions: force, slosh.x and slosh.v, the energies, the wall heights.
    /// (The substeps follow the fully discrete scheme, which differs from the semi-discrete
    /// flow by its time-stepping error.)
    fn rate(&self, which: Output, a: f64, _a_rate: f64) -> f64 {
        let ch = &self.channel;
        let (h, q) = (&self.flow.depth, &self.flow.discharge);
        let c = self.drag();
        let r = ch.semi_discrete(&self.flow, a, c);
        let dx = ch.dx();
        let n = ch.cells;
        let dry = DRY * ch.depth;
        let dq = |i: usize| r.discharge[i];
        let momentum_rate = (0..n).map(dq).sum::<f64>() * dx;
        // Wall depths 1.5 H_0 - 0.5 H_1 (cut at 0) and their rates.
        let [left, right] = ch.wall_depths(&self.flow);
        let wall_rate = |depth: f64, near: usize, next: usize| {
            if depth > 0.0 {
                1.5 * r.depth[near] - 0.5 * r.depth[next]
            } else {
                0.0
            }
        };
        let (dl, dr) = (wall_rate(left, 0, 1), wall_rate(right, n - 1, n - 2));
        let power_in = -a * r.mass_flux.iter().sum::<f64>() * dx;
        let stored_rate = || {
            (0..n)
                .map(|i| {
                    let u = velocity(q[i], h[i], dry);
                    u * dq(i) - 0.5 * u * u * r.depth[i] + ch.g_e * (h[i] - ch.depth) * r.depth[i]
                })
                .sum::<f64>()
                * dx
        };
        match which {
            Output::Force => {
                let force = ch.g_e * (right * dr - left * dl) + c * momentum_rate;
                if ch.screens.is_empty() {
                    self.scale * force
                } else {
                    let drag = ch.screens.drag_rate(h, q, &r.depth, &r.discharge, dry);
                    self.scale * (force + drag * dx)
                }
            }
            Output::X => {
                let mid = 0.5 * ch.length;
                self.rho_b
                    * (0..n)
                        .map(|i| r.depth[i] * (ch.centre(i) - mid))
                        .sum::<f64>()
                    * dx
                    / self.m1
            }
            Output::V => self.rho_b * momentum_rate / self.m1,
            Output::EnergyInput => self.scale * power_in,
            Output::EnergyStored => self.scale * stored_rate(),
            Output::EnergyDissipated => self.scale * (power_in - stored_rate()),
            Output::SurfaceLeft => dl,
            Output::SurfaceRight => dr,
            Output::ForceMean
            | Output::BaseShear
            | Output::Amplitude
            | Output::Zeta
            | Output::ImpactZ
            | Output::Impacts
            | Output::ImpactImpulse => 0.0,
        }
    }

    fn set_damping(&mut self, zeta: f64) {
        self.zeta = zeta;
    }

    fn state_len(&self) -> usize {
        2 * self.channel.cells + CARRIED
    }

    fn save(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(&self.flow.depth);
        out.extend_from_slice(&self.flow.discharge);
        out.push(self.work);
    }

    fn load(&mut self, state: &[f64]) -> Result<(), String> {
        let n = self.channel.cells;
        let (depth, rest) = state.split_at(n);
        if depth.iter().any(|&h| h < 0.0) {
            return Err("the state holds a negative depth".into());
        }
        let volume = depth.iter().sum::<f64>() * self.channel.dx();
        let still = self.channel.depth * self.channel.length;
        // Mass is conserved to round-off: a state of another liquid is not this tank's.
        if (volume / still - 1.0).abs() > 1e-9 {
            return Err(format!(
                "the state holds {volume:e} m^2 of liquid per unit breadth, the tank {still:e}"
            ));
        }
        self.flow.depth.copy_from_slice(depth);
        self.flow.discharge.copy_from_slice(&rest[..n]);
        self.work = rest[n];
        Ok(())
    }
}

pub mod continuous;
#[cfg(test)]
mod tests;
