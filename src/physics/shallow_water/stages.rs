//! The time stepping of the shallow-water scheme: the stages of SSPRK(10,4) as a table.

/// SSPRK(10,4) of Ketcheson (2008): ten forward-Euler stages of dt/6 (SSP coefficient 6:
/// positivity up to six times the forward-Euler step, 0.6 of it per stage against SSPRK3's
/// 1/3), fourth order, every stage weighted 1/10. Stages 1-5 march from U0; after the fifth,
/// U1 = 3/5 U0 + 2/5 U1 (= U0 + (2/3) A, A the weighted sum of the rates so far); stages
/// 6-9 march on; the tenth only adds its rate: U = U0 + A.
pub(super) const RATIO: f64 = 6.0;
/// A's share in register 1 when it restarts from U0 after the fifth stage.
const RESTART_SHARE: f64 = 2.0 / 3.0;

/// A stage: its time in the substep and how far it moves register 1 (fractions of dt), and
/// its weight in the substep (and in its quadrature of the impulse and the work: fourth
/// order, so a cubic's integral is exact).
#[derive(Clone, Copy, Debug)]
pub(super) struct Stage {
    pub(super) at: f64,
    pub(super) ahead: f64,
    pub(super) weight: f64,
    /// Register 1 after the stage is U0 + share A instead ([`super::scheme::March::restart`]).
    pub(super) restart: Option<f64>,
}

const fn stage(at: f64, ahead: f64) -> Stage {
    Stage {
        at,
        ahead,
        weight: 0.1,
        restart: None,
    }
}

/// A stage after which register 1 is U0 + share A.
const fn restart(at: f64, share: f64) -> Stage {
    Stage {
        restart: Some(share),
        ..stage(at, 0.0)
    }
}

/// Right-hand sides per substep.
pub const STAGE_COUNT: u64 = STAGES.len() as u64;

pub(super) const STAGES: [Stage; 10] = [
    stage(0.0, 1.0 / 6.0),
    stage(1.0 / 6.0, 1.0 / 6.0),
    stage(2.0 / 6.0, 1.0 / 6.0),
    stage(3.0 / 6.0, 1.0 / 6.0),
    // Register 1 restarts from U0 after the fifth stage: U0 + (2/3) A.
    restart(4.0 / 6.0, RESTART_SHARE),
    stage(1.0 / 3.0, 1.0 / 6.0),
    stage(1.0 / 2.0, 1.0 / 6.0),
    stage(2.0 / 3.0, 1.0 / 6.0),
    stage(5.0 / 6.0, 1.0 / 6.0),
    // The tenth only adds its rate: U = U0 + A.
    restart(1.0, 1.0),
];
