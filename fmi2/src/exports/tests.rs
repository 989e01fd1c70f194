//! The exports driven as a host drives them, with a slave of the tests' own that can panic and
//! leaves the slave contract's defaults (`Slave::tolerance`, `Slave::notice`) as they are:
//! neither FMU of the workspace panics through its entry points, and TLD overrides both defaults.

use std::collections::BTreeMap;
use std::ffi::CString;
use std::sync::{Mutex, Once};

use fmi_sys::fmi2::*;

use super::*;
use crate::continuous::Continuous;
use crate::description::{Table, VarType};
use crate::frame::Reader;
use crate::slave::Context;
use crate::status::refuse;

/// A slave with one variable, a Boolean at value reference 0 (its own: not in the table, which
/// the shared layer leaves to the slave): it counts its steps, takes a step of `PANIC_STEP` s for a bug
/// (it panics), and one of `NOTICE_STEP` s for a step with a notice (which it leaves to the
/// default `notice`). It keeps the experiment's tolerance as `initialise` sees it.
pub(super) struct Testy {
    steps: u32,
    pub(super) tolerance: Option<f64>,
    flag: f64,
}

pub(super) const PANIC_STEP: f64 = 13.0;
pub(super) const NOTICE_STEP: f64 = 7.0;

static TABLE: Table = Table {
    model_identifier: "Testy",
    guid: "{testy}",
    variables: &[],
    vr_index: &[],
    log_categories: &[
        log_category::LOG_STATUS_ERROR,
        log_category::LOG_STATUS_WARNING,
        log_category::LOG_CALLS,
    ],
};

impl Continuous for Testy {}

/// Testy's get and set: only its Boolean, value reference 0.
fn flag_only(vrs: &[u32], ty: VarType, function: &str) -> Result<(), Refusal> {
    match vrs.iter().find(|&&r| r != 0) {
        None if ty == VarType::Boolean || vrs.is_empty() => Ok(()),
        None => Err(refuse(format!("{function}: the variable is a Boolean"))),
        Some(r) => Err(refuse(format!("{function}: no variable {r}"))),
    }
}

impl Slave for Testy {
    const TABLE: &'static Table = &TABLE;
    const MARK: u64 = 0x5445_5354_5953_4c56;
    const STATE_TAG: [u8; 4] = *b"TSTY";
    const STATE_VERSION: u16 = 1;

    fn new() -> Self {
        Testy {
            steps: 0,
            tolerance: None,
            flag: 0.0,
        }
    }
    fn initialise(&mut self, context: &Context) -> Result<Vec<String>, Refusal> {
        self.tolerance = context.experiment.tolerance;
        Ok(Vec::new())
    }
    fn uninitialise(&mut self) {}
    fn step(&mut self, _: &Context, _: f64, h: f64) -> Result<bool, Refusal> {
        assert!(h != PANIC_STEP, "a bug in the slave's step");
        self.steps += 1;
        Ok(h == NOTICE_STEP)
    }
    fn get<T>(
        &self,
        _: &Context,
        vrs: &[u32],
        out: &mut [T],
        ty: VarType,
        f: &str,
        to: fn(f64) -> T,
    ) -> Reply {
        flag_only(vrs, ty, f)?;
        out.iter_mut().for_each(|slot| *slot = to(self.flag));
        Ok(Status::Ok)
    }
    fn set<T: Copy>(
        &mut self,
        _: &Context,
        vrs: &[u32],
        values: &[T],
        ty: VarType,
        f: &str,
        from: fn(T) -> f64,
    ) -> Reply {
        flag_only(vrs, ty, f)?;
        if let Some(&v) = values.last() {
            self.flag = from(v);
        }
        Ok(Status::Ok)
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
        Err(refuse("no outputs"))
    }
    fn save(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.steps.to_le_bytes());
    }
    fn load(_: &Context, _: bool, part: &mut Reader) -> Result<Self, String> {
        Ok(Testy {
            steps: part.u32()?,
            tolerance: None,
            flag: 0.0,
        })
    }
}

/// The C entry points, as an FMU of Testy exports them.
mod c {
    use super::Testy;
    crate::export_fmi2!(Testy);
    pub(super) use fmi2_exports::fmi2DoStep;
}

/// What each instance logged, by instance name: (level, message).
static RECORDS: Mutex<BTreeMap<String, Vec<(log::Level, String)>>> = Mutex::new(BTreeMap::new());

/// The host's log, as fmi-sys's C logger hands the messages to the `log` crate.
struct Capture;

impl log::Log for Capture {
    fn enabled(&self, _: &log::Metadata) -> bool {
        true
    }
    fn log(&self, record: &log::Record) {
        let said = (record.level(), record.args().to_string());
        let mut records = RECORDS.lock().unwrap();
        records
            .entry(record.target().into())
            .or_default()
            .push(said);
    }
    fn flush(&self) {}
}

/// The messages logged so far for the instance `name`, with their levels.
pub(crate) fn logs_of(name: &str) -> Vec<(log::Level, String)> {
    let records = RECORDS.lock().unwrap();
    records.get(name).cloned().unwrap_or_default()
}

/// Route the host's log (fmi-sys's C logger, through the `log` crate) into [`RECORDS`]: once
/// per test process, for every test module that reads it with [`logs_of`].
pub(crate) fn capture_logs() {
    static LOGGER: Once = Once::new();
    LOGGER.call_once(|| {
        log::set_logger(&Capture).unwrap();
        log::set_max_level(log::LevelFilter::Trace);
    });
}

/// An instance of `S` named `name` made by fmi2Instantiate for the interface `kind` with
/// `logging_on`, logging through fmi-sys's C logger into [`RECORDS`]; with the callbacks, which
/// must outlive it.
pub(crate) fn instantiate<S: Slave>(
    name: &str,
    kind: fmi2Type,
    logging_on: bool,
) -> (fmi2Component, Box<fmi2CallbackFunctions>) {
    capture_logs();
    let callbacks = Box::new(fmi2CallbackFunctions {
        logger: Some(fmi_sys::fmi2::logger::callback_logger_handler),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    });
    let name = CString::new(name).unwrap();
    let guid = CString::new(S::TABLE.guid).unwrap();
    // SAFETY: valid strings and callbacks, which outlive the instance.
    let c = unsafe {
        fmi2Instantiate::<S>(
            name.as_ptr(),
            kind,
            guid.as_ptr(),
            std::ptr::null(),
            &*callbacks,
            0,
            i32::from(logging_on),
        )
    };
    assert!(!c.is_null());
    (c, callbacks)
}

/// An instance of Testy, named `name` (each test its own), logging through fmi-sys's C logger
/// into [`RECORDS`], set up with `tolerance` and initialised.
pub(super) struct Host {
    pub(super) c: fmi2Component,
    _callbacks: Box<fmi2CallbackFunctions>,
}

impl Host {
    pub(super) fn new(name: &str, tolerance: Option<f64>) -> Self {
        let (c, callbacks) = instantiate::<Testy>(name, fmi2Type_fmi2CoSimulation, false);
        let host = Host {
            c,
            _callbacks: callbacks,
        };
        host.initialise(tolerance);
        host
    }

    pub(super) fn initialise(&self, tolerance: Option<f64>) {
        // SAFETY: our live instance.
        unsafe {
            let t = tolerance.unwrap_or(0.0);
            let setup =
                fmi2SetupExperiment::<Testy>(self.c, tolerance.is_some() as i32, t, 0.0, 0, 0.0);
            assert_eq!(setup, fmi2Status_fmi2OK);
            assert_eq!(
                fmi2EnterInitializationMode::<Testy>(self.c),
                fmi2Status_fmi2OK
            );
            assert_eq!(
                fmi2ExitInitializationMode::<Testy>(self.c),
                fmi2Status_fmi2OK
            );
        }
    }

    pub(super) fn instance(&self) -> &Instance<Testy> {
        // SAFETY: our live instance.
        unsafe { Instance::<Testy>::from_ptr(self.c) }
            .map(|i| &*i)
            .unwrap()
    }

    pub(super) fn step(&self, h: f64) -> fmi2Status {
        let t = self.instance().context.time;
        // SAFETY: our live instance.
        unsafe { fmi2DoStep::<Testy>(self.c, t, h, 1) }
    }
}

impl Drop for Host {
    fn drop(&mut self) {
        // SAFETY: our instance, freed once.
        unsafe { fmi2FreeInstance::<Testy>(self.c) };
    }
}

#[test]
fn a_panic_in_a_call_is_an_error_that_leaves_only_reset() {
    let name = "panicky";
    let host = Host::new(name, None);
    assert_eq!(host.step(1.0), fmi2Status_fmi2OK);
    assert_eq!(host.instance().slave.steps, 1);

    // The slave's bug: caught, an error said, the step not taken. Called through the extern
    // "C" function the FMU exports (a panic escaping it would abort the test).
    // SAFETY: our live instance.
    let status = unsafe { c::fmi2DoStep(host.c, 1.0, PANIC_STEP, 1) };
    assert_eq!(status, fmi2Status_fmi2Error);
    let logs = logs_of(name);
    assert_eq!(
        logs,
        [(
            log::Level::Error,
            "fmi2DoStep: internal error (please report it); call fmi2Reset or fmi2FreeInstance"
                .to_string()
        )]
    );
    assert_eq!(host.instance().context.time, 1.0);

    // Broken: any call but reset and free refused, saying so.
    assert_eq!(host.step(1.0), fmi2Status_fmi2Error);
    assert_eq!(host.instance().slave.steps, 1);
    let mut state: fmi2FMUstate = std::ptr::null_mut();
    // SAFETY: our live instance, a valid out slot.
    assert_eq!(
        unsafe { fmi2GetFMUstate::<Testy>(host.c, &mut state) },
        fmi2Status_fmi2Error
    );
    assert!(state.is_null());
    let logs = logs_of(name);
    assert_eq!(logs.len(), 3);
    assert!(
        logs[1..]
            .iter()
            .all(|(l, m)| *l == log::Level::Error && m.contains("fmi2Reset")),
        "{logs:?}"
    );

    // Reset: a new instance, which runs again.
    // SAFETY: our live instance.
    assert_eq!(unsafe { fmi2Reset::<Testy>(host.c) }, fmi2Status_fmi2OK);
    host.initialise(None);
    assert_eq!(host.instance().context.time, 0.0);
    assert_eq!(host.step(0.5), fmi2Status_fmi2OK);
    assert_eq!(host.instance().slave.steps, 1);
    assert_eq!(logs_of(name).len(), 3);
}

#[test]
fn the_slave_defaults_keep_the_tolerance_and_say_nothing() {
    let name = "defaults";
    let host = Host::new(name, Some(2.5e-5));
    assert_eq!(host.instance().slave.tolerance, Some(2.5e-5));
    assert_eq!(host.instance().context.experiment.tolerance, Some(2.5e-5));
    // A step that asks for its notice: the default has none, so no warning.
    assert_eq!(host.step(NOTICE_STEP), fmi2Status_fmi2OK);
    assert_eq!(host.instance().slave.steps, 1);
    assert_eq!(host.instance().context.time, NOTICE_STEP);
    assert_eq!(logs_of(name), []);
}

/// fmi2SetBoolean and fmi2GetBoolean convert as FMI 2.0 says: fmi2False is 0, any other value
/// true, read back as fmi2True (1).
#[test]
fn booleans_travel_as_fmi2_true_and_false() {
    let host = Host::new("booleans", None);
    let r: fmi2ValueReference = 0;
    for (set, want) in [(0, 0), (1, 1), (0, 0), (7, 1), (-1, 1)] {
        let mut got: fmi2Boolean = 42;
        // SAFETY: our live instance; one value reference and one value each.
        unsafe {
            assert_eq!(
                fmi2SetBoolean::<Testy>(host.c, &r, 1, &set),
                fmi2Status_fmi2OK
            );
            assert_eq!(
                fmi2GetBoolean::<Testy>(host.c, &r, 1, &mut got),
                fmi2Status_fmi2OK
            );
        }
        assert_eq!(got, want, "set {set}");
    }
    assert_eq!(logs_of("booleans"), []);
}
