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
pub struct Limiting {
    pub g: f64,
    pub inv_g: f64,
    pub thin: f64,
}

/// The faces of a cell of depth `depth` and velocity `u` from the differences of the surface
/// w = H + z and of u across its left and right interfaces, `rise` the pseudo-bottom's rise
/// from one cell to the next: (left depth, left velocity, right depth, right velocity).
#[inline(always)]
pub fn faces_of(
    depth: f64,
    u: f64,
    dw: [f64; 2],
    du: [f64; 2],
    rise: f64,
    limiting: Limiting,
) -> (f64, f64, f64, f64) {
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
    let dh = smaller(larger(sw - rise, -most), most);
    let du = su;
    (
        depth - 0.5 * dh,
        u - 0.5 * du,
        depth + 0.5 * dh,
        u + 0.5 * du,
    )
}
