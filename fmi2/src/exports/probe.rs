//! Probe: the slave of the shared layer's tests, with a variable table of every kind the layer
//! checks (a fixed and a tunable parameter with bounds, an Integer, an Enumeration, a calculated
//! parameter, a continuous and a discrete input, a Boolean, an output, a local), a quick path
//! for some of them, first-order input and output derivatives, two continuous states for Model
//! Exchange, and what the instance must handle: models that Model Exchange offers and one it
//! does not, an initialisation warning, step notices, states whose outputs overflow. Its
//! answers are simple enough to work out by hand:
//!
//! - y = k u, its derivative k du (du: u's input derivative), g = 2 k, l = c;
//! - Model Exchange: x' = (x1, -k x0) (an oscillator), one event indicator x0;
//! - n chooses the model: [`CS_ONLY`] runs in Co-Simulation only, [`WARNS`] initialises with a
//!   warning; a Co-Simulation step of h counts itself and moves x0 by h, with a notice for a
//!   step of [`NOTICE_STEP`];
//! - it keeps the defaults of `Slave::flag` and of `Continuous`'s nominals, completed step,
//!   event update and directional derivatives.
//!
//! `MARK` is a parameter so that the state boxes' marks can be tested for more than one FMU.
//! [`Rig`] drives an instance of it (or of any slave) through the exports, as a host does.

use std::ffi::CString;
use std::marker::PhantomData;

use fmi_sys::fmi2::*;

use super::tests::{instantiate, logs_of};
use super::*;
use crate::continuous::Continuous;
use crate::description::{Causality, Table, VarType, Variability, Variable};
use crate::frame::{Reader, put_f64, put_f64_list};
use crate::slave::Context;

pub(crate) const K: u32 = 10;
pub(crate) const C: u32 = 11;
pub(crate) const N: u32 = 12;
pub(crate) const MODE: u32 = 13;
pub(crate) const G: u32 = 14;
pub(crate) const U: u32 = 20;
pub(crate) const JUMP: u32 = 21;
pub(crate) const ON: u32 = 22;
pub(crate) const Y: u32 = 30;
pub(crate) const L: u32 = 31;

/// Models, by n: Co-Simulation only; the start value; offered, with an initialisation warning.
pub(crate) const CS_ONLY: i32 = 1;
pub(crate) const ME: i32 = 3;
pub(crate) const WARNS: i32 = 4;

/// A Co-Simulation step of this size asks for its notice.
pub(crate) const NOTICE_STEP: f64 = 0.25;

#[allow(clippy::too_many_arguments)]
const fn var(
    name: &'static str,
    vr: u32,
    ty: VarType,
    causality: Causality,
    variability: Variability,
    start: Option<f64>,
    min: Option<f64>,
    max: Option<f64>,
) -> Variable {
    Variable {
        name,
        vr,
        ty,
        causality,
        variability,
        start,
        min,
        max,
        items: &[],
        unit: "",
        description: "",
    }
}

use Causality::{CalculatedParameter, Input, Local, Output, Parameter};
use VarType::{Boolean, Enumeration, Integer, Real};
use Variability::{Continuous as Cont, Discrete, Fixed, Tunable};

/// The variables, in an order that is not the value references' (position != vr).
pub(crate) const VARIABLES: &[Variable] = &[
    var(
        "k",
        K,
        Real,
        Parameter,
        Fixed,
        Some(2.0),
        Some(0.5),
        Some(4.0),
    ),
    var("c", C, Real, Parameter, Tunable, Some(0.1), Some(0.0), None),
    var(
        "n",
        N,
        Integer,
        Parameter,
        Fixed,
        Some(3.0),
        Some(1.0),
        Some(10.0),
    ),
    Variable {
        items: &[("A", 1), ("B", 2), ("C", 5)],
        ..var(
            "mode",
            MODE,
            Enumeration,
            Parameter,
            Fixed,
            Some(2.0),
            None,
            None,
        )
    },
    var("g", G, Real, CalculatedParameter, Fixed, None, None, None),
    var("u", U, Real, Input, Cont, Some(0.0), None, None),
    var("jump", JUMP, Real, Input, Discrete, Some(0.0), None, None),
    var("on", ON, Boolean, Input, Discrete, Some(0.0), None, None),
    var("y", Y, Real, Output, Cont, None, None, None),
    var("l", L, Real, Local, Cont, None, None, None),
];

const VR_INDEX: [i32; 32] = {
    let mut index = [-1; 32];
    let mut i = 0;
    while i < VARIABLES.len() {
        index[VARIABLES[i].vr as usize] = i as i32;
        i += 1;
    }
    index
};

pub(crate) static TABLE: Table = Table {
    model_identifier: "Probe",
    guid: "{probe}",
    variables: VARIABLES,
    vr_index: &VR_INDEX,
    log_categories: &[
        log_category::LOG_STATUS_ERROR,
        log_category::LOG_STATUS_WARNING,
        log_category::LOG_CALLS,
    ],
};

/// Position in [`VARIABLES`] of `vr` (the tests' own lookup, not the table's).
pub(crate) fn at(vr: u32) -> usize {
    VARIABLES
        .iter()
        .position(|v| v.vr == vr)
        .expect("a Probe variable")
}

pub(crate) struct Probe<const MARK: u64> {
    /// The stored values by position (y, g and l are computed).
    values: Vec<f64>,
    /// u's input derivative.
    du: f64,
    pub(crate) x: [f64; 2],
    /// Co-Simulation steps taken.
    pub(crate) steps: u32,
    /// How often initialisation was undone.
    pub(crate) undone: u32,
    /// The flag `load` was given (None: not loaded).
    pub(crate) restored_flag: Option<bool>,
}

impl<const MARK: u64> Probe<MARK> {
    fn value(&self, i: usize) -> f64 {
        let v = |vr| self.values[at(vr)];
        match VARIABLES[i].vr {
            Y => v(K) * v(U),
            G => 2.0 * v(K),
            L => v(C),
            _ => self.values[i],
        }
    }

    /// The value of `vr`, as fmi2Get* hands it out.
    pub(crate) fn value_of(&self, vr: u32) -> f64 {
        self.value(at(vr))
    }

    /// With the stored value of `vr` changed (however out of bounds): for the states tests
    /// make up.
    pub(crate) fn with(mut self, vr: u32, value: f64) -> Self {
        self.values[at(vr)] = value;
        self
    }

    fn model(&self) -> i32 {
        self.values[at(N)] as i32
    }
}

impl<const MARK: u64> Continuous for Probe<MARK> {
    const STATES: usize = 2;
    const EVENT_INDICATORS: usize = 1;

    fn offers_model_exchange(&self) -> Result<(), String> {
        match self.model() {
            CS_ONLY => Err(format!("n = {CS_ONLY} runs in Co-Simulation only")),
            _ => Ok(()),
        }
    }
    fn states(&self, x: &mut [f64]) -> Reply {
        x.copy_from_slice(&self.x);
        Ok(Status::Ok)
    }
    fn set_states(&mut self, _: &Context, x: &[f64]) -> Reply {
        self.x.copy_from_slice(x);
        Ok(Status::Ok)
    }
    fn derivatives(&self, _: &Context, dx: &mut [f64]) -> Reply {
        dx.copy_from_slice(&[self.x[1], -self.values[at(K)] * self.x[0]]);
        Ok(Status::Ok)
    }
    fn event_indicators(&self, _: &Context, out: &mut [f64]) -> Reply {
        out[0] = self.x[0];
        Ok(Status::Ok)
    }
}

impl<const MARK: u64> Slave for Probe<MARK> {
    const TABLE: &'static Table = &TABLE;
    const MARK: u64 = MARK;
    const STATE_TAG: [u8; 4] = *b"PRBs";
    const STATE_VERSION: u16 = 1;

    fn new() -> Self {
        Probe {
            values: VARIABLES.iter().map(|v| v.start.unwrap_or(0.0)).collect(),
            du: 0.0,
            x: [0.0; 2],
            steps: 0,
            undone: 0,
            restored_flag: None,
        }
    }
    fn initialise(&mut self, _: &Context) -> Result<Vec<String>, Refusal> {
        Ok(match self.model() {
            WARNS => vec![format!("n = {WARNS} is approximate")],
            _ => Vec::new(),
        })
    }
    fn uninitialise(&mut self) {
        self.undone += 1;
    }
    fn step(&mut self, _: &Context, _: f64, h: f64) -> Result<bool, Refusal> {
        self.x[0] += h;
        self.steps += 1;
        Ok(h == NOTICE_STEP)
    }
    fn notice(&mut self, context: &Context) -> Option<String> {
        Some(format!("a notice at t = {}", context.time))
    }
    fn get<T>(
        &self,
        _: &Context,
        vrs: &[u32],
        out: &mut [T],
        ty: VarType,
        function: &str,
        to: fn(f64) -> T,
    ) -> Reply {
        for (slot, &r) in out.iter_mut().zip(vrs) {
            let (i, _) = TABLE.typed_variable(r, ty, function)?;
            *slot = to(self.value(i));
        }
        Ok(Status::Ok)
    }
    fn set<T: Copy>(
        &mut self,
        context: &Context,
        vrs: &[u32],
        values: &[T],
        ty: VarType,
        function: &str,
        from: fn(T) -> f64,
    ) -> Reply {
        // All or nothing: set on a copy, kept only if every value was taken.
        let mut next = self.values.clone();
        for (&r, &v) in vrs.iter().zip(values) {
            next[TABLE.settable(context.phase, r, from(v), ty, function)?] = from(v);
        }
        self.values = next;
        Ok(Status::Ok)
    }
    /// u alone, the per-step input: any finite value in every phase that allows a set.
    fn set_quietly(&mut self, r: u32, value: f64, ty: VarType) -> bool {
        let take = r == U && ty == Real && value.is_finite();
        if take {
            self.values[at(U)] = value;
        }
        take
    }
    /// k and u as Reals, n as an Integer: stored values.
    fn get_quietly<T>(&self, vrs: &[u32], out: &mut [T], ty: VarType, to: fn(f64) -> T) -> bool {
        for (slot, &r) in out.iter_mut().zip(vrs) {
            let v = match (r, ty) {
                (K | U, Real) | (N, Integer) => self.values[at(r)],
                _ => return false,
            };
            if !v.is_finite() {
                return false;
            }
            *slot = to(v);
        }
        true
    }
    fn set_input_derivatives(&mut self, vrs: &[u32], orders: &[i32], values: &[f64]) -> Reply {
        for ((&r, &order), &v) in vrs.iter().zip(orders).zip(values) {
            TABLE.check_input_derivative(r, order, v, 1)?;
        }
        if let Some(&du) = values.last() {
            self.du = du;
        }
        Ok(Status::Ok)
    }
    fn output_derivatives(
        &self,
        context: &Context,
        vrs: &[u32],
        orders: &[i32],
        put: impl FnMut(usize, f64),
    ) -> Reply {
        let model = context.phase.initialised().then_some(self);
        let output = |r: u32| (r == Y).then_some(());
        let rate = |p: &Self, ()| p.values[at(K)] * p.du;
        TABLE.first_output_derivatives(model, vrs, orders, output, rate, put)
    }
    fn save(&self, out: &mut Vec<u8>) {
        put_f64_list(out, &self.values);
        put_f64_list(out, &self.x);
        put_f64(out, self.du);
        out.extend_from_slice(&self.steps.to_le_bytes());
    }
    fn load(_: &Context, flag: bool, part: &mut Reader) -> Result<Self, String> {
        let values = part.f64_list()?;
        let x = part.f64_list()?;
        let du = part.f64()?;
        let steps = part.u32()?;
        let x: [f64; 2] = x.try_into().map_err(|_| "two states".to_string())?;
        if values.len() != VARIABLES.len() {
            return Err("one value per variable".into());
        }
        Ok(Probe {
            values,
            du,
            x,
            steps,
            undone: 0,
            restored_flag: Some(flag),
        })
    }
}

/// The mark of the Probe most tests use.
pub(crate) const MARK: u64 = 0x5052_4f42_4520_2020;
pub(crate) type P = Probe<MARK>;

/// An instance of `S` made through fmi2Instantiate and driven as a host drives it, logging
/// through fmi-sys's C logger into exports::tests' capture under its `name` (each test its
/// own); freed on drop.
pub(crate) struct Rig<S: Slave> {
    pub(crate) c: fmi2Component,
    name: String,
    _callbacks: Box<fmi2CallbackFunctions>,
    _slave: PhantomData<S>,
}

const OK: fmi2Status = fmi2Status_fmi2OK;

impl<S: Slave> Rig<S> {
    /// Instantiated (`kind`: fmi2CoSimulation or fmi2ModelExchange), with fmi2Instantiate's
    /// loggingOn.
    pub(crate) fn new(name: &str, kind: fmi2Type, logging_on: bool) -> Self {
        let (c, callbacks) = instantiate::<S>(name, kind, logging_on);
        Rig {
            c,
            name: name.into(),
            _callbacks: callbacks,
            _slave: PhantomData,
        }
    }

    /// Instantiated, set up (no tolerance, start 0, no stop) and in initialisation mode.
    pub(crate) fn in_initialisation(name: &str, kind: fmi2Type, logging_on: bool) -> Self {
        let rig = Self::new(name, kind, logging_on);
        assert_eq!(rig.setup(None, 0.0, None), OK);
        // SAFETY: our live instance.
        assert_eq!(unsafe { fmi2EnterInitializationMode::<S>(rig.c) }, OK);
        rig
    }

    /// Initialised: StepComplete (Co-Simulation) or EventMode (Model Exchange).
    pub(crate) fn running(name: &str, kind: fmi2Type, logging_on: bool) -> Self {
        let rig = Self::in_initialisation(name, kind, logging_on);
        // SAFETY: our live instance.
        assert_eq!(unsafe { fmi2ExitInitializationMode::<S>(rig.c) }, OK);
        rig
    }

    pub(crate) fn instance(&self) -> &Instance<S> {
        // SAFETY: our live instance.
        unsafe { Instance::<S>::from_ptr(self.c) }
            .map(|i| &*i)
            .expect("our instance")
    }

    /// What the instance logged so far: (level, message).
    pub(crate) fn logs(&self) -> Vec<(log::Level, String)> {
        logs_of(&self.name)
    }

    pub(crate) fn setup(
        &self,
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    ) -> fmi2Status {
        let (tol_on, tol) = (i32::from(tolerance.is_some()), tolerance.unwrap_or(0.0));
        let (stop_on, stop) = (i32::from(stop.is_some()), stop.unwrap_or(0.0));
        // SAFETY: our live instance.
        unsafe { fmi2SetupExperiment::<S>(self.c, tol_on, tol, start, stop_on, stop) }
    }

    /// fmi2EnterInitializationMode (which must pass), then fmi2ExitInitializationMode: the
    /// second's status.
    pub(crate) fn initialise(&self) -> fmi2Status {
        // SAFETY: our live instance.
        unsafe {
            assert_eq!(fmi2EnterInitializationMode::<S>(self.c), OK);
            fmi2ExitInitializationMode::<S>(self.c)
        }
    }

    pub(crate) fn step(&self, t: f64, h: f64) -> fmi2Status {
        // SAFETY: our live instance.
        unsafe { fmi2DoStep::<S>(self.c, t, h, 0) }
    }

    pub(crate) fn set_real(&self, r: u32, v: f64) -> fmi2Status {
        // SAFETY: our live instance; one value reference and one value.
        unsafe { fmi2SetReal::<S>(self.c, &r, 1, &v) }
    }

    pub(crate) fn set_integer(&self, r: u32, v: i32) -> fmi2Status {
        // SAFETY: as above.
        unsafe { fmi2SetInteger::<S>(self.c, &r, 1, &v) }
    }

    pub(crate) fn get_real(&self, r: u32) -> (fmi2Status, f64) {
        let mut v = f64::NAN;
        // SAFETY: as above.
        let status = unsafe { fmi2GetReal::<S>(self.c, &r, 1, &mut v) };
        (status, v)
    }

    /// fmi2GetRealStatus(fmi2LastSuccessfulTime).
    pub(crate) fn last_successful_time(&self) -> f64 {
        let mut t = f64::NAN;
        let kind = fmi2StatusKind_fmi2LastSuccessfulTime;
        // SAFETY: our live instance, a valid out slot.
        assert_eq!(unsafe { fmi2GetRealStatus::<S>(self.c, kind, &mut t) }, OK);
        t
    }

    pub(crate) fn debug_logging(&self, on: bool, categories: &[&str]) -> fmi2Status {
        let owned: Vec<CString> = categories
            .iter()
            .map(|c| CString::new(*c).expect("a category"))
            .collect();
        let pointers: Vec<fmi2String> = owned.iter().map(|c| c.as_ptr()).collect();
        let (n, on) = (pointers.len(), i32::from(on));
        // SAFETY: our live instance; the category strings outlive the call.
        unsafe { fmi2SetDebugLogging::<S>(self.c, on, n, pointers.as_ptr()) }
    }

    /// The instance's state, serialised (fmi2GetFMUstate, fmi2SerializeFMUstate).
    pub(crate) fn saved(&self) -> Vec<u8> {
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        let mut size = 0;
        // SAFETY: our live instance and the state it makes, freed here.
        unsafe {
            assert_eq!(fmi2GetFMUstate::<S>(self.c, &mut state), OK);
            assert_eq!(
                fmi2SerializedFMUstateSize::<S>(self.c, state, &mut size),
                OK
            );
            let mut bytes = vec![0u8; size];
            let into = bytes.as_mut_ptr().cast();
            assert_eq!(fmi2SerializeFMUstate::<S>(self.c, state, into, size), OK);
            assert_eq!(fmi2FreeFMUstate::<S>(self.c, &mut state), OK);
            bytes
        }
    }

    /// Restore serialised `bytes`: fmi2DeSerializeFMUstate's status, and if it made a state,
    /// fmi2SetFMUstate's.
    pub(crate) fn restore(&self, bytes: &[u8]) -> (fmi2Status, Option<fmi2Status>) {
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        let (from, size) = (bytes.as_ptr().cast(), bytes.len());
        // SAFETY: our live instance, the host's buffer, the state made here and freed.
        unsafe {
            let made = fmi2DeSerializeFMUstate::<S>(self.c, from, size, &mut state);
            if made != OK {
                assert!(state.is_null());
                return (made, None);
            }
            let set = fmi2SetFMUstate::<S>(self.c, state);
            fmi2FreeFMUstate::<S>(self.c, &mut state);
            (made, Some(set))
        }
    }
}

impl<S: Slave> Drop for Rig<S> {
    fn drop(&mut self) {
        // SAFETY: our instance, freed once.
        unsafe { fmi2FreeInstance::<S>(self.c) };
    }
}

/// The last message logged for the instance `name`.
pub(crate) fn last_log(name: &str) -> Option<(log::Level, String)> {
    logs_of(name).pop()
}
