//! The instance against the FMI 2.0 standard's rules, driven through the exports' generic
//! bodies as a host drives them, with the tests' slave Probe (exports/probe.rs): the log and its
//! switches (2.1.5), fmi2SetupExperiment's arguments (2.1.6), fmi2DoStep's communication points
//! and fmi2LastSuccessfulTime (4.2.2, 4.2.3), FMU states kept to the interface that saved them
//! (2.1.8), and the quick paths of fmi2SetReal and fmi2GetReal held to the state machine.

use std::ffi::CString;

use fmi_sys::fmi2::*;
use log::Level::{Error, Info, Warn};

use super::*;
use crate::exports::probe::{CS_ONLY, K, ME, N, NOTICE_STEP, P, Rig, U, WARNS, Y};
use crate::exports::{fmi2ExitInitializationMode, fmi2Terminate};
use crate::frame::Common;

const OK: fmi2Status = fmi2Status_fmi2OK;
const WARNING: fmi2Status = fmi2Status_fmi2Warning;
const ERROR: fmi2Status = fmi2Status_fmi2Error;
const CS: fmi2Type = fmi2Type_fmi2CoSimulation;
const ME_TYPE: fmi2Type = fmi2Type_fmi2ModelExchange;

fn said(level: log::Level, message: &str) -> (log::Level, String) {
    (level, message.to_string())
}

/// A Co-Simulation instance set up from `start` to `stop` and initialised.
fn running(name: &str, start: f64, stop: Option<f64>) -> Rig<P> {
    let fmu = Rig::new(name, CS, false);
    assert_eq!(fmu.setup(None, start, stop), OK);
    assert_eq!(fmu.initialise(), OK);
    fmu
}

/// loggingOn (fmi2Instantiate, fmi2SetDebugLogging) and the categories decide what is logged:
/// no categories means all of them (FMI 2.0, 2.1.5), logCalls traces every call carried out.
/// Errors and warnings are logged whatever the switches: the host must learn why a call failed
/// or what to mind (each with its status, fmi2Error or fmi2Warning).
#[test]
fn the_log_follows_logging_on_and_the_categories() {
    let fmu = Rig::<P>::new("probe-log", CS, false);
    assert_eq!(fmu.setup(None, 0.0, None), OK);
    assert_eq!(fmu.step(0.0, 1.0), ERROR);
    let logs = fmu.logs();
    assert_eq!(logs.len(), 1, "{logs:?}");
    assert_eq!(logs[0].0, Error);
    assert!(
        logs[0]
            .1
            .starts_with("fmi2DoStep is not allowed in state Instantiated")
    );
    // The instance's own rule, asked directly: a call's trace only when calls are logged.
    fmu.instance().log(Status::Ok, "logCalls", "a trace");
    fmu.instance()
        .log(Status::Warning, "logStatusWarning", "a warning");
    assert_eq!(fmu.logs()[1..], [said(Warn, "a warning")]);

    // Logging on for errors alone: calls carried out are still not traced.
    assert_eq!(fmu.debug_logging(true, &["logStatusError"]), OK);
    assert_eq!(fmu.set_integer(N, WARNS), OK);
    assert_eq!(fmu.logs().len(), 2);
    assert_eq!(fmu.initialise(), WARNING);
    assert_eq!(fmu.logs()[2..], [said(Warn, "n = 4 is approximate")]);

    // logCalls: each call carried out, by name (fmi2SetDebugLogging's own included, since it
    // turned the trace on).
    assert_eq!(fmu.debug_logging(true, &["logCalls"]), OK);
    assert_eq!(fmu.step(0.0, 0.5), OK);
    let traced = [said(Info, "fmi2SetDebugLogging"), said(Info, "fmi2DoStep")];
    assert_eq!(fmu.logs()[3..], traced);

    // Off, no categories: nothing; on, no categories: every category, the trace too.
    assert_eq!(fmu.debug_logging(false, &[]), OK);
    assert_eq!(fmu.step(0.5, 0.5), OK);
    assert_eq!(fmu.logs().len(), 5);
    assert_eq!(fmu.debug_logging(true, &[]), OK);
    assert_eq!(fmu.step(1.0, 0.5), OK);
    assert_eq!(fmu.logs()[5..], traced);

    // An unknown category: fmi2Warning, named with the known ones; the known ones still count.
    assert_eq!(fmu.debug_logging(false, &["logCalls", "nonsense"]), WARNING);
    let warning = "fmi2SetDebugLogging: unknown log categories [\"nonsense\"] ignored (known: \
                   logStatusError, logStatusWarning, logCalls)";
    assert_eq!(fmu.logs()[7..], [said(Warn, warning)]);
    assert_eq!(fmu.step(1.5, 0.5), OK);
    assert_eq!(fmu.logs().len(), 8);

    // loggingOn at fmi2Instantiate: traced from the first call.
    let verbose = Rig::<P>::new("probe-log-on", CS, true);
    assert_eq!(verbose.setup(None, 0.0, None), OK);
    assert_eq!(verbose.logs(), [said(Info, "fmi2SetupExperiment")]);
}

/// fmi2SetReal and fmi2GetReal of one value take the slave's quick path only where the table
/// allows the call and nothing is to be logged: elsewhere they are refused as FMI 2.0 says
/// (fmi2GetReal not in instantiated, fmi2SetReal not in terminated), each refusal logged, and
/// with logCalls every call is traced.
#[test]
fn quick_paths_keep_the_state_machine_and_the_log() {
    let fmu = Rig::<P>::new("probe-quick", CS, false);
    assert_eq!(fmu.get_real(K).0, ERROR);
    assert_eq!(fmu.set_real(U, 3.0), OK);
    assert_eq!(fmu.instance().slave.value_of(U), 3.0);
    assert_eq!(fmu.setup(None, 0.0, None), OK);
    assert_eq!(fmu.initialise(), OK);
    assert_eq!(fmu.get_real(U), (OK, 3.0));
    assert_eq!(fmu.logs().len(), 1);

    assert_eq!(fmu.debug_logging(true, &["logCalls"]), OK);
    assert_eq!(fmu.set_real(U, 4.0), OK);
    assert_eq!(fmu.get_real(U), (OK, 4.0));
    let traced = ["fmi2SetDebugLogging", "fmi2SetReal", "fmi2GetReal"].map(|m| said(Info, m));
    assert_eq!(fmu.logs()[1..], traced);

    assert_eq!(fmu.debug_logging(false, &[]), OK);
    // SAFETY: our live instance.
    assert_eq!(unsafe { fmi2Terminate::<P>(fmu.c) }, OK);
    assert_eq!(fmu.set_real(U, 5.0), ERROR);
    assert_eq!(fmu.instance().slave.value_of(U), 4.0);
    let logs = fmu.logs();
    assert_eq!(logs.len(), 5);
    assert_eq!(logs[4].0, Error);
    assert!(
        logs[4]
            .1
            .starts_with("fmi2SetReal is not allowed in state Terminated")
    );
    assert_eq!(fmu.get_real(U), (OK, 4.0));
}

/// fmi2SetupExperiment (FMI 2.0, 2.1.6) takes a tolerance if defined, startTime and stopTime if
/// defined; a stop at the start is an empty experiment. It refuses (fmi2Error, logged, the
/// experiment kept) a start or stop time that is not finite, a stop before the start, and a
/// tolerance that is not positive and finite. fmi2EnterInitializationMode starts the time at
/// startTime.
#[test]
fn setup_experiment_takes_a_consistent_experiment_and_refuses_the_rest() {
    let fmu = Rig::<P>::new("probe-setup", CS, false);
    let taken = [
        (None, 0.0, None),
        (Some(1e-6), -5.0, Some(10.0)),
        (Some(1e-3), 2.0, Some(2.0)),
    ];
    for (tolerance, start, stop) in taken {
        assert_eq!(fmu.setup(tolerance, start, stop), OK);
        let experiment = frame::Experiment {
            tolerance,
            start,
            stop,
        };
        assert_eq!(fmu.instance().context.experiment, experiment);
    }
    let kept = fmu.instance().context.experiment;
    let inf = f64::INFINITY;
    let refused = [
        (None, f64::NAN, None, "startTime NaN is not finite"),
        (None, inf, None, "startTime inf is not finite"),
        (None, -inf, Some(1.0), "startTime -inf is not finite"),
        (
            None,
            2.0,
            Some(1.999),
            "stopTime 1.999 must be finite and not before startTime 2",
        ),
        (None, 2.0, Some(inf), "stopTime inf must be finite"),
        (None, 2.0, Some(f64::NAN), "stopTime NaN must be finite"),
        (
            Some(0.0),
            2.0,
            None,
            "tolerance 0 must be positive and finite",
        ),
        (
            Some(-1e-6),
            2.0,
            None,
            "tolerance -0.000001 must be positive",
        ),
        (
            Some(inf),
            2.0,
            None,
            "tolerance inf must be positive and finite",
        ),
        (Some(f64::NAN), 2.0, None, "tolerance NaN must be positive"),
    ];
    for (k, (tolerance, start, stop, why)) in refused.into_iter().enumerate() {
        assert_eq!(fmu.setup(tolerance, start, stop), ERROR, "{why}");
        assert_eq!(fmu.instance().context.experiment, kept, "{why}");
        let logs = fmu.logs();
        assert_eq!(logs.len(), k + 1);
        assert_eq!(logs[k].0, Error);
        assert!(
            logs[k].1.starts_with("fmi2SetupExperiment: "),
            "{}",
            logs[k].1
        );
        assert!(logs[k].1.contains(why), "{} lacks {why}", logs[k].1);
    }
    assert_eq!(fmu.initialise(), OK);
    assert_eq!(fmu.last_successful_time(), 2.0);
}

/// fmi2DoStep (FMI 2.0, 4.2.2): a communicationStepSize > 0 from currentCommunicationPoint,
/// the end of the step before; not past the stop time. Every refusal is fmi2Error, logged, and
/// changes nothing: fmi2LastSuccessfulTime (4.2.3) stays the end of the last step taken. A
/// step with a notice of the slave's is fmi2Warning with the notice logged.
#[test]
fn do_step_goes_on_from_the_last_communication_point() {
    let fmu = running("probe-step", 0.0, Some(10.0));
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let refused = [
        (
            0.0,
            0.0,
            "communicationStepSize 0 must be positive and finite",
        ),
        (0.0, -1.0, "communicationStepSize -1 must be positive"),
        (
            0.0,
            inf,
            "communicationStepSize inf must be positive and finite",
        ),
        (0.0, nan, "communicationStepSize NaN must be positive"),
        (nan, 1.0, "currentCommunicationPoint NaN is not finite"),
        (-inf, 1.0, "currentCommunicationPoint -inf is not finite"),
        (
            1.0,
            1.0,
            "currentCommunicationPoint 1 does not match the FMU's time 0",
        ),
        (-0.5, 1.0, "currentCommunicationPoint -0.5 does not match"),
        (0.0, 10.5, "the step to 10.5 would pass the stop time 10"),
    ];
    for (k, (t, h, why)) in refused.into_iter().enumerate() {
        assert_eq!(fmu.step(t, h), ERROR, "{why}");
        assert_eq!(fmu.last_successful_time(), 0.0, "{why}");
        assert_eq!(fmu.instance().slave.steps, 0, "{why}");
        let logs = fmu.logs();
        assert_eq!(logs.len(), k + 1);
        assert_eq!(logs[k].0, Error);
        assert!(logs[k].1.starts_with("fmi2DoStep: "), "{}", logs[k].1);
        assert!(logs[k].1.contains(why), "{} lacks {why}", logs[k].1);
    }
    let n = fmu.logs().len();
    assert_eq!(fmu.step(0.0, 1.0), OK);
    assert_eq!(fmu.last_successful_time(), 1.0);
    assert_eq!(fmu.instance().slave.x[0], 1.0);
    assert_eq!(fmu.step(1.0, NOTICE_STEP), WARNING);
    assert_eq!(fmu.last_successful_time(), 1.25);
    assert_eq!(fmu.logs()[n..], [said(Warn, "a notice at t = 1.25")]);
    // To the stop time exactly, then not a step further.
    assert_eq!(fmu.step(1.25, 8.75), OK);
    assert_eq!(fmu.last_successful_time(), 10.0);
    assert_eq!(fmu.step(10.0, 1e-3), ERROR);
    assert_eq!(fmu.last_successful_time(), 10.0);
    assert_eq!(fmu.instance().slave.steps, 3);
}

/// Hosts add up their communication points with rounding: the FMU takes a point off its time
/// (or a step's end off the stop time) by up to 1e-9 of the time (at least of 1 s) plus 1e-6
/// of the step, and refuses more. Each term checked where it is the one that counts: half of
/// the allowance taken, twice refused.
#[test]
fn do_step_takes_the_hosts_rounding_and_no_more() {
    // (start, stop, the allowance's term that counts, h): about 1e6 s, where 1e-9 of the time
    // is 1 ms; and at 0 s with a step of 100 s, where 1e-6 of the step is 0.1 ms.
    for (start, h, allowance) in [(1e6, 1e-3, 1e-3), (0.0, 100.0, 1e-4)] {
        for (factor, expected) in [(0.5, OK), (2.0, ERROR)] {
            let name = format!("probe-slack-{start}-{factor}");
            let fmu = running(&name, start, None);
            let t = start + factor * allowance;
            assert_eq!(fmu.step(t, h), expected, "{name}");
            let end = if expected == OK { t + h } else { start };
            assert_eq!(fmu.last_successful_time(), end, "{name}");
        }
    }
    // "Up to": at 0 s (where the difference is exact) a point off by the allowance itself.
    let fmu = running("probe-slack-exact", 0.0, None);
    let allowance = 1e-9 * 1.0 + 1e-6 * 100.0;
    assert_eq!(fmu.step(allowance, 100.0), OK);
    // The stop time: a last step that ends past it by less than the allowance ends there.
    for (stop, h, allowance) in [(1e6, 1.0, 1e-3), (100.0, 100.0, 1e-4)] {
        for (factor, expected) in [(0.5, OK), (2.0, ERROR)] {
            let name = format!("probe-stop-{stop}-{factor}");
            let start = stop - h;
            let fmu = running(&name, start, Some(stop));
            assert_eq!(fmu.step(start, h + factor * allowance), expected, "{name}");
        }
    }
}

/// FMU states (FMI 2.0, 2.1.8) restore into an instance of the interface that saved them: a
/// Co-Simulation state in stepComplete means nothing to Model Exchange and a running Model
/// Exchange state nothing to Co-Simulation. States from before initialisation go into either;
/// a terminated one into Model Exchange only if Model Exchange offers its model, and so for any
/// running Model Exchange state (a forged one too: the coverage-guided fuzzer's finding).
/// fmi2DeSerializeFMUstate already refuses what fmi2SetFMUstate would.
#[test]
fn states_restore_into_the_interface_that_saved_them() {
    let cs = Rig::<P>::new("probe-state-cs", CS, false);
    let me = Rig::<P>::new("probe-state-me", ME_TYPE, false);
    assert_eq!(cs.set_real(U, 3.0), OK);
    assert_eq!(cs.set_integer(N, CS_ONLY), OK);
    let cs_only_instantiated = cs.saved();
    assert_eq!(cs.set_integer(N, ME), OK);
    let instantiated = cs.saved();
    assert_eq!(me.restore(&cs_only_instantiated), (OK, Some(OK)));
    assert_eq!(me.instance().slave.value_of(N), f64::from(CS_ONLY));
    assert_eq!(me.restore(&instantiated), (OK, Some(OK)));
    assert_eq!(me.instance().slave.value_of(U), 3.0);
    assert_eq!(me.instance().phase(), Phase::Instantiated);

    assert_eq!(cs.setup(None, 0.0, None), OK);
    assert_eq!(cs.initialise(), OK);
    assert_eq!(cs.step(0.0, 1.0), OK);
    let stepped = cs.saved();
    assert_eq!(me.setup(None, 0.0, None), OK);
    assert_eq!(me.initialise(), OK);
    assert_eq!(me.instance().phase(), Phase::EventMode);
    let event_mode = me.saved();

    let refused = |fmu: &Rig<P>, bytes: &[u8], why: &str| {
        assert_eq!(fmu.restore(bytes), (ERROR, None), "{why}");
        let logs = fmu.logs();
        let (level, message) = logs.last().unwrap();
        assert_eq!(*level, Error);
        assert!(
            message.starts_with("fmi2DeSerializeFMUstate: "),
            "{message}"
        );
        assert!(message.contains(why), "{message} lacks {why}");
    };
    refused(&me, &stepped, "it was saved by a Co-Simulation instance");
    refused(
        &cs,
        &event_mode,
        "it was saved by a Model Exchange instance",
    );
    assert_eq!(me.instance().phase(), Phase::EventMode);
    assert_eq!(cs.instance().phase(), Phase::StepComplete);
    assert_eq!(cs.step(1.0, 1.0), OK);
    assert_eq!(cs.restore(&stepped), (OK, Some(OK)));
    assert_eq!(cs.last_successful_time(), 1.0);
    assert_eq!(me.restore(&event_mode), (OK, Some(OK)));

    // Terminated: a Co-Simulation-only model's state goes into Co-Simulation alone.
    let cs_only = Rig::<P>::new("probe-state-cs-only", CS, false);
    assert_eq!(cs_only.set_integer(N, CS_ONLY), OK);
    assert_eq!(cs_only.setup(None, 0.0, None), OK);
    assert_eq!(cs_only.initialise(), OK);
    // SAFETY: live instances.
    unsafe {
        assert_eq!(fmi2Terminate::<P>(cs_only.c), OK);
        assert_eq!(fmi2Terminate::<P>(me.c), OK);
    }
    let terminated_cs_only = cs_only.saved();
    let offered = "Model Exchange is not offered for its parameters: n = 1 runs in \
                   Co-Simulation only";
    refused(&me, &terminated_cs_only, offered);
    assert_eq!(cs.restore(&terminated_cs_only), (OK, Some(OK)));
    assert_eq!(cs.instance().phase(), Phase::Terminated);
    let terminated_me = me.saved();
    assert_eq!(me.restore(&terminated_me), (OK, Some(OK)));

    // A made-up Event Mode state of the Co-Simulation-only model.
    let common = Common {
        phase: Phase::EventMode,
        experiment: frame::Experiment::default(),
        time: 0.0,
        flag: false,
    };
    let cs_only_slave = P::new().with(N, f64::from(CS_ONLY));
    let forged = frame::encode(&P::STATE_TAG, P::STATE_VERSION, "{probe}", &common, |out| {
        cs_only_slave.save(out)
    });
    refused(&me, &forged, offered);
    assert_eq!(me.instance().phase(), Phase::Terminated);
}

/// A state the frame and the slave accept can still hold values whose outputs overflow (the
/// fuzzer's finding 5; here y = k u = 2 * 1e308): refused, naming the variable, since nothing
/// that is not finite may leave through fmi2GetReal. The same state with finite outputs is
/// taken, and the Integer, Enumeration and Boolean variables are not read as Reals.
#[test]
fn a_state_whose_outputs_overflow_is_refused() {
    let fmu = running("probe-overflow", 0.0, None);
    let common = Common {
        phase: Phase::StepComplete,
        experiment: frame::Experiment::default(),
        time: 0.0,
        flag: false,
    };
    let state = |u: f64| {
        frame::encode(&P::STATE_TAG, P::STATE_VERSION, "{probe}", &common, |out| {
            P::new().with(U, u).save(out)
        })
    };
    assert_eq!(fmu.restore(&state(1e308)), (ERROR, None));
    let logs = fmu.logs();
    assert_eq!(logs.len(), 1);
    assert!(
        logs[0]
            .1
            .ends_with("is not usable: its values give y = inf"),
        "{logs:?}"
    );
    assert_eq!(fmu.instance().slave.value_of(U), 0.0);
    assert_eq!(fmu.restore(&state(1e300)), (OK, Some(OK)));
    assert_eq!(fmu.get_real(Y), (OK, 2e300));
}

/// A Model Exchange instance of a model Model Exchange does not offer: fmi2ExitInitializationMode
/// refuses it, undoes the initialisation and leaves the instance in Initialization Mode, where
/// the host may choose another model.
#[test]
fn model_exchange_of_a_model_not_offered_stays_in_initialization_mode() {
    let fmu = Rig::<P>::new("probe-me-refused", ME_TYPE, false);
    assert_eq!(fmu.set_integer(N, CS_ONLY), OK);
    assert_eq!(fmu.setup(None, 0.0, None), OK);
    assert_eq!(fmu.initialise(), ERROR);
    assert_eq!(fmu.instance().phase(), Phase::InitializationMode);
    assert_eq!(fmu.instance().slave.undone, 1);
    let logs = fmu.logs();
    assert!(
        logs[0]
            .1
            .ends_with("not offered for these parameters: n = 1 runs in Co-Simulation only")
    );
    assert_eq!(fmu.set_integer(N, ME), OK);
    // SAFETY: our live instance.
    assert_eq!(unsafe { fmi2ExitInitializationMode::<P>(fmu.c) }, OK);
    assert_eq!(fmu.instance().phase(), Phase::EventMode);
}

/// fmi2FreeInstance wipes the instance's mark before its memory goes back, so that a pointer
/// to it is no longer taken for an instance: checked here on live memory, after `unmark`.
#[test]
fn an_unmarked_instance_is_not_taken_for_one() {
    let logger = crate::logger::Logger::new(None, std::ptr::null_mut());
    let name = CString::new("probe-unmarked").unwrap();
    let mut inst = Box::new(Instance::<P>::new(name, logger, false, Kind::CoSimulation));
    let p = (&mut *inst as *mut Instance<P>).cast();
    // SAFETY: a live instance, then the same memory unmarked.
    unsafe {
        assert!(Instance::<P>::from_ptr(p).is_some());
        inst.unmark();
        assert!(Instance::<P>::from_ptr(p).is_none());
    }
}
