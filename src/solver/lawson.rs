//! Exponential (Lawson) fourth-order Runge-Kutta with a fixed internal step, for a right-hand
//! side split into a damped linear oscillator and a remainder ([`OscillatorSplit`]): classical
//! RK4 on the remainder in the frame that moves with the oscillator's exact flow. The free
//! motion of a linear oscillator is integrated exactly whatever the step, and the error of a
//! weakly nonlinear one scales with the remainder, not with the oscillation.
//!
//! With E = exp(L h/2) and E2 = exp(L h) the flows of the linear part L, and k_i the remainder:
//!   k1 = r(t, y),               k2 = r(t + h/2, E (y + h/2 k1)),
//!   k3 = r(t + h/2, E y + h/2 k2),  k4 = r(t + h, E2 y + h E k3),
//!   y1 = E2 y + h/6 (E2 k1 + 2 E (k2 + k3) + k4).
//! (Hochbruck & Ostermann, Exponential integrators, Acta Numerica 2010, section 2.3.)

use super::fixed::{OneStep, StepBound, fixed_steps};
use super::{OscillatorSplit, SolveError, SolveStats};

/// The flows of the linear part over h/2 and h for one (h, w2, c), and their second columns
/// (where a slope of y1 goes) times the weights the step applies to them.
#[derive(Clone, Copy, Debug)]
struct Flows {
    key: [f64; 3],
    /// E - I and E2 - I.
    half: [[f64; 2]; 2],
    full: [[f64; 2]; 2],
    /// h/2 E[:, 1], h E[:, 1], h/3 E[:, 1], h/6 E2[:, 1].
    cols: [[f64; 2]; 4],
}

impl Flows {
    /// The flows of `f`'s linear part for key (h, w2, c). Out of line and cold: inlined, the
    /// propagator's exp, sin and cos could be hoisted ahead of the cache check (the compiler
    /// may speculate calls it knows to be pure) and paid on every step, not on a miss only.
    #[cold]
    #[inline(never)]
    fn of<const N: usize, F: OscillatorSplit<N>>(f: &F, key: [f64; 3]) -> Self {
        let h = key[0];
        Flows::new(key, f.flow_change(0.5 * h), f.flow_change(h))
    }

    /// From the flows' changes E - I and E2 - I.
    fn new(key: [f64; 3], half: [[f64; 2]; 2], full: [[f64; 2]; 2]) -> Self {
        let h = key[0];
        let col = |d: &[[f64; 2]; 2], w: f64| [w * d[0][1], w * (1.0 + d[1][1])];
        Flows {
            key,
            half,
            full,
            cols: [
                col(&half, 0.5 * h),
                col(&half, h),
                col(&half, h / 3.0),
                col(&full, h / 6.0),
            ],
        }
    }
}

/// Flows derived from the configuration and the step alone: equal whatever they hold, so that
/// a cache filled by a refused step leaves an integrator equal to what it was. Empty: a key
/// that equals none (NaN).
#[derive(Clone, Copy, Debug)]
struct FlowCache(Flows);

impl Default for FlowCache {
    fn default() -> Self {
        let zero = [[0.0; 2]; 2];
        FlowCache(Flows::new([f64::NAN; 3], zero, zero))
    }
}

impl PartialEq for FlowCache {
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

/// Lawson RK4 with equal internal steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExpRk4 {
    bound: StepBound,
    /// The flows of the last step size: communication steps are usually all alike, and the
    /// exponential and trigonometric functions would otherwise dominate a step's cost.
    flows: FlowCache,
}

impl ExpRk4 {
    pub fn new(max_step: f64, max_steps: u64) -> Self {
        ExpRk4 {
            bound: StepBound::new(max_step, max_steps),
            flows: FlowCache::default(),
        }
    }

    /// Advance `y` from `t0` to `t1`. On error `y` is left unchanged.
    pub fn integrate<const N: usize, F: OscillatorSplit<N>>(
        &mut self,
        f: &F,
        t0: f64,
        t1: f64,
        y: &mut [f64; N],
    ) -> Result<SolveStats, SolveError> {
        struct Lawson<'a, F> {
            f: &'a F,
            cache: &'a mut Flows,
        }
        impl<const N: usize, F: OscillatorSplit<N>> OneStep<N> for Lawson<'_, F> {
            /// The cache is checked once per interval: all its steps have the same size.
            #[inline(always)]
            fn prepare(&mut self, h: f64) {
                let (w2, c) = self.f.oscillator();
                let k = &self.cache.key;
                // (NaN, the empty cache's key, equals nothing.)
                if !(k[0] == h && k[1] == w2 && k[2] == c) {
                    *self.cache = Flows::of(self.f, [h, w2, c]);
                }
            }

            #[inline(always)]
            fn step(&mut self, t: f64, h: f64, z: &[f64; N]) -> [f64; N] {
                step(self.f, self.cache, t, h, z)
            }
        }
        let mut lawson = Lawson {
            f,
            cache: &mut self.flows.0,
        };
        fixed_steps(t0, t1, &self.bound, 4, y, &mut lawson)
    }
}

/// One Lawson RK4 step of `h` from (t, z) with the flows of h/2 and h.
#[inline(always)]
fn step<const N: usize, F: OscillatorSplit<N>>(
    f: &F,
    flows: &Flows,
    t: f64,
    h: f64,
    z: &[f64; N],
) -> [f64; N] {
    let r = |t: f64, y: &[f64; N]| {
        let mut dy = [0.0; N];
        f.remainder(t, y, &mut dy);
        dy
    };
    let (e, e2) = (&flows.half, &flows.full);
    // E z = z + (E - I) z: rounded relative to the change.
    let apply = |d: &[[f64; 2]; 2]| {
        [
            z[0] + (d[0][0] * z[0] + d[0][1] * z[1]),
            z[1] + (d[1][0] * z[0] + d[1][1] * z[1]),
        ]
    };
    let (ez, e2z) = (apply(e), apply(e2));
    let [half_col, full_col, third_col, sixth_col2] = flows.cols;
    // A stage: the oscillator pair from its flowed part plus the slope of y1 carried by a
    // weighted column of a flow (the remainder acts on y1 only); the other components as in
    // classical RK4.
    let stage = |pair: [f64; 2], col: [f64; 2], w: f64, k: &[f64; N]| -> [f64; N] {
        std::array::from_fn(|i| match i {
            0 => pair[0] + k[1] * col[0],
            1 => pair[1] + k[1] * col[1],
            _ => z[i] + w * k[i],
        })
    };
    let half = 0.5 * h;
    let k1 = r(t, z);
    let k2 = r(t + half, &stage(ez, half_col, half, &k1));
    // E y + h/2 k2: the slope enters unflowed.
    let y3 = std::array::from_fn(|i| match i {
        0 => ez[0],
        1 => ez[1] + half * k2[1],
        _ => z[i] + half * k2[i],
    });
    let k3 = r(t + half, &y3);
    let k4 = r(t + h, &stage(e2z, full_col, h, &k3));
    let sixth = h / 6.0;
    let k23 = k2[1] + k3[1];
    std::array::from_fn(|i| match i {
        0 => e2z[0] + (k1[1] * sixth_col2[0] + k23 * third_col[0]),
        1 => e2z[1] + (k1[1] * sixth_col2[1] + k23 * third_col[1] + sixth * k4[1]),
        _ => z[i] + sixth * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]),
    })
}
