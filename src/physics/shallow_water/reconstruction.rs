//! The reconstruction of a cell's faces from its neighbours: the limited slopes of the surface
//! and the velocity, and the depth slope cut for positivity (why these choices: [`super`]'s
//! scheme documentation and docs/SHALLOW_WATER.md).

use super::lanes::{larger, smaller};

/// Minmod of the left and right differences: the smaller in magnitude if they have one sign,
/// else 0 (without branches: vectorisable).
#[inline(always)]
fn limited(left: f64, right: f64) -> f64 {
    let m = smaller(left.abs(), right.abs());
    if left * right <= 0.0 {
        0.0
    } else {
        m.copysign(left)
    }
}

/// The monotonised central limiter (van Leer 1977) of the left and right differences: the
/// smallest of twice either and their mean, if they have one sign, else 0 (without branches).
#[inline(always)]
fn monotonised(left: f64, right: f64) -> f64 {
    let m = smaller(
        2.0 * smaller(left.abs(), right.abs()),
        0.5 * (left + right).abs(),
    );
    if left * right <= 0.0 {
        0.0
    } else {
        m.copysign(left)
    }
}

/// What the limiting of a cell's slopes needs besides its differences: gravity, its inverse,
/// and the thin depth (below it, minmod by component).
#[derive(Clone, Copy, Debug)]
pub(super) struct Limiting {
    pub(super) g: f64,
    pub(super) inv_g: f64,
    pub(super) thin: f64,
}

/// The limited slopes (depth, velocity) of a cell of depth `depth` from the differences of
/// the surface w = H + z and of the velocity u across its left and right interfaces, `rise`
/// the pseudo-bottom's rise from one cell to the next; the depth's slope is cut so that
/// neither face is negative (|dH| <= 2 H: the faces' mean is the cell's depth).
#[inline(always)]
pub(super) fn slopes_of(
    depth: f64,
    dw: [f64; 2],
    du: [f64; 2],
    rise: f64,
    limiting: Limiting,
) -> (f64, f64) {
    // The slopes of the surface and the velocity. Where the cell is deeper than thin, limited
    // in the characteristic variables of the linearised equations, the Riemann invariants'
    // differentials du +- k dw, k = sqrt(g/H) = g/c (monotonised central on each: a bore is a
    // jump of one family only, so the other is not clipped or steepened with it), then taken
    // back: dw = (p - m)/(2k), du = (p + m)/2; k H/g = 1/k. Otherwise minmod by component
    // (a thin film's k is unbounded; a face velocity then stays between its neighbours').
    // Both are computed and one selected (no branch: vectorised).
    let k = (limiting.g / depth).sqrt();
    let p = monotonised(du[0] + k * dw[0], du[1] + k * dw[1]);
    let m = monotonised(du[0] - k * dw[0], du[1] - k * dw[1]);
    let (sw, su) = if depth >= limiting.thin {
        ((p - m) * (0.5 * k * depth * limiting.inv_g), 0.5 * (p + m))
    } else {
        (limited(dw[0], dw[1]), limited(du[0], du[1]))
    };
    // Depth slope = surface slope - bottom slope, cut so that no face is negative.
    // (A NaN depth stays NaN, and the step that made it is refused.)
    let most = 2.0 * larger(depth, 0.0);
    (smaller(larger(sw - rise, -most), most), su)
}

/// The faces of a cell of depth `depth` and velocity `u` with the slopes `dh`, `du`: (left
/// depth, left velocity, right depth, right velocity).
#[inline(always)]
pub(super) fn faces_of(depth: f64, u: f64, dh: f64, du: f64) -> (f64, f64, f64, f64) {
    (
        depth - 0.5 * dh,
        u - 0.5 * du,
        depth + 0.5 * dh,
        u + 0.5 * du,
    )
}

/// MUSCL-Hancock's predictor (van Leer 1984; Toro, "Riemann solvers and numerical methods for
/// fluid dynamics", ch. 14): a cell's faces evolved by half a substep with the cell's own
/// slopes, in the primitive variables (H, u) of the quasi-linear equations
///
/// ```text
/// H_t + u H_x + H u_x = 0,    u_t + u u_x + g_e w_x = 0    (w = H + z, z = a_b x / g_e),
/// ```
///
/// both faces moved by the same increment: no division, and the tilted lake at rest (dw = du
/// = 0) keeps its faces exactly. Where the cell or either evolved face is thinner than `thin`
/// (films, drying fronts, where the linearisation fails) the faces are kept as reconstructed:
/// there the substep is first order in time. Measured, not proven, to keep the faces
/// non-negative; the substep's positivity is guaranteed by its fallback
/// (`super::Channel::advance_in`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Predictor {
    /// dt/(2 dx).
    pub(super) half: f64,
    pub(super) g: f64,
    /// The pseudo-bottom's rise from one cell to the next (a_b's mean over the substep).
    pub(super) rise: f64,
    pub(super) thin: f64,
}

impl Predictor {
    /// The faces (as [`faces_of`]) of a cell of depth `h`, velocity `u` and slopes `dh`, `du`,
    /// evolved by half a substep. Both cases computed and one selected (no branch).
    #[inline(always)]
    pub(super) fn faces(&self, h: f64, u: f64, dh: f64, du: f64) -> (f64, f64, f64, f64) {
        let faces = faces_of(h, u, dh, du);
        let (hl, ul, hr, ur) = faces;
        let dh_t = self.half * (u * dh + h * du);
        let du_t = self.half * (u * du + self.g * (dh + self.rise));
        let evolved = (hl - dh_t, ul - du_t, hr - dh_t, ur - du_t);
        if evolved.0 >= self.thin && evolved.2 >= self.thin && h >= self.thin {
            evolved
        } else {
            faces
        }
    }
}
