//! The amplitude tracker on the step's own path, for a damping law that ignores the amplitude:
//! the step's input is written down before the step ([`StagedTracker::stage`]) and taken in
//! once the step has succeeded ([`StagedTracker::commit`]), so that nothing of the tracker is
//! live across the model's step (no registers saved around it) and the step's code is the one a
//! fixed amplitude runs. The same operations in the same order as
//! [`AmplitudeTracker::update`]: the same bits.
//!
//! Taking the inputs in later, a record of several steps replayed when something reads the
//! tracker, was measured slower (docs/ARCHITECTURE.md, issue #29's third pass): the filters
//! are a chain of dependent operations, which overlaps the model's step when taken in step by
//! step and stands alone when replayed.

use super::{AmplitudeTracker, Coefficients};

/// An [`AmplitudeTracker`] and the input of the step under way.
#[derive(Clone, Debug)]
pub struct StagedTracker {
    now: AmplitudeTracker,
    /// The base acceleration and velocity [`StagedTracker::stage`] wrote down (the velocity
    /// only while the host drives it: the rebuilt one never reads it).
    accel: f64,
    velocity: f64,
}

/// Equal trackers: the same tracker (what is written down is scratch for the step under way).
impl PartialEq for StagedTracker {
    fn eq(&self, other: &Self) -> bool {
        self.now == other.now
    }
}

impl From<AmplitudeTracker> for StagedTracker {
    fn from(now: AmplitudeTracker) -> Self {
        StagedTracker {
            now,
            accel: 0.0,
            velocity: 0.0,
        }
    }
}

impl StagedTracker {
    /// Write down the input of a step of length `h` about to be taken, if it can be taken in
    /// as it is (the tracker's coefficients are for `h` and the input does not switch the
    /// velocity source): true, and [`StagedTracker::commit`] takes it in once the step has
    /// succeeded (a refused step's is overwritten by the next). False: nothing written; the
    /// step's input must be taken in by [`AmplitudeTracker::update`].
    #[inline(always)]
    pub fn stage(&mut self, h: f64, accel: f64, velocity: f64) -> bool {
        let now = &self.now;
        if now.coefficients.h != h || (velocity != 0.0 && !now.measured_v_seen) {
            return false;
        }
        self.accel = accel;
        if now.measured_v_seen {
            self.velocity = velocity;
        }
        true
    }

    /// Take in the input [`StagedTracker::stage`] wrote down.
    #[inline(always)]
    pub fn commit(&mut self) {
        let Coefficients {
            alpha,
            decay,
            decay_m1,
            ..
        } = self.now.coefficients;
        self.now
            .apply(alpha, decay, decay_m1, self.accel, self.velocity);
    }

    /// The tracker.
    pub fn get(&self) -> &AmplitudeTracker {
        &self.now
    }

    /// The tracker, to change it.
    pub fn get_mut(&mut self) -> &mut AmplitudeTracker {
        &mut self.now
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Staged and committed step by step (a refused step's input written down and dropped, the
    /// interval length changing, the host's base.v appearing halfway: those steps taken in by
    /// `update`, as the damper does), the tracker is the one `update` makes, bit for bit.
    #[test]
    fn staged_steps_are_updates() {
        let (tau, leak, prior, w) = (2.2, 0.28, 0.005, 5.9);
        let mut eager = AmplitudeTracker::new(tau, leak, prior, w);
        let mut staged = StagedTracker::from(eager.clone());
        let (mut t, mut taken_in_later) = (0.0, 0);
        for k in 0..2000 {
            let h = [1e-3, 4e-3, 1e-3, 2.5e-3][(k / 300) % 4];
            let accel = -w * w * 0.003 * (w * t).sin();
            let velocity = if k >= 1000 {
                w * 0.003 * (w * t).cos()
            } else {
                0.0
            };
            if k % 97 == 5 {
                // A step the model refuses: written down, never committed.
                let _ = staged.stage(h, 1e3, velocity);
            }
            if staged.stage(h, accel, velocity) {
                staged.commit();
                taken_in_later += 1;
            } else {
                staged.get_mut().update(h, accel, velocity);
            }
            eager.update(h, accel, velocity);
            assert_eq!(staged.get(), &eager, "step {k}");
            assert_eq!(
                staged.get().state().map(f64::to_bits),
                eager.state().map(f64::to_bits),
                "step {k}"
            );
            t += h;
        }
        assert_eq!(
            staged.get().estimate().to_bits(),
            eager.estimate().to_bits()
        );
        // Nearly every step went the staged way; the switch and each new length did not.
        assert!(taken_in_later > 1900, "{taken_in_later}");
    }
}
