//! One FMU instance: the FMI 2.0 Co-Simulation call sequence and stepping. The phase of every
//! call is checked before it gets here (exports, by the table in `calls`); every refused call
//! leaves the instance exactly as it was and says why.

use std::ffi::CString;

use super::calls::{Call, Phase};
use super::logger::Logger;
use super::params::{Configuration, Values};
use super::status::{Refusal, Reply, Status, refuse};
use super::vars::{LOG_CATEGORIES, VARIABLES, finite, index_of, log_category, vr};
use crate::model::{Damper, StepError};
use crate::solver::SolveError;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Experiment {
    pub tolerance: Option<f64>,
    pub start: f64,
    pub stop: Option<f64>,
}

const MAGIC: u64 = 0x544c_445f_464d_5532;

pub struct Instance {
    magic: u64,
    name: CString,
    logger: Logger,
    logging_on: bool,
    log_calls: bool,
    pub(super) phase: Phase,
    pub(super) values: Values,
    pub(super) user_tolerance: bool,
    pub(super) experiment: Experiment,
    pub(super) time: f64,
    /// Derivatives of base.a (orders 1 and 2) for the next step only.
    pub(super) a_derivatives: [f64; 2],
    pub(super) sim: Option<Damper>,
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
    #[inline(always)]
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
            Status::Ok => self.logs_calls(),
            // Errors and warnings are always reported: the host must learn why a call failed.
            _ => true,
        };
        if wanted {
            self.logger.log(&self.name, status, category, message);
        }
    }

    /// The damper's notice of implausible motion, to the host as a warning once per run.
    #[cold]
    #[inline(never)]
    fn pass_notice(&mut self) -> Status {
        let (time, a) = (self.time, self.values.get(vr::BASE_A));
        let Some(notice) = self.sim.as_mut().and_then(|sim| sim.notice(a)) else {
            return Status::Ok;
        };
        self.log(
            Status::Warning,
            log_category::LOG_STATUS_WARNING,
            &format!("fmi2DoStep to t = {time}: {notice}"),
        );
        Status::Warning
    }

    /// Whether the host asked for every call to be logged.
    #[inline(always)]
    pub fn logs_calls(&self) -> bool {
        self.logging_on && self.log_calls
    }

    /// Whether `call` is allowed in the instance's phase; if not, why and what to do.
    #[inline(always)]
    pub fn require(&self, call: &Call) -> Result<(), Refusal> {
        if self.phase.bit() & call.allowed != 0 {
            Ok(())
        } else {
            Err(refuse(self.phase.refusal(call)))
        }
    }

    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> Reply {
        let mut unknown = Vec::new();
        let mut calls = self.log_calls;
        if categories.is_empty() {
            calls = on;
        }
        for c in categories {
            match c.as_str() {
                log_category::LOG_CALLS => calls = on,
                log_category::LOG_STATUS_ERROR | log_category::LOG_STATUS_WARNING => {}
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
                log_category::LOG_STATUS_WARNING,
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
        self.time = self.experiment.start;
        self.phase = Phase::InitializationMode;
        Ok(Status::Ok)
    }

    pub fn exit_initialization_mode(&mut self) -> Reply {
        let (sim, warnings) = self.build()?;
        self.sim = Some(sim);
        self.phase = Phase::StepComplete;
        for w in &warnings {
            self.log(Status::Warning, log_category::LOG_STATUS_WARNING, w);
        }
        Ok(if warnings.is_empty() {
            Status::Ok
        } else {
            Status::Warning
        })
    }

    pub fn terminate(&mut self) -> Reply {
        self.phase = Phase::Terminated;
        Ok(Status::Ok)
    }

    /// Back to a new instance's state; also the way out of an internal error.
    pub fn reset(&mut self) -> Reply {
        self.phase = Phase::Instantiated;
        self.values = Values::start();
        self.user_tolerance = false;
        self.experiment = Experiment::default();
        self.time = 0.0;
        self.a_derivatives = [0.0; 2];
        self.sim = None;
        Ok(Status::Ok)
    }

    pub(super) fn build(&self) -> Result<(Damper, Vec<String>), Refusal> {
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
    pub(super) fn simulation<'a>(
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
    pub fn do_step(&mut self, t: f64, h: f64) -> Reply {
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
            Ok(report) => {
                self.time = t + h;
                // Input derivatives describe one communication step.
                self.a_derivatives = [0.0; 2];
                if report.implausible {
                    return Ok(self.pass_notice());
                }
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

    pub fn last_successful_time(&self) -> f64 {
        self.time
    }
}
