//! Probe: a slave of the instance tests' own, small enough to predict every answer, with what
//! the shared instance must handle: Real and Integer variables, a quick path for one input and
//! one output, initialisation warnings and refusals, a model that Model Exchange offers and
//! one it does not, step notices, and a saved part that can hold values whose output
//! overflows. And a host for it: the generic bodies of the exports (what `export_fmi2!` emits
//! for an FMU), a logger into the tests' log capture.

use std::ffi::CString;

use fmi_sys::fmi2::*;

use crate::continuous::Continuous;
use crate::description::{Causality, Table, VarType, Variability, Variable, log_category};
use crate::exports::tests::{instantiate, logs_of};
use crate::exports::*;
use crate::frame::{self, Reader};
use crate::instance::Instance;
use crate::slave::{Context, Slave};
use crate::status::{Refusal, Reply, Status, refuse};

/// Value references: y = x * gain (output), gain (parameter, also the quick input), model
/// (Integer parameter).
pub(super) const Y: u32 = 0;
pub(super) const GAIN: u32 = 1;
pub(super) const MODEL: u32 = 2;

/// The models: Co-Simulation only; offered in Model Exchange; offered, with an
/// initialisation warning; refused by initialisation.
pub(super) const CS_ONLY: i32 = 0;
pub(super) const ME: i32 = 1;
pub(super) const WARNS: i32 = 2;
pub(super) const FAILS: i32 = 3;

/// A step of this size asks for its notice.
pub(super) const NOTICE_STEP: f64 = 0.25;

const fn variable(name: &'static str, vr: u32, ty: VarType, causality: Causality) -> Variable {
    Variable {
        name,
        vr,
        ty,
        causality,
        variability: Variability::Tunable,
        start: None,
        min: None,
        max: None,
        items: &[],
        unit: "",
        description: "",
    }
}

static TABLE: Table = Table {
    model_identifier: "Probe",
    guid: "{probe}",
    variables: &[
        variable("y", Y, VarType::Real, Causality::Output),
        variable("gain", GAIN, VarType::Real, Causality::Parameter),
        variable("model", MODEL, VarType::Integer, Causality::Parameter),
    ],
    vr_index: &[0, 1, 2],
    log_categories: &[
        log_category::LOG_STATUS_ERROR,
        log_category::LOG_STATUS_WARNING,
        log_category::LOG_CALLS,
    ],
};

#[derive(Debug, PartialEq)]
pub(super) struct Probe {
    pub(super) x: f64,
    pub(super) gain: f64,
    pub(super) model: i32,
    pub(super) steps: u32,
    /// How often initialisation was undone.
    pub(super) undone: u32,
}

impl Probe {
    fn value(&self, r: u32) -> f64 {
        match r {
            Y => self.x * self.gain,
            GAIN => self.gain,
            _ => f64::from(self.model),
        }
    }

    /// Its part of a saved state, for states the tests make up.
    pub(super) fn part(x: f64, gain: f64, model: i32, out: &mut Vec<u8>) {
        frame::put_f64(out, x);
        frame::put_f64(out, gain);
        out.extend_from_slice(&model.to_le_bytes());
        out.extend_from_slice(&0u32.to_le_bytes());
    }
}

/// Every value reference of `vrs` names a variable of type `ty`.
fn typed(vrs: &[u32], ty: VarType, function: &str) -> Result<(), Refusal> {
    for &r in vrs {
        TABLE.typed_variable(r, ty, function)?;
    }
    Ok(())
}

impl Continuous for Probe {
    fn offers_model_exchange(&self) -> Result<(), String> {
        match self.model {
            ME | WARNS => Ok(()),
            m => Err(format!("model {m} runs in Co-Simulation only")),
        }
    }
}

impl Slave for Probe {
    const TABLE: &'static Table = &TABLE;
    const MARK: u64 = 0x5052_4f42_4553_4c56;
    const STATE_TAG: [u8; 4] = *b"PRBE";
    const STATE_VERSION: u16 = 3;

    fn new() -> Self {
        Probe {
            x: 1.0,
            gain: 2.0,
            model: CS_ONLY,
            steps: 0,
            undone: 0,
        }
    }
    fn initialise(&mut self, _: &Context) -> Result<Vec<String>, Refusal> {
        match self.model {
            FAILS => Err(refuse("model 3 does not start")),
            WARNS => Ok(vec!["model 2 is approximate".into()]),
            _ => Ok(Vec::new()),
        }
    }
    fn uninitialise(&mut self) {
        self.undone += 1;
    }
    fn step(&mut self, _: &Context, _: f64, h: f64) -> Result<bool, Refusal> {
        self.x += h;
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
        typed(vrs, ty, function)?;
        for (slot, &r) in out.iter_mut().zip(vrs) {
            *slot = to(self.value(r));
        }
        Ok(Status::Ok)
    }
    fn set<T: Copy>(
        &mut self,
        _: &Context,
        vrs: &[u32],
        values: &[T],
        ty: VarType,
        function: &str,
        from: fn(T) -> f64,
    ) -> Reply {
        typed(vrs, ty, function)?;
        if vrs.contains(&Y) {
            return Err(refuse(format!("{function}: y is an output")));
        }
        for (&r, &v) in vrs.iter().zip(values) {
            match r {
                GAIN => self.gain = from(v),
                _ => self.model = from(v) as i32,
            }
        }
        Ok(Status::Ok)
    }
    fn set_quietly(&mut self, r: u32, value: f64, ty: VarType) -> bool {
        let quiet = r == GAIN && ty == VarType::Real;
        if quiet {
            self.gain = value;
        }
        quiet
    }
    fn get_quietly(&self, r: u32, ty: VarType) -> Option<f64> {
        (r == Y && ty == VarType::Real).then(|| self.value(Y))
    }
    fn set_input_derivatives(&mut self, _: &[u32], _: &[i32], _: &[f64]) -> Reply {
        Err(refuse("no inputs"))
    }
    fn output_derivatives(
        &self,
        _: &Context,
        _: &[u32],
        _: &[i32],
        _: impl FnMut(usize, f64),
    ) -> Reply {
        Err(refuse("no output derivatives"))
    }
    fn save(&self, out: &mut Vec<u8>) {
        Self::part(self.x, self.gain, self.model, out);
        // Overwrite the step count Probe::part leaves at 0.
        let n = out.len();
        out[n - 4..].copy_from_slice(&self.steps.to_le_bytes());
    }
    fn load(_: &Context, _: bool, part: &mut Reader) -> Result<Self, String> {
        Ok(Probe {
            x: part.f64()?,
            gain: part.f64()?,
            model: part.u32()? as i32,
            steps: part.u32()?,
            undone: 0,
        })
    }
}

/// An instance of Probe made through fmi2Instantiate, freed on drop; its log is captured.
pub(super) struct Fmu {
    pub(super) c: fmi2Component,
    name: String,
    _callbacks: Box<fmi2CallbackFunctions>,
}

impl Fmu {
    /// A new instance `name` (each test its own) of the interface `kind`, with fmi2Instantiate's
    /// loggingOn.
    pub(super) fn new(name: &str, kind: fmi2Type, logging_on: bool) -> Self {
        let (c, callbacks) = instantiate::<Probe>(name, kind, logging_on);
        Fmu {
            c,
            name: name.into(),
            _callbacks: callbacks,
        }
    }

    pub(super) fn instance(&self) -> &Instance<Probe> {
        // SAFETY: our live instance.
        unsafe { Instance::<Probe>::from_ptr(self.c) }
            .map(|i| &*i)
            .unwrap()
    }

    /// What the instance logged so far: (level, message).
    pub(super) fn logs(&self) -> Vec<(log::Level, String)> {
        logs_of(&self.name)
    }

    pub(super) fn setup(
        &self,
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    ) -> fmi2Status {
        let (tol_on, tol) = (i32::from(tolerance.is_some()), tolerance.unwrap_or(0.0));
        let (stop_on, stop) = (i32::from(stop.is_some()), stop.unwrap_or(0.0));
        // SAFETY: our live instance.
        unsafe { fmi2SetupExperiment::<Probe>(self.c, tol_on, tol, start, stop_on, stop) }
    }

    /// fmi2EnterInitializationMode then fmi2ExitInitializationMode: the second's status.
    pub(super) fn initialise(&self) -> fmi2Status {
        // SAFETY: our live instance.
        unsafe {
            assert_eq!(
                fmi2EnterInitializationMode::<Probe>(self.c),
                fmi2Status_fmi2OK
            );
            fmi2ExitInitializationMode::<Probe>(self.c)
        }
    }

    pub(super) fn step(&self, t: f64, h: f64) -> fmi2Status {
        // SAFETY: our live instance.
        unsafe { fmi2DoStep::<Probe>(self.c, t, h, 0) }
    }

    pub(super) fn set_real(&self, r: u32, v: f64) -> fmi2Status {
        // SAFETY: our live instance; one value reference and one value.
        unsafe { fmi2SetReal::<Probe>(self.c, &r, 1, &v) }
    }

    pub(super) fn set_integer(&self, r: u32, v: i32) -> fmi2Status {
        // SAFETY: as above.
        unsafe { fmi2SetInteger::<Probe>(self.c, &r, 1, &v) }
    }

    pub(super) fn get_real(&self, r: u32) -> (fmi2Status, f64) {
        let mut v = f64::NAN;
        // SAFETY: as above.
        let status = unsafe { fmi2GetReal::<Probe>(self.c, &r, 1, &mut v) };
        (status, v)
    }

    /// fmi2GetRealStatus(fmi2LastSuccessfulTime).
    pub(super) fn last_successful_time(&self) -> f64 {
        let mut t = f64::NAN;
        // SAFETY: our live instance, a valid out slot.
        let status = unsafe {
            fmi2GetRealStatus::<Probe>(self.c, fmi2StatusKind_fmi2LastSuccessfulTime, &mut t)
        };
        assert_eq!(status, fmi2Status_fmi2OK);
        t
    }

    pub(super) fn debug_logging(&self, on: bool, categories: &[&str]) -> fmi2Status {
        let owned: Vec<CString> = categories
            .iter()
            .map(|c| CString::new(*c).unwrap())
            .collect();
        let pointers: Vec<fmi2String> = owned.iter().map(|c| c.as_ptr()).collect();
        // SAFETY: our live instance; the category strings outlive the call.
        unsafe {
            fmi2SetDebugLogging::<Probe>(self.c, i32::from(on), pointers.len(), pointers.as_ptr())
        }
    }

    /// The instance's state, serialised (fmi2GetFMUstate, fmi2SerializeFMUstate).
    pub(super) fn saved(&self) -> Vec<u8> {
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        let mut size = 0;
        // SAFETY: our live instance and the state it makes, freed here.
        unsafe {
            assert_eq!(
                fmi2GetFMUstate::<Probe>(self.c, &mut state),
                fmi2Status_fmi2OK
            );
            fmi2SerializedFMUstateSize::<Probe>(self.c, state, &mut size);
            let mut bytes = vec![0u8; size];
            let status =
                fmi2SerializeFMUstate::<Probe>(self.c, state, bytes.as_mut_ptr().cast(), size);
            assert_eq!(status, fmi2Status_fmi2OK);
            fmi2FreeFMUstate::<Probe>(self.c, &mut state);
            bytes
        }
    }

    /// Restore serialised `bytes`: fmi2DeSerializeFMUstate's status, and if it made a state,
    /// fmi2SetFMUstate's.
    pub(super) fn restore(&self, bytes: &[u8]) -> (fmi2Status, Option<fmi2Status>) {
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: our live instance, the host's buffer, the state made here and freed.
        unsafe {
            let made = fmi2DeSerializeFMUstate::<Probe>(
                self.c,
                bytes.as_ptr().cast(),
                bytes.len(),
                &mut state,
            );
            if made != fmi2Status_fmi2OK {
                assert!(state.is_null());
                return (made, None);
            }
            let set = fmi2SetFMUstate::<Probe>(self.c, state);
            fmi2FreeFMUstate::<Probe>(self.c, &mut state);
            (made, Some(set))
        }
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        // SAFETY: our instance, freed once.
        unsafe { fmi2FreeInstance::<Probe>(self.c) };
    }
}
