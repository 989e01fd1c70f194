//! The defaults of the Model Exchange contract, which a slave that does not offer Model
//! Exchange keeps (Testy in exports/tests.rs, TLD's ShallowWater-only needs): each says it is
//! not offered, or answers what FMI 2.0 asks of an FMU that has nothing to say.

use super::*;
use crate::calls::Phase;
use crate::frame::Experiment;

struct Bare;
impl Continuous for Bare {}

const CONTEXT: Context = Context {
    phase: Phase::ContinuousTimeMode,
    experiment: Experiment {
        tolerance: None,
        start: 0.0,
        stop: None,
    },
    time: 1.5,
};

fn said(reply: Reply) -> String {
    reply.err().map(|e| *e.message).unwrap_or_default()
}

#[test]
fn the_defaults_do_not_offer_model_exchange() {
    let mut bare = Bare;
    assert_eq!(Bare::STATES, 0);
    assert_eq!(Bare::EVENT_INDICATORS, 0);
    assert_eq!(Bare::MODEL_EXCHANGE_NOTE, None);
    assert_eq!(
        bare.offers_model_exchange(),
        Err("this FMU does not offer Model Exchange".into())
    );
    let not = |f: &str| format!("{f}: this FMU does not offer Model Exchange");
    assert_eq!(said(bare.states(&mut [])), not("fmi2GetContinuousStates"));
    assert_eq!(
        said(bare.set_states(&CONTEXT, &[])),
        not("fmi2SetContinuousStates")
    );
    assert_eq!(
        said(bare.derivatives(&CONTEXT, &mut [])),
        not("fmi2GetDerivatives")
    );
    let mut dv = [7.0];
    assert_eq!(
        said(bare.directional_derivative(&CONTEXT, &[1], &[2], &[1.0], &mut dv)),
        "fmi2GetDirectionalDerivative: providesDirectionalDerivative is false"
    );
    assert_eq!(dv, [7.0]);
}

/// Nominals of 1.0 (FMI 2.0, fmi2GetNominalsOfContinuousStates: "a nominal value x_nominal[i]
/// = 1.0 should be returned" when the FMU has none), indicators that never change sign, no
/// event asked for after a step, an event update that changes nothing and plans no time event.
#[test]
fn the_defaults_answer_nothing_happens() {
    let mut bare = Bare;
    let mut nominals = [0.0, -3.0, f64::NAN];
    assert_eq!(bare.nominals(&mut nominals), Ok(Status::Ok));
    assert_eq!(nominals, [1.0; 3]);
    let mut indicators = [f64::NAN; 2];
    assert_eq!(
        bare.event_indicators(&CONTEXT, &mut indicators),
        Ok(Status::Ok)
    );
    assert_eq!(indicators, [1.0; 2]);
    assert_eq!(bare.completed_step(&CONTEXT), Ok(false));
    assert_eq!(
        bare.event_update(&CONTEXT),
        Ok(EventUpdate {
            states_changed: false,
            next_event: None
        })
    );
}
