//! TLD.fmu's shared library driven through its fmi2* C entry points (the fmi2-host crate).

use fmi2_host::{Instance as Fmi2Instance, Library, Value};

/// Value references the loop uses (from modelDescription.xml, passed in by the driver).
#[derive(Clone, Copy, Debug)]
pub struct Vrs {
    pub base_a: u32,
    pub x: u32,
    pub v: u32,
    pub force: u32,
    pub mass_inactive: u32,
}

/// dlopen the FMU's binary (no resource location); its messages go to standard error.
pub fn load(path: &str, guid: &str) -> Result<Library, String> {
    fmi2_host::print_messages();
    // SAFETY: the driver names the FMU's own binary, built for the FMI 2.0 ABI.
    unsafe { Library::load(path, guid, None) }
}

/// One initialised instance, ready to step.
pub struct Instance {
    inst: Fmi2Instance,
    vrs: Vrs,
    out_vr: [u32; 3],
    out: [f64; 3],
}

impl Instance {
    /// A fresh instance with these parameters (value reference, value) set before
    /// initialisation.
    pub fn new(lib: &Library, vrs: Vrs, params: &[(u32, Value)]) -> Result<Self, String> {
        let mut inst = Fmi2Instance::new(lib, "bench")?;
        inst.initialize(params)?;
        Ok(Instance {
            inst,
            vrs,
            out_vr: [vrs.x, vrs.v, vrs.force],
            out: [0.0; 3],
        })
    }

    pub fn mass_inactive(&self) -> Result<f64, String> {
        let mut v = [0.0];
        self.inst.get_real(&[self.vrs.mass_inactive], &mut v)?;
        Ok(v[0])
    }
}

impl crate::Damper for Instance {
    /// fmi2SetReal(base.a) + fmi2DoStep + fmi2GetReal(slosh.x, slosh.v, force).
    #[inline]
    fn step(&mut self, t: f64, dt: f64, ab: f64) -> Result<[f64; 3], String> {
        let i = &mut self.inst;
        // the reference in place (from_ref): no copy per step
        i.set_real(std::slice::from_ref(&self.vrs.base_a), &[ab])
            .map_err(|r| format!("fmi2SetReal(base.a) status {}", r.status))?;
        i.do_step(t, dt)
            .map_err(|r| format!("fmi2DoStep at t = {t} status {}", r.status))?;
        i.get_real(&self.out_vr, &mut self.out)
            .map_err(|r| format!("fmi2GetReal status {}", r.status))?;
        Ok(self.out)
    }

    fn outputs(&mut self) -> Result<[f64; 3], String> {
        self.inst.get_real(&self.out_vr, &mut self.out)?;
        Ok(self.out)
    }
}
