//! The FMU state as bytes. Used for fmi2GetFMUstate/fmi2SetFMUstate as well as for
//! serialisation, so both paths are the same code. The format is explicit (no memory copy), so
//! a state restores in another process, another instance, another build of the same model:
//!
//! ```text
//! "TLDs" | format version u16 | reserved u16 | GUID length u16 | GUID bytes
//!        | payload length u32 | payload | FNV-1a 64 checksum of everything before it
//! payload: phase u8 | flags u8 | time, tolerance, start, stop f64
//!        | derivatives of base.a for the next step (orders 1, 2) f64
//!        | number of variables u32 | their values f64...
//!        | number of simulation values u32 (0: not initialised) | the values f64...
//! ```
//! All numbers little-endian.

use super::instance::{Refusal, refuse};
use super::vars::GUID;

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
