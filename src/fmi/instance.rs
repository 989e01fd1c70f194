//! One FMU instance: the FMI 2.0 Co-Simulation call-sequence state machine, variable access
//! and stepping. Every refused call leaves the instance exactly as it was and says why.

use std::ffi::CString;

use super::logger::Logger;
use super::params::{
    Configuration, Source, Values, derived_value, free_real_input, output_of, source_of,
};
use super::snapshot::Saved;
use super::vars::{
    Causality, LOG_CATEGORIES, VARIABLES, VarType, Variability, Variable, finite, index_of, vr,
};
use crate::model::{Damper, Inputs, Output, StepError};
use crate::solver::SolveError;

/// fmi2Status, as a Rust enum.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    Ok = 0,
    Warning = 1,
    Discard = 2,
    Error = 3,
    Fatal = 4,
}

/// A call the instance did not carry out, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Refusal {
    pub status: Status,
    /// Boxed so that a refusal is two words: every call's result then comes back in
    /// registers, not through memory.
    #[allow(clippy::box_collection)] // the point: one word, not three
    pub message: Box<String>,
}

impl Refusal {
    pub fn new(status: Status, message: impl Into<String>) -> Self {
        Refusal {
            status,
            message: Box::new(message.into()),
        }
    }
}

pub type Reply = Result<Status, Refusal>;

pub fn refuse(message: impl Into<String>) -> Refusal {
    Refusal::new(Status::Error, message)
}

/// States of the FMI 2.0 Co-Simulation state machine this FMU can be in (it never runs
/// asynchronously, and a refused step leaves it in StepComplete at the step's start).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    Instantiated,
    InitializationMode,
    StepComplete,
    Terminated,
    /// After an internal error (a caught panic): only fmi2Reset and fmi2FreeInstance work.
    Broken,
}

/// Sets of phases in which a function may be called.
pub mod allow {
    pub const INSTANTIATED: u8 = 1;
    pub const INITIALIZATION: u8 = 2;
    pub const STEP_COMPLETE: u8 = 4;
    pub const TERMINATED: u8 = 8;
    pub const ANY: u8 = INSTANTIATED | INITIALIZATION | STEP_COMPLETE | TERMINATED;
    pub const GET: u8 = INITIALIZATION | STEP_COMPLETE | TERMINATED;
    pub const SET: u8 = INSTANTIATED | INITIALIZATION | STEP_COMPLETE;
    pub const STATUS: u8 = STEP_COMPLETE | TERMINATED;
}

impl Phase {
    fn bit(self) -> u8 {
        match self {
            Phase::Instantiated => allow::INSTANTIATED,
            Phase::InitializationMode => allow::INITIALIZATION,
            Phase::StepComplete => allow::STEP_COMPLETE,
            Phase::Terminated => allow::TERMINATED,
            Phase::Broken => 0,
        }
    }

    fn describe(mask: u8) -> String {
        let names = [
            (allow::INSTANTIATED, "Instantiated"),
            (allow::INITIALIZATION, "InitializationMode"),
            (allow::STEP_COMPLETE, "StepComplete"),
            (allow::TERMINATED, "Terminated"),
        ];
        let list: Vec<&str> = names
            .iter()
            .filter(|(b, _)| mask & b != 0)
            .map(|(_, n)| *n)
            .collect();
        if list.is_empty() {
            "no state of this FMU".into()
        } else {
            list.join(", ")
        }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Experiment {
    tolerance: Option<f64>,
    start: f64,
    stop: Option<f64>,
}

const MAGIC: u64 = 0x544c_445f_464d_5532;

/// A saved state, checked and ready to become the instance.
struct Restored {
    phase: Phase,
    values: Values,
    experiment: Experiment,
    user_tolerance: bool,
    time: f64,
    a_derivatives: [f64; 2],
    sim: Option<Damper>,
}

pub struct Instance {
    magic: u64,
    name: CString,
    logger: Logger,
    logging_on: bool,
    log_calls: bool,
    phase: Phase,
    values: Values,
    user_tolerance: bool,
    experiment: Experiment,
    time: f64,
    /// Derivatives of base.a (orders 1 and 2) for the next step only.
    a_derivatives: [f64; 2],
    sim: Option<Damper>,
}

impl Instance {
    pub fn new(name: CString, logger: Logger, logging_on: bool) -> Self {
        Instance {
            magic: MAGIC,
            name,
            logger,
            logging_on,
            log_calls: logging_on,
            phase: Phase::Instantiated,
            values: Values::start(),
            user_tolerance: false,
            experiment: Experiment::default(),
            time: 0.0,
            a_derivatives: [0.0; 2],
            sim: None,
        }
    }

    /// The instance behind a component pointer, if it carries our mark.
    ///
    /// # Safety
    /// `c` must be null or point to readable memory; a pointer we handed out and that was not
    /// freed is always accepted.
    pub unsafe fn from_ptr<'a>(c: *mut std::ffi::c_void) -> Option<&'a mut Instance> {
        let p = c as *mut Instance;
        if p.is_null() || !p.is_aligned() {
            return None;
        }
        // SAFETY: per the contract above; the mark tells our instances from anything else.
        unsafe {
            if (*p).magic == MAGIC {
                Some(&mut *p)
            } else {
                None
            }
        }
    }

    /// Wipe the mark before the memory is freed, so a second free is recognised.
    pub fn unmark(&mut self) {
        self.magic = 0;
    }

    pub fn set_broken(&mut self) {
        self.phase = Phase::Broken;
    }

    pub fn log(&self, status: Status, category: &str, message: &str) {
        let wanted = match status {
            Status::Ok => self.logging_on && self.log_calls,
            // Errors and warnings are always reported: the host must learn why a call failed.
            _ => true,
        };
        if wanted {
            self.logger.log(&self.name, status, category, message);
        }
    }

    /// Log a call when the host asked for logCalls.
    pub fn trace(&self, describe: impl FnOnce() -> String) {
        if self.logs_calls() {
            self.logger
                .log(&self.name, Status::Ok, "logCalls", &describe());
        }
    }

    #[inline]
    pub fn require(&self, allowed: u8, function: &str) -> Result<(), Refusal> {
        // Broken has no bit: it never passes.
        if self.phase.bit() & allowed != 0 {
            Ok(())
        } else {
            Err(self.not_allowed(allowed, function))
        }
    }

    #[cold]
    fn not_allowed(&self, allowed: u8, function: &str) -> Refusal {
        if self.phase == Phase::Broken {
            return refuse(format!(
                "{function} refused: an internal error made this instance unusable; call fmi2Reset or fmi2FreeInstance"
            ));
        }
        refuse(format!(
            "{function} is not allowed in state {:?} (allowed in: {})",
            self.phase,
            Phase::describe(allowed)
        ))
    }

    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Reply {
        let mut unknown = Vec::new();
        let mut calls = self.log_calls;
        if categories.is_empty() {
            calls = on;
        }
        for c in categories {
            match c.as_str() {
                "logCalls" => calls = on,
                "logStatusError" | "logStatusWarning" => {}
                other => unknown.push(other.chars().take(64).collect::<String>()),
            }
        }
        self.logging_on = on;
        self.log_calls = calls;
        if unknown.is_empty() {
            Ok(Status::Ok)
        } else {
            self.log(
                Status::Warning,
                "logStatusWarning",
                &format!(
                    "fmi2SetDebugLogging: unknown log categories {unknown:?} ignored (known: {})",
                    LOG_CATEGORIES.join(", ")
                ),
            );
            Ok(Status::Warning)
        }
    }

    pub fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    ) -> Reply {
        self.require(allow::INSTANTIATED, "fmi2SetupExperiment")?;
        if !start.is_finite() {
            return Err(refuse(format!(
                "fmi2SetupExperiment: startTime {start} is not finite"
            )));
        }
        if let Some(stop) = stop
            && (!stop.is_finite() || stop < start)
        {
            return Err(refuse(format!(
                "fmi2SetupExperiment: stopTime {stop} must be finite and not before startTime {start}"
            )));
        }
        if let Some(tol) = tolerance
            && !(tol.is_finite() && tol > 0.0)
        {
            return Err(refuse(format!(
                "fmi2SetupExperiment: tolerance {tol} must be positive and finite"
            )));
        }
        // Keep the tolerance inside the range the solver.tolerance parameter declares.
        let range = index_of(vr::SOLVER_TOLERANCE).and_then(|i| VARIABLES.get(i));
        let tolerance = tolerance.map(|t| {
            let lo = range.and_then(|v| v.min).unwrap_or(t);
            let hi = range.and_then(|v| v.max).unwrap_or(t);
            t.clamp(lo, hi)
        });
        self.experiment = Experiment {
            tolerance,
            start,
            stop,
        };
        Ok(Status::Ok)
    }

    pub fn enter_initialization_mode(&mut self) -> Reply {
        self.require(allow::INSTANTIATED, "fmi2EnterInitializationMode")?;
        self.time = self.experiment.start;
        self.phase = Phase::InitializationMode;
        Ok(Status::Ok)
    }

    pub fn exit_initialization_mode(&mut self) -> Reply {
        self.require(allow::INITIALIZATION, "fmi2ExitInitializationMode")?;
        let (sim, warnings) = self.build()?;
        self.sim = Some(sim);
        self.phase = Phase::StepComplete;
        for w in &warnings {
            self.log(Status::Warning, "logStatusWarning", w);
        }
        Ok(if warnings.is_empty() {
            Status::Ok
        } else {
            Status::Warning
        })
    }

    pub fn terminate(&mut self) -> Reply {
        self.require(allow::STEP_COMPLETE, "fmi2Terminate")?;
        self.phase = Phase::Terminated;
        Ok(Status::Ok)
    }

    pub fn reset(&mut self) -> Reply {
        if self.phase != Phase::Broken {
            self.require(allow::ANY, "fmi2Reset")?;
        }
        self.phase = Phase::Instantiated;
        self.values = Values::start();
        self.user_tolerance = false;
        self.experiment = Experiment::default();
        self.time = 0.0;
        self.a_derivatives = [0.0; 2];
        self.sim = None;
        Ok(Status::Ok)
    }

    fn build(&self) -> Result<(Damper, Vec<String>), Refusal> {
        Damper::configure(&self.configuration())
            .map_err(|e| refuse(format!("the parameters are inconsistent: {e}")))
    }

    /// The parameters as the models read them.
    fn configuration(&self) -> Configuration<'_> {
        Configuration {
            values: &self.values,
            tolerance: self.experiment.tolerance,
            user_tolerance: self.user_tolerance,
        }
    }

    /// The running simulation, or during initialisation one built on the parameters set so
    /// far (kept in `provisional` for the rest of the call).
    fn simulation<'a>(
        &'a self,
        provisional: &'a mut Option<Damper>,
    ) -> Result<&'a Damper, Refusal> {
        if let Some(sim) = &self.sim {
            return Ok(sim);
        }
        if provisional.is_none() {
            *provisional = Some(self.build()?.0);
        }
        provisional.as_ref().ok_or_else(|| refuse("no simulation"))
    }

    #[inline]
    fn variable(vr: u32, function: &str) -> Result<(usize, &'static Variable), Refusal> {
        match index_of(vr).and_then(|i| VARIABLES.get(i).map(|v| (i, v))) {
            Some(found) => Ok(found),
            None => Err(Self::unknown(vr, function)),
        }
    }

    #[cold]
    fn unknown(vr: u32, function: &str) -> Refusal {
        refuse(format!("{function}: unknown value reference {vr}"))
    }

    #[cold]
    fn wrong_type(vr: u32, var: &Variable, function: &str) -> Refusal {
        refuse(format!(
            "{function}: '{}' (value reference {vr}) is of type {:?}",
            var.name, var.ty
        ))
    }

    /// The variable behind `vr`, if it is of the type `ty` the calling function handles
    /// (fmi2Get/SetInteger also serve Enumeration variables).
    #[inline]
    fn typed_variable(
        vr: u32,
        ty: VarType,
        function: &str,
    ) -> Result<(usize, &'static Variable), Refusal> {
        let (index, var) = Self::variable(vr, function)?;
        if var.accessed_as(ty) {
            Ok((index, var))
        } else {
            Err(Self::wrong_type(vr, var, function))
        }
    }

    /// Values of the variables `vrs` of type `ty` (integers as f64), handed to `put` by position.
    #[inline(always)]
    pub fn get(
        &self,
        vrs: &[u32],
        ty: VarType,
        function: &str,
        mut put: impl FnMut(usize, f64),
    ) -> Reply {
        self.require(allow::GET, function)?;
        let inputs = self.values.inputs(self.a_derivatives);
        for (k, &r) in vrs.iter().enumerate() {
            let value = match source_of(r, ty) {
                Source::Stored(index) => self.values.at(index),
                Source::Output(which) => match &self.sim {
                    Some(sim) => sim.output(which, &inputs),
                    None => self.output_before_init(which, &inputs)?,
                },
                Source::Derived => {
                    let mut provisional = None;
                    let derived = self.simulation(&mut provisional)?.derived();
                    derived_value(r, &derived).ok_or_else(|| Self::no_value(r, function))?
                }
                Source::NoValue(_) => return Err(Self::no_value(r, function)),
                Source::WrongType(index) => {
                    return Err(Self::wrong_type(r, &VARIABLES[index], function));
                }
                Source::Unknown => return Err(Self::unknown(r, function)),
            };
            put(k, value);
        }
        Ok(Status::Ok)
    }

    /// Whether the host asked for every call to be logged.
    #[inline]
    fn logs_calls(&self) -> bool {
        self.logging_on && self.log_calls
    }

    /// fmi2GetReal's fast path, for the per-step reads of a running simulation: what `get`
    /// answers when it succeeds, without building argument slices or refusals. None (nothing
    /// written that matters: the general path then writes every value or refuses) when a
    /// pointer is null or misaligned, calls are logged, the state does not allow gets, there is
    /// no simulation yet, or a variable is anything but a stored Real or an output of
    /// [`Damper::per_step_output`].
    ///
    /// # Safety
    /// `vr` and `value`, when not null, must point to `nvr` elements each.
    #[inline(always)]
    pub unsafe fn fast_get_real(
        &self,
        vr: *const u32,
        nvr: usize,
        value: *mut f64,
    ) -> Option<Status> {
        // The general path refuses counts no array can hold before touching anything; so
        // must this one (a host's -1 as size_t would otherwise be written through).
        if vr.is_null()
            || value.is_null()
            || !vr.is_aligned()
            || !value.is_aligned()
            || nvr > isize::MAX as usize / size_of::<f64>()
        {
            return None;
        }
        if self.phase.bit() & allow::GET == 0 || self.logs_calls() {
            return None;
        }
        let sim = self.sim.as_ref()?;
        for k in 0..nvr {
            // SAFETY: k < nvr, per the contract.
            let r = unsafe { *vr.add(k) };
            let v = match source_of(r, VarType::Real) {
                Source::Output(which) => sim.per_step_output(which)?,
                Source::Stored(index) => self.values.at(index),
                _ => return None,
            };
            // SAFETY: k < nvr, per the contract.
            unsafe { *value.add(k) = v };
        }
        Some(Status::Ok)
    }

    /// fmi2SetReal's fast path, for the per-step input: one variable that `set` would accept,
    /// set the same way. None (nothing changed) for anything else, and whenever calls are
    /// logged; the general path then takes the call.
    ///
    /// # Safety
    /// `vr` and `value`, when not null, must point to `nvr` elements each.
    #[inline(always)]
    pub unsafe fn fast_set_real(
        &mut self,
        vr: *const u32,
        nvr: usize,
        value: *const f64,
    ) -> Option<Status> {
        if nvr != 1 || vr.is_null() || value.is_null() || !vr.is_aligned() || !value.is_aligned() {
            return None;
        }
        if self.phase.bit() & allow::SET == 0 || self.logs_calls() {
            return None;
        }
        // SAFETY: one element each, per the contract.
        let (r, v) = unsafe { (*vr, *value) };
        // The per-step input by a table lookup; any other variable (and a value that is not
        // finite) by the general path's full check. Nothing here calls out, so the host's
        // per-step call costs no saved registers.
        let index = free_real_input(r).filter(|_| finite(v))?;
        self.put(r, index, v);
        Some(Status::Ok)
    }

    /// An output before the simulation exists: from the simulation the values would start.
    #[cold]
    #[inline(never)]
    fn output_before_init(&self, which: Output, inputs: &Inputs) -> Result<f64, Refusal> {
        let mut provisional = None;
        Ok(self.simulation(&mut provisional)?.output(which, inputs))
    }

    #[cold]
    fn no_value(vr: u32, function: &str) -> Refusal {
        let name = index_of(vr).map_or("?", |i| VARIABLES[i].name);
        refuse(format!("{function}: '{name}' has no value"))
    }

    /// Set the variables `vrs` of type `ty`: all are checked before any is changed.
    #[inline(always)]
    pub fn set(&mut self, vrs: &[u32], values: &[f64], ty: VarType, function: &str) -> Reply {
        self.require(allow::SET, function)?;
        // One variable (an input per step, the usual call): checked and set in one pass.
        if let ([r], [value]) = (vrs, values) {
            let index = self.check_set(*r, *value, ty, function)?;
            self.put(*r, index, *value);
            return Ok(Status::Ok);
        }
        for (&r, &value) in vrs.iter().zip(values) {
            self.check_set(r, value, ty, function)?;
        }
        for (&r, &value) in vrs.iter().zip(values) {
            if let Some(index) = index_of(r) {
                self.put(r, index, value);
            }
        }
        Ok(Status::Ok)
    }

    #[inline]
    fn put(&mut self, r: u32, index: usize, value: f64) {
        self.values.set_at(index, value);
        if r == vr::SOLVER_TOLERANCE {
            self.user_tolerance = true;
        }
    }

    /// The position in the values of the variable `r`, if `value` may be set there now.
    #[inline(always)]
    fn check_set(&self, r: u32, value: f64, ty: VarType, function: &str) -> Result<usize, Refusal> {
        let (index, var) = Self::typed_variable(r, ty, function)?;
        match var.causality {
            Causality::Parameter => {
                let before_init =
                    matches!(self.phase, Phase::Instantiated | Phase::InitializationMode);
                if !before_init && var.variability != Variability::Tunable {
                    return Err(refuse(format!(
                        "{function}: '{}' is a fixed parameter and can only be set before fmi2ExitInitializationMode",
                        var.name
                    )));
                }
            }
            Causality::Input => {}
            _ => {
                return Err(refuse(format!(
                    "{function}: '{}' is computed by the FMU and cannot be set",
                    var.name
                )));
            }
        }
        if let Some(reason) = var.reject(value) {
            return Err(refuse(format!("{function}: {reason}")));
        }
        Ok(index)
    }

    /// fmi2SetRealInputDerivatives: derivatives of Real inputs for the next step. base.a's are
    /// used (orders 1 and 2); those of base.v and base.x are accepted and not needed.
    pub fn set_input_derivatives(&mut self, vrs: &[u32], orders: &[i32], values: &[f64]) -> Reply {
        const F: &str = "fmi2SetRealInputDerivatives";
        self.require(allow::SET, F)?;
        for ((&r, &order), &value) in vrs.iter().zip(orders).zip(values) {
            let (_, var) = Self::variable(r, F)?;
            if var.causality != Causality::Input || var.ty != VarType::Real {
                return Err(refuse(format!("{F}: '{}' is not a Real input", var.name)));
            }
            if !(1..=2).contains(&order) {
                return Err(refuse(format!(
                    "{F}: order {order} for '{}' is not supported (1 or 2)",
                    var.name
                )));
            }
            if !value.is_finite() {
                return Err(refuse(format!(
                    "{F}: derivative {value} of '{}' must be finite",
                    var.name
                )));
            }
        }
        for ((&r, &order), &value) in vrs.iter().zip(orders).zip(values) {
            if r == vr::BASE_A {
                self.a_derivatives[order as usize - 1] = value;
            }
        }
        Ok(Status::Ok)
    }

    /// fmi2GetRealOutputDerivatives: exact first derivatives of outputs, handed to `put`.
    pub fn output_derivatives(
        &self,
        vrs: &[u32],
        orders: &[i32],
        mut put: impl FnMut(usize, f64),
    ) -> Reply {
        const F: &str = "fmi2GetRealOutputDerivatives";
        self.require(allow::STATUS, F)?;
        let sim = self
            .sim
            .as_ref()
            .ok_or_else(|| refuse(format!("{F}: not initialised")))?;
        let inputs = self.values.inputs(self.a_derivatives);
        for (k, (&r, &order)) in vrs.iter().zip(orders).enumerate() {
            let (_, var) = Self::variable(r, F)?;
            let Some(which) = output_of(r) else {
                return Err(refuse(format!("{F}: '{}' is not an output", var.name)));
            };
            if order != 1 {
                return Err(refuse(format!(
                    "{F}: order {order} of '{}' is not offered (maxOutputDerivativeOrder = 1)",
                    var.name
                )));
            }
            let value = sim.output_derivative(which, &inputs);
            put(k, value);
        }
        Ok(Status::Ok)
    }

    #[inline]
    pub fn do_step(&mut self, t: f64, h: f64) -> Reply {
        self.require(allow::STEP_COMPLETE, "fmi2DoStep")?;
        if !(finite(h) && h > 0.0) {
            return Err(refuse(format!(
                "fmi2DoStep: communicationStepSize {h} must be positive and finite"
            )));
        }
        if !finite(t) {
            return Err(refuse(format!(
                "fmi2DoStep: currentCommunicationPoint {t} is not finite"
            )));
        }
        // Hosts accumulate time with rounding: accept a small mismatch, refuse a real one.
        let slack = 1e-9 * self.time.abs().max(1.0) + 1e-6 * h;
        if (t - self.time).abs() > slack {
            return Err(refuse(format!(
                "fmi2DoStep: currentCommunicationPoint {t} does not match the FMU's time {} (the FMU cannot jump in time)",
                self.time
            )));
        }
        if let Some(stop) = self.experiment.stop
            && t + h > stop + 1e-9 * stop.abs().max(1.0) + 1e-6 * h
        {
            return Err(refuse(format!(
                "fmi2DoStep: the step to {} would pass the stop time {stop}",
                t + h
            )));
        }
        let inputs = self.values.inputs(self.a_derivatives);
        let sim = self
            .sim
            .as_mut()
            .ok_or_else(|| refuse("fmi2DoStep: no simulation (not initialised)"))?;
        match sim.step(t, h, &inputs) {
            Ok(_) => {
                self.time = t + h;
                // Input derivatives describe one communication step.
                self.a_derivatives = [0.0; 2];
                Ok(Status::Ok)
            }
            Err(e) => {
                let status = match e {
                    StepError::Solver(SolveError::TooManySteps { .. }) => Status::Discard,
                    _ => Status::Error,
                };
                let hint = if status == Status::Discard {
                    " The state is left at the start of the step; retry with a smaller communication step."
                } else {
                    " The state is left at the start of the step."
                };
                Err(Refusal::new(
                    status,
                    format!("fmi2DoStep from t = {t} by {h}: {e}.{hint}"),
                ))
            }
        }
    }

    /// The whole instance (less what the host gave it) as bytes.
    pub fn save(&self) -> Vec<u8> {
        Saved {
            phase: match self.phase {
                Phase::Instantiated => 0,
                Phase::InitializationMode => 1,
                Phase::StepComplete => 2,
                Phase::Terminated | Phase::Broken => 3,
            },
            user_tolerance: self.user_tolerance,
            tolerance: self.experiment.tolerance,
            start: self.experiment.start,
            stop: self.experiment.stop,
            time: self.time,
            a_derivatives: self.a_derivatives,
            values: self.values.as_slice().to_vec(),
            simulation: self.sim.as_ref().map(Damper::snapshot).unwrap_or_default(),
        }
        .encode()
    }

    /// Check a saved state completely, without applying it.
    pub fn check_saved(bytes: &[u8]) -> Result<(), Refusal> {
        Self::restored(bytes).map(|_| ())
    }

    /// Become the instance `bytes` describes; on any error nothing changes.
    pub fn load(&mut self, bytes: &[u8]) -> Reply {
        let r = Self::restored(bytes)?;
        self.phase = r.phase;
        self.values = r.values;
        self.experiment = r.experiment;
        self.user_tolerance = r.user_tolerance;
        self.time = r.time;
        self.a_derivatives = r.a_derivatives;
        self.sim = r.sim;
        Ok(Status::Ok)
    }

    fn restored(bytes: &[u8]) -> Result<Restored, Refusal> {
        let bad = |why: String| refuse(format!("the FMU state is not usable: {why}"));
        let s = Saved::decode(bytes).map_err(|r| bad(*r.message))?;
        let phase = match s.phase {
            0 => Phase::Instantiated,
            1 => Phase::InitializationMode,
            2 => Phase::StepComplete,
            3 => Phase::Terminated,
            other => return Err(bad(format!("unknown state code {other}"))),
        };
        let [d1, d2] = s.a_derivatives;
        let finite = [s.time, s.start, s.stop.unwrap_or(0.0), d1, d2]
            .iter()
            .all(|x| x.is_finite());
        let tolerance_ok = s.tolerance.is_none_or(|t| t.is_finite() && t > 0.0);
        if !finite || !tolerance_ok {
            return Err(bad(
                "non-finite time, tolerance, experiment bounds or input derivatives".into(),
            ));
        }
        let values = Values::from_saved(&s.values).map_err(bad)?;
        let initialised = matches!(phase, Phase::StepComplete | Phase::Terminated);
        let sim = if initialised {
            let configuration = Configuration {
                values: &values,
                tolerance: s.tolerance,
                user_tolerance: s.user_tolerance,
            };
            Some(Damper::restore(&configuration, &s.simulation).map_err(bad)?)
        } else if s.simulation.is_empty() {
            None
        } else {
            return Err(bad(
                "simulation values in a state before initialisation".into()
            ));
        };
        Ok(Restored {
            phase,
            values,
            experiment: Experiment {
                tolerance: s.tolerance,
                start: s.start,
                stop: s.stop,
            },
            user_tolerance: s.user_tolerance,
            time: s.time,
            a_derivatives: s.a_derivatives,
            sim,
        })
    }

    pub fn last_successful_time(&self) -> Result<f64, Refusal> {
        self.require(allow::STATUS, "fmi2GetRealStatus")?;
        Ok(self.time)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table behind fmi2SetReal's fast path must agree with the full check: every variable
    /// in it takes any finite value, at its own position, in every phase that allows sets, and
    /// refuses a non-finite one; and every Real input the full check would take that way is in it.
    #[test]
    fn free_real_inputs_are_what_the_full_check_accepts() {
        let mut inst = Instance::new(c"t".into(), Logger::new(None, std::ptr::null_mut()), false);
        let mut listed = 0;
        for phase in [
            Phase::Instantiated,
            Phase::InitializationMode,
            Phase::StepComplete,
        ] {
            assert_ne!(phase.bit() & allow::SET, 0);
            inst.phase = phase;
            for var in VARIABLES {
                let r = var.vr;
                let full = |v: f64| inst.check_set(r, v, VarType::Real, "t").ok();
                let any_finite = [f64::MAX, -f64::MAX, 0.0, 5e-324, -1.5e7]
                    .iter()
                    .all(|&v| full(v) == index_of(r));
                match free_real_input(r) {
                    Some(index) => {
                        listed += 1;
                        assert_eq!(Some(index), index_of(r), "{}", var.name);
                        assert!(any_finite, "{} in {phase:?}", var.name);
                        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                            assert_eq!(full(v), None, "{} = {v}", var.name);
                        }
                    }
                    None => assert!(
                        !(any_finite && var.causality == Causality::Input),
                        "{} is a Real input the full check takes as any finite value: list it",
                        var.name
                    ),
                }
            }
        }
        assert!(listed >= 3, "base.a, base.v and base.x at least");
    }
}
