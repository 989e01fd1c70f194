//! An experiment for issue #29 item 3 (docs/SHALLOW_WATER.md, "Levers measured"): the
//! shallow-water model's spatial operator (the characteristic MC reconstruction of the surface
//! and the velocity, HLL with Einfeldt's speeds, mirror walls, the pseudo-bottom a_b x/g_e,
//! drag by Strang splitting) advanced by the one-stage MUSCL-Hancock scheme (van Leer 1984;
//! Toro, "Riemann solvers and numerical methods for fluid dynamics", ch. 14) instead of
//! SSPRK(10,4): per substep the faces are reconstructed once, evolved by half a substep with
//! the cell's own gradients (the predictor), and one HLL flux per interface is taken between
//! the evolved faces (the corrector); the screens split as the model splits them. Not the
//! model: no films beyond the model's dry-cell stop, no outputs but force.mean and the balances.
//!
//! `cargo run --release --example swe_hancock -- accuracy [RATIOS] [CELLS] [COURANT] [PREDICTOR]`:
//! the time-history and amplitude measures of examples/swe_accuracy.rs against its reference
//! histories (target/swe_accuracy_3200_<ratio>.txt, which that example writes), with the mass
//! drift, the energy balance and the CPU time per doStep of this scheme and of the committed
//! one (the model's `Channel::advance_in`) at the same cells. PREDICTOR: `primitive` (default)
//! or `conservative`.
//!
//! `cargo run --release --example swe_hancock -- rest [CELLS] [COURANT]`: the tilted lake at
//! rest; `-- dambreak [COURANT]`: Ritter's and Stoker's dam breaks; `-- standing [COURANT]`:
//! the smooth standing wave's order; `-- decay [COURANT]`: the linear free decay's frequency
//! and damping (modes 1 and 3); `-- screens [COURANT]`: damping screens' decay and balances;
//! `-- violent
//! [CELLS] [COURANT] [SECONDS]`: resonant forcing that dries the bed (mass, positivity, momentum, energy).

use tld_fmu::description::vr;
use tld_fmu::model::{Common, StartValues};
use tld_fmu::physics::base::BaseAcceleration;
use tld_fmu::physics::laws::DampingLaw;
use tld_fmu::physics::screens::loss_coefficient;
use tld_fmu::physics::shallow_water::lanes::{Survey, decayed, faster, lane_sum, settle, smaller};
use tld_fmu::physics::shallow_water::reconstruction::{Limiting, faces_of};
use tld_fmu::physics::shallow_water::scheme::{Side, hll, velocity};
use tld_fmu::physics::shallow_water::screens::ScreenCells;
use tld_fmu::physics::shallow_water::{Channel, Flow, Scratch};

const SHALLOW_WATER: f64 = 5.0;
const BOUNDARY_LAYER: f64 = 3.0;
const FIXED: f64 = 1.0;
const LAMBDA: f64 = 0.02;
const STEP: f64 = 0.01;
const SECONDS: f64 = 60.0;
/// A substep whose interfaces meet a wave faster than this Courant number allows is taken
/// again, shorter (MUSCL-Hancock is stable up to 1).
const COURANT_BOUND: f64 = 1.0;
/// The Courant number a substep whose corrector left a negative depth is taken again at.
const POSITIVE_COURANT: f64 = 0.45;

/// How the faces are evolved by half a substep.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Predictor {
    /// In (H, u) with the cell's slopes: H' = H_f - dt/(2 dx) (u dH + H du),
    /// u' = u_f - dt/(2 dx) (u du + g_e dw) (dw = dH + rise: the pseudo-bottom's force is in
    /// the surface slope). No division; the lake at rest is kept exactly (dw = du = 0).
    Primitive,
    /// In (H, q) with the flux difference of the cell's own faces and the source -a H:
    /// Toro's form.
    Conservative,
}

/// What a communication step did, per unit breadth and density (as the model's `Advanced`),
/// and what the experiment watches.
#[derive(Clone, Copy, Debug, Default)]
struct Done {
    impulse: f64,
    work: f64,
    substeps: u64,
    rejected: u64,
    /// Cell-substeps whose predictor was skipped (a predicted face thinner than `thin`).
    skipped: u64,
    /// The smallest depth after any corrector, before the dry cells are stopped.
    shallowest: f64,
}

/// MUSCL-Hancock on a channel; the storage of its passes.
struct Hancock {
    ch: Channel,
    courant: f64,
    predictor: Predictor,
    u: Vec<f64>,
    q0: Vec<f64>,
    next_h: Vec<f64>,
    next_q: Vec<f64>,
    behind_h: Vec<f64>,
    behind_u: Vec<f64>,
    ahead_h: Vec<f64>,
    ahead_u: Vec<f64>,
    mass: Vec<f64>,
    momentum: Vec<f64>,
    speed: Vec<f64>,
    /// 1 where the predictor was skipped, per cell.
    skip: Vec<f64>,
}

impl Hancock {
    fn new(ch: Channel, courant: f64, predictor: Predictor) -> Self {
        let n = ch.cells;
        let v = |k| vec![0.0; k];
        Hancock {
            ch,
            courant,
            predictor,
            u: v(n),
            q0: v(n),
            next_h: v(n),
            next_q: v(n),
            behind_h: v(n + 1),
            behind_u: v(n + 1),
            ahead_h: v(n + 1),
            ahead_u: v(n + 1),
            mass: v(n + 1),
            momentum: v(n + 1),
            speed: v(n + 1),
            skip: v(n),
        }
    }

    /// Advance `f` by `step` (from the base input's t0 = 0) under drag coefficient `c`; the
    /// widest instruction set this CPU has, as the model's step does.
    fn advance(&mut self, f: &mut Flow, step: f64, base: &BaseAcceleration, c: f64) -> Done {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: this CPU has AVX-512F (just checked).
            return unsafe { self.advance_avx512(f, step, base, c) };
        }
        self.advance_passes(f, step, base, c)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    fn advance_avx512(&mut self, f: &mut Flow, step: f64, base: &BaseAcceleration, c: f64) -> Done {
        self.advance_passes(f, step, base, c)
    }

    #[inline(always)]
    fn advance_passes(&mut self, f: &mut Flow, step: f64, base: &BaseAcceleration, c: f64) -> Done {
        let g = self.ch.g_e;
        let dry = self.ch.grid().dry;
        let mut speed = f
            .depth
            .iter()
            .zip(&f.discharge)
            .map(|(&h, &q)| velocity(q, h, dry).abs() + (g * h.max(0.0)).sqrt())
            .fold(0.0, f64::max);
        let dx = self.ch.dx();
        let mut done = Done {
            shallowest: f64::INFINITY,
            ..Done::default()
        };
        let mut t = 0.0;
        while t < step {
            let remaining = step - t;
            let dt_cfl = if speed > 0.0 {
                self.courant * dx / speed
            } else {
                f64::INFINITY
            };
            let substeps = (remaining / dt_cfl).ceil().max(1.0);
            let last = substeps <= 1.0;
            let dt = if last {
                remaining
            } else {
                remaining / substeps
            };
            match self.substep(f, t, dt, base, c, &mut done) {
                Ok(s) => {
                    done.substeps += 1;
                    speed = s;
                    t = if last { step } else { t + dt };
                }
                Err(faster) => {
                    done.rejected += 1;
                    speed = faster;
                }
            }
        }
        done
    }

    /// One substep dt from t: drag dt/2, MUSCL-Hancock, drag dt/2. Ok(the largest interface
    /// speed) or Err(it) when it exceeds the bound (nothing changed). In passes without
    /// branches, as the model's sweep (so that the compiler vectorises them).
    #[inline(always)]
    fn substep(
        &mut self,
        f: &mut Flow,
        t: f64,
        dt: f64,
        base: &BaseAcceleration,
        c: f64,
        done: &mut Done,
    ) -> Result<f64, f64> {
        let grid = self.ch.grid();
        let (n, dx, g, dry, thin) = (grid.cells, grid.dx, grid.g_e, grid.dry, grid.thin);
        let limiting = Limiting {
            g,
            inv_g: 1.0 / g,
            thin,
        };
        let h = &f.depth[..n];
        let decay = (-0.5 * c * dt).exp();
        // The first drag half (U0's discharges) and the momentum before it.
        let p0 = decayed(&f.discharge[..n], &mut self.q0[..n], decay);
        // The screens' first half after the drag's (each exact, Strang-symmetric overall, as
        // the model): the discharge they take is their impulse on the tank.
        let screens = !self.ch.screens.is_empty();
        let mut taken = 0.0;
        if screens {
            taken += self.ch.screens.apply(h, &mut self.q0[..n], 0.5 * dt, dry) * dx;
        }
        let q0 = &self.q0[..n];
        // The input's mean over the substep, in the reconstruction (the pseudo-bottom), the
        // predictor and the corrector's source: exact for the quadratic input, so the momentum
        // identity holds. (With a_b at t in the reconstruction and the predictor, as a first
        // version had, the dissipated energy decreased in the first 4-11 steps from rest.)
        let am = (base.integral(t + dt) - base.integral(t)) / dt;
        let rise = am * dx / g;
        let u = &mut self.u[..n];
        for ((u, &h), &q) in u.iter_mut().zip(h).zip(q0) {
            *u = velocity(q, h, dry);
        }
        let u = &*u;
        let evolve = Evolve {
            half: 0.5 * dt / dx,
            g,
            rise,
            source: 0.5 * dt * am,
            dry,
            thin,
            conservative: self.predictor == Predictor::Conservative,
        };
        // The faces (cell i: ahead of interface i, behind interface i + 1) as the model's
        // sweep forms them (at the walls with the mirror cell's differences), then evolved by
        // dt/2. The edge cells first, then the interior in one loop.
        let (ahead_h, ahead_u) = (&mut self.ahead_h[..=n], &mut self.ahead_u[..=n]);
        let (behind_h, behind_u) = (&mut self.behind_h[..=n], &mut self.behind_u[..=n]);
        let skip = &mut self.skip[..n];
        let last = n - 1;
        for (i, dw, du) in [
            (0, [0.0, h[1] - h[0] + rise], [2.0 * u[0], u[1] - u[0]]),
            (
                last,
                [h[last] - h[last - 1] + rise, 0.0],
                [u[last] - u[last - 1], -2.0 * u[last]],
            ),
        ] {
            let faces = faces_of(h[i], u[i], dw, du, rise, limiting);
            (
                ahead_h[i],
                ahead_u[i],
                behind_h[i + 1],
                behind_u[i + 1],
                skip[i],
            ) = evolve.of(h[i], u[i], faces);
        }
        let cells = ahead_h[1..last]
            .iter_mut()
            .zip(&mut ahead_u[1..last])
            .zip(behind_h[2..n].iter_mut().zip(&mut behind_u[2..n]))
            .zip(&mut skip[1..last]);
        for ((((lh, lu), (rh, ru)), sk), (h, u)) in cells.zip(h.windows(3).zip(u.windows(3))) {
            let faces = faces_of(
                h[1],
                u[1],
                [h[1] - h[0] + rise, h[2] - h[1] + rise],
                [u[1] - u[0], u[2] - u[1]],
                rise,
                limiting,
            );
            (*lh, *lu, *rh, *ru, *sk) = evolve.of(h[1], u[1], faces);
        }
        (behind_h[0], behind_u[0]) = (ahead_h[0], -ahead_u[0]);
        (ahead_h[n], ahead_u[n]) = (behind_h[n], -behind_u[n]);
        // The corrector's fluxes between the evolved faces.
        let root_g = g.sqrt();
        let (mass, momentum, speed) = (
            &mut self.mass[..=n],
            &mut self.momentum[..=n],
            &mut self.speed[..=n],
        );
        let out = mass
            .iter_mut()
            .zip(momentum.iter_mut())
            .zip(speed.iter_mut());
        let behind = behind_h.iter().zip(behind_u.iter());
        let ahead = ahead_h.iter().zip(ahead_u.iter());
        for (((f, m), s), ((&hl, &ul), (&hr, &ur))) in out.zip(behind.zip(ahead)) {
            (*f, *m, *s) = hll(Side { h: hl, u: ul }, Side { h: hr, u: ur }, g, root_g, dry);
        }
        (mass[0], mass[n]) = (0.0, 0.0);
        let mut lanes = [0.0; 16];
        let mut chunks = speed.chunks_exact(16);
        for c in &mut chunks {
            for (l, &s) in lanes.iter_mut().zip(c) {
                *l = faster(*l, s);
            }
        }
        for (l, &s) in lanes.iter_mut().zip(chunks.remainder()) {
            *l = faster(*l, s);
        }
        let fastest = lanes.into_iter().fold(0.0, faster);
        if fastest * dt > COURANT_BOUND * dx {
            return Err(fastest);
        }
        // The update; the source -a_b H with H the mean of the substep's ends: the sources
        // sum to -a_b times the (conserved) volume, and the lake at rest keeps H. The depth's
        // increment as lam f[1] - lam f[0]: each interface's lam f is the same number for both
        // its cells, so only the final subtraction rounds (with lam (f[1] - f[0]) the volume
        // drifted by up to 1.6e-13 of itself in 60 s, 1.4e-13 in an hour of the violent run;
        // now 3e-16 and 4e-14, the model's 3.2e-14).
        let lam = dt / dx;
        let source = 0.5 * dt * am;
        let (next_h, next_q) = (&mut self.next_h[..n], &mut self.next_q[..n]);
        let next = next_h.iter_mut().zip(next_q.iter_mut());
        let fluxes = mass.windows(2).zip(momentum.windows(2));
        for (((nh, nq), (&h, &q)), (f, m)) in next.zip(h.iter().zip(q0)).zip(fluxes) {
            let hn = h - (lam * f[1] - lam * f[0]);
            *nq = q - lam * (m[1] - m[0]) - source * (h + hn);
            *nh = hn;
        }
        // Positivity is not guaranteed at Courant numbers above 1/2: a substep whose corrector
        // leaves a negative depth is taken again at POSITIVE_COURANT (by the speed that gives
        // it, as a substep meeting a faster wave is).
        let mut lanes = [f64::INFINITY; 8];
        for c in next_h.chunks(8) {
            for (l, &h) in lanes.iter_mut().zip(c) {
                *l = smaller(*l, h);
            }
        }
        if lanes.into_iter().fold(f64::INFINITY, smaller) < 0.0
            && fastest * dt > POSITIVE_COURANT * dx * (1.0 + 1e-9)
        {
            return Err(fastest * self.courant / POSITIVE_COURANT);
        }
        let interior = lane_sum(&mass[1..n]);
        let impulse = (1.0 - decay) * p0 * dx + dt * (momentum[n] - momentum[0]);
        let skipped = lane_sum(skip);
        std::mem::swap(&mut f.depth, &mut self.next_h);
        std::mem::swap(&mut f.discharge, &mut self.next_q);
        if screens {
            taken += self
                .ch
                .screens
                .apply(&f.depth, &mut f.discharge, 0.5 * dt, dry)
                * dx;
        }
        // The second drag half, the momentum before it, the shallowest depth; then the
        // films, as the model: a dry cell's discharge goes to the bottom.
        let Survey {
            sum: p1,
            shallowest,
            ..
        } = settle(&f.depth, &mut f.discharge, decay);
        let mut stopped = 0.0;
        if shallowest < dry {
            for (h, q) in f.depth.iter_mut().zip(f.discharge.iter_mut()) {
                if *h < dry {
                    *h = h.max(0.0);
                    stopped += *q;
                    *q = 0.0;
                }
            }
        }
        done.impulse += impulse + taken + (1.0 - decay) * p1 * dx + stopped * dx;
        done.work -= dt * am * interior * dx;
        done.skipped += skipped as u64;
        done.shallowest = done.shallowest.min(shallowest);
        Ok(fastest)
    }
}

/// The predictor: a cell's faces evolved by half a substep.
#[derive(Clone, Copy, Debug)]
struct Evolve {
    /// dt/(2 dx).
    half: f64,
    g: f64,
    /// The pseudo-bottom's rise from one cell to the next.
    rise: f64,
    /// dt/2 times a_b's mean over the substep (the conservative predictor's source).
    source: f64,
    dry: f64,
    thin: f64,
    conservative: bool,
}

impl Evolve {
    /// The faces (left depth, velocity, right depth, velocity) of a cell of depth `h` and
    /// velocity `u` evolved by dt/2, and 1 where the predictor was skipped (the cell or an
    /// evolved face thinner than `thin`: the faces at t are kept), else 0. Every case computed
    /// and one selected (no branch).
    #[inline(always)]
    fn of(
        &self,
        h: f64,
        u: f64,
        (hl, ul, hr, ur): (f64, f64, f64, f64),
    ) -> (f64, f64, f64, f64, f64) {
        let (pl, vl, pr, vr) = if self.conservative {
            let (ql, qr) = (hl * ul, hr * ur);
            let dm = self.half * (qr - ql);
            let flux = |h: f64, q: f64, u: f64| q * u + 0.5 * self.g * h * h;
            let dp = self.half * (flux(hr, qr, ur) - flux(hl, ql, ul)) + self.source * h;
            let (pl, pr) = (hl - dm, hr - dm);
            (
                pl,
                velocity(ql - dp, pl, self.dry),
                pr,
                velocity(qr - dp, pr, self.dry),
            )
        } else {
            let (dh, dv) = (hr - hl, ur - ul);
            let dh_t = self.half * (u * dh + h * dv);
            let du_t = self.half * (u * dv + self.g * (dh + self.rise));
            (hl - dh_t, ul - du_t, hr - dh_t, ur - du_t)
        };
        let keep = pl >= self.thin && pr >= self.thin && h >= self.thin;
        if keep {
            (pl, vl, pr, vr, 0.0)
        } else {
            (hl, ul, hr, ur, 1.0)
        }
    }
}

/// The thread's CPU time [s].
fn cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: a valid pointer to a timespec, a clock every Linux has.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + 1e-9 * ts.tv_nsec as f64
}

/// The lab tank with the FMU's defaults, the boundary-layer zeta, the scale rho b tanks and
/// omega_1.
fn lab(cells: usize) -> Result<(Channel, f64, f64, f64), String> {
    let p = StartValues::default()
        .with(vr::MODEL, SHALLOW_WATER)
        .with(vr::SWE_CELLS, cells as f64)
        .with(vr::DAMPING, BOUNDARY_LAYER)
        .with(vr::AMPLITUDE, FIXED);
    let common = Common::read(&p)?.0;
    let t = common.tank;
    let DampingLaw::BoundaryLayer(zeta) = common.damping else {
        return Err("not boundary-layer damping".into());
    };
    let scale = t.density * t.breadth * f64::from(common.tanks);
    Ok((
        Channel::new(t.length, t.depth, t.g, cells),
        zeta,
        scale,
        t.fundamental().omega,
    ))
}

/// What one run of the scene gives.
struct Run {
    history: Vec<f64>,
    cpu: f64,
    mass_drift: f64,
    /// The smallest and the largest per-step increment of dissipated energy, and how many
    /// were negative.
    dissipation: (f64, f64, usize),
    /// The times [s] at which the dissipated energy decreased (the first 8).
    created: Vec<f64>,
    done: Done,
}

fn scene(
    cells: usize,
    ratio: f64,
    mut step: impl FnMut(&Channel, &mut Flow, &BaseAcceleration, f64) -> Done,
) -> Result<Run, String> {
    let (ch, zeta, scale, omega) = lab(cells)?;
    let c = 2.0 * zeta * omega;
    let w = ratio * omega;
    let amplitude = LAMBDA * ch.length;
    let mut f = ch.at_rest();
    let volume = ch.volume(&f);
    let steps = (SECONDS / STEP).round() as usize;
    let mut history = Vec::with_capacity(steps);
    let mut total = Done {
        shallowest: f64::INFINITY,
        ..Done::default()
    };
    let mut cpu = 0.0;
    let mut dissipation = (f64::INFINITY, f64::NEG_INFINITY, 0);
    let mut stored = ch.energy(&f);
    let mut created = Vec::new();
    for k in 0..steps {
        let t = k as f64 * STEP;
        let (s, co) = (w * t).sin_cos();
        let base = BaseAcceleration {
            t0: 0.0,
            a: [
                -w * w * amplitude * s,
                -w.powi(3) * amplitude * co,
                w.powi(4) * amplitude * s,
            ],
        };
        let started = cpu_seconds();
        let d = step(&ch, &mut f, &base, c);
        cpu += cpu_seconds() - started;
        history.push(scale * d.impulse / STEP);
        let e = ch.energy(&f);
        let inc = d.work - (e - stored);
        stored = e;
        dissipation.0 = dissipation.0.min(inc);
        dissipation.1 = dissipation.1.max(inc);
        dissipation.2 += usize::from(inc < 0.0);
        if inc < 0.0 && created.len() < 8 {
            created.push(t + STEP);
        }
        total.substeps += d.substeps;
        total.rejected += d.rejected;
        total.skipped += d.skipped;
        total.shallowest = total.shallowest.min(d.shallowest);
        if !f.depth.iter().chain(&f.discharge).all(|x| x.is_finite()) {
            return Err(format!("{cells} cells: not finite at step {k}"));
        }
    }
    Ok(Run {
        history,
        cpu,
        mass_drift: ch.volume(&f) / volume - 1.0,
        dissipation,
        created,
        done: total,
    })
}

fn arg<T: std::str::FromStr + Clone>(k: usize, default: &[T]) -> Result<Vec<T>, String> {
    match std::env::args().nth(k) {
        None => Ok(default.to_vec()),
        Some(s) => s
            .split(',')
            .map(|x| x.parse().map_err(|_| format!("argument {k}: {x}?")))
            .collect(),
    }
}

fn accuracy() -> Result<(), String> {
    let ratios: Vec<f64> = arg(2, &[1.0, 1.1])?;
    let counts: Vec<usize> = arg(3, &[100, 150, 175, 200, 250])?;
    let courant: f64 = arg(4, &[0.9])?[0];
    let predictor = match std::env::args().nth(5).as_deref() {
        None | Some("primitive") => Predictor::Primitive,
        Some("conservative") => Predictor::Conservative,
        Some(other) => return Err(format!("predictor {other}?")),
    };
    let after = (30.0 / STEP).round() as usize;
    println!("MUSCL-Hancock, Courant {courant}, {predictor:?} predictor");
    for ratio in ratios {
        let cache = format!("target/swe_accuracy_3200_{ratio}.txt");
        let r = std::fs::read_to_string(&cache)
            .map_err(|e| format!("{cache}: {e} (run examples/swe_accuracy first)"))?
            .lines()
            .map(|l| l.parse::<f64>().map_err(|e| format!("{cache}: {e}")))
            .collect::<Result<Vec<f64>, String>>()?;
        let peak = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let r_amp = r[after..].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let measure = |y: &[f64]| {
            let ms = y.iter().zip(&r).map(|(y, r)| (y - r).powi(2)).sum::<f64>() / y.len() as f64;
            let amp = y[after..].iter().fold(0.0f64, |m, x| m.max(x.abs()));
            (100.0 * ms.sqrt() / peak, 100.0 * (amp / r_amp - 1.0))
        };
        for &cells in &counts {
            let ch = lab(cells)?.0;
            let mut hancock = stepper(ch, courant, Some(predictor));
            let h = scene(cells, ratio, |_, f, base, c| hancock(f, STEP, base, c))?;
            let mut committed = stepper(ch, courant, None);
            let m = scene(cells, ratio, |_, f, base, c| committed(f, STEP, base, c))?;
            let steps = h.history.len() as f64;
            for (name, run) in [("hancock", &h), ("committed", &m)] {
                let (rms, amp) = measure(&run.history);
                println!(
                    "w/w1 {ratio} cells {cells:4} {name:9}: rms {rms:.3} % amp {amp:+.3} % | \
                     {:.2} us CPU/step, {:.2} ns per cell-substep, {:.2} substeps/step, \
                     rejected {}, predictor skipped {} | mass drift {:.1e} | dissipation \
                     increments min {:.2e} max {:.2e}, {} negative (at {:?} s) | shallowest {:.3e} m",
                    1e6 * run.cpu / steps,
                    1e9 * run.cpu / (run.done.substeps as f64 * cells as f64),
                    run.done.substeps as f64 / steps,
                    run.done.rejected,
                    run.done.skipped,
                    run.mass_drift,
                    run.dissipation.0,
                    run.dissipation.1,
                    run.dissipation.2,
                    run.created,
                    run.done.shallowest,
                );
            }
        }
    }
    Ok(())
}

/// The tilted lake at rest: a_b = 0.5 m/s^2 held, 2 s of 10 ms steps, from the exact state.
fn rest() -> Result<(), String> {
    let cells: usize = arg(2, &[50])?[0];
    let courant: f64 = arg(3, &[0.9])?[0];
    let (ch, _, _, _) = lab(cells)?;
    let a = 0.5;
    let f = Flow {
        depth: (0..cells)
            .map(|i| ch.depth - a * (ch.centre(i) - 0.5 * ch.length) / ch.g_e)
            .collect(),
        discharge: vec![0.0; cells],
    };
    let start = f.clone();
    for predictor in [Predictor::Primitive, Predictor::Conservative] {
        let mut g = f.clone();
        let mut s = Hancock::new(ch, courant, predictor);
        for _ in 0..200 {
            s.advance(&mut g, STEP, &BaseAcceleration::held(a), 0.0);
        }
        let c = (ch.g_e * ch.depth).sqrt();
        let u = g
            .discharge
            .iter()
            .zip(&g.depth)
            .map(|(q, h)| (q / h).abs() / c)
            .fold(0.0, f64::max);
        let dh = g
            .depth
            .iter()
            .zip(&start.depth)
            .map(|(x, y)| (x - y).abs() / ch.depth)
            .fold(0.0, f64::max);
        println!("lake at rest, {predictor:?}: max |u|/c {u:.2e}, max |dH|/h {dh:.2e}");
    }
    Ok(())
}

/// The exact depth of a dam break at x0 (depth `left` against `right`, 0 for a dry bed, both
/// at rest, gravity `g`) at xi = (x - x0)/t: Ritter's (dry) or Stoker's (wet) solution.
fn dam_depth(left: f64, right: f64, g: f64, xi: f64) -> f64 {
    let c0 = (g * left).sqrt();
    // The centred rarefaction u - c = xi, u + 2c = 2 c0: c = (2 c0 - xi)/3.
    let fan = |xi: f64| ((2.0 * c0 - xi) / 3.0).powi(2) / g;
    if xi <= -c0 {
        return left;
    }
    if right <= 0.0 {
        return if xi < 2.0 * c0 { fan(xi) } else { 0.0 };
    }
    // Stoker: the middle depth hm where the rarefaction's velocity 2 (c0 - sqrt(g hm)) meets
    // the bore's into still water, (hm - right) sqrt(g (hm + right)/(2 hm right)); the
    // difference falls with hm, so bisect on (right, left).
    let gap = |hm: f64| {
        2.0 * (c0 - (g * hm).sqrt()) - (hm - right) * (g * (hm + right) / (2.0 * hm * right)).sqrt()
    };
    let mut bracket = (right, left);
    for _ in 0..100 {
        let mid = 0.5 * (bracket.0 + bracket.1);
        bracket = if gap(mid) > 0.0 {
            (mid, bracket.1)
        } else {
            (bracket.0, mid)
        };
    }
    let hm = 0.5 * (bracket.0 + bracket.1);
    let um = 2.0 * (c0 - (g * hm).sqrt());
    if xi < um - (g * hm).sqrt() {
        fan(xi)
    } else if xi < hm * um / (hm - right) {
        hm
    } else {
        right
    }
}

/// Dam breaks in a 1 m channel (g_e = 9.81, no bottom, no drag), 0.1 m at x < 0.4 m onto a dry
/// bed (Ritter) and onto 0.02 m (Stoker), 0.2 s: the L1 error of the depth at 50, 100, 200
/// cells, of this scheme and of the committed one (the configuration of the model's test
/// `dam_breaks_converge_to_ritter_and_stoker`), and the smallest depth.
fn dambreak() -> Result<(), String> {
    let courant: f64 = arg(2, &[0.9])?[0];
    let (left, g, x0, time) = (0.1, 9.81, 0.4, 0.2);
    for right in [0.0, 0.02] {
        for cells in [50, 100, 200] {
            let ch = Channel {
                length: 1.0,
                depth: left,
                g_e: g,
                cells,
                screens: ScreenCells::NONE,
            };
            let start = Flow {
                depth: (0..cells)
                    .map(|i| if ch.centre(i) < x0 { left } else { right })
                    .collect(),
                discharge: vec![0.0; cells],
            };
            let l1 = |f: &Flow| -> f64 {
                (0..cells)
                    .map(|i| {
                        (f.depth[i] - dam_depth(left, right, g, (ch.centre(i) - x0) / time)).abs()
                    })
                    .sum::<f64>()
                    * ch.dx()
            };
            let mut line = format!("dam break onto {right} m, {cells} cells: L1");
            for predictor in [Predictor::Primitive, Predictor::Conservative] {
                let mut f = start.clone();
                let d = Hancock::new(ch, courant, predictor).advance(
                    &mut f,
                    time,
                    &BaseAcceleration::held(0.0),
                    0.0,
                );
                line += &format!(
                    " {predictor:?} {:.2e} (shallowest after a corrector {:.1e} m, predictor \
                     skipped {}),",
                    l1(&f),
                    d.shallowest,
                    d.skipped
                );
            }
            let mut f = start.clone();
            ch.advance(&mut f, time, &BaseAcceleration::held(0.0), 0.0, u64::MAX)
                .map_err(|e| format!("{e:?}"))?;
            println!("{line} committed {:.2e}", l1(&f));
        }
    }
    Ok(())
}

/// The fundamental standing wave at 1e-4 h (linear), one period free: the L1 error of the
/// depth against the start, relative to the amplitude times the length, at 16, 32, 64, 128
/// cells, and the orders (the model's test `smooth_standing_wave_converges_at_second_order`
/// asks more than 1.8).
fn standing() -> Result<(), String> {
    let courant: f64 = arg(2, &[0.9])?[0];
    for predictor in [
        Some(Predictor::Primitive),
        Some(Predictor::Conservative),
        None,
    ] {
        let mut errors = vec![];
        for cells in [16, 32, 64, 128] {
            let (ch, _, _, _) = lab(cells)?;
            let amp = 1e-4 * ch.depth;
            let start = standing_mode(&ch, 1.0, amp);
            let period = 2.0 * ch.length / (ch.g_e * ch.depth).sqrt();
            let mut f = start.clone();
            let held = BaseAcceleration::held(0.0);
            stepper(ch, courant, predictor)(&mut f, period, &held, 0.0);
            let l1: f64 = f
                .depth
                .iter()
                .zip(&start.depth)
                .map(|(a, b)| (a - b).abs())
                .sum::<f64>()
                * ch.dx()
                / (amp * ch.length);
            errors.push(l1);
        }
        let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        let name = predictor.map_or("committed".to_string(), |p| format!("{p:?}"));
        let errors: Vec<String> = errors.iter().map(|e| format!("{e:.2e}")).collect();
        println!("standing wave, {name}: L1 {errors:?}, orders {orders:.2?}");
    }
    Ok(())
}

/// Linear free decay (amplitude 1e-4 h) of mode `k` (1 or 3) in 64 cells with drag zeta, as the
/// model's tests `linear_free_decay_gives_omega_1_and_the_drags_zeta` (k = 1, zeta 0.02, 6 s of
/// 2 ms steps) and `third_mode_is_at_three_omega_1` (k = 3, no drag, 1 s of 1 ms steps) run it:
/// the frequency from the first moment's upward zero crossings (undamped: / sqrt(1 - zeta^2))
/// and, for the fundamental, zeta from the decay of its peaks; at the tests' steps and at
/// 10 ms steps (Courant 0.9 reached). Bounds of the tests: (pi/64)^2 = 2.4e-3 relative for
/// omega, absolute for zeta; (3 pi/64)^2 for the third mode.
fn decay() -> Result<(), String> {
    let courant: f64 = arg(2, &[0.9])?[0];
    let cells = 64;
    let (ch, _, _, omega) = lab(cells)?;
    let pi = std::f64::consts::PI;
    for (k, zeta, step, seconds) in [
        (1.0, 0.02, 0.002, 6.0f64),
        (1.0, 0.02, 0.01, 6.0),
        (3.0, 0.0, 0.001, 1.0),
        (3.0, 0.0, 0.01, 1.0),
    ] {
        let start = standing_mode(&ch, k, 1e-4 * ch.depth);
        let steps = (seconds / step).round() as usize;
        let c = 2.0 * zeta * omega;
        let held = BaseAcceleration::held(0.0);
        let mut line = format!("mode {k}, {step} s steps:");
        for predictor in [Some(Predictor::Primitive), None] {
            let mut f = start.clone();
            let mut advance = stepper(ch, courant, predictor);
            let mut series = vec![(0.0, ch.moment(&f))];
            for j in 1..=steps {
                advance(&mut f, step, &held, c);
                series.push((j as f64 * step, ch.moment(&f)));
            }
            let ups: Vec<f64> = series
                .windows(2)
                .filter(|p| p[0].1 < 0.0 && p[1].1 >= 0.0)
                .map(|p| p[0].0 - p[0].1 * (p[1].0 - p[0].0) / (p[1].1 - p[0].1))
                .collect();
            let n = ups.len() - 1;
            let w = 2.0 * pi * n as f64 / (ups[n] - ups[0]);
            let wn = w / (1.0 - zeta * zeta).sqrt();
            let quarter = 0.5 * pi / w;
            let peak = |t: f64| {
                series
                    .iter()
                    .filter(|(s, _)| (s - t).abs() < quarter)
                    .fold(0.0f64, |m, (_, v)| m.max(v.abs()))
            };
            let (t0, t1) = (ups[0] - quarter, ups[n] - quarter);
            let measured = (peak(t0) / peak(t1)).ln() / (t1 - t0) / wn;
            let name = predictor.map_or("committed", |_| "Hancock (primitive)");
            line += &format!(
                " {name}: omega {:+.2e} relative to {k} omega_1, zeta {measured:.5};",
                wn / (k * omega) - 1.0
            );
        }
        println!("{line}");
    }
    Ok(())
}

/// Mode `k` of height `amp` at the walls as cell averages of amp cos(k pi x/a), at rest.
fn standing_mode(ch: &Channel, k: f64, amp: f64) -> Flow {
    let wave = k * std::f64::consts::PI / ch.length;
    let dx = ch.dx();
    Flow {
        depth: (0..ch.cells)
            .map(|i| {
                let (x0, x1) = (i as f64 * dx, (i + 1) as f64 * dx);
                ch.depth + amp * ((wave * x1).sin() - (wave * x0).sin()) / (wave * dx)
            })
            .collect(),
        discharge: vec![0.0; ch.cells],
    }
}

/// One of the two schemes stepping a channel: MUSCL-Hancock with `predictor`, or (None) the
/// committed one (the model's `Channel::advance_in`).
fn stepper(
    ch: Channel,
    courant: f64,
    predictor: Option<Predictor>,
) -> impl FnMut(&mut Flow, f64, &BaseAcceleration, f64) -> Done {
    let mut s = predictor.map(|p| Hancock::new(ch, courant, p));
    let mut scratch = Scratch::new(ch.cells);
    move |f, step, base, c| match &mut s {
        Some(s) => s.advance(f, step, base, c),
        None => {
            let a = ch
                .advance_in(&mut scratch, f, step, base, c, u64::MAX)
                .expect("the committed scheme steps");
            Done {
                impulse: a.impulse,
                work: a.work,
                substeps: a.substeps,
                rejected: a.rejected,
                ..Done::default()
            }
        }
    }
}

/// Damping screens (Tait's pair at 0.4 a and 0.6 a), as the model's tests in
/// src/physics/shallow_water/tests/screens.rs: the free decay from 1 % of h at the walls (2 ms
/// steps, 4 s, no drag) against the closed-form equivalent damping per wave height
/// (4/(3 pi^2)) C_l sum |sin(pi x_j/a)|^3 / h, the bare tank's decay subtracted, at 25-200
/// cells (the test: within 2 %); and violent forcing (A = 0.005 and 0.05 m, 40 cells, 800
/// steps of 10 ms, zeta 0.005): mass, the momentum identity with the screens' drag, and the
/// smallest increment of dissipated energy (the test: never negative).
fn screens() -> Result<(), String> {
    let courant: f64 = arg(2, &[0.9])?[0];
    let pi = std::f64::consts::PI;
    for hancock in [true, false] {
        let name = if hancock {
            "Hancock (primitive)"
        } else {
            "committed"
        };
        let decay_rate = |ch: Channel, eta0: f64| -> f64 {
            let mut step = stepper(ch, courant, hancock.then_some(Predictor::Primitive));
            let mut f = standing_mode(&ch, 1.0, eta0);
            let mut series = vec![(0.0, ch.moment(&f))];
            for j in 1..=2000 {
                step(&mut f, 0.002, &BaseAcceleration::held(0.0), 0.0);
                series.push((j as f64 * 0.002, ch.moment(&f)));
            }
            // The peaks of each half cycle as 1/(wave height); their least-squares slope over
            // omega_1 is zeta per wave height.
            let p: Vec<(f64, f64)> = series
                .windows(3)
                .filter(|w| w[1].1.abs() >= w[0].1.abs() && w[1].1.abs() > w[2].1.abs())
                .map(|w| {
                    (
                        w[1].0,
                        2.0 * ch.length * ch.length / (pi * pi * w[1].1.abs()),
                    )
                })
                .collect();
            let n = p.len() as f64;
            let mt = p.iter().map(|q| q.0).sum::<f64>() / n;
            let my = p.iter().map(|q| q.1).sum::<f64>() / n;
            let slope = p.iter().map(|q| (q.0 - mt) * (q.1 - my)).sum::<f64>()
                / p.iter().map(|q| (q.0 - mt).powi(2)).sum::<f64>();
            slope * ch.length / (pi * (ch.g_e * ch.depth).sqrt())
        };
        for s in [0.5, 0.7] {
            let c_l = loss_coefficient(s);
            let mut line = format!("{name}, screens S = {s}, free decay vs closed form:");
            for cells in [25, 50, 100, 200] {
                let bare = lab(cells)?.0;
                let ch = bare.with_screens(&[0.4 * bare.length, 0.6 * bare.length], c_l);
                let cubes = 2.0 * (0.4 * pi).sin().powi(3);
                let expected = 4.0 / (3.0 * pi * pi) * c_l * cubes / ch.depth;
                let measured =
                    decay_rate(ch, 0.01 * ch.depth) - decay_rate(bare, 0.01 * bare.depth);
                line += &format!(" {cells} cells {:+.4},", measured / expected - 1.0);
            }
            println!("{line}");
        }
        for amplitude in [0.005, 0.05] {
            let bare = lab(40)?.0;
            let (_, _, _, w) = lab(40)?;
            let ch = bare.with_screens(
                &[0.4 * bare.length, 0.6 * bare.length],
                loss_coefficient(0.5),
            );
            let mut step = stepper(ch, courant, hancock.then_some(Predictor::Primitive));
            let mut f = ch.at_rest();
            let v = ch.volume(&f);
            let (mut p0, mut input, mut last) = (0.0, 0.0, 0.0);
            let (mut mass, mut residual, mut scale, mut least) =
                (0.0f64, 0.0f64, 0.0f64, f64::INFINITY);
            for k in 0..800 {
                let t = k as f64 * 0.01;
                let (sn, cs) = (w * t).sin_cos();
                let a2 = amplitude * w * w;
                let base = BaseAcceleration {
                    t0: 0.0,
                    a: [a2 * sn, a2 * w * cs, -a2 * w * w * sn],
                };
                let d = step(&mut f, 0.01, &base, 2.0 * 0.005 * w);
                mass = mass.max((ch.volume(&f) / v - 1.0).abs());
                let p1 = ch.momentum(&f);
                residual = residual.max((d.impulse + v * base.integral(0.01) + (p1 - p0)).abs());
                scale = scale.max(d.impulse.abs());
                p0 = p1;
                input += d.work;
                let dissipated = input - ch.energy(&f);
                least = least.min(dissipated - last);
                last = dissipated;
            }
            println!(
                "{name}, screens S = 0.5, violent A = {amplitude} m, 40 cells: mass {mass:.1e}, \
                 momentum residual {residual:.1e} of impulses up to {scale:.1e}, smallest \
                 dissipation increment {least:.2e}, dissipated {last:.3e}"
            );
        }
    }
    Ok(())
}

/// Resonant forcing violent enough for bores and for the bed to run dry at the walls (the
/// model's test `violent_sloshing_conserves_mass_and_stays_non_negative`: A = 0.1 m at
/// omega_1, zeta 0.005, 20 s or SECONDS): mass, depths, dry cells, the momentum balance per step
/// (impulse = -V integral a_b dt - Delta integral q dx) and the energy.
fn violent() -> Result<(), String> {
    let cells: usize = arg(2, &[40])?[0];
    let courant: f64 = arg(3, &[0.9])?[0];
    let seconds: f64 = arg(4, &[20.0])?[0];
    let steps = (seconds / STEP).round() as usize;
    let (ch, _, _, omega) = lab(cells)?;
    let amplitude = 0.1;
    for predictor in [Predictor::Primitive, Predictor::Conservative] {
        let mut s = Hancock::new(ch, courant, predictor);
        let mut f = ch.at_rest();
        let v = ch.volume(&f);
        let (mut drift, mut lowest, mut dry_cells) = (0.0f64, f64::INFINITY, 0usize);
        let (mut residual, mut scale, mut p0) = (0.0f64, 0.0f64, 0.0);
        let (mut created, mut worst_created, mut largest) = (0usize, 0.0f64, 0.0f64);
        let mut stored = ch.energy(&f);
        let mut when = Vec::new();
        let mut total = Done {
            shallowest: f64::INFINITY,
            ..Done::default()
        };
        for k in 0..steps {
            let t = k as f64 * STEP;
            let (sn, cs) = (omega * t).sin_cos();
            let w2 = amplitude * omega * omega;
            let base = BaseAcceleration {
                t0: 0.0,
                a: [w2 * sn, w2 * omega * cs, -w2 * omega * omega * sn],
            };
            let d = s.advance(&mut f, STEP, &base, 2.0 * 0.005 * omega);
            total.substeps += d.substeps;
            total.rejected += d.rejected;
            total.skipped += d.skipped;
            total.shallowest = total.shallowest.min(d.shallowest);
            drift = drift.max((ch.volume(&f) / v - 1.0).abs());
            lowest = lowest.min(f.depth.iter().copied().fold(f64::INFINITY, f64::min));
            dry_cells += f.depth.iter().filter(|&&h| h < 1e-3 * ch.depth).count();
            let p1 = ch.momentum(&f);
            residual = residual.max((d.impulse + v * base.integral(STEP) + (p1 - p0)).abs());
            scale = scale.max(d.impulse.abs());
            p0 = p1;
            let e = ch.energy(&f);
            let inc = d.work - (e - stored);
            stored = e;
            largest = largest.max(inc);
            if inc < 0.0 {
                created += 1;
                worst_created = worst_created.min(inc);
                if when.len() < 12 {
                    when.push(t + STEP);
                }
            }
            if !f.depth.iter().chain(&f.discharge).all(|x| x.is_finite()) {
                println!("{predictor:?}: not finite at step {k}");
                break;
            }
        }
        println!(
            "violent, {cells} cells, {predictor:?}: mass drift up to {drift:.1e}, lowest depth \
             {lowest:.2e} m (after a corrector, before the films are stopped: {:.2e} m), \
             {dry_cells} cell-steps below 1e-3 h, predictor skipped {} \
             cell-substeps, substeps {}, rejected {}; momentum residual {:.1e} of impulses up \
             to {scale:.1e}; dissipation decreased in {created} of {steps} steps (worst \
             {worst_created:.2e}, largest increment {largest:.2e}; at {when:.2?} s)",
            total.shallowest, total.skipped, total.substeps, total.rejected, residual,
        );
    }
    Ok(())
}

fn main() -> Result<(), String> {
    match std::env::args().nth(1).as_deref() {
        Some("accuracy") => accuracy(),
        Some("rest") => rest(),
        Some("dambreak") => dambreak(),
        Some("violent") => violent(),
        Some("standing") => standing(),
        Some("decay") => decay(),
        Some("screens") => screens(),
        _ => Err(
            "usage: swe_hancock accuracy|rest|dambreak|violent|standing|decay|screens [...]".into(),
        ),
    }
}
