//! The call-sequence target: bytes decode (through `arbitrary`) to an instance (Model Exchange or
//! Co-Simulation, logging on or off, parameters set as Integers, 0 to 2 steps into
//! initialisation) and up to `MAX_CALLS` calls of every fmi2 entry point a host can make on an
//! instance, Model Exchange's included, with arguments a host may hand over: unknown value
//! references, NaN, infinities, huge and negative steps, wrong lengths, null pointers,
//! corrupted states. Each call is checked by `Run::perform_checked` (the invariants: lib.rs).

use std::ffi::{CString, c_char};

use arbitrary::{Arbitrary, Unstructured};
use fmi_sys::fmi2::*;
use fmi2_slave::Slave;
use fmi2_slave::description::VarType;
use fmi2_slave::exports as fmi;

use super::{ERROR, Host, OK, assert_valid_status, logged, refused};
pub use crate::arguments::*;

const MAX_CALLS: usize = 64;

/// One call of an fmi2 entry point on the instance (or, `NullInstance`, on none).
#[derive(Arbitrary, Clone, Debug)]
pub enum Call {
    Setup {
        tolerance: Option<Real>,
        start: Real,
        stop: Option<Real>,
    },
    Enter,
    Exit,
    Terminate,
    Reset,
    SetReal {
        vrs: Vec<Vr>,
        values: Vec<Real>,
        null: bool,
    },
    SetInteger {
        vrs: Vec<Vr>,
        values: Vec<Int>,
    },
    SetBoolean {
        vrs: Vec<Vr>,
        values: Vec<i32>,
    },
    SetString {
        vrs: Vec<Vr>,
        text: String,
        null: bool,
    },
    GetReal {
        vrs: Vec<Vr>,
        null: bool,
    },
    GetInteger {
        vrs: Vec<Vr>,
    },
    GetBoolean {
        vrs: Vec<Vr>,
    },
    GetString {
        vrs: Vec<Vr>,
    },
    DoStep {
        /// Offset of the communication point from the FMU's time (`None`: none).
        offset: Option<Real>,
        h: Step,
        no_set_prior: bool,
    },
    CancelStep,
    Logging {
        on: bool,
        categories: Vec<u8>,
    },
    Status {
        kind: u8,
        which: u8,
    },
    InputDerivatives {
        vrs: Vec<Vr>,
        orders: Vec<Int>,
        values: Vec<Real>,
    },
    OutputDerivatives {
        vrs: Vec<Vr>,
        orders: Vec<Int>,
    },
    GetState,
    SetState,
    FreeState,
    /// The host's state serialised, `corrupt` (position, xor) applied, deserialised and set.
    SerialisedState {
        corrupt: Option<(u16, u8)>,
    },
    SetTime {
        t: Real,
    },
    SetStates {
        values: Vec<Real>,
        len: Len,
    },
    /// 0: fmi2GetContinuousStates, 1: fmi2GetDerivatives, 2: fmi2GetNominalsOfContinuousStates,
    /// 3: fmi2GetEventIndicators.
    Query {
        which: u8,
        len: Len,
    },
    EnterEventMode,
    NewDiscreteStates,
    EnterContinuousTimeMode,
    CompletedIntegratorStep {
        no_set_prior: bool,
    },
    Directional {
        unknowns: Vec<Vr>,
        knowns: Vec<Vr>,
        dv: Vec<Real>,
    },
    NullInstance,
}

/// How an input starts: the instance, then parameters set before initialisation.
#[derive(Arbitrary, Debug)]
pub struct Start {
    model_exchange: bool,
    logging_on: bool,
    depth: u8,
    parameters: Vec<(Vr, Int)>,
}

/// The calls made on an instance a fuzzed state was just loaded into (the deserialise target):
/// whatever the state holds, stepping, integrating and reading it keep the invariants.
pub fn after_load<S: Slave>() -> Vec<Call> {
    let all = |n: u8| (0..n).map(Vr::Known).collect::<Vec<_>>();
    let reals: Vec<Vr> = (0..=u8::MAX)
        .zip(S::TABLE.variables)
        .filter(|(_, v)| v.ty == VarType::Real)
        .map(|(i, _)| Vr::Known(i))
        .collect();
    let mut calls = vec![
        Call::GetReal {
            vrs: reals.clone(),
            null: false,
        },
        Call::Status { kind: 2, which: 1 },
    ];
    for which in 0..4 {
        calls.push(Call::Query {
            which,
            len: Len::Right,
        });
    }
    calls.extend([
        Call::Directional {
            unknowns: all(8),
            knowns: all(8),
            dv: vec![Real::Special(2); 8],
        },
        Call::CompletedIntegratorStep { no_set_prior: true },
        Call::NewDiscreteStates,
        Call::EnterContinuousTimeMode,
        Call::SetTime { t: Real::Milli(10) },
        Call::Query {
            which: 1,
            len: Len::Right,
        },
        Call::EnterEventMode,
        Call::NewDiscreteStates,
        Call::DoStep {
            offset: Some(Real::Milli(0)),
            h: Step::Usual(1),
            no_set_prior: false,
        },
        Call::GetReal {
            vrs: reals,
            null: false,
        },
        Call::OutputDerivatives {
            vrs: all(8),
            orders: vec![Int::Small(1); 8],
        },
        Call::Terminate,
        Call::Reset,
    ]);
    calls
}

/// The call-sequence target.
pub fn calls<S: Slave>(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let Ok(start) = Start::arbitrary(&mut u) else {
        return;
    };
    let mut run = Run::new(Host::<S>::new(start.model_exchange, start.logging_on));
    let (vrs, values): (Vec<Vr>, Vec<Int>) = start.parameters.into_iter().take(4).unzip();
    run.perform_checked(&Call::SetInteger { vrs, values });
    run.host.initialise(start.depth % 3);
    for _ in 0..MAX_CALLS {
        match Call::arbitrary(&mut u) {
            Ok(call) => run.perform_checked(&call),
            Err(_) => break,
        }
    }
}

/// An instance and the host's copy of its last saved state, serialised.
pub struct Run<S: Slave> {
    pub host: Host<S>,
    saved: Option<Vec<u8>>,
}

/// At most four values of an array argument (what the calls hand over is that long).
fn four<T: Copy>(xs: &[T], fill: T) -> [T; 4] {
    let mut out = [fill; 4];
    for (o, x) in out.iter_mut().zip(xs) {
        *o = *x;
    }
    out
}

/// `n` values: those of `xs` converted by `f`, then `fill`.
fn padded<A: Copy, T: Copy>(xs: &[A], n: usize, fill: T, f: fn(A) -> T) -> Vec<T> {
    (0..n).map(|i| xs.get(i).map_or(fill, |&x| f(x))).collect()
}

fn all_finite(xs: &[f64]) -> bool {
    xs.iter().all(|x| x.is_finite())
}

impl<S: Slave> Run<S> {
    pub fn new(host: Host<S>) -> Self {
        Run { host, saved: None }
    }

    fn vr(&self, v: Vr) -> u32 {
        let known = S::TABLE.variables;
        match v {
            Vr::Known(i) if !known.is_empty() => known[usize::from(i) % known.len()].vr,
            Vr::Known(i) => u32::from(i),
            Vr::Any(r) => r,
        }
    }

    fn vrs(&self, vs: &[Vr]) -> Vec<u32> {
        vs.iter().map(|&v| self.vr(v)).collect()
    }

    /// `call`, then the invariants (lib.rs).
    pub fn perform_checked(&mut self, call: &Call) {
        let before = self.host.serialised();
        let from = logged();
        let (status, numbers) = self.perform(call);
        assert_valid_status(status, call);
        if let Call::SerialisedState { corrupt: None } = call
            && self.saved.is_some()
        {
            assert_eq!(
                status, OK,
                "the instance's own serialised state was refused"
            );
        }
        if matches!(call, Call::NullInstance) {
            assert_eq!(status, ERROR, "a call on no instance");
            return;
        }
        if refused(status) {
            assert!(
                logged() > from,
                "{call:?} refused ({status}) without a message"
            );
            assert_eq!(
                before,
                self.host.serialised(),
                "refused {call:?} ({status}) changed the instance"
            );
        } else if let Some(numbers) = numbers {
            assert!(all_finite(&numbers), "{call:?} handed out {numbers:?}");
        }
    }

    /// Carries out `call`: its status, and the numbers it handed out (if it hands out reals).
    fn perform(&mut self, call: &Call) -> (fmi2Status, Option<Vec<f64>>) {
        let c = self.host.c;
        let mut time = 0.0;
        // SAFETY (this block and the calls below): our live instance; every buffer is as long
        // as the count handed over with it, or null where the call is about null pointers.
        unsafe { fmi::fmi2GetRealStatus::<S>(c, fmi2StatusKind_fmi2LastSuccessfulTime, &mut time) };
        let status = unsafe {
            match call {
                Call::Setup {
                    tolerance,
                    start,
                    stop,
                } => fmi::fmi2SetupExperiment::<S>(
                    c,
                    i32::from(tolerance.is_some()),
                    tolerance.map_or(0.0, Real::value),
                    start.value(),
                    i32::from(stop.is_some()),
                    stop.map_or(0.0, Real::value),
                ),
                Call::Enter => fmi::fmi2EnterInitializationMode::<S>(c),
                Call::Exit => fmi::fmi2ExitInitializationMode::<S>(c),
                Call::Terminate => fmi::fmi2Terminate::<S>(c),
                Call::Reset => fmi::fmi2Reset::<S>(c),
                Call::SetReal { vrs, values, null } => {
                    let vrs = self.vrs(&vrs[..vrs.len().min(4)]);
                    let values = four(values, Real::Milli(0)).map(Real::value);
                    let p = if *null {
                        std::ptr::null()
                    } else {
                        values.as_ptr()
                    };
                    fmi::fmi2SetReal::<S>(c, vrs.as_ptr(), vrs.len(), p)
                }
                Call::SetInteger { vrs, values } => {
                    let vrs = self.vrs(&vrs[..vrs.len().min(4)]);
                    let values = four(values, Int::Small(0)).map(Int::value);
                    fmi::fmi2SetInteger::<S>(c, vrs.as_ptr(), vrs.len(), values.as_ptr())
                }
                Call::SetBoolean { vrs, values } => {
                    let vrs = self.vrs(&vrs[..vrs.len().min(4)]);
                    let values = four(values, 0);
                    fmi::fmi2SetBoolean::<S>(c, vrs.as_ptr(), vrs.len(), values.as_ptr())
                }
                Call::SetString { vrs, text, null } => {
                    let vrs = self.vrs(&vrs[..vrs.len().min(4)]);
                    let text = CString::new(text.replace('\0', "")).unwrap_or_default();
                    let p: *const c_char = if *null {
                        std::ptr::null()
                    } else {
                        text.as_ptr()
                    };
                    fmi::fmi2SetString::<S>(c, vrs.as_ptr(), vrs.len(), [p; 4].as_ptr())
                }
                Call::GetReal { vrs, null } => {
                    let vrs = self.vrs(vrs);
                    let mut out = vec![0.0; vrs.len()];
                    let p = if *null {
                        std::ptr::null_mut()
                    } else {
                        out.as_mut_ptr()
                    };
                    let status = fmi::fmi2GetReal::<S>(c, vrs.as_ptr(), vrs.len(), p);
                    return (status, Some(out));
                }
                Call::GetInteger { vrs } => {
                    let vrs = self.vrs(vrs);
                    let mut out = vec![0; vrs.len()];
                    fmi::fmi2GetInteger::<S>(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
                }
                Call::GetBoolean { vrs } => {
                    let vrs = self.vrs(vrs);
                    let mut out = vec![0; vrs.len()];
                    fmi::fmi2GetBoolean::<S>(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
                }
                Call::GetString { vrs } => {
                    let vrs = self.vrs(vrs);
                    let mut out = vec![std::ptr::null(); vrs.len()];
                    fmi::fmi2GetString::<S>(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr())
                }
                Call::DoStep {
                    offset,
                    h,
                    no_set_prior,
                } => {
                    let t = offset.map_or(0.0, |o| time + o.value());
                    fmi::fmi2DoStep::<S>(c, t, h.value(), i32::from(*no_set_prior))
                }
                Call::CancelStep => fmi::fmi2CancelStep::<S>(c),
                Call::Logging { on, categories } => {
                    let known = S::TABLE.log_categories;
                    let owned: Vec<CString> = categories
                        .iter()
                        .take(4)
                        .map(|&i| match known.get(usize::from(i)) {
                            Some(k) => CString::new(*k).unwrap_or_default(),
                            None if i % 3 == 0 => c"%s%n".to_owned(),
                            None => c"noSuchCategory".to_owned(),
                        })
                        .collect();
                    let ptrs: Vec<*const c_char> = owned.iter().map(|s| s.as_ptr()).collect();
                    fmi::fmi2SetDebugLogging::<S>(c, i32::from(*on), ptrs.len(), ptrs.as_ptr())
                }
                Call::Status { kind, which } => {
                    let kind = u32::from(*kind % 6);
                    match which % 5 {
                        0 => fmi::fmi2GetStatus::<S>(c, kind, &mut 0),
                        1 => {
                            let mut r = 0.0;
                            let status = fmi::fmi2GetRealStatus::<S>(c, kind, &mut r);
                            return (status, Some(vec![r]));
                        }
                        2 => fmi::fmi2GetIntegerStatus::<S>(c, kind, &mut 0),
                        3 => fmi::fmi2GetBooleanStatus::<S>(c, kind, &mut 0),
                        _ => fmi::fmi2GetStringStatus::<S>(c, kind, &mut std::ptr::null()),
                    }
                }
                Call::InputDerivatives {
                    vrs,
                    orders,
                    values,
                } => {
                    let vrs = self.vrs(&vrs[..vrs.len().min(4)]);
                    let orders = four(orders, Int::Small(1)).map(Int::value);
                    let values = four(values, Real::Milli(0)).map(Real::value);
                    fmi::fmi2SetRealInputDerivatives::<S>(
                        c,
                        vrs.as_ptr(),
                        vrs.len(),
                        orders.as_ptr(),
                        values.as_ptr(),
                    )
                }
                Call::OutputDerivatives { vrs, orders } => {
                    let vrs = self.vrs(&vrs[..vrs.len().min(8)]);
                    let orders = padded(orders, vrs.len(), 1, Int::value);
                    let mut out = vec![0.0; vrs.len()];
                    let status = fmi::fmi2GetRealOutputDerivatives::<S>(
                        c,
                        vrs.as_ptr(),
                        vrs.len(),
                        orders.as_ptr(),
                        out.as_mut_ptr(),
                    );
                    return (status, Some(out));
                }
                Call::GetState => {
                    let status = fmi::fmi2GetFMUstate::<S>(c, &mut self.host.state);
                    if status == OK {
                        self.saved = Some(self.host.serialised());
                    }
                    status
                }
                Call::SetState => fmi::fmi2SetFMUstate::<S>(c, self.host.state),
                Call::FreeState => {
                    self.saved = None;
                    fmi::fmi2FreeFMUstate::<S>(c, &mut self.host.state)
                }
                Call::SerialisedState { corrupt } => {
                    let mut bytes = self.saved.clone().unwrap_or_default();
                    if let (Some((at, xor)), false) = (corrupt, bytes.is_empty()) {
                        let n = bytes.len();
                        bytes[usize::from(*at) % n] ^= xor;
                    }
                    let (made, set) = self.host.load(&bytes);
                    set.unwrap_or(made)
                }
                Call::SetTime { t } => fmi::fmi2SetTime::<S>(c, t.value()),
                Call::SetStates { values, len } => {
                    let n = len.value(S::STATES);
                    let x = padded(values, n, 0.0, Real::value);
                    fmi::fmi2SetContinuousStates::<S>(c, x.as_ptr(), n)
                }
                Call::Query { which, len } => {
                    let right = if which % 4 == 3 {
                        S::EVENT_INDICATORS
                    } else {
                        S::STATES
                    };
                    let n = len.value(right);
                    let mut out = vec![0.0; n];
                    let p = out.as_mut_ptr();
                    let status = match which % 4 {
                        0 => fmi::fmi2GetContinuousStates::<S>(c, p, n),
                        1 => fmi::fmi2GetDerivatives::<S>(c, p, n),
                        2 => fmi::fmi2GetNominalsOfContinuousStates::<S>(c, p, n),
                        _ => fmi::fmi2GetEventIndicators::<S>(c, p, n),
                    };
                    return (status, Some(out));
                }
                Call::EnterEventMode => fmi::fmi2EnterEventMode::<S>(c),
                Call::NewDiscreteStates => {
                    // SAFETY: a C struct of integers and a double: all zero is a value.
                    let mut info: fmi2EventInfo = std::mem::zeroed();
                    let status = fmi::fmi2NewDiscreteStates::<S>(c, &mut info);
                    let next = if info.nextEventTimeDefined != 0 {
                        vec![info.nextEventTime]
                    } else {
                        Vec::new()
                    };
                    return (status, Some(next));
                }
                Call::EnterContinuousTimeMode => fmi::fmi2EnterContinuousTimeMode::<S>(c),
                Call::CompletedIntegratorStep { no_set_prior } => {
                    let (mut enter, mut terminate) = (0, 0);
                    fmi::fmi2CompletedIntegratorStep::<S>(
                        c,
                        i32::from(*no_set_prior),
                        &mut enter,
                        &mut terminate,
                    )
                }
                Call::Directional {
                    unknowns,
                    knowns,
                    dv,
                } => {
                    let unknowns = self.vrs(&unknowns[..unknowns.len().min(8)]);
                    let knowns = self.vrs(&knowns[..knowns.len().min(8)]);
                    let dv = padded(dv, knowns.len(), 1.0, Real::value);
                    let mut out = vec![0.0; unknowns.len()];
                    let status = fmi::fmi2GetDirectionalDerivative::<S>(
                        c,
                        unknowns.as_ptr(),
                        unknowns.len(),
                        knowns.as_ptr(),
                        knowns.len(),
                        dv.as_ptr(),
                        out.as_mut_ptr(),
                    );
                    // A finite seed gives finite directional derivatives.
                    return (status, all_finite(&dv).then_some(out));
                }
                Call::NullInstance => fmi::fmi2DoStep::<S>(std::ptr::null_mut(), 0.0, 0.01, 0).max(
                    fmi::fmi2GetReal::<S>(std::ptr::null_mut(), &0, 1, [0.0].as_mut_ptr()),
                ),
            }
        };
        (status, None)
    }
}
