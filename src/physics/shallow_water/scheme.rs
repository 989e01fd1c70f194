//! The semi-discrete finite-volume scheme for the shallow-water equations in the tank frame
//! (MODEL.md section 7): limited linear reconstruction, hydrostatic treatment of the inertial
//! force as a bottom, HLL fluxes with Einfeldt's wave speeds, reflective walls.
//!
//! Why these choices:
//! - HLL with Einfeldt's speeds (HLLE): the 1-D shallow-water system has no contact wave, so
//!   HLLC would add nothing; Roe's solver needs a Harten entropy fix and fails at dry states.
//!   HLLE's speeds bound the physical ones, which makes it entropy satisfying with no fix
//!   (Harten, Lax & van Leer 1983), positively conservative (Einfeldt et al. 1991), and exact
//!   for a front running onto a dry bed when the dry side's speeds are those of the
//!   rarefaction's tip (u -+ 2c).
//! - The inertial force -H a_b is the bottom slope of a pseudo-bottom z = a_b x / g_e. That
//!   bottom is linear, so it is continuous at every interface and the hydrostatic
//!   reconstruction of Audusse et al. (2004) reduces to reconstructing the surface w = H + z
//!   (not H) and keeping the interface depths as they are. The source is then -a_b H_i dx,
//!   the cell average: the tilted lake at rest (w constant, q = 0) has equal depths on both
//!   sides of every interface and a pressure difference across each cell of
//!   g_e (H+^2 - H-^2)/2 = -a_b H_i dx exactly (H+ + H- = 2 H_i), so it stays at rest; and
//!   the sources of all cells sum to -a_b times the mass, which is conserved, so the momentum
//!   balance closes exactly (h force.mean = -M_l a_b h - Delta P).
//! - Limiter ([`super::reconstruction`]): monotonised central (MC) on the characteristic
//!   variables of the linearised equations in (w, u), the Riemann invariants' differentials
//!   du +- sqrt(g/H) dw; the depth's slope is then cut to |dH| <= 2 H so that neither face
//!   depth is negative (positivity, Kurganov & Petrova 2007), which keeps the cell average and
//!   so the lake at rest wherever it is wet (there both differentials are 0). A bore is a jump
//!   of one family: limited by component, MC (or superbee, van Leer, theta = 1.5) on w sharpens
//!   it but overshoots the wall force in the step after each bore reaches a wall (+3 % at
//!   1.1 omega_1, 150 cells); by characteristic the other family is left smooth and the
//!   overshoot is gone, and the force.mean history at 150 cells is 1.1 % off a converged
//!   solution against minmod's 2.0 % (docs/SHALLOW_WATER.md). Below 1e-3 h (films, drying
//!   fronts) minmod on w and u by component, the scheme's limiter before 2026-11-27.
//! - The velocity, not the discharge, is reconstructed: a face velocity then lies between its
//!   neighbours' however thin the face's depth, which bounds the wave speeds at a drying front
//!   (with the discharge reconstructed, q/H of a thin face ran away within a few substeps).
//! - Walls: mirror ghost cells, w and H even, q odd; the HLL flux of two mirror states has no
//!   mass flux and the momentum flux g_e H^2/2 + H u (u - s), the wall pressure.

use super::lanes::{faster, lane_sum, larger, smaller, whole_chunks};
use super::reconstruction::{Limiting, Predictor, faces_of, slopes_of};

/// The discretisation: cells across the tank, their width, gravity with the dispersion
/// correction, and the depth below which a cell counts as dry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    pub cells: usize,
    pub dx: f64,
    pub g_e: f64,
    pub dry: f64,
    /// The depth below which a cell's faces are limited by component (surface and velocity,
    /// minmod) instead of in characteristic variables: thin films and drying fronts.
    pub thin: f64,
}

/// The semi-discrete right-hand side at one state, and what the step needs of it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rates {
    /// dH_i/dt and dq_i/dt (without the drag, which the step integrates exactly).
    pub depth: Vec<f64>,
    pub discharge: Vec<f64>,
    /// Momentum flux (pressure per unit breadth over rho) at the walls x = 0 and x = a.
    pub wall: [f64; 2],
    /// Mass flux through each interior interface (cells - 1 values): the rate of the first
    /// moment of the depth is dx times their sum.
    pub mass_flux: Vec<f64>,
    /// Largest wave speed |s| of any interface [m/s].
    pub speed: f64,
}

impl Rates {
    pub fn new(cells: usize) -> Self {
        Rates {
            depth: vec![0.0; cells],
            discharge: vec![0.0; cells],
            wall: [0.0; 2],
            mass_flux: vec![0.0; cells.saturating_sub(1)],
            speed: 0.0,
        }
    }
}

/// Velocity of discharge q at depth h, desingularised below the dry depth `dry` (Kurganov &
/// Petrova 2007): exactly q/h for h >= dry, going smoothly to 0 with h.
#[inline]
pub fn velocity(q: f64, h: f64, dry: f64) -> f64 {
    // One division either way (a select, not a branch: vectorisable).
    let (num, den) = if h >= dry {
        (q, h)
    } else {
        (q * 2.0 * h, h * h + dry * dry)
    };
    num / den
}

/// One side of an interface: depth and velocity.
#[derive(Clone, Copy, Debug)]
struct Side {
    h: f64,
    u: f64,
}

/// HLL flux (mass, momentum) between `l` and `r` with Einfeldt's wave speeds, and the largest
/// |speed|, under gravity `g` (`root_g` its square root). A side shallower than `dry` is dry:
/// the front then runs at u -+ 2c of the wet side. Every case is computed and the right one
/// selected, without branches, so that a loop of these is vectorised (the unselected ones
/// may be NaN: the square root of a dry face a few ulps below 0, 0/0 between dry faces).
///
/// One division: the speeds are carried times D = sqrt(H_L) + sqrt(H_R) > 0 (the Roe
/// velocity's denominator), which changes no sign and so no case, and the HLL flux's
/// denominator becomes D (S_R - S_L).
#[inline(always)]
fn hll(l: Side, r: Side, g: f64, root_g: f64, dry: f64) -> (f64, f64, f64) {
    let (wet_l, wet_r) = (l.h >= dry, r.h >= dry);
    // Square roots of the depths: the Roe weights, and times sqrt(g) the celerities.
    let (rl, rr) = (l.h.sqrt(), r.h.sqrt());
    let (cl, cr) = (root_g * rl, root_g * rr);
    // D times the Roe velocity, and the Roe celerity.
    let d = rl + rr;
    let du = rl * l.u + rr * r.u;
    let c = (0.5 * g * (l.h + r.h)).sqrt();
    // D times the speeds s_L, s_R.
    let (sl, sr) = if !wet_l {
        (d * (r.u - 2.0 * cr), d * (r.u + cr))
    } else if !wet_r {
        (d * (l.u - cl), d * (l.u + 2.0 * cl))
    } else {
        (
            smaller(d * (l.u - cl), du - d * c),
            larger(d * (r.u + cr), du + d * c),
        )
    };
    let flux = |s: Side| (s.h * s.u, s.h * s.u * s.u + 0.5 * g * s.h * s.h);
    let ((fl, ml), (fr, mr)) = (flux(l), flux(r));
    let width = sr - sl;
    let inv = 1.0 / (d * width);
    let (dsl, dsr, slr) = (d * sl, d * sr, sl * sr);
    let between = (
        (dsr * fl - dsl * fr + slr * (r.h - l.h)) * inv,
        (dsr * ml - dsl * mr + slr * (r.h * r.u - l.h * l.u)) * inv,
    );
    let (f, m) = if sl >= 0.0 {
        (fl, ml)
    } else if sr <= 0.0 {
        (fr, mr)
    } else {
        between
    };
    if !wet_l && !wet_r {
        (0.0, 0.0, 0.0)
    } else {
        // max(|s_L|, |s_R|) = max(|S_L|, |S_R|) / D = max(..) (S_R - S_L) / (D (S_R - S_L)).
        (f, m, larger(sl.abs(), sr.abs()) * width * inv)
    }
}

/// The faces of the interior cells 1 + a .. 1 + b for `part` = a..b, from the depths `h` and
/// velocities `u` of all cells, into `faces` = [ahead_h, ahead_u, behind_h, behind_u] by
/// interface: cell c's left face is the state ahead of interface c, its right face the state
/// behind interface c + 1. `form` makes a cell's faces from its depth, velocity and
/// slopes (as reconstructed, or evolved by the predictor).
#[inline(always)]
fn interior_faces(
    h: &[f64],
    u: &[f64],
    rise: f64,
    limiting: Limiting,
    form: impl Fn(f64, f64, f64, f64) -> (f64, f64, f64, f64),
    faces: [&mut [f64]; 4],
    part: std::ops::Range<usize>,
) {
    let (a, b) = (part.start, part.end);
    let [ahead_h, ahead_u, behind_h, behind_u] = faces;
    let cells = ahead_h[1 + a..1 + b]
        .iter_mut()
        .zip(&mut ahead_u[1 + a..1 + b])
        .zip(
            behind_h[2 + a..2 + b]
                .iter_mut()
                .zip(&mut behind_u[2 + a..2 + b]),
        );
    let (h, u) = (&h[a..b + 2], &u[a..b + 2]);
    for ((((lh, lu), (rh, ru)), h), u) in cells.zip(h.windows(3)).zip(u.windows(3)) {
        let (dh, du) = slopes_of(
            h[1],
            [h[1] - h[0] + rise, h[2] - h[1] + rise],
            [u[1] - u[0], u[2] - u[1]],
            rise,
            limiting,
        );
        (*lh, *lu, *rh, *ru) = form(h[1], u[1], dh, du);
    }
}

/// The faces of all cells ([`interior_faces`], the two wall cells with the mirror cell's
/// differences: 0 for w, +-2u for u) and the walls' mirror states: behind the left wall and
/// ahead of the right one, the wall cell's face with the velocity reversed.
#[inline(always)]
fn all_faces(
    h: &[f64],
    u: &[f64],
    rise: f64,
    limiting: Limiting,
    form: impl Fn(f64, f64, f64, f64) -> (f64, f64, f64, f64) + Copy,
    [ahead_h, ahead_u, behind_h, behind_u]: [&mut [f64]; 4],
) {
    let n = h.len();
    let last = n - 1;
    let edges = if n > 1 {
        [
            (0, [0.0, h[1] - h[0] + rise], [2.0 * u[0], u[1] - u[0]]),
            (
                last,
                [h[last] - h[last - 1] + rise, 0.0],
                [u[last] - u[last - 1], -2.0 * u[last]],
            ),
        ]
    } else {
        [(0, [0.0, 0.0], [2.0 * u[0], -2.0 * u[0]]); 2]
    };
    for (i, dw, du) in edges {
        let (dh, du) = slopes_of(h[i], dw, du, rise, limiting);
        (ahead_h[i], ahead_u[i], behind_h[i + 1], behind_u[i + 1]) = form(h[i], u[i], dh, du);
    }
    for part in whole_chunks(n.saturating_sub(2)) {
        let faces = [&mut *ahead_h, &mut *ahead_u, &mut *behind_h, &mut *behind_u];
        interior_faces(h, u, rise, limiting, form, faces, part);
    }
    (behind_h[0], behind_u[0]) = (ahead_h[0], -ahead_u[0]);
    (ahead_h[n], ahead_u[n]) = (behind_h[n], -behind_u[n]);
}

/// The HLL fluxes (mass, momentum, largest speed) through the interfaces a..b, each between
/// the state behind it and the state ahead of it: `sides` = [behind_h, behind_u, ahead_h,
/// ahead_u] by interface.
#[inline(always)]
fn fluxes(
    sides: [&[f64]; 4],
    out: [&mut [f64]; 3],
    g: f64,
    dry: f64,
    part: std::ops::Range<usize>,
) {
    let (a, b) = (part.start, part.end);
    let [behind_h, behind_u, ahead_h, ahead_u] = sides;
    let [mass, momentum, speed] = out;
    let root_g = g.sqrt();
    let out = mass[a..b]
        .iter_mut()
        .zip(&mut momentum[a..b])
        .zip(&mut speed[a..b]);
    let behind = behind_h[a..b].iter().zip(&behind_u[a..b]);
    let ahead = ahead_h[a..b].iter().zip(&ahead_u[a..b]);
    for (((f, m), s), ((&hl, &ul), (&hr, &ur))) in out.zip(behind.zip(ahead)) {
        (*f, *m, *s) = hll(Side { h: hl, u: ul }, Side { h: hr, u: ur }, g, root_g, dry);
    }
}

/// What a pass of the right-hand side gives besides the cell rates.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sweep {
    /// Momentum flux (pressure per unit breadth over rho) at the walls x = 0 and x = a.
    pub wall: [f64; 2],
    /// Sum of the mass fluxes through the interior interfaces: dx times it is the rate of the
    /// first moment of the depth.
    pub mass_flux: f64,
    /// Largest wave speed |s| of any interface [m/s].
    pub speed: f64,
}

/// A substep of length `dt` taken in the pass instead of the rates written to
/// [`Faces::rates`]: with `predict`, MUSCL-Hancock (the faces evolved by dt/2 in the faces
/// pass, [`Predictor`]); without, the forward-Euler step of the semi-discrete scheme (the
/// positivity fallback). Either way U' = U - dt/dx (F_R - F_L) + dt S into `next` (depths,
/// discharges), fused into the pass that would form the rates; the inertial source with the
/// depth's mean over the substep, -a (H + H')/2 (`a` the input's mean over the substep).
#[derive(Debug)]
pub struct Update<'a> {
    pub dt: f64,
    pub predict: bool,
    pub next: [&'a mut [f64]; 2],
}

/// Storage of [`sweep`]: per cell its velocity and its rates, per interface (cells + 1, the
/// walls included) the depths and velocities behind and ahead of it (the faces of the cells
/// either side; at a wall, the mirror of the wall cell's face), the mass and momentum fluxes
/// and the largest wave speed.
#[derive(Debug)]
pub struct Faces {
    depth_rate: Vec<f64>,
    discharge_rate: Vec<f64>,
    u: Vec<f64>,
    behind_h: Vec<f64>,
    behind_u: Vec<f64>,
    ahead_h: Vec<f64>,
    ahead_u: Vec<f64>,
    mass: Vec<f64>,
    momentum: Vec<f64>,
    speed: Vec<f64>,
}

impl Faces {
    pub fn new(cells: usize) -> Self {
        let v = |n| vec![0.0; n];
        Faces {
            depth_rate: v(cells),
            discharge_rate: v(cells),
            u: v(cells),
            behind_h: v(cells + 1),
            behind_u: v(cells + 1),
            ahead_h: v(cells + 1),
            ahead_u: v(cells + 1),
            mass: v(cells + 1),
            momentum: v(cells + 1),
            speed: v(cells + 1),
        }
    }

    /// dH_i/dt and dq_i/dt of the last [`sweep`] (without the drag, which the step
    /// integrates exactly).
    pub fn rates(&self) -> (&[f64], &[f64]) {
        (&self.depth_rate, &self.discharge_rate)
    }

    /// The mass fluxes through the interior interfaces of the last [`sweep`] (cells - 1).
    pub fn mass_fluxes(&self) -> &[f64] {
        let n = self.u.len();
        &self.mass[1..n]
    }
}

/// The semi-discrete right-hand side at depths `h` and discharges `q` under the base
/// acceleration `a`, into `faces` ([`Faces::rates`], [`Faces::mass_fluxes`]).
///
/// In passes over the cells and the interfaces, each a loop without branches that the
/// compiler vectorises: the velocities (a division each), the faces, the fluxes (3 square
/// roots and 2 divisions each), then the rates. The divisions and square roots bound the
/// cost; vectorised, they take a fraction of their scalar time. LLVM declines 2-lane SSE2
/// for the flux loop, so the same code is also compiled for AVX-512F (8 lanes) and AVX2 (4
/// lanes) and the widest the CPU has runs (checked per call: a cached flag). The same
/// operations on the same numbers in the same order (no fused multiply-adds, nothing
/// reassociated): the results are bit for bit those of the baseline build (tested).
pub fn sweep(grid: &Grid, h: &[f64], q: &[f64], a: f64, faces: &mut Faces) -> Sweep {
    sweep_widest(grid, h, q, a, faces, None)
}

builds! {
    /// [`sweep_passes`] in the widest build this CPU runs.
    fn sweep_widest, sweep_avx512, sweep_avx2, sweep_builds = sweep_passes(
        grid: &Grid,
        h: &[f64],
        q: &[f64],
        a: f64,
        faces: &mut Faces,
        update: Option<&mut Update>,
    ) -> Sweep;
}

/// Every build of [`sweep_passes`] this CPU can run, by name, each given to `check` with what
/// it left in `faces` (the rates), and the substeps of length `dt` it takes with the predictor
/// and without (the tests compare them).
#[cfg(test)]
#[allow(clippy::type_complexity)]
pub(super) fn each_build(
    grid: &Grid,
    h: &[f64],
    q: &[f64],
    a: f64,
    dt: f64,
    faces: &mut Faces,
    mut check: impl FnMut(&str, Sweep, &Faces, [(Sweep, [&[f64]; 2]); 2]),
) {
    let n = grid.cells;
    for (name, build) in sweep_builds() {
        let s = build(grid, h, q, a, faces, None);
        let mut steps = [true, false].map(|predict| {
            let (mut next_h, mut next_q) = (vec![0.0; n], vec![0.0; n]);
            let mut update = Update {
                dt,
                predict,
                next: [&mut next_h, &mut next_q],
            };
            let s = build(grid, h, q, a, &mut Faces::new(n), Some(&mut update));
            (s, next_h, next_q)
        });
        let [hancock, euler] = &mut steps;
        assert_eq!(
            euler.0, s,
            "{name}: the fallback's fluxes are the rates' fluxes"
        );
        check(
            name,
            s,
            faces,
            [
                (hancock.0, [&hancock.1, &hancock.2]),
                (euler.0, [&euler.1, &euler.2]),
            ],
        );
    }
}

/// The passes of [`sweep`], for any CPU (the baseline build); with `update`, a substep is
/// taken instead of the rates written ([`Update`]; [`Faces::rates`] is then not written).
/// Inlined into the builds of a whole communication step ([`super::Channel::advance_in`]).
#[inline(always)]
pub(super) fn sweep_passes(
    grid: &Grid,
    h: &[f64],
    q: &[f64],
    a: f64,
    faces: &mut Faces,
    update: Option<&mut Update>,
) -> Sweep {
    let n = grid.cells;
    let (h, q) = (&h[..n], &q[..n]);
    let (g, dry, dx) = (grid.g_e, grid.dry, grid.dx);
    let limiting = Limiting {
        g,
        inv_g: 1.0 / g,
        thin: grid.thin,
    };
    let inv_dx = 1.0 / dx;
    // Rise of the pseudo-bottom z = a x / g_e from one cell centre to the next.
    let rise = a * dx / g;
    // All of the cells' (interfaces') length: no bounds checks in the passes.
    let Faces {
        depth_rate,
        discharge_rate,
        u,
        behind_h,
        behind_u,
        ahead_h,
        ahead_u,
        mass,
        momentum,
        speed,
    } = faces;
    let u = &mut u[..n];
    let (behind_h, behind_u) = (&mut behind_h[..=n], &mut behind_u[..=n]);
    let (ahead_h, ahead_u) = (&mut ahead_h[..=n], &mut ahead_u[..=n]);
    let (mass, momentum, speed) = (&mut mass[..=n], &mut momentum[..=n], &mut speed[..=n]);
    for ((u, &h), &q) in u.iter_mut().zip(h).zip(q) {
        *u = velocity(q, h, dry);
    }
    let u = &*u;
    // Cell i's faces from the differences of the surface w = H + z and of u across its left
    // and right interfaces, evolved by half the substep if it is MUSCL-Hancock's (a loop for
    // each: no branch per cell).
    let sides = [&mut *ahead_h, &mut *ahead_u, &mut *behind_h, &mut *behind_u];
    match &update {
        Some(Update {
            dt, predict: true, ..
        }) => {
            let predictor = Predictor {
                half: 0.5 * dt * inv_dx,
                g,
                rise,
                thin: grid.thin,
            };
            all_faces(
                h,
                u,
                rise,
                limiting,
                |h, u, dh, du| predictor.faces(h, u, dh, du),
                sides,
            );
        }
        _ => all_faces(h, u, rise, limiting, faces_of, sides),
    }
    for part in whole_chunks(n + 1) {
        let sides = [&*behind_h, &*behind_u, &*ahead_h, &*ahead_u];
        fluxes(
            sides,
            [&mut *mass, &mut *momentum, &mut *speed],
            g,
            dry,
            part,
        );
    }
    // No mass flux through the walls (by symmetry; the formula leaves rounding there).
    (mass[0], mass[n]) = (0.0, 0.0);
    // The largest speed, in 16 lanes (the maximum does not depend on the order; 16: two
    // independent chains of 8-lane maxima, not one of 4-lane ones twice as long).
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
    let out = Sweep {
        wall: [momentum[0], momentum[n]],
        mass_flux: lane_sum(&mass[1..n]),
        speed: lanes.into_iter().fold(0.0, faster),
    };
    // The rates or the substep; the inertial force on a cell's liquid is -a_b H_i (the cell
    // average).
    let fluxes = mass.windows(2).zip(momentum.windows(2));
    match update {
        None => {
            let rates = depth_rate[..n].iter_mut().zip(&mut discharge_rate[..n]);
            for (((dh, dq), &h), (f, m)) in rates.zip(h).zip(fluxes) {
                *dh = -(f[1] - f[0]) * inv_dx;
                *dq = -(m[1] - m[0]) * inv_dx - a * h;
            }
        }
        Some(Update {
            dt,
            next: [next_h, next_q],
            ..
        }) => {
            let lam = *dt * inv_dx;
            let source = 0.5 * *dt * a;
            let next = next_h[..n].iter_mut().zip(next_q[..n].iter_mut());
            // The depth's increment as lam F_R - lam F_L: each interface's lam F is the same
            // number for both its cells, so the volume changes only by the final subtractions'
            // rounding (with lam (F_R - F_L) it drifted 1.6e-13 of itself in 60 s). The
            // source -a (H + H')/2: the sources sum to -a times the conserved volume (the
            // momentum balance closes), and the lake at rest keeps H.
            for (((nh, nq), (&h, &q)), (f, m)) in next.zip(h.iter().zip(q)).zip(fluxes) {
                let hn = h - (lam * f[1] - lam * f[0]);
                *nq = q - lam * (m[1] - m[0]) - source * (h + hn);
                *nh = hn;
            }
        }
    }
    out
}

/// The semi-discrete right-hand side at depths `h` and discharges `q` under the base
/// acceleration `a`, into `out`.
pub fn rates(grid: &Grid, h: &[f64], q: &[f64], a: f64, out: &mut Rates) {
    let mut faces = Faces::new(grid.cells);
    let s = sweep(grid, h, q, a, &mut faces);
    let (dh, dq) = faces.rates();
    out.depth.copy_from_slice(dh);
    out.discharge.copy_from_slice(dq);
    out.mass_flux.copy_from_slice(faces.mass_fluxes());
    out.wall = s.wall;
    out.speed = s.speed;
}
