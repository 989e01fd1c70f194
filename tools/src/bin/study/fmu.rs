//! TLD.fmu's shared library driven through its fmi2* C entry points, as any host does (the
//! fmi2-host crate: dlopened, every function resolved once at load, each call's status checked).

use fmi2_host::Value;

/// One parameter value to set before initialisation, by value reference (the names were
/// resolved against the modelDescription by the caller): exactly one of real, integer (an
/// Enumeration's too) and boolean.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Param {
    pub vr: u32,
    #[serde(default, deserialize_with = "crate::protocol::some_number")]
    pub real: Option<f64>,
    #[serde(default)]
    pub integer: Option<i32>,
    #[serde(default)]
    pub boolean: Option<bool>,
}

impl Param {
    pub fn value(&self) -> Result<Value, String> {
        match (self.real, self.integer, self.boolean) {
            (Some(x), None, None) => Ok(Value::Real(x)),
            (None, Some(i), None) => Ok(Value::Integer(i)),
            (None, None, Some(b)) => Ok(Value::Boolean(b)),
            _ => Err(format!(
                "parameter vr {}: give exactly one of real, integer, boolean",
                self.vr
            )),
        }
    }
}

/// The value references the coupling uses, from the modelDescription (the caller reads them).
#[derive(Clone, Copy, Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vrs {
    #[serde(rename = "base.a")]
    pub base_a: u32,
    #[serde(rename = "base.v")]
    pub base_v: u32,
    #[serde(rename = "base.x")]
    pub base_x: u32,
    pub force: u32,
    #[serde(rename = "force.mean")]
    pub force_mean: u32,
    #[serde(rename = "mass.inactive")]
    pub mass_inactive: u32,
}

/// A loaded FMU binary and the value references.
pub struct Library {
    lib: fmi2_host::Library,
    pub vrs: Vrs,
}

pub use fmi2_host::take_messages;

impl Library {
    /// dlopen `path` (the FMU's binaries/linux64/<modelIdentifier>.so); its messages are kept
    /// for the error of a run (take_messages).
    pub fn load(path: &str, guid: &str, resources: &str, vrs: Vrs) -> Result<Self, String> {
        fmi2_host::keep_messages();
        // SAFETY: the client names the FMU's binary, built for the FMI 2.0 ABI.
        let lib = unsafe { fmi2_host::Library::load(path, guid, Some(resources)) }?;
        Ok(Library { lib, vrs })
    }
}

/// One FMU instance (co-simulation), reused across runs through fmi2Reset.
pub struct Instance {
    inst: fmi2_host::Instance,
    vrs: Vrs,
    /// the outputs read after every step: force, force.mean
    out_vr: [u32; 2],
    pub force: f64,
    pub force_mean: f64,
    fresh: bool,
    /// time spent inside fmi2DoStep, measured only when `timed` (the clock costs ~50 ns a step)
    pub timed: bool,
    pub in_do_step: std::time::Duration,
}

impl Instance {
    pub fn new(lib: &Library, name: &str) -> Result<Self, String> {
        Ok(Instance {
            inst: fmi2_host::Instance::new(&lib.lib, name)?,
            vrs: lib.vrs,
            out_vr: [lib.vrs.force, lib.vrs.force_mean],
            force: 0.0,
            force_mean: 0.0,
            fresh: true,
            timed: false,
            in_do_step: std::time::Duration::ZERO,
        })
    }

    /// Set up a run: fmi2Reset (unless fresh), fmi2SetupExperiment(start 0, no tolerance, no
    /// stop time), the parameters in order, initialisation; returns mass.inactive.
    pub fn configure(&mut self, params: &[Param]) -> Result<f64, String> {
        if !self.fresh {
            self.inst.reset()?;
        }
        self.fresh = false;
        let params = params
            .iter()
            .map(|p| Ok((p.vr, p.value()?)))
            .collect::<Result<Vec<_>, String>>()?;
        self.inst.initialize(&params)?;
        let mut inactive = [0.0];
        self.inst
            .get_real(&[self.vrs.mass_inactive], &mut inactive)
            .map_err(|r| format!("fmi2GetReal(mass.inactive) returned status {}", r.status))?;
        self.read()?;
        Ok(inactive[0])
    }

    /// force and force.mean now.
    pub fn read(&mut self) -> Result<(), String> {
        let mut v = [0.0; 2];
        self.inst
            .get_real(&self.out_vr, &mut v)
            .map_err(|_| "fmi2GetReal failed".to_string())?;
        [self.force, self.force_mean] = v;
        Ok(())
    }

    /// The floor's absolute acceleration, velocity and displacement (base.a, base.v, base.x).
    pub fn set_inputs(&mut self, t: f64, a: f64, v: f64, x: f64) -> Result<(), String> {
        let vr = [self.vrs.base_a, self.vrs.base_v, self.vrs.base_x];
        self.inst
            .set_real(&vr, &[a, v, x])
            .map_err(|_| format!("the damper refused its inputs at t = {t}"))
    }

    /// fmi2DoStep from t by h with the inputs set (a_rate, if given, is d(base.a)/dt at t,
    /// fmi2SetRealInputDerivatives of order 1); then read the outputs.
    pub fn step_with_rate(&mut self, t: f64, h: f64, a_rate: Option<f64>) -> Result<(), String> {
        if let Some(r) = a_rate {
            self.inst
                .set_real_input_derivatives(&[self.vrs.base_a], &[1], &[r])
                .map_err(|_| format!("the damper refused the input derivative at t = {t}"))?;
        }
        let stepped = if self.timed {
            let t0 = std::time::Instant::now();
            let s = self.inst.do_step(t, h);
            self.in_do_step += t0.elapsed();
            s
        } else {
            self.inst.do_step(t, h)
        };
        stepped.map_err(|_| format!("the damper refused a step at t = {t}"))?;
        self.read()
    }

    /// fmi2DoStep from t by h with these inputs held over the step.
    pub fn step(&mut self, t: f64, h: f64, a: f64, v: f64, x: f64) -> Result<(), String> {
        self.set_inputs(t, a, v, x)?;
        self.step_with_rate(t, h, None)
    }

    /// d(force)/dt now (fmi2GetRealOutputDerivatives, order 1).
    pub fn force_rate(&mut self) -> Result<f64, String> {
        let mut d = [0.0];
        self.inst
            .get_real_output_derivatives(&[self.vrs.force], &[1], &mut d)
            .map_err(|_| "fmi2GetRealOutputDerivatives failed".to_string())?;
        Ok(d[0])
    }
}
