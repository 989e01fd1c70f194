//! The FMU state as bytes. Used for fmi2GetFMUstate/fmi2SetFMUstate as well as for
//! serialisation, so both paths are the same code. The format is explicit (no memory copy), so
//! a state restores in another process, another instance, another build of the same model:
//!
//! ```text
//! "TLDs" | format version u16 | reserved u16 | GUID length u16 | GUID bytes
//!        | payload length u32 | payload | FNV-1a 64 checksum of everything before it
//! payload: phase u8 | flags u8 | time, tolerance, start, stop f64
//!        | derivatives of base.a for the next step (orders 1, 2) f64
//!        | number of variables u32 | their values f64... (the 54 of the first version-1
//!          build, then those added since up to the last one away from its start value)
//!        | number of simulation values u32 (0: not initialised) | the values f64...
//! simulation values: the model's own part (`Model::save`: its state, then three numbers the
//!        integrator carries, 0 for the exact models) | the damper's frame (amplitude, mean-force
//!        flag and value, amplitude estimator: `Damper::snapshot`)
//! ```
//! tests/golden/ holds a state of this version for every model: the layout cannot change
//! without a test failing (tests/golden_state.rs).
//! All numbers little-endian.

use super::calls::Phase;
use super::instance::{Experiment, Instance};
use super::params::{Configuration, Values};
use super::status::{Refusal, Reply, Status, refuse};
use super::vars::GUID;
use crate::model::Damper;

const MAGIC: &[u8; 4] = b"TLDs";
pub const FORMAT_VERSION: u16 = 1;

/// Everything an instance is, less what the host gave it (name, callbacks, logging).
#[derive(Clone, Debug, PartialEq)]
pub struct Saved {
    pub phase: u8,
    pub user_tolerance: bool,
    pub tolerance: Option<f64>,
    pub start: f64,
    pub stop: Option<f64>,
    pub time: f64,
    pub a_derivatives: [f64; 2],
    pub values: Vec<f64>,
    pub simulation: Vec<f64>,
}

fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

impl Saved {
    pub fn encode(&self) -> Vec<u8> {
        let mut p = Vec::with_capacity(64 + 8 * (self.values.len() + self.simulation.len()));
        p.push(self.phase);
        let flags = u8::from(self.user_tolerance)
            | u8::from(self.tolerance.is_some()) << 1
            | u8::from(self.stop.is_some()) << 2;
        p.push(flags);
        let [d1, d2] = self.a_derivatives;
        for x in [
            self.time,
            self.tolerance.unwrap_or(0.0),
            self.start,
            self.stop.unwrap_or(0.0),
            d1,
            d2,
        ] {
            p.extend_from_slice(&x.to_le_bytes());
        }
        for list in [&self.values, &self.simulation] {
            p.extend_from_slice(&(list.len() as u32).to_le_bytes());
            for x in list.iter() {
                p.extend_from_slice(&x.to_le_bytes());
            }
        }
        let mut out = Vec::with_capacity(p.len() + 64);
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&0u16.to_le_bytes());
        out.extend_from_slice(&(GUID.len() as u16).to_le_bytes());
        out.extend_from_slice(GUID.as_bytes());
        out.extend_from_slice(&(p.len() as u32).to_le_bytes());
        out.extend_from_slice(&p);
        let sum = fnv1a(&out);
        out.extend_from_slice(&sum.to_le_bytes());
        out
    }

    /// Decode and check a buffer; says precisely what is wrong with a bad one.
    pub fn decode(bytes: &[u8]) -> Result<Saved, Refusal> {
        let mut r = Reader { bytes, at: 0 };
        if r.take(4)? != MAGIC {
            return Err(refuse("not a TLD.fmu state (bad magic number)"));
        }
        let version = r.u16()?;
        if version != FORMAT_VERSION {
            return Err(refuse(format!(
                "state format version {version} is not supported (this build reads version {FORMAT_VERSION})"
            )));
        }
        r.u16()?;
        let guid_len = usize::from(r.u16()?);
        let guid = r.take(guid_len)?;
        if guid != GUID.as_bytes() {
            return Err(refuse(format!(
                "the state belongs to another model (GUID {}), not to {GUID}",
                String::from_utf8_lossy(guid)
            )));
        }
        let payload_len = r.u32()? as usize;
        let payload_start = r.at;
        r.take(payload_len)?;
        let body_end = r.at;
        let sum = u64::from_le_bytes(r.array::<8>()?);
        if r.at != bytes.len() {
            return Err(refuse(format!(
                "{} unexpected bytes after the state",
                bytes.len() - r.at
            )));
        }
        if sum != fnv1a(&bytes[..body_end]) {
            return Err(refuse("the state is corrupted (checksum mismatch)"));
        }
        let mut p = Reader {
            bytes: &bytes[payload_start..body_end],
            at: 0,
        };
        let phase = p.u8()?;
        let flags = p.u8()?;
        let (time, tolerance, start, stop) = (p.f64()?, p.f64()?, p.f64()?, p.f64()?);
        let a_derivatives = [p.f64()?, p.f64()?];
        let values = p.f64_list()?;
        let simulation = p.f64_list()?;
        if p.at != payload_len {
            return Err(refuse("the state's payload has trailing bytes"));
        }
        Ok(Saved {
            phase,
            user_tolerance: flags & 1 != 0,
            tolerance: (flags & 2 != 0).then_some(tolerance),
            start,
            stop: (flags & 4 != 0).then_some(stop),
            time,
            a_derivatives,
            values,
            simulation,
        })
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], Refusal> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| {
            refuse(format!(
                "the state is truncated ({} bytes)",
                self.bytes.len()
            ))
        })?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn array<const N: usize>(&mut self) -> Result<[u8; N], Refusal> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N)?);
        Ok(a)
    }
    fn u8(&mut self) -> Result<u8, Refusal> {
        Ok(self.array::<1>()?[0])
    }
    fn u16(&mut self) -> Result<u16, Refusal> {
        Ok(u16::from_le_bytes(self.array()?))
    }
    fn u32(&mut self) -> Result<u32, Refusal> {
        Ok(u32::from_le_bytes(self.array()?))
    }
    fn f64(&mut self) -> Result<f64, Refusal> {
        Ok(f64::from_le_bytes(self.array()?))
    }
    fn f64_list(&mut self) -> Result<Vec<f64>, Refusal> {
        let n = self.u32()? as usize;
        if n > (self.bytes.len() - self.at) / 8 {
            return Err(refuse(
                "the state is truncated (a list is longer than the buffer)",
            ));
        }
        (0..n).map(|_| self.f64()).collect()
    }
}

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

impl Instance {
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
            values: self.values.to_saved().to_vec(),
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
}
