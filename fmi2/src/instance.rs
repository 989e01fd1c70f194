//! One FMU instance: what every FMU shares (its name, logger and logging switches, the phase of
//! the call sequence, the experiment, the time) around the slave. The phase of every call is
//! checked before it gets here (exports, by the table in `calls`); every refused call leaves
//! the instance exactly as it was and says why.

use std::ffi::CString;

use crate::calls::{Call, Phase};
use crate::description::{VarType, log_category};
use crate::frame::{self, Common, Experiment};
use crate::logger::Logger;
use crate::slave::{Context, Slave};
use crate::status::{Refusal, Reply, Status, refuse};

/// The interface an instance was made for (fmi2Instantiate's fmuType).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    CoSimulation,
    ModelExchange,
}

pub struct Instance<S> {
    magic: u64,
    pub kind: Kind,
    name: CString,
    logger: Logger,
    logging_on: bool,
    log_calls: bool,
    pub context: Context,
    pub slave: S,
}

impl<S: Slave> Instance<S> {
    pub fn new(name: CString, logger: Logger, logging_on: bool, kind: Kind) -> Self {
        Instance {
            magic: S::MARK,
            kind,
            name,
            logger,
            logging_on,
            log_calls: logging_on,
            context: Context {
                phase: Phase::Instantiated,
                experiment: Experiment::default(),
                time: 0.0,
            },
            slave: S::new(),
        }
    }

    /// The instance behind a component pointer, if it carries the mark of this slave.
    ///
    /// # Safety
    /// `c` must be null or point to readable memory; a pointer we handed out and that was not
    /// freed is always accepted.
    #[inline(always)]
    pub unsafe fn from_ptr<'a>(c: *mut std::ffi::c_void) -> Option<&'a mut Self> {
        let p = c as *mut Self;
        if p.is_null() || !p.is_aligned() {
            return None;
        }
        // SAFETY: per the contract above; the mark tells our instances from anything else.
        unsafe {
            if (*p).magic == S::MARK {
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
        self.context.phase = Phase::Broken;
    }

    pub fn phase(&self) -> Phase {
        self.context.phase
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

    /// Whether the host asked for every call to be logged.
    #[inline(always)]
    pub fn logs_calls(&self) -> bool {
        self.logging_on && self.log_calls
    }

    /// Whether `call` is allowed in the instance's phase and carried out with nothing to log
    /// (the host did not ask for every call to be logged): what a quick path may assume.
    #[inline(always)]
    pub fn passes_quietly(&self, call: &Call) -> bool {
        self.context.phase.bit() & call.allowed != 0 && !self.logs_calls()
    }

    /// Whether `call` is allowed in the instance's phase; if not, why and what to do.
    #[inline(always)]
    pub fn require(&self, call: &Call) -> Result<(), Refusal> {
        if self.context.phase.bit() & call.allowed != 0 {
            Ok(())
        } else {
            Err(self.refused(call))
        }
    }

    /// Why `call` is refused in this phase (out of line: the per-step calls pass).
    #[cold]
    #[inline(never)]
    fn refused(&self, call: &Call) -> Refusal {
        refuse(self.context.phase.refusal(call, S::TABLE.model_identifier))
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
                    S::TABLE.log_categories.join(", ")
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
        self.context.experiment = Experiment {
            tolerance: tolerance.map(S::tolerance),
            start,
            stop,
        };
        Ok(Status::Ok)
    }

    pub fn enter_initialization_mode(&mut self) -> Reply {
        self.context.time = self.context.experiment.start;
        self.context.phase = Phase::InitializationMode;
        Ok(Status::Ok)
    }

    pub fn exit_initialization_mode(&mut self) -> Reply {
        let warnings = self.slave.initialise(&self.context)?;
        self.context.phase = match self.kind {
            Kind::CoSimulation => Phase::StepComplete,
            Kind::ModelExchange => {
                if let Err(why) = self.slave.offers_model_exchange() {
                    // Back to where the host was: it may choose another model and try again.
                    self.slave.uninitialise();
                    return Err(refuse(format!(
                        "fmi2ExitInitializationMode: Model Exchange is not offered for these parameters: {why}"
                    )));
                }
                Phase::EventMode
            }
        };
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
        self.context.phase = Phase::Terminated;
        Ok(Status::Ok)
    }

    /// Back to a new instance's state; also the way out of an internal error.
    pub fn reset(&mut self) -> Reply {
        self.context = Context {
            phase: Phase::Instantiated,
            experiment: Experiment::default(),
            time: 0.0,
        };
        self.slave = S::new();
        Ok(Status::Ok)
    }

    #[inline]
    pub fn do_step(&mut self, t: f64, h: f64) -> Reply {
        let now = self.context.time;
        // The usual step, told in a few instructions: h positive and finite, t within 1e-6 h of
        // the FMU's time (so finite), which the checks of `step_refusal::check` accept too.
        let usual = h > 0.0 && h <= f64::MAX && (t - now).abs() <= 1e-6 * h;
        if !usual {
            step_refusal::check(t, h, now)?;
        }
        if let Some(stop) = self.context.experiment.stop
            && t + h > stop + 1e-9 * stop.abs().max(1.0) + 1e-6 * h
        {
            return Err(step_refusal::past_stop(t + h, stop));
        }
        let noticed = self.slave.step(&self.context, t, h)?;
        self.context.time = t + h;
        if noticed {
            return Ok(self.pass_notice());
        }
        Ok(Status::Ok)
    }

    /// The slave's notice of the step just carried out, to the host as a warning.
    #[cold]
    #[inline(never)]
    fn pass_notice(&mut self) -> Status {
        let Some(message) = self.slave.notice(&self.context) else {
            return Status::Ok;
        };
        self.log(Status::Warning, log_category::LOG_STATUS_WARNING, &message);
        Status::Warning
    }

    pub fn last_successful_time(&self) -> f64 {
        self.context.time
    }

    /// The whole instance (less what the host gave it) as bytes.
    pub fn save(&self) -> Vec<u8> {
        let common = Common {
            phase: self.context.phase,
            experiment: self.context.experiment,
            time: self.context.time,
            flag: self.slave.flag(),
        };
        frame::encode(
            &S::STATE_TAG,
            S::STATE_VERSION,
            S::TABLE.guid,
            &common,
            |out| self.slave.save(out),
        )
    }

    /// The context and slave `bytes` describe, checked completely (a running state of one
    /// interface does not restore into an instance of the other).
    fn restored(&self, bytes: &[u8]) -> Result<(Context, S), Refusal> {
        let (context, slave) = Self::restored_any(bytes)?;
        let me_phase = matches!(context.phase, Phase::EventMode | Phase::ContinuousTimeMode);
        let cs_phase = context.phase == Phase::StepComplete;
        match self.kind {
            Kind::CoSimulation if me_phase => Err(frame::unusable(
                "it was saved by a Model Exchange instance; restore it into one made with fmi2ModelExchange",
            )),
            Kind::ModelExchange if cs_phase => Err(frame::unusable(
                "it was saved by a Co-Simulation instance; restore it into one made with fmi2CoSimulation",
            )),
            // Running or terminated, a Model Exchange instance hands out continuous states: its
            // parameters must be ones Model Exchange offers (a forged or Co-Simulation state of
            // another model is not; found by the coverage-guided fuzzer).
            Kind::ModelExchange if me_phase || context.phase == Phase::Terminated => {
                match slave.offers_model_exchange() {
                    Ok(()) => Ok((context, slave)),
                    Err(why) => Err(frame::unusable(&format!(
                        "Model Exchange is not offered for its parameters: {why}"
                    ))),
                }
            }
            _ => Ok((context, slave)),
        }
    }

    fn restored_any(bytes: &[u8]) -> Result<(Context, S), Refusal> {
        let t = S::TABLE;
        let read = || -> Result<(Context, S), String> {
            let (common, mut part) = frame::decode(
                bytes,
                &S::STATE_TAG,
                S::STATE_VERSION,
                t.guid,
                t.model_identifier,
            )?;
            let context = Context {
                phase: common.phase,
                experiment: common.experiment,
                time: common.time,
            };
            let slave = S::load(&context, common.flag, &mut part)?;
            part.finish()?;
            finite_values(&context, &slave)?;
            Ok((context, slave))
        };
        read().map_err(|why| frame::unusable(&why))
    }

    /// Check a saved state completely, without applying it.
    pub fn check_saved(&self, bytes: &[u8]) -> Result<(), Refusal> {
        self.restored(bytes).map(|_| ())
    }

    /// Become the instance `bytes` describes; on any error nothing changes.
    pub fn load(&mut self, bytes: &[u8]) -> Reply {
        let (context, slave) = self.restored(bytes)?;
        self.context = context;
        self.slave = slave;
        Ok(Status::Ok)
    }
}

/// fmi2DoStep's checks of its arguments and their refusals, out of line (see
/// [`super::Instance::do_step`]).
mod step_refusal {
    use crate::status::{Refusal, refuse};

    /// A step from `t` by `h` where the FMU's time is `now`: h positive and finite, t finite
    /// and `now` but for the rounding of a host that accumulates time. The refusals are made
    /// out of line from the values: a message formed here would keep t, h and the times in
    /// memory for its arguments.
    #[inline(never)]
    pub fn check(t: f64, h: f64, now: f64) -> Result<(), Refusal> {
        if !(crate::description::finite(h) && h > 0.0) {
            return Err(size(h));
        }
        if !crate::description::finite(t) {
            return Err(point(t));
        }
        // Hosts accumulate time with rounding: accept a small mismatch, refuse a real one.
        let slack = 1e-9 * now.abs().max(1.0) + 1e-6 * h;
        if (t - now).abs() > slack {
            return Err(jump(t, now));
        }
        Ok(())
    }

    #[cold]
    #[inline(never)]
    pub fn size(h: f64) -> Refusal {
        refuse(format!(
            "fmi2DoStep: communicationStepSize {h} must be positive and finite"
        ))
    }

    #[cold]
    #[inline(never)]
    pub fn point(t: f64) -> Refusal {
        refuse(format!(
            "fmi2DoStep: currentCommunicationPoint {t} is not finite"
        ))
    }

    #[cold]
    #[inline(never)]
    pub fn jump(t: f64, now: f64) -> Refusal {
        refuse(format!(
            "fmi2DoStep: currentCommunicationPoint {t} does not match the FMU's time {now} (the FMU cannot jump in time)"
        ))
    }

    #[cold]
    #[inline(never)]
    pub fn past_stop(end: f64, stop: f64) -> Refusal {
        refuse(format!(
            "fmi2DoStep: the step to {end} would pass the stop time {stop}"
        ))
    }
}

/// Every Real variable of a slave just loaded from a state that the slave can read is finite.
/// A state is bytes from a host: one that passes the frame's checks (its checksum recomputed)
/// and the slave's own can still hold finite numbers from which outputs and derivatives come
/// out infinite or NaN (coverage-guided fuzzing found such a TLD state: fuzz/, docs/FUZZING.md).
fn finite_values<S: Slave>(context: &Context, slave: &S) -> Result<(), String> {
    for v in S::TABLE.variables.iter().filter(|v| v.ty == VarType::Real) {
        let mut x = [0.0];
        let read = slave.get(context, &[v.vr], &mut x, VarType::Real, "", |x| x);
        if read.is_ok() && !x[0].is_finite() {
            return Err(format!("its values give {} = {}", v.name, x[0]));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
