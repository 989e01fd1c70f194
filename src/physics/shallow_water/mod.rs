//! The nonlinear shallow-water equations in the tank frame (MODEL.md section 7):
//!
//! ```text
//! H_t + q_x = 0
//! q_t + (q^2/H + g_e H^2/2)_x = -H a_b(t) - c q,     q = 0 at x = 0 and x = a,
//! g_e = g sigma, sigma = tanh(pi h/a)/(pi h/a),      c = 2 zeta omega_1,
//! ```
//!
//! solved by a second-order Godunov-type finite-volume scheme ([`scheme`]: limited
//! reconstruction, HLL fluxes, well balanced), MUSCL-Hancock in time (one flux evaluation per
//! substep between faces evolved by half of it: [`reconstruction::Predictor`]), with a
//! positivity-preserving fallback, the drag and the screens integrated exactly by Strang
//! splitting. Per unit of rho b throughout: the model multiplies by the density, the breadth
//! and the tanks.
//!
//! The time step: each substep is the CFL step; the communication step's remainder is divided
//! into equal substeps n = ceil(remaining / dt_cfl), recomputed after every substep (the speeds
//! change), so that the last one lands exactly on the communication point.
//!
//! Positivity: MUSCL-Hancock's predictor is not proven to keep the depths non-negative (it
//! kept them so in every run measured). A substep whose result has a negative depth or a
//! non-finite value is taken again without the predictor, as a forward-Euler step of the
//! semi-discrete scheme at Courant number [`FALLBACK_CFL`] <= 1/2, which keeps them
//! non-negative: the cell's depth is the mean of its two face depths (both >= 0, the slope
//! being cut to |dH| <= 2 H), and with HLL fluxes whose speeds bound the face velocities
//! (Einfeldt's: s_L <= u, s_R >= u of each side) the new depth is
//! H' >= (1/2 - lam s) H_- + (1/2 - lam s) H_+ plus non-negative terms, lam s <= 1/2
//! (the argument of Kurganov & Petrova 2007 for their central-upwind flux; HLL's has the same
//! form). Round-off can still leave a drained cell a few ulps below 0: set to 0.

/// One function compiled for several instruction sets: `$passes` (`#[inline(always)]`, any
/// CPU: the baseline build) inlined into `$avx512` and `$avx2`, compiled with those target
/// features, and `$dispatch`, which runs the widest this CPU has (`is_x86_feature_detected`
/// caches its answer). `$builds` (tests only) lists the builds this CPU can run, by name. The
/// same operations in the same order in every build, no fused multiply-adds (the compiler
/// contracts none unasked): the same bits, which the tests check.
macro_rules! builds {
    (
        $(#[$meta:meta])*
        $vis:vis fn $dispatch:ident, $avx512:ident, $avx2:ident, $builds:ident = $passes:ident
        ($($arg:ident: $ty:ty),* $(,)?) -> $ret:ty;
    ) => {
        $(#[$meta])*
        $vis fn $dispatch($($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            {
                if std::arch::is_x86_feature_detected!("avx512f") {
                    // SAFETY: only AVX-512F is needed, and this CPU has it (just checked).
                    return unsafe { $avx512($($arg),*) };
                }
                if std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: only AVX2 is needed, and this CPU has it (just checked).
                    return unsafe { $avx2($($arg),*) };
                }
            }
            $passes($($arg),*)
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx512f")]
        fn $avx512($($arg: $ty),*) -> $ret {
            $passes($($arg),*)
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        fn $avx2($($arg: $ty),*) -> $ret {
            $passes($($arg),*)
        }

        /// The builds of this function the CPU can run, by name (the tests compare them).
        #[cfg(test)]
        #[allow(clippy::type_complexity)]
        pub(super) fn $builds() -> Vec<(&'static str, fn($($ty),*) -> $ret)> {
            let mut builds: Vec<(&'static str, fn($($ty),*) -> $ret)> =
                vec![("baseline", |$($arg),*| $passes($($arg),*))];
            #[cfg(target_arch = "x86_64")]
            {
                if std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: returned to run on this CPU only, which has AVX2 (just checked).
                    builds.push(("avx2", |$($arg),*| unsafe { $avx2($($arg),*) }));
                }
                if std::arch::is_x86_feature_detected!("avx512f") {
                    // SAFETY: returned to run on this CPU only, which has AVX-512F.
                    builds.push(("avx512f", |$($arg),*| unsafe { $avx512($($arg),*) }));
                }
            }
            builds
        }
    };
}

#[cfg(test)]
mod exact;
mod lanes;
mod reconstruction;
pub mod scheme;
pub mod screens;
#[cfg(test)]
mod tests;

use crate::physics::base::BaseAcceleration;
use crate::solver::SolveError;
use lanes::{Survey, decayed, faster, lane_sum, lane_sum_by, survey};
use scheme::{Faces, Grid, Rates, Update, rates, sweep_passes, velocity};
use screens::ScreenCells;

/// Courant number of a substep against the largest interface wave speed of the last one.
/// MUSCL-Hancock is stable up to 1; a larger Courant number gave a smaller error (the worst
/// rms of force.mean over 0.9-1.15 omega_1 at 150 cells: 0.90 % at 0.5, 0.71 % at 0.9,
/// docs/SHALLOW_WATER.md), 0.9 leaves room for the speeds to grow within a substep.
pub const CFL: f64 = 0.9;
/// The stability bound: a substep whose interfaces meet a faster wave than this allows is
/// taken again, shorter.
const CFL_BOUND: f64 = 1.0;
/// The positivity fallback's Courant number, and its bound (the module documentation).
pub const FALLBACK_CFL: f64 = 0.45;
const FALLBACK_BOUND: f64 = 0.5;

/// The still-water depth below which a cell is dry, relative to the still depth: its liquid
/// is a film that the bottom's friction stops (its discharge goes to the tank as an impulse).
pub const DRY: f64 = 1e-9;

/// The depth, relative to the still depth, below which a cell's slopes are limited by
/// component (minmod on the surface and the velocity) instead of in characteristic variables
/// ([`scheme`]): films and drying fronts, where the characteristic speed g/c is unbounded.
pub const THIN: f64 = 1e-3;

/// A tank's liquid as the scheme sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Channel {
    /// Tank length a [m].
    pub length: f64,
    /// Still-water depth h [m].
    pub depth: f64,
    /// Gravity with the dispersion correction, g_e = g sigma [m/s^2].
    pub g_e: f64,
    pub cells: usize,
    /// Damping screens ([`screens`]; none from [`Channel::new`]).
    pub screens: ScreenCells,
}

impl Channel {
    /// The channel of a tank of length `length`, still depth `depth`, under gravity `g`, in
    /// `cells` cells; g_e = g tanh(pi h/a)/(pi h/a) makes the linear fundamental frequency
    /// pi sqrt(g_e h)/a equal Eq 2.2's omega_1.
    pub fn new(length: f64, depth: f64, g: f64, cells: usize) -> Self {
        let k = std::f64::consts::PI * depth / length;
        Channel {
            length,
            depth,
            g_e: g * k.tanh() / k,
            cells,
            screens: ScreenCells::NONE,
        }
    }

    /// This channel with screens of loss coefficient `c_l` at `positions` [m from x = 0].
    pub fn with_screens(self, positions: &[f64], c_l: f64) -> Self {
        Channel {
            screens: ScreenCells::new(positions, c_l, self.dx(), self.cells),
            ..self
        }
    }

    pub fn dx(&self) -> f64 {
        self.length / self.cells as f64
    }

    pub fn grid(&self) -> Grid {
        Grid {
            cells: self.cells,
            dx: self.dx(),
            g_e: self.g_e,
            dry: DRY * self.depth,
            thin: THIN * self.depth,
        }
    }

    /// Centre of cell i, from the left wall [m].
    pub fn centre(&self, i: usize) -> f64 {
        (i as f64 + 0.5) * self.dx()
    }

    /// Still water.
    pub fn at_rest(&self) -> Flow {
        Flow {
            depth: vec![self.depth; self.cells],
            discharge: vec![0.0; self.cells],
        }
    }

    /// The liquid volume per unit breadth [m^2].
    pub fn volume(&self, f: &Flow) -> f64 {
        lane_sum(&f.depth) * self.dx()
    }

    /// The liquid momentum per unit breadth and density, integral of q [m^3/s].
    pub fn momentum(&self, f: &Flow) -> f64 {
        lane_sum(&f.discharge) * self.dx()
    }

    /// First moment of the depth about the tank centre, integral of H (x - a/2) [m^3]: the
    /// volume times the centre of mass's offset.
    pub fn moment(&self, f: &Flow) -> f64 {
        let mid = 0.5 * self.length;
        let h = &f.depth[..self.cells];
        lane_sum_by(h.len(), |i| h[i] * (self.centre(i) - mid)) * self.dx()
    }

    /// Mechanical energy per unit breadth and density, integral of q^2/(2H) + g_e (H-h)^2/2
    /// [m^4/s^2] (the kinetic part with the desingularised velocity, 0 in a dry cell).
    pub fn energy(&self, f: &Flow) -> f64 {
        let dry = DRY * self.depth;
        let (h, q) = (&f.depth[..self.cells], &f.discharge[..self.cells]);
        lane_sum_by(h.len(), |i| {
            let eta = h[i] - self.depth;
            0.5 * q[i] * velocity(q[i], h[i], dry) + 0.5 * self.g_e * eta * eta
        }) * self.dx()
    }

    /// Depth at the walls x = 0 and x = a: extrapolated linearly from the two cells next to
    /// each (second order where the flow is smooth, exact for the tilted lake at rest), not
    /// below 0. The state alone: no base acceleration enters, so the force built of it has no
    /// feedthrough.
    pub fn wall_depths(&self, f: &Flow) -> [f64; 2] {
        let h = &f.depth;
        let n = self.cells;
        if n < 2 {
            return [h[0], h[0]];
        }
        [
            (1.5 * h[0] - 0.5 * h[1]).max(0.0),
            (1.5 * h[n - 1] - 0.5 * h[n - 2]).max(0.0),
        ]
    }

    /// Force of the liquid on the tank per unit breadth and density [m^3/s^2], state only:
    /// g_e (H(a)^2 - H(0)^2)/2 + c integral q dx with the extrapolated wall depths, plus the
    /// screens' drag (C_l/2) q|q|/H at each.
    pub fn force(&self, f: &Flow, c: f64) -> f64 {
        let [l, r] = self.wall_depths(f);
        let force = 0.5 * self.g_e * (r * r - l * l) + c * self.momentum(f);
        if self.screens.is_empty() {
            force
        } else {
            let dry = DRY * self.depth;
            force + self.screens.drag(&f.depth, &f.discharge, dry) * self.dx()
        }
    }

    /// The semi-discrete right-hand side at `f` under base acceleration `a` (no drag).
    pub fn rates(&self, f: &Flow, a: f64) -> Rates {
        let mut out = Rates::new(self.cells);
        rates(&self.grid(), &f.depth, &f.discharge, a, &mut out);
        out
    }

    /// The semi-discrete equations' right-hand side at `f`, under base acceleration `a` and
    /// drag coefficient `c` [1/s]: [`Channel::rates`] with the drag -c q and the screens'
    /// losses added to the discharge rates (what the substeps split off and integrate exactly).
    /// The ODE a host's solver integrates in Model Exchange, and along which the outputs'
    /// rates are taken.
    pub fn semi_discrete(&self, f: &Flow, a: f64, c: f64) -> Rates {
        let mut r = self.rates(f, a);
        if !self.screens.is_empty() {
            let dry = DRY * self.depth;
            self.screens
                .add_rates(&f.depth, &f.discharge, &mut r.discharge, dry);
        }
        for (dq, q) in r.discharge.iter_mut().zip(&f.discharge) {
            *dq -= c * q;
        }
        r
    }

    /// Advance `f` by `h` under base acceleration `base` and drag coefficient `c` [1/s], in at
    /// most `most` substeps. On error `f` is left part-way: callers step a copy.
    pub fn advance(
        &self,
        f: &mut Flow,
        h: f64,
        base: &BaseAcceleration,
        c: f64,
        most: u64,
    ) -> Result<Advanced, SolveError> {
        self.advance_in(&mut Scratch::new(self.cells), f, h, base, c, most)
    }

    /// [`Channel::advance`] with the storage `w` (of this channel's cells) supplied: no
    /// allocation.
    pub fn advance_in(
        &self,
        w: &mut Scratch,
        f: &mut Flow,
        h: f64,
        base: &BaseAcceleration,
        c: f64,
        most: u64,
    ) -> Result<Advanced, SolveError> {
        advance(self, w, f, h, base, c, most)
    }

    /// Every build of [`Channel::advance_in`] this CPU can run, by name, each on a copy of
    /// `f` (the tests compare them).
    #[cfg(test)]
    pub(super) fn each_build(
        &self,
        f: &Flow,
        h: f64,
        base: &BaseAcceleration,
        c: f64,
    ) -> Vec<(&'static str, Result<Advanced, SolveError>, Flow)> {
        let mut w = Scratch::new(self.cells);
        advance_builds()
            .into_iter()
            .map(|(name, build)| {
                let mut g = f.clone();
                let r = build(self, &mut w, &mut g, h, base, c, u64::MAX);
                (name, r, g)
            })
            .collect()
    }

    /// Largest |u| + sqrt(g_e H) of the cell averages.
    #[inline(always)]
    fn cell_speed(&self, f: &Flow) -> f64 {
        let dry = DRY * self.depth;
        let speed = |h: f64, q: f64| velocity(q, h, dry).abs() + (self.g_e * h.max(0.0)).sqrt();
        // In eight lanes, without branches (vectorised); a NaN is passed over, as f64::max
        // does (the step then refuses the state).
        let mut lanes = [0.0; 8];
        let (hs, qs) = (f.depth.chunks_exact(8), f.discharge.chunks_exact(8));
        let rest = hs.remainder().iter().zip(qs.remainder());
        for (h, q) in hs.zip(qs) {
            for ((l, &h), &q) in lanes.iter_mut().zip(h).zip(q) {
                *l = faster(*l, speed(h, q));
            }
        }
        for (l, (&h, &q)) in lanes.iter_mut().zip(rest) {
            *l = faster(*l, speed(h, q));
        }
        lanes.into_iter().fold(0.0, faster)
    }

    /// One substep dt from time t: drag dt/2 exactly, the screens dt/2, MUSCL-Hancock on the
    /// hyperbolic part and the inertial force (with `predict`; without, its positivity
    /// fallback), the screens dt/2, drag dt/2 (Strang: second order, and the drag never limits
    /// the step). Err: taken again (nothing changed): a wave too fast for dt, or, with
    /// `predict`, a negative depth or a non-finite value.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn substep(
        &self,
        f: &mut Flow,
        w: &mut Scratch,
        t: f64,
        dt: f64,
        base: &BaseAcceleration,
        c: f64,
        predict: bool,
    ) -> Result<Substep, Retake> {
        let grid = self.grid();
        let (n, dx, dry) = (self.cells, grid.dx, grid.dry);
        let bound = if predict { CFL_BOUND } else { FALLBACK_BOUND };
        let decay = (-0.5 * c * dt).exp();
        // The drag's impulse on the tank is the momentum it takes from the liquid: (1 - decay)
        // times the momentum (the sum of the discharges times dx) before each half.
        let drag_loss = |p: f64| (1.0 - decay) * p;
        let Scratch {
            q0,
            next_h,
            next_q,
            faces,
        } = w;
        // U0 = the state after the first drag half: the depths are f's.
        let p0 = decayed(&f.discharge, q0, decay);
        let mut impulse = drag_loss(p0 * dx);
        // The screens' first half (after the drag's: each exact, Strang-symmetric overall).
        let screens = !self.screens.is_empty();
        if screens {
            impulse += self.screens.apply(&f.depth, q0, 0.5 * dt, dry) * dx;
        }
        // The input's mean over the substep, in the reconstruction (the pseudo-bottom), the
        // predictor and the source: exact for the input's quadratic, so the momentum balance
        // closes. (With a_b at t in the reconstruction and the predictor, the dissipated
        // energy decreased in the first steps from rest.)
        let a = (base.integral(t + dt) - base.integral(t)) / dt;
        let mut update = Update {
            dt,
            predict,
            next: [&mut next_h[..n], &mut next_q[..n]],
        };
        let s = sweep_passes(&grid, &f.depth, q0, a, faces, Some(&mut update));
        if s.speed * dt > bound * dx {
            return Err(Retake::Faster(s.speed));
        }
        let Survey { shallowest, finite } = survey(next_h, next_q);
        if predict && (shallowest < 0.0 || !finite) {
            return Err(Retake::Negative);
        }
        impulse += dt * (s.wall[1] - s.wall[0]);
        // The inertial force's power on the discrete liquid: -a_b times the rate of its first
        // moment, dx times the interior mass fluxes (the continuum's -a_b integral q dx is the
        // same; this discrete form is the one the scheme's energy is consistent with, the
        // pseudo-bottom a_b x/g_e entering the hydrostatic reconstruction as a bottom does),
        // at the fluxes of the substep's middle.
        let work = -dt * a * s.mass_flux * dx;
        std::mem::swap(&mut f.depth, next_h);
        // The screens' second half before the drag's (the halves mirror each other).
        if screens {
            impulse += self.screens.apply(&f.depth, next_q, 0.5 * dt, dry) * dx;
        }
        // The second drag half, with the momentum before it (one vectorised pass).
        let p1 = decayed(next_q, &mut f.discharge, decay);
        impulse += drag_loss(p1 * dx);
        // The films: a dry cell's discharge goes to the bottom.
        if shallowest < dry {
            let mut stopped = 0.0;
            for (h, q) in f.depth.iter_mut().zip(f.discharge.iter_mut()) {
                // Round-off can leave a drained cell a few ulps below 0 (the fallback's
                // positivity holds in exact arithmetic).
                if *h < dry {
                    *h = h.max(0.0);
                    stopped += *q;
                    *q = 0.0;
                }
            }
            impulse += stopped * dx;
        }
        Ok(Substep {
            impulse,
            work,
            speed: s.speed,
            finite,
        })
    }
}

/// The substeps of [`Channel::advance_in`], for any CPU (the baseline build): compiled
/// whole, the scheme's passes included, for each instruction set the CPU may have
/// ([`advance`]), the widest chosen once per communication step.
#[inline(always)]
fn advance_passes(
    ch: &Channel,
    w: &mut Scratch,
    f: &mut Flow,
    h: f64,
    base: &BaseAcceleration,
    c: f64,
    most: u64,
) -> Result<Advanced, SolveError> {
    let grid = ch.grid();
    let dx = grid.dx;
    let mut done = Advanced::default();
    let mut t = 0.0;
    // The largest face speed met so far in this step: the next substep's CFL speed.
    let mut speed = ch.cell_speed(f);
    // MUSCL-Hancock, or after a substep of it was refused for a negative depth, its fallback.
    let mut predict = true;
    while t < h {
        let remaining = h - t;
        let courant = if predict { CFL } else { FALLBACK_CFL };
        let dt_cfl = if speed > 0.0 {
            courant * dx / speed
        } else {
            f64::INFINITY
        };
        let substeps = (remaining / dt_cfl).ceil().max(1.0);
        if done.substeps as f64 + substeps > most as f64 {
            return Err(SolveError::TooManySteps { limit: most, t });
        }
        let last = substeps <= 1.0;
        let dt = if last {
            remaining
        } else {
            remaining / substeps
        };
        match ch.substep(f, w, t, dt, base, c, predict) {
            Ok(sub) => {
                done.impulse += sub.impulse;
                done.work += sub.work;
                done.substeps += 1;
                speed = sub.speed;
                predict = true;
                t = if last { h } else { t + dt };
                if !sub.finite {
                    return Err(SolveError::NonFinite { t });
                }
            }
            // A wave faster than the step allows: take it again at the CFL step of that
            // speed (the state is untouched until a substep is accepted).
            Err(Retake::Faster(faster)) => {
                done.rejected += 1;
                speed = faster;
            }
            // A negative depth (or a non-finite value): take it again by the fallback.
            Err(Retake::Negative) => {
                done.rejected += 1;
                done.fallbacks += 1;
                predict = false;
            }
        }
    }
    Ok(done)
}

builds! {
    /// [`Channel::advance_in`]: every substep of a communication step in the widest build.
    fn advance, advance_avx512, advance_avx2, advance_builds = advance_passes(
        ch: &Channel,
        w: &mut Scratch,
        f: &mut Flow,
        h: f64,
        base: &BaseAcceleration,
        c: f64,
        most: u64,
    ) -> Result<Advanced, SolveError>;
}

/// What a communication step did, per unit breadth and density.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Advanced {
    /// Impulse of the liquid on the tank [m^3/s]: the wall pressures, the drag and the dry
    /// cells' friction, summed over the substeps.
    pub impulse: f64,
    /// Work of the inertial force -a_b on the liquid, integral of -a_b integral q dx dt
    /// [m^4/s^2].
    pub work: f64,
    pub substeps: u64,
    /// Substeps taken again: shorter, for a wave faster than the CFL step allowed, or by the
    /// fallback.
    pub rejected: u64,
    /// Of those, the substeps taken again by the positivity fallback (MUSCL-Hancock left a
    /// negative depth or a non-finite value).
    pub fallbacks: u64,
}

/// Why a substep is taken again.
enum Retake {
    /// A wave faster than the substep's Courant bound allows, of this speed.
    Faster(f64),
    /// MUSCL-Hancock left a negative depth or a non-finite value.
    Negative,
}

/// One accepted substep.
struct Substep {
    impulse: f64,
    work: f64,
    /// Largest interface wave speed.
    speed: f64,
    /// Whether the new state is finite (before the films are stopped).
    finite: bool,
}

/// Depths and discharges: the state of the liquid in one tank.
#[derive(Clone, Debug, PartialEq)]
pub struct Flow {
    /// H_i [m].
    pub depth: Vec<f64>,
    /// q_i [m^2/s].
    pub discharge: Vec<f64>,
}

/// Storage of a substep: the discharges of U0 (its depths are the state's), the new state and
/// the passes' ([`Faces`]). It holds nothing from one call to the next.
#[derive(Debug)]
pub struct Scratch {
    q0: Vec<f64>,
    next_h: Vec<f64>,
    next_q: Vec<f64>,
    faces: Faces,
}

impl Scratch {
    pub fn new(cells: usize) -> Self {
        let v = || vec![0.0; cells];
        Scratch {
            q0: v(),
            next_h: v(),
            next_q: v(),
            faces: Faces::new(cells),
        }
    }
}
