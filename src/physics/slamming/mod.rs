//! The impact (slamming) mass of the sloshing-slamming S^2 model (seed Eqs 2.5-2.8 with the
//! corrections of MODEL.md section 3). Relative to the tank it moves freely, z'' = -a_b, and
//! hits the walls at z = +-d/2. The colliding pair is the water and the tank walls; within a
//! step the tank is the host's and counts as infinitely heavy (mu -> 0), so an impact reverses
//! the relative velocity with restitution e, loses (1 - e^2) v^2 / 2 per unit mass, and hands the
//! impulse (1 + e) v to the tank.
//!
//! Between impacts the motion is a polynomial in time (the base acceleration is one over a
//! step), so impacts are located as roots of that polynomial to machine precision, not by
//! checking step ends. Chattering ends when the rebound is slower than `rest_speed`: the mass
//! then rests on the wall for as long as the base acceleration presses it there, pushing on the
//! tank with -a_b per unit mass, and leaves when the acceleration turns.

use super::base::BaseAcceleration;

/// Impacts in one step before the step is refused (chattering that does not end).
const MAX_IMPACTS_PER_STEP: u64 = 100_000;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slamming {
    /// d: the free travel of the impact mass between the walls [m].
    pub clearance: f64,
    /// e: coefficient of restitution of the water on the walls.
    pub restitution: f64,
    /// Rebound speed below which the mass comes to rest on the wall [m/s].
    pub rest_speed: f64,
}

/// State of the impact mass (per unit mass) and what it has exchanged.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SlamState {
    /// Position relative to the tank's centre, |z| <= d/2 [m].
    pub z: f64,
    /// Velocity relative to the tank [m/s].
    pub v: f64,
    /// 0: in flight; +1 or -1: resting on that wall.
    pub contact: i8,
    pub impacts: u64,
    /// Work of the base, integral of -a_b v.
    pub work_in: f64,
    /// Energy lost in impacts.
    pub dissipated: f64,
    /// Impulse the impacts gave the tank so far, per unit mass [m/s] (not what the wall gives
    /// the mass while it rests there).
    pub impulse: f64,
}

/// Integrals of the base acceleration from 0: P1(s) = int a, P2(s) = int int a.
fn p1(b: &BaseAcceleration, s: f64) -> f64 {
    b.integral(s)
}

fn p2(b: &BaseAcceleration, s: f64) -> f64 {
    let a = &b.a;
    s * s * (a[0] / 2.0 + s * (a[1] / 6.0 + s * a[2] / 24.0))
}

impl Slamming {
    /// Free flight from (z0, v0) at local time s0 to s.
    fn flight(b: &BaseAcceleration, z0: f64, v0: f64, s0: f64, s: f64) -> (f64, f64) {
        let tau = s - s0;
        let z = z0 + v0 * tau - (p2(b, s) - p2(b, s0) - p1(b, s0) * tau);
        let v = v0 - (p1(b, s) - p1(b, s0));
        (z, v)
    }

    /// The first time in (s0, s1] at which the flight from (z0, v0) reaches a wall: the time and
    /// the wall (+1 or -1), or None.
    fn next_impact(
        &self,
        b: &BaseAcceleration,
        z0: f64,
        v0: f64,
        s0: f64,
        s1: f64,
    ) -> Option<(f64, i8)> {
        let half = 0.5 * self.clearance;
        // Outside the walls by how much (positive: beyond one of them).
        let beyond = |s: f64| {
            let (z, _) = Self::flight(b, z0, v0, s0, s);
            z.abs() - half
        };
        // Between impacts |z| <= d/2 and the trajectory is a polynomial of degree <= 4 whose
        // curvature is bounded by the base acceleration: sample finely enough that it cannot leave
        // and return between samples unnoticed, then bisect the first sign change.
        let amax = acceleration_bound(b, s0, s1);
        let vmax = v0.abs() + amax * (s1 - s0);
        let resolution = if vmax > 0.0 {
            0.01 * self.clearance / vmax
        } else {
            s1 - s0
        };
        let n = ((s1 - s0) / resolution).ceil().clamp(8.0, 4096.0) as usize;
        let grid = |k: usize| s0 + (s1 - s0) * k as f64 / n as f64;
        let mut lo = s0;
        for k in 1..=n {
            let hi = grid(k);
            if beyond(hi) >= 0.0 {
                // The first crossing lies in (lo, hi]: bisect to the last bit.
                let (mut a, mut c) = (lo, hi);
                for _ in 0..200 {
                    let m = 0.5 * (a + c);
                    if m <= a || m >= c {
                        break;
                    }
                    if beyond(m) >= 0.0 { c = m } else { a = m }
                }
                let (z, _) = Self::flight(b, z0, v0, s0, c);
                return Some((c, if z > 0.0 { 1 } else { -1 }));
            }
            lo = hi;
        }
        None
    }

    /// While resting on `wall`, the first time in (s0, s1] at which the base acceleration stops
    /// pressing the mass onto it (a_b wall > 0), or None.
    fn release(b: &BaseAcceleration, wall: i8, s0: f64, s1: f64) -> Option<f64> {
        let pulls = |s: f64| !pressed(wall, b.at(s));
        if pulls(s0) {
            return Some(s0);
        }
        let n = 64;
        let mut lo = s0;
        for k in 1..=n {
            let hi = s0 + (s1 - s0) * k as f64 / n as f64;
            if pulls(hi) {
                let (mut a, mut c) = (lo, hi);
                for _ in 0..200 {
                    let m = 0.5 * (a + c);
                    if m <= a || m >= c {
                        break;
                    }
                    if pulls(m) { c = m } else { a = m }
                }
                return Some(c);
            }
            lo = hi;
        }
        None
    }

    /// The impact law (Eq 2.5 with the tank as the infinitely heavy partner, MODEL.md section
    /// 3) at the instant the mass reaches `wall` (+1 or -1) with relative velocity `v_hit`
    /// under base acceleration `a`: the mass rebounds with -e v_hit from the wall, or comes to
    /// rest on it if that rebound is slower than `rest_speed` while `a` presses it there. Counts
    /// the impact and its dissipated energy; returns the impulse given to the tank per unit
    /// mass, v_hit - v_after [m/s].
    pub fn hit(&self, st: &mut SlamState, wall: i8, v_hit: f64, a: f64) -> f64 {
        let mut v_after = -self.restitution * v_hit;
        st.z = f64::from(wall) * 0.5 * self.clearance;
        st.impacts += 1;
        if v_after.abs() < self.rest_speed && pressed(wall, a) {
            // The rebound is negligible: the mass comes to rest on the wall.
            v_after = 0.0;
            st.contact = wall;
        }
        // The tank takes the momentum the water loses; the energy is dissipated.
        st.dissipated += 0.5 * (v_hit * v_hit - v_after * v_after);
        st.v = v_after;
        st.impulse += v_hit - v_after;
        v_hit - v_after
    }

    /// Advance the impact mass by `h` under `base` (local time 0..h). Returns the impulse the
    /// mass gave the tank over the step, per unit mass [m/s], or Err if chattering did not end.
    pub fn advance(
        &self,
        st: &mut SlamState,
        h: f64,
        base: &BaseAcceleration,
    ) -> Result<f64, String> {
        let half = 0.5 * self.clearance;
        let mut s = 0.0;
        let mut impulse = 0.0;
        let mut impacts = 0u64;
        let mut next = *st;
        while s < h {
            if next.contact != 0 {
                let wall = next.contact;
                let until = Self::release(base, wall, s, h).unwrap_or(h);
                // Pressed onto the wall: the wall holds it with the base's acceleration.
                impulse -= p1(base, until) - p1(base, s);
                s = until;
                if s < h {
                    next.contact = 0;
                }
                continue;
            }
            let v_start = next.v;
            match self.next_impact(base, next.z, next.v, s, h) {
                None => {
                    let (z, v) = Self::flight(base, next.z, next.v, s, h);
                    next.work_in += 0.5 * (v * v - v_start * v_start);
                    (next.z, next.v) = (z.clamp(-half, half), v);
                    s = h;
                }
                Some((t_hit, wall)) => {
                    let (_, v_hit) = Self::flight(base, next.z, next.v, s, t_hit);
                    next.work_in += 0.5 * (v_hit * v_hit - v_start * v_start);
                    impacts += 1;
                    if impacts > MAX_IMPACTS_PER_STEP {
                        return Err(format!(
                            "more than {MAX_IMPACTS_PER_STEP} impacts in one step: chattering did not end"
                        ));
                    }
                    impulse += self.hit(&mut next, wall, v_hit, base.at(t_hit));
                    s = t_hit;
                }
            }
        }
        *st = next;
        Ok(impulse)
    }
}

/// Whether base acceleration `a` presses the mass onto `wall` (+1 or -1): its acceleration
/// relative to the tank, -a, points into that wall (or vanishes).
pub fn pressed(wall: i8, a: f64) -> bool {
    a * f64::from(wall) <= 0.0
}

/// A bound of abs(a_b) over [s0, s1]: the polynomial is about b.t0, so its terms grow with the
/// distance from t0, which for a search starting after an impact is more than s1 - s0.
fn acceleration_bound(b: &BaseAcceleration, s0: f64, s1: f64) -> f64 {
    let reach = (s0 - b.t0).abs().max((s1 - b.t0).abs());
    b.a[0].abs() + reach * (b.a[1].abs() + reach * b.a[2].abs())
}

#[cfg(test)]
mod tests;
