//! Online estimate of the excitation amplitude A_e from the base motion (MODEL.md section 2:
//! nobody hands A_e over in a co-simulation).
//!
//! For harmonic base motion x_b = A sin(w t): <v^2> = w^2 A^2/2 and <a^2> = w^4 A^2/2, so
//! A = sqrt(2) <v^2> / sqrt(<a^2>) whatever w is. The mean squares come from two cascaded
//! first-order low-pass filters (time constant tau each: ripple at 2w falls as 1/(2 w tau)^2),
//! normalised by the filters' response to a constant so early estimates are not biased low.
//! When the host never sets the base velocity, the velocity is rebuilt from the acceleration by
//! a leaky integrator v' = a - w_c v, and its known gain w / sqrt(w^2 + w_c^2) is undone.

use std::cell::Cell;

/// Two cascaded first-order low-pass filters of each of `N` signals, sampled once per interval
/// with the same gain: the same operations lane by lane, so that the signals' updates pack into
/// one vector operation each (SSE2, NEON) with each lane's bits those of its own scalar update.
#[derive(Clone, Copy, Debug, PartialEq)]
struct MeanSquare<const N: usize> {
    first: [f64; N],
    second: [f64; N],
}

impl<const N: usize> Default for MeanSquare<N> {
    fn default() -> Self {
        MeanSquare {
            first: [0.0; N],
            second: [0.0; N],
        }
    }
}

impl<const N: usize> MeanSquare<N> {
    #[inline(always)]
    fn update(&mut self, alpha: [f64; N], sample: [f64; N]) {
        for ((first, s), alpha) in self.first.iter_mut().zip(sample).zip(alpha) {
            *first += alpha * (s - *first);
        }
        for ((second, first), alpha) in self.second.iter_mut().zip(self.first).zip(alpha) {
            *second += alpha * (first - *second);
        }
    }
}

impl<const N: usize> MeanSquare<N> {
    /// The filters' time derivatives under `sample`, time constant `tau`: the ODEs whose exact
    /// solution for a held sample [`MeanSquare::update`]'s first stage is; its second stage is
    /// fed the first stage's new value, held, not its path, and differs from these ODEs'
    /// solution by (first - sample) e^(-h/tau) (1 - e^(-h/tau) - h/tau), second order in h/tau
    /// (physics::amplitude_tests checks it).
    fn rates(&self, tau: f64, sample: [f64; N]) -> ([f64; N], [f64; N]) {
        (
            std::array::from_fn(|k| (sample[k] - self.first[k]) / tau),
            std::array::from_fn(|k| (self.first[k] - self.second[k]) / tau),
        )
    }
}

/// Number of values in [`AmplitudeTracker::continuous_state`]: the rebuilt velocity and the
/// three filter pairs, the estimator as ODEs in continuous time (the velocity source, measured
/// or rebuilt, is a discrete state).
pub const TRACKER_CONTINUOUS: usize = 7;

/// The lanes of [`AmplitudeTracker::squares`].
const V: usize = 0;
const A: usize = 1;

/// Number of values in [`AmplitudeTracker::state`].
pub const TRACKER_STATE: usize = 8;

/// The weight of the prior in the estimate of the estimator as ODEs (Model Exchange): its mean
/// squares are those of the prior's harmonic motion counted as this much filtered data, beside
/// the filters' own (whose weight grows from 0 to 1). The estimate then starts at the prior and
/// leaves it smoothly however small the filters still are, instead of jumping where a host's
/// trial state puts a mean square at 0 (docs/MODEL_EXCHANGE.md): 1e-6 is 5e5 times the
/// solver noise of the mean squares at rtol 1e-12 (their nominals are twice the prior's), and
/// moves the estimate from Co-Simulation's formula by 1e-6 relative once the filters are full.
pub const PRIOR_WEIGHT: f64 = 1e-6;

/// What an update takes from the interval's length alone: computed for the first interval of a
/// length and kept while the host's step stays the same (three exponentials per step otherwise,
/// most of the tracker's cost). The same expressions as computed afresh: the same bits.
#[derive(Clone, Copy, Debug)]
struct Coefficients {
    /// The interval length they are for (NaN: none yet).
    h: f64,
    /// The filters' gain 1 - e^(-h/tau), once per lane of the mean squares (one vector load,
    /// not a load and a broadcast).
    alpha: [f64; 2],
    /// The velocity rebuild's decay e^(-w_c h) and e^(-w_c h) - 1.
    decay: f64,
    decay_m1: f64,
}

impl Coefficients {
    const NONE: Coefficients = Coefficients {
        h: f64::NAN,
        alpha: [0.0; 2],
        decay: 0.0,
        decay_m1: 0.0,
    };
}

#[derive(Clone, Debug)]
pub struct AmplitudeTracker {
    tau: f64,
    leak: f64,
    prior: f64,
    /// The frequency of the prior's harmonic motion [rad/s] ([`PRIOR_WEIGHT`]).
    prior_omega: f64,
    rebuilt_v: f64,
    measured_v_seen: bool,
    /// The estimator runs as ODEs in a host's solver (Model Exchange): its estimate counts the
    /// prior as [`PRIOR_WEIGHT`] of data ([`AmplitudeTracker::continuous_estimate`]).
    continuous: bool,
    /// The mean squares of the base velocity (lane `V`) and acceleration (lane `A`).
    squares: MeanSquare<2>,
    /// The filters' response to a constant 1 (their normalisation), as of `pending` updates
    /// ago: it does not depend on the input, so [`AmplitudeTracker::take_in`] counts its
    /// updates and a read applies them ([`AmplitudeTracker::weight`]), the same operations.
    /// In cells: a read (`&self`) applies them once, for every later read.
    weight: Cell<MeanSquare<1>>,
    /// Updates of `weight` counted, not applied (all with the current coefficients: a new
    /// interval length applies them first).
    pending: Cell<u64>,
    /// Derived from `h`, `tau` and `leak`: not part of what the tracker is.
    coefficients: Coefficients,
}

/// Equal trackers: the same settings and state (whatever interval length they last saw).
impl PartialEq for AmplitudeTracker {
    fn eq(&self, other: &Self) -> bool {
        (
            self.tau,
            self.leak,
            self.prior,
            self.prior_omega,
            self.rebuilt_v,
        ) == (
            other.tau,
            other.leak,
            other.prior,
            other.prior_omega,
            other.rebuilt_v,
        ) && (self.measured_v_seen, self.continuous) == (other.measured_v_seen, other.continuous)
            && (self.squares, self.weight()) == (other.squares, other.weight())
    }
}

impl AmplitudeTracker {
    /// `tau`: filter time constant [s]; `leak`: corner w_c of the velocity rebuild [rad/s];
    /// `prior`: the estimate before any data, taken as harmonic motion at `prior_omega` [rad/s]
    /// where the estimator runs as ODEs ([`PRIOR_WEIGHT`]).
    pub fn new(tau: f64, leak: f64, prior: f64, prior_omega: f64) -> Self {
        AmplitudeTracker {
            tau,
            leak,
            prior,
            prior_omega,
            rebuilt_v: 0.0,
            measured_v_seen: false,
            continuous: false,
            squares: MeanSquare::default(),
            weight: Cell::new(MeanSquare::default()),
            pending: Cell::new(0),
            coefficients: Coefficients::NONE,
        }
    }

    /// Take in the base acceleration and velocity held over an interval of length `h`. Inlined
    /// into the step (a call and the tracker's state spilled around it cost as much as the
    /// filters); what changes rarely is out of line.
    #[inline(always)]
    pub fn update(&mut self, h: f64, accel: f64, velocity: f64) {
        self.advance::<false>(h, accel, velocity);
    }

    /// [`AmplitudeTracker::update`] with the weight's update counted, not applied: the same
    /// bits once read, for the path where nothing reads the estimate every step (there the
    /// weight's update was about a third of the tracker's time per step; a law that reads the
    /// estimate after every update would apply it at once anyway, through the cell).
    #[inline(always)]
    pub fn take_in(&mut self, h: f64, accel: f64, velocity: f64) {
        self.advance::<true>(h, accel, velocity);
    }

    /// The update; the weight's counted if `COUNT_WEIGHT`.
    #[inline(always)]
    fn advance<const COUNT_WEIGHT: bool>(&mut self, h: f64, accel: f64, velocity: f64) {
        // Both rare cases behind one branch, in integer bits: an interval length other than
        // the coefficients' (h > 0: equal bits are equal lengths; NaN, no coefficients yet,
        // equals none), or a base velocity other than +-0 (NaN included, as `!= 0.0` has it)
        // while the estimator still rebuilds the velocity (the mask all ones until then).
        let other_h = self.coefficients.h.to_bits() ^ h.to_bits();
        let rebuilding = u64::from(self.measured_v_seen).wrapping_sub(1);
        let new_velocity = (velocity.to_bits() << 1) & rebuilding;
        if other_h | new_velocity != 0 {
            self.settle(h, velocity);
        }
        let Coefficients {
            alpha,
            decay,
            decay_m1,
            ..
        } = self.coefficients;
        let v = if self.measured_v_seen {
            velocity
        } else {
            self.rebuilt_v
        };
        self.squares.update(alpha, [v * v, accel * accel]);
        if COUNT_WEIGHT {
            *self.pending.get_mut() += 1;
        } else {
            let mut weight = self.weight();
            weight.update([alpha[0]], [1.0]);
            self.weight.set(weight);
        }
        // Exact advance of v' = a - w_c v with a held.
        self.rebuilt_v = self.rebuilt_v * decay - accel * decay_m1 / self.leak;
    }

    /// The weight filters now: the counted updates applied (and kept applied), the same
    /// operations in the same order, stopped where they no longer change it (a fixed point of
    /// the recursion, reached within a few tens of time constants: every later update would
    /// leave it too). A read after n counted steps costs at most that many updates, once.
    fn weight(&self) -> MeanSquare<1> {
        let mut weight = self.weight.get();
        let pending = self.pending.get();
        if pending > 0 {
            self.pending.set(0);
            let alpha = [self.coefficients.alpha[0]];
            for _ in 0..pending {
                let before = weight;
                weight.update(alpha, [1.0]);
                if weight == before {
                    break;
                }
            }
            self.weight.set(weight);
        }
        weight
    }

    /// What an update over an interval of length `h` with the base velocity `velocity` needs
    /// before the filters when it is not what the last one had: the coefficients for `h`, the
    /// switch to the measured velocity.
    #[cold]
    #[inline(never)]
    fn settle(&mut self, h: f64, velocity: f64) {
        if self.coefficients.h != h {
            self.set_interval(h);
        }
        self.sees_velocity(velocity);
    }

    /// The coefficients for intervals of length `h`.
    #[cold]
    #[inline(never)]
    fn set_interval(&mut self, h: f64) {
        // The counted updates of the weight were with the old coefficients' gain.
        self.weight();
        self.coefficients = Coefficients {
            h,
            alpha: [-(-h / self.tau).exp_m1(); 2],
            decay: (-self.leak * h).exp(),
            decay_m1: (-self.leak * h).exp_m1(),
        };
    }

    /// The host drives base.v: restart the velocity statistics from the measured signal.
    #[cold]
    #[inline(never)]
    fn restart_measured(&mut self) {
        self.measured_v_seen = true;
        self.squares = MeanSquare::default();
        self.weight.set(MeanSquare::default());
        self.pending.set(0);
    }

    /// Whether the host's base velocity `velocity` switches the estimator to it (it is not 0
    /// and the estimator still rebuilds the velocity from the acceleration).
    #[inline(always)]
    pub fn would_see_velocity(&self, velocity: f64) -> bool {
        velocity != 0.0 && !self.measured_v_seen
    }

    /// The switch (Model Exchange's event): restart the statistics from the measured velocity,
    /// once. True if it did.
    pub fn sees_velocity(&mut self, velocity: f64) -> bool {
        let switch = self.would_see_velocity(velocity);
        if switch {
            self.restart_measured();
        }
        switch
    }

    /// The estimator's continuous part: [rebuilt v, <v^2> first, second, <a^2> first, second,
    /// weight first, second].
    pub fn continuous_state(&self) -> [f64; TRACKER_CONTINUOUS] {
        // The saved state without its flag (position 1).
        let s = self.state();
        std::array::from_fn(|k| s[if k == 0 { 0 } else { k + 1 }])
    }

    /// Take the continuous part (as [`AmplitudeTracker::continuous_state`] gives it) from a
    /// host's solver; the velocity source stays, and the estimator is one of ODEs from now on
    /// ([`AmplitudeTracker::continuous_estimate`]). Any finite values are taken: a solver's
    /// trial state may put a mean square or weight slightly below 0, far less than the prior's
    /// share. Err (nothing taken) for a non-finite value.
    pub fn set_continuous_state(&mut self, s: &[f64; TRACKER_CONTINUOUS]) -> Result<(), String> {
        if s.iter().any(|v| !v.is_finite()) {
            return Err("amplitude estimator state not finite".into());
        }
        let mut saved = self.state();
        saved[0] = s[0];
        saved[2..].copy_from_slice(&s[1..]);
        self.take_state(&saved);
        self.continuous = true;
        Ok(())
    }

    /// The velocity whose square the first filter of lane `V` takes in.
    fn velocity(&self, measured: f64) -> f64 {
        if self.measured_v_seen {
            measured
        } else {
            self.rebuilt_v
        }
    }

    /// The time derivatives of [`AmplitudeTracker::continuous_state`] under the base
    /// acceleration `accel` and velocity `velocity`: v' = a - w_c v and each filter pair's.
    pub fn continuous_rates(&self, accel: f64, velocity: f64) -> [f64; TRACKER_CONTINUOUS] {
        let v = self.velocity(velocity);
        let (first, second) = self.squares.rates(self.tau, [v * v, accel * accel]);
        let ([w1], [w2]) = self.weight().rates(self.tau, [1.0]);
        [
            accel - self.leak * self.rebuilt_v,
            first[V],
            second[V],
            first[A],
            second[A],
            w1,
            w2,
        ]
    }

    /// J d of [`AmplitudeTracker::continuous_rates`]: their exact change for the change `d` of
    /// the continuous state and `da`, `dv` of the base acceleration and velocity (the rates
    /// are linear but for the squares of the velocity and the acceleration).
    pub fn rates_tangent(
        &self,
        accel: f64,
        velocity: f64,
        d: &[f64; TRACKER_CONTINUOUS],
        da: f64,
        dv: f64,
    ) -> [f64; TRACKER_CONTINUOUS] {
        let dv = if self.measured_v_seen { dv } else { d[0] };
        let d_square = 2.0 * self.velocity(velocity) * dv;
        let tau = self.tau;
        [
            da - self.leak * d[0],
            (d_square - d[1]) / tau,
            (d[1] - d[2]) / tau,
            (2.0 * accel * da - d[3]) / tau,
            (d[3] - d[4]) / tau,
            -d[5] / tau,
            (d[5] - d[6]) / tau,
        ]
    }

    /// The evolving part of the estimator, for saving the state: the flag at position 1 is
    /// 1 once the velocity is measured, plus 2 once the estimator runs as ODEs.
    pub fn state(&self) -> [f64; TRACKER_STATE] {
        [
            self.rebuilt_v,
            f64::from(u8::from(self.measured_v_seen) + 2 * u8::from(self.continuous)),
            self.squares.first[V],
            self.squares.second[V],
            self.squares.first[A],
            self.squares.second[A],
            self.weight().first[0],
            self.weight().second[0],
        ]
    }

    /// Restore a state saved with [`AmplitudeTracker::state`].
    pub fn set_state(&mut self, s: &[f64; TRACKER_STATE]) -> Result<(), String> {
        if s.iter().any(|v| !v.is_finite())
            || s[2..].iter().any(|v| *v < 0.0)
            || !matches!(s[1], 0.0 | 1.0 | 2.0 | 3.0)
        {
            return Err("amplitude estimator state out of range".into());
        }
        self.take_state(s);
        Ok(())
    }

    /// Take a saved state as it is (checked by the caller).
    fn take_state(&mut self, s: &[f64; TRACKER_STATE]) {
        self.rebuilt_v = s[0];
        self.measured_v_seen = matches!(s[1], 1.0 | 3.0);
        self.continuous = s[1] >= 2.0;
        self.squares = MeanSquare {
            first: [s[2], s[4]],
            second: [s[3], s[5]],
        };
        self.pending.set(0);
        self.weight = Cell::new(MeanSquare {
            first: [s[6]],
            second: [s[7]],
        });
    }

    /// The current amplitude estimate [m]: Co-Simulation's of the filters (a mean square or
    /// weight below 0 counts as 0, so any finite state gives a finite estimate), or, once the
    /// estimator runs as ODEs, [`AmplitudeTracker::continuous_estimate`]'s.
    pub fn estimate(&self) -> f64 {
        if self.continuous {
            return self.continuous_estimate().0;
        }
        let w = self.weight().second[0].max(0.0);
        if w <= 0.0 {
            return self.prior;
        }
        self.of_means(
            self.squares.second[V].max(0.0) / w,
            self.squares.second[A].max(0.0) / w,
        )
        .map_or(self.prior, |(estimate, _)| estimate)
    }

    /// The estimate from the mean squares `v2` of the velocity and `a2` of the acceleration,
    /// with its partial derivatives by them; None where they give none (the prior stands).
    fn of_means(&self, v2: f64, a2: f64) -> Option<(f64, [f64; 2])> {
        if !(a2 > 0.0 && v2 > 0.0) {
            return None;
        }
        let (estimate, slopes) = if self.measured_v_seen {
            let e = std::f64::consts::SQRT_2 * v2 / a2.sqrt();
            (e, [e / v2, -0.5 * e / a2])
        } else {
            // The rebuilt velocity has <v^2> = <a^2> / (w^2 + w_c^2): solve for w^2.
            let w2 = a2 / v2 - self.leak * self.leak;
            if w2 <= 0.0 {
                return None;
            }
            let e = std::f64::consts::SQRT_2 * a2.sqrt() / w2;
            (
                e,
                [e * a2 / (v2 * v2 * w2), e * (0.5 / a2 - 1.0 / (v2 * w2))],
            )
        };
        estimate.is_finite().then_some((estimate, slopes))
    }

    /// The mean squares [<v^2>, <a^2>] of the prior's harmonic motion (amplitude `prior` at
    /// `prior_omega`), of the velocity the estimator takes in (rebuilt: through the leak's
    /// gain).
    fn prior_means(&self) -> [f64; 2] {
        let w = self.prior_omega;
        let a2 = 0.5 * (self.prior * w * w).powi(2);
        let v2 = if self.measured_v_seen {
            0.5 * (self.prior * w).powi(2)
        } else {
            a2 / (w * w + self.leak * self.leak)
        };
        [v2, a2]
    }

    /// The estimate of the estimator as ODEs, and its gradient by the continuous state (in
    /// [`AmplitudeTracker::continuous_state`]'s order): the prior's mean squares count as
    /// [`PRIOR_WEIGHT`] of data beside the filters', so the estimate is the prior at the start
    /// (all filters 0) and a smooth function of the filters from there; where even that gives
    /// no estimate (a mean square or weight below minus the prior's share, or w^2 <= 0) it
    /// is the prior, its gradient 0.
    pub fn continuous_estimate(&self) -> (f64, [f64; TRACKER_CONTINUOUS]) {
        let [v0, a0] = self.prior_means();
        let w = self.weight().second[0] + PRIOR_WEIGHT;
        let v = self.squares.second[V] + PRIOR_WEIGHT * v0;
        let a = self.squares.second[A] + PRIOR_WEIGHT * a0;
        let mut gradient = [0.0; TRACKER_CONTINUOUS];
        if w <= 0.0 {
            return (self.prior, gradient);
        }
        let Some((estimate, [by_v2, by_a2])) = self.of_means(v / w, a / w) else {
            return (self.prior, gradient);
        };
        // The means are v/w and a/w: by w, -(v by_v2 + a by_a2)/w^2.
        gradient[2] = by_v2 / w;
        gradient[4] = by_a2 / w;
        gradient[6] = -(v * by_v2 + a * by_a2) / (w * w);
        (estimate, gradient)
    }
}

#[cfg(test)]
mod tests;
