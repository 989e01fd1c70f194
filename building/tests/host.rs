//! Building.fmu's native FMI test host: the workspace's raw test host (tests/fmi_host, which
//! TLD.fmu's tests load theirs with), loading libbuilding_fmu, with Building's own helpers.
#![allow(dead_code)]

#[path = "../../tests/fmi_host/mod.rs"]
mod fmi_host;

pub(crate) use building_model::description::GUID;
pub use building_model::description::vr;
pub(crate) use fmi_host::*;
pub use fmi_sys::fmi2::*;

/// The library's crate name, which the test host loads.
pub(crate) const LIBRARY: &str = "building_fmu";

impl Instance {
    pub fn derivative(&self, r: u32, order: i32, v: f64) -> fmi2Status {
        unsafe {
            self.lib
                .fmi2SetRealInputDerivatives(self.c, &r, 1, &order, &v)
        }
    }
    pub fn rate(&self, r: u32) -> f64 {
        let (mut v, order) = (f64::NAN, 1);
        let s = unsafe {
            self.lib
                .fmi2GetRealOutputDerivatives(self.c, &r, 1, &order, &mut v)
        };
        assert_eq!(s, OK, "rate {r}: {:?}", self.logs());
        v
    }
    /// The parameters (value reference, value; integers for storeys and tld.floor), then
    /// initialised.
    pub fn initialise(&self, params: &[(u32, f64)]) {
        assert_eq!(self.setup(), OK);
        assert_eq!(self.enter(), OK);
        for &(r, v) in params {
            let s = if r == vr::STOREYS || r == vr::TLD_FLOOR {
                self.set_integer(r, v as i32)
            } else {
                self.set_real(r, v)
            };
            assert_eq!(s, OK, "{r} = {v}: {:?}", self.logs());
        }
        assert_eq!(self.exit(), OK, "{:?}", self.logs());
    }
    /// Become the serialised state `bytes`; the status of the restore.
    pub fn restore(&self, bytes: &[u8]) -> fmi2Status {
        let (st, mut s) = deserialize(self, bytes);
        if st != OK {
            return st;
        }
        // SAFETY: our instance and a state it just made, freed once.
        unsafe {
            let st = self.lib.fmi2SetFMUstate(self.c, s);
            assert_eq!(self.lib.fmi2FreeFMUstate(self.c, &mut s), OK);
            st
        }
    }
}
