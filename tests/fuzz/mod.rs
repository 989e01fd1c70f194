//! The call-sequence fuzzer's engine, shared by the fuzz tests of every FMU of the workspace
//! (tests/fuzz_calls.rs for TLD.fmu, building/tests/fuzz_calls.rs for Building.fmu): random
//! sequences of FMI 2.0 calls with random arguments (illegal orders, NaN/Inf, zero, negative and
//! huge steps, unknown value references, null pointers, corrupted states, repeated
//! terminate/reset) against the built library.
//!
//! Invariants, checked after every call:
//! - the process survives and every status is a valid fmi2Status (OK..Error; never Fatal);
//! - a refused call (fmi2Error or fmi2Discard) leaves the instance exactly as it was: its
//!   serialised state, which holds every variable, the time and the simulation state, is
//!   byte-for-byte the one before the call.
//!
//! Each sequence runs on a Co-Simulation or a Model Exchange instance (drawn), and the calls
//! include Model Exchange's (time, states, derivatives, nominals, event indicators, event and
//! continuous-time modes, completed steps, directional derivatives).
//!
//! The number of sequences is bounded for CI (PROPTEST_CASES overrides it) and printed.
//!
//! The instances are the workspace's raw test host's (tests/fmi_host), which every fuzz test
//! loads its FMU with and names at its root (`Instance`, `OK`, ...).

use super::{DISCARD, ERROR, Instance, OK};
use fmi_sys::fmi2::*;
use proptest::prelude::*;
use std::ffi::CString;
use std::sync::atomic::{AtomicU64, Ordering};

/// What the fuzzer needs of an FMU besides its library: its value references, an output to read.
pub struct Target {
    pub value_references: Vec<u32>,
    pub output: u32,
    /// Continuous states the model description declares (Model Exchange).
    pub states: usize,
}

const SEQUENCES: u32 = 2000;

static CALLS: AtomicU64 = AtomicU64::new(0);
static REFUSED: AtomicU64 = AtomicU64::new(0);

#[derive(Clone, Debug)]
pub enum Arg {
    Valid,
    Null,
}

#[derive(Clone, Debug)]
pub enum Call {
    Setup {
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    },
    Enter,
    Exit,
    Terminate,
    Reset,
    SetReal {
        vrs: Vec<u32>,
        values: Vec<f64>,
        ptr: Arg,
    },
    SetInteger {
        vrs: Vec<u32>,
        values: Vec<i32>,
    },
    SetBoolean {
        vrs: Vec<u32>,
    },
    SetString {
        vrs: Vec<u32>,
    },
    GetReal {
        vrs: Vec<u32>,
        ptr: Arg,
    },
    GetInteger {
        vrs: Vec<u32>,
    },
    GetBoolean {
        vrs: Vec<u32>,
    },
    GetString {
        vrs: Vec<u32>,
    },
    DoStep {
        offset: f64,
        h: f64,
    },
    Logging {
        on: bool,
        categories: Vec<String>,
    },
    SaveState,
    RestoreState {
        corrupt: Option<usize>,
    },
    FreeState,
    InputDerivative {
        vr: u32,
        order: i32,
        value: f64,
    },
    OutputDerivative {
        vr: u32,
        order: i32,
    },
    Status {
        kind: u32,
    },
    CancelStep,
    ModelExchange,
    NullInstance,
    SetTime {
        t: f64,
    },
    SetStates {
        values: Vec<f64>,
    },
    /// 0: fmi2GetContinuousStates, 1: fmi2GetDerivatives, 2: fmi2GetNominalsOfContinuousStates,
    /// 3: fmi2GetEventIndicators, of `n` values.
    StateQuery {
        which: u8,
        n: usize,
    },
    EventMode,
    NewDiscreteStates,
    ContinuousTimeMode,
    CompletedStep,
    Directional {
        unknown: u32,
        known: u32,
        dv: f64,
    },
}

fn value_reference(known: Vec<u32>) -> impl Strategy<Value = u32> {
    prop_oneof![8 => proptest::sample::select(known), 1 => Just(7u32), 1 => Just(9999u32), 1 => Just(u32::MAX)]
}

fn real() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -10.0..10.0f64,
        1 => proptest::sample::select(vec![
            0.0, -0.0, 1.0, -1.0, 0.25, 2.0, 1e-3, 1e-300, -1e-300, 1e300, -1e300,
            f64::NAN, f64::INFINITY, f64::NEG_INFINITY, f64::MIN_POSITIVE, f64::MAX,
        ]),
    ]
}

fn step() -> impl Strategy<Value = f64> {
    prop_oneof![
        6 => proptest::sample::select(vec![1e-3, 0.01, 0.05, 0.3]),
        1 => proptest::sample::select(vec![0.0, -0.01, f64::NAN, f64::INFINITY, 1e-12, 1e6, 5.0]),
    ]
}

fn call(known: Vec<u32>, states: usize) -> impl Strategy<Value = Call> {
    let vr = move || value_reference(known.clone());
    let bad = || proptest::sample::select(vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300]);
    let small = move || prop_oneof![30 => -0.05..0.05f64, 1 => real(), 1 => bad()];
    let lengths = move || prop_oneof![8 => Just(states), 1 => 0..states + 2];
    let vrs = || proptest::collection::vec(vr(), 0..4);
    let ptr = || prop_oneof![9 => Just(Arg::Valid), 1 => Just(Arg::Null)];
    prop_oneof![
        2 => (proptest::option::of(real()), real(), proptest::option::of(real()))
            .prop_map(|(tolerance, start, stop)| Call::Setup { tolerance, start, stop }),
        3 => Just(Call::Enter),
        3 => Just(Call::Exit),
        1 => Just(Call::Terminate),
        1 => Just(Call::Reset),
        6 => (vrs(), proptest::collection::vec(real(), 4), ptr())
            .prop_map(|(vrs, values, ptr)| Call::SetReal { vrs, values, ptr }),
        2 => (vrs(), proptest::collection::vec(-3..1000i32, 4)).prop_map(|(vrs, values)| Call::SetInteger { vrs, values }),
        1 => vrs().prop_map(|vrs| Call::SetBoolean { vrs }),
        1 => vrs().prop_map(|vrs| Call::SetString { vrs }),
        3 => (vrs(), ptr()).prop_map(|(vrs, ptr)| Call::GetReal { vrs, ptr }),
        1 => vrs().prop_map(|vrs| Call::GetInteger { vrs }),
        1 => vrs().prop_map(|vrs| Call::GetBoolean { vrs }),
        1 => vrs().prop_map(|vrs| Call::GetString { vrs }),
        8 => (prop_oneof![9 => Just(0.0), 1 => real()], step()).prop_map(|(offset, h)| Call::DoStep { offset, h }),
        1 => (any::<bool>(), proptest::collection::vec(
                proptest::sample::select(vec!["logCalls", "logStatusError", "%s%n", "", "logAll"]), 0..3))
            .prop_map(|(on, c)| Call::Logging { on, categories: c.into_iter().map(String::from).collect() }),
        2 => Just(Call::SaveState),
        2 => proptest::option::of(0usize..400).prop_map(|corrupt| Call::RestoreState { corrupt }),
        1 => Just(Call::FreeState),
        2 => (vr(), -1..4i32, real()).prop_map(|(vr, order, value)| Call::InputDerivative { vr, order, value }),
        1 => (vr(), -1..3i32).prop_map(|(vr, order)| Call::OutputDerivative { vr, order }),
        1 => (0..5u32).prop_map(|kind| Call::Status { kind }),
        1 => Just(Call::CancelStep),
        1 => Just(Call::ModelExchange),
        1 => Just(Call::NullInstance),
        3 => prop_oneof![6 => 0.0..1.0f64, 1 => real(), 1 => bad()].prop_map(|t| Call::SetTime { t }),
        4 => lengths().prop_flat_map(move |n| proptest::collection::vec(small(), n))
            .prop_map(|values| Call::SetStates { values }),
        4 => (0..4u8, lengths()).prop_map(|(which, n)| Call::StateQuery { which, n }),
        2 => Just(Call::EventMode),
        2 => Just(Call::NewDiscreteStates),
        3 => Just(Call::ContinuousTimeMode),
        2 => Just(Call::CompletedStep),
        1 => (vr(), vr(), real()).prop_map(|(unknown, known, dv)| Call::Directional { unknown, known, dv }),
    ]
}

/// The instance's complete serialised state (the observer: fmi2GetFMUstate is allowed in every
/// state and is itself checked by the round-trip tests).
fn fingerprint(inst: &Instance) -> Vec<u8> {
    inst.serialised()
}

struct Fuzz {
    inst: Instance,
    output: u32,
    saved: Option<Vec<u8>>,
    state: fmi2FMUstate,
}

impl Fuzz {
    fn perform(&mut self, call: &Call) -> fmi2Status {
        let (lib, c) = (self.inst.lib, self.inst.c);
        let t = {
            let mut t = 0.0;
            // The FMU's own time when it has one; 0 otherwise.
            unsafe { lib.fmi2GetRealStatus(c, fmi2StatusKind_fmi2LastSuccessfulTime, &mut t) };
            t
        };
        unsafe {
            match call {
                Call::Setup {
                    tolerance,
                    start,
                    stop,
                } => lib.fmi2SetupExperiment(
                    c,
                    i32::from(tolerance.is_some()),
                    tolerance.unwrap_or(0.0),
                    *start,
                    i32::from(stop.is_some()),
                    stop.unwrap_or(0.0),
                ),
                Call::Enter => lib.fmi2EnterInitializationMode(c),
                Call::Exit => lib.fmi2ExitInitializationMode(c),
                Call::Terminate => lib.fmi2Terminate(c),
                Call::Reset => lib.fmi2Reset(c),
                Call::SetReal { vrs, values, ptr } => match ptr {
                    Arg::Valid => lib.fmi2SetReal(c, vrs.as_ptr(), vrs.len(), values.as_ptr()),
                    Arg::Null => lib.fmi2SetReal(c, vrs.as_ptr(), vrs.len(), std::ptr::null()),
                },
                Call::SetInteger { vrs, values } => {
                    lib.fmi2SetInteger(c, vrs.as_ptr(), vrs.len(), values.as_ptr())
                }
                Call::SetBoolean { vrs } => {
                    lib.fmi2SetBoolean(c, vrs.as_ptr(), vrs.len(), [1i32; 4].as_ptr())
                }
                Call::SetString { vrs } => {
                    let s = CString::new("text").unwrap();
                    let p = [s.as_ptr(); 4];
                    lib.fmi2SetString(c, vrs.as_ptr(), vrs.len(), p.as_ptr())
                }
                Call::GetReal { vrs, ptr } => {
                    let mut out = [0.0; 4];
                    match ptr {
                        Arg::Valid => lib.fmi2GetReal(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()),
                        Arg::Null => {
                            lib.fmi2GetReal(c, std::ptr::null(), vrs.len(), out.as_mut_ptr())
                        }
                    }
                }
                Call::GetInteger { vrs } => {
                    lib.fmi2GetInteger(c, vrs.as_ptr(), vrs.len(), [0i32; 4].as_mut_ptr())
                }
                Call::GetBoolean { vrs } => {
                    lib.fmi2GetBoolean(c, vrs.as_ptr(), vrs.len(), [0i32; 4].as_mut_ptr())
                }
                Call::GetString { vrs } => lib.fmi2GetString(
                    c,
                    vrs.as_ptr(),
                    vrs.len(),
                    [std::ptr::null(); 4].as_mut_ptr(),
                ),
                Call::DoStep { offset, h } => lib.fmi2DoStep(c, t + offset, *h, 0),
                Call::Logging { on, categories } => {
                    let owned: Vec<CString> = categories
                        .iter()
                        .map(|s| CString::new(s.as_str()).unwrap())
                        .collect();
                    let ptrs: Vec<*const std::ffi::c_char> =
                        owned.iter().map(|s| s.as_ptr()).collect();
                    lib.fmi2SetDebugLogging(c, i32::from(*on), ptrs.len(), ptrs.as_ptr())
                }
                Call::SaveState => {
                    let status = lib.fmi2GetFMUstate(c, &mut self.state);
                    if status == OK {
                        self.saved = Some(fingerprint(&self.inst));
                    }
                    status
                }
                Call::RestoreState { corrupt: None } => lib.fmi2SetFMUstate(c, self.state),
                Call::RestoreState { corrupt: Some(at) } => {
                    // A serialised state, corrupted at one byte, deserialised into a new state.
                    let mut bytes = self.saved.clone().unwrap_or_else(|| vec![0u8; 8]);
                    let n = bytes.len();
                    bytes[at % n] ^= 0x21;
                    let mut s: fmi2FMUstate = std::ptr::null_mut();
                    let status = lib.fmi2DeSerializeFMUstate(
                        c,
                        bytes.as_ptr() as *const fmi2Byte,
                        n,
                        &mut s,
                    );
                    lib.fmi2FreeFMUstate(c, &mut s);
                    status
                }
                Call::FreeState => {
                    let status = lib.fmi2FreeFMUstate(c, &mut self.state);
                    self.saved = None;
                    status
                }
                Call::InputDerivative { vr, order, value } => {
                    lib.fmi2SetRealInputDerivatives(c, vr, 1, order, value)
                }
                Call::OutputDerivative { vr, order } => {
                    let mut out = 0.0;
                    lib.fmi2GetRealOutputDerivatives(c, vr, 1, order, &mut out)
                }
                Call::Status { kind } => {
                    let (mut r, mut i, mut b, mut s, mut st) =
                        (0.0, 0i32, 0i32, std::ptr::null(), 0u32);
                    let all = [
                        lib.fmi2GetStatus(c, *kind, &mut st),
                        lib.fmi2GetRealStatus(c, *kind, &mut r),
                        lib.fmi2GetIntegerStatus(c, *kind, &mut i),
                        lib.fmi2GetBooleanStatus(c, *kind, &mut b),
                        lib.fmi2GetStringStatus(c, *kind, &mut s),
                    ];
                    *all.iter().max().unwrap_or(&OK)
                }
                Call::CancelStep => lib.fmi2CancelStep(c),
                // Two states: the wrong number for every FMU here (refused in every phase).
                Call::ModelExchange => {
                    let mut x = [0.0; 2];
                    lib.fmi2GetContinuousStates(c, x.as_mut_ptr(), 2)
                }
                Call::SetTime { t } => lib.fmi2SetTime(c, *t),
                Call::SetStates { values } => {
                    lib.fmi2SetContinuousStates(c, values.as_ptr(), values.len())
                }
                Call::StateQuery { which, n } => {
                    let mut out = vec![0.0; *n];
                    let p = out.as_mut_ptr();
                    match which {
                        0 => lib.fmi2GetContinuousStates(c, p, *n),
                        1 => lib.fmi2GetDerivatives(c, p, *n),
                        2 => lib.fmi2GetNominalsOfContinuousStates(c, p, *n),
                        _ => lib.fmi2GetEventIndicators(c, p, *n),
                    }
                }
                Call::EventMode => lib.fmi2EnterEventMode(c),
                Call::NewDiscreteStates => {
                    let mut info = fmi2EventInfo {
                        newDiscreteStatesNeeded: 0,
                        terminateSimulation: 0,
                        nominalsOfContinuousStatesChanged: 0,
                        valuesOfContinuousStatesChanged: 0,
                        nextEventTimeDefined: 0,
                        nextEventTime: 0.0,
                    };
                    lib.fmi2NewDiscreteStates(c, &mut info)
                }
                Call::ContinuousTimeMode => lib.fmi2EnterContinuousTimeMode(c),
                Call::CompletedStep => {
                    let (mut enter, mut terminate) = (0, 0);
                    lib.fmi2CompletedIntegratorStep(c, 1, &mut enter, &mut terminate)
                }
                Call::Directional { unknown, known, dv } => {
                    let mut out = 0.0;
                    lib.fmi2GetDirectionalDerivative(c, unknown, 1, known, 1, dv, &mut out)
                }
                Call::NullInstance => {
                    lib.fmi2DoStep(std::ptr::null_mut(), 0.0, 0.01, 0)
                        .max(lib.fmi2GetReal(
                            std::ptr::null_mut(),
                            &self.output,
                            1,
                            [0.0].as_mut_ptr(),
                        ))
                }
            }
        }
    }
}

impl Drop for Fuzz {
    fn drop(&mut self) {
        let (lib, c) = (self.inst.lib, self.inst.c);
        unsafe { lib.fmi2FreeFMUstate(c, &mut self.state) };
    }
}

/// Runs the fuzzer on `target`; each sequence starts with one drawn from `prefix` (the
/// parameters that make instances differ, and how far into initialisation it starts).
pub fn run(target: Target, prefix: impl Strategy<Value = Vec<Call>>) {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(SEQUENCES);
    let config = ProptestConfig {
        cases,
        failure_persistence: None,
        ..ProptestConfig::default()
    };
    let mut runner = proptest::test_runner::TestRunner::new(config);
    let known = target.value_references.clone();
    let sequences = (
        any::<bool>(),
        prefix,
        proptest::collection::vec(call(known, target.states), 1..40),
    )
        .prop_map(|(me, mut p, rest)| {
            p.extend(rest);
            (me, p)
        });
    let result = runner.run(&sequences, |(me, calls)| {
        let fmu_type = if me {
            fmi2Type_fmi2ModelExchange
        } else {
            fmi2Type_fmi2CoSimulation
        };
        let mut fuzz = Fuzz {
            inst: Instance::of_type("fuzz", fmu_type),
            output: target.output,
            saved: None,
            state: std::ptr::null_mut(),
        };
        for call in &calls {
            let before = fingerprint(&fuzz.inst);
            let status = fuzz.perform(call);
            CALLS.fetch_add(1, Ordering::Relaxed);
            prop_assert!(status <= ERROR, "{call:?} returned {status}");
            if status == ERROR || status == DISCARD {
                REFUSED.fetch_add(1, Ordering::Relaxed);
                if !matches!(call, Call::NullInstance) {
                    prop_assert_eq!(
                        &before,
                        &fingerprint(&fuzz.inst),
                        "refused {:?} changed the instance",
                        call
                    );
                }
            }
        }
        Ok(())
    });
    eprintln!(
        "fuzz: {cases} random call sequences, {} FMI calls, {} of them refused (fmi2Error/fmi2Discard), invariants held: {}",
        CALLS.load(Ordering::Relaxed),
        REFUSED.load(Ordering::Relaxed),
        result.is_ok()
    );
    if let Err(e) = result {
        panic!("{e}");
    }
}

/// The prefixes of the sequences: the call `parameters` draws (setting what makes instances
/// differ), then a third of them initialised, a third in initialisation mode, so that the calls
/// reach every state, not mostly the first.
pub fn starting_with(parameters: impl Strategy<Value = Call>) -> impl Strategy<Value = Vec<Call>> {
    (0..3usize, parameters).prop_map(|(depth, parameters)| {
        let mut calls = vec![parameters];
        calls.extend(initialisation(depth));
        calls
    })
}

/// The calls that take a new instance `depth` steps into initialisation: 0 none, 1 into
/// initialisation mode, 2 initialised.
pub fn initialisation(depth: usize) -> Vec<Call> {
    let mut calls = Vec::new();
    if depth >= 1 {
        calls.push(Call::Setup {
            tolerance: None,
            start: 0.0,
            stop: None,
        });
        calls.push(Call::Enter);
    }
    if depth == 2 {
        calls.push(Call::Exit);
    }
    calls
}
