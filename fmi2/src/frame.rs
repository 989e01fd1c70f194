//! The frame of a saved state, the same bytes for fmi2GetFMUstate and serialisation: explicit
//! (no memory copy), so a state restores in another process, another instance, another build.
//!
//! ```text
//! tag (4 bytes, the FMU's) | format version u16 | reserved u16 | GUID length u16 | GUID bytes
//!        | payload length u32 | payload | FNV-1a 64 checksum of everything before it
//! payload: phase u8 (0 Instantiated, 1 InitializationMode, 2 StepComplete, 3 Terminated,
//!          4 EventMode, 5 ContinuousTimeMode) | flags u8 | time, tolerance, start, stop f64 | the slave's part
//! flags: bit 0 the slave's own, bit 1 tolerance defined, bit 2 stop time defined
//! ```
//! All numbers little-endian. The slave's part is written and read by the slave
//! ([`crate::Slave::save`], [`crate::Slave::load`]) through [`Reader`].

use crate::calls::Phase;
use crate::status::{Refusal, refuse};

/// What fmi2SetupExperiment gave.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Experiment {
    pub tolerance: Option<f64>,
    pub start: f64,
    pub stop: Option<f64>,
}

/// The shared part of a saved instance: its phase, experiment and time, and the slave's flag.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Common {
    pub phase: Phase,
    pub experiment: Experiment,
    pub time: f64,
    pub flag: bool,
}

/// The frame's checksum (FNV-1a 64) of `bytes`: public so that a fuzzer can make a mutated
/// state pass the check and reach the parser behind it (fuzz/).
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

fn phase_code(phase: Phase) -> u8 {
    match phase {
        Phase::Instantiated => 0,
        Phase::InitializationMode => 1,
        Phase::StepComplete => 2,
        Phase::Terminated | Phase::Broken => 3,
        Phase::EventMode => 4,
        Phase::ContinuousTimeMode => 5,
    }
}

/// Append `x` little-endian.
pub fn put_f64(out: &mut Vec<u8>, x: f64) {
    out.extend_from_slice(&x.to_le_bytes());
}

/// Append a list: its length u32, then the values.
pub fn put_f64_list(out: &mut Vec<u8>, list: &[f64]) {
    out.extend_from_slice(&(list.len() as u32).to_le_bytes());
    for &x in list {
        put_f64(out, x);
    }
}

/// The framed state: `common`, then what `slave` appends to the payload.
pub fn encode(
    tag: &[u8; 4],
    version: u16,
    guid: &str,
    common: &Common,
    slave: impl FnOnce(&mut Vec<u8>),
) -> Vec<u8> {
    let mut p = Vec::with_capacity(256);
    p.push(phase_code(common.phase));
    let e = &common.experiment;
    p.push(
        u8::from(common.flag)
            | u8::from(e.tolerance.is_some()) << 1
            | u8::from(e.stop.is_some()) << 2,
    );
    for x in [
        common.time,
        e.tolerance.unwrap_or(0.0),
        e.start,
        e.stop.unwrap_or(0.0),
    ] {
        put_f64(&mut p, x);
    }
    slave(&mut p);
    let mut out = Vec::with_capacity(p.len() + 64);
    out.extend_from_slice(tag);
    out.extend_from_slice(&version.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    out.extend_from_slice(&(guid.len() as u16).to_le_bytes());
    out.extend_from_slice(guid.as_bytes());
    out.extend_from_slice(&(p.len() as u32).to_le_bytes());
    out.extend_from_slice(&p);
    let sum = fnv1a(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

/// Check the frame of `bytes` and read the shared part; returns it with a reader at the
/// slave's part. Says precisely what is wrong with a bad buffer.
pub fn decode<'a>(
    bytes: &'a [u8],
    tag: &[u8; 4],
    version: u16,
    guid: &str,
    model: &str,
) -> Result<(Common, Reader<'a>), String> {
    let mut r = Reader { bytes, at: 0 };
    if r.take(4)? != tag {
        return Err(format!("not a {model}.fmu state (bad magic number)"));
    }
    let found = r.u16()?;
    if found != version {
        return Err(format!(
            "state format version {found} is not supported (this build reads version {version})"
        ));
    }
    r.u16()?;
    let guid_len = usize::from(r.u16()?);
    let found = r.take(guid_len)?;
    if found != guid.as_bytes() {
        return Err(format!(
            "the state belongs to another model (GUID {}), not to {guid}",
            String::from_utf8_lossy(found)
        ));
    }
    let payload_len = r.u32()? as usize;
    let payload_start = r.at;
    r.take(payload_len)?;
    let body_end = r.at;
    let sum = u64::from_le_bytes(r.array::<8>()?);
    if r.at != bytes.len() {
        return Err(format!(
            "{} unexpected bytes after the state",
            bytes.len() - r.at
        ));
    }
    if sum != fnv1a(&bytes[..body_end]) {
        return Err("the state is corrupted (checksum mismatch)".into());
    }
    let mut p = Reader {
        bytes: &bytes[payload_start..body_end],
        at: 0,
    };
    let phase = match p.u8()? {
        0 => Phase::Instantiated,
        1 => Phase::InitializationMode,
        2 => Phase::StepComplete,
        3 => Phase::Terminated,
        4 => Phase::EventMode,
        5 => Phase::ContinuousTimeMode,
        other => return Err(format!("unknown state code {other}")),
    };
    let flags = p.u8()?;
    let (time, tolerance, start, stop) = (p.f64()?, p.f64()?, p.f64()?, p.f64()?);
    let common = Common {
        phase,
        experiment: Experiment {
            tolerance: (flags & 2 != 0).then_some(tolerance),
            start,
            stop: (flags & 4 != 0).then_some(stop),
        },
        time,
        flag: flags & 1 != 0,
    };
    let finite = [time, start, common.experiment.stop.unwrap_or(0.0)]
        .iter()
        .all(|x| x.is_finite());
    let tolerance_ok = common
        .experiment
        .tolerance
        .is_none_or(|t| t.is_finite() && t > 0.0);
    if !finite || !tolerance_ok {
        return Err("non-finite time, tolerance or experiment bounds".into());
    }
    Ok((common, p))
}

/// Reads a payload in order; every read checks the length.
pub struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end =
            end.ok_or_else(|| format!("the state is truncated ({} bytes)", self.bytes.len()))?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn array<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N)?);
        Ok(a)
    }
    pub fn u8(&mut self) -> Result<u8, String> {
        Ok(self.array::<1>()?[0])
    }
    pub fn u16(&mut self) -> Result<u16, String> {
        Ok(u16::from_le_bytes(self.array()?))
    }
    pub fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.array()?))
    }
    pub fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.array()?))
    }
    /// A list written by [`put_f64_list`].
    pub fn f64_list(&mut self) -> Result<Vec<f64>, String> {
        let n = self.u32()? as usize;
        if n > (self.bytes.len() - self.at) / 8 {
            return Err("the state is truncated (a list is longer than the buffer)".into());
        }
        (0..n).map(|_| self.f64()).collect()
    }
    /// Whether everything was read.
    pub fn finish(&self) -> Result<(), String> {
        if self.at == self.bytes.len() {
            Ok(())
        } else {
            Err("the state's payload has trailing bytes".into())
        }
    }
}

/// A refusal for an unusable state.
#[cold]
pub fn unusable(why: &str) -> Refusal {
    refuse(format!("the FMU state is not usable: {why}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    const TAG: &[u8; 4] = b"TSTs";
    const GUID: &str = "{guid}";

    fn sample() -> (Common, Vec<u8>) {
        let common = Common {
            phase: Phase::StepComplete,
            experiment: Experiment {
                tolerance: Some(1e-6),
                start: 0.5,
                stop: None,
            },
            time: 2.25,
            flag: true,
        };
        let bytes = encode(TAG, 3, GUID, &common, |out| put_f64_list(out, &[1.0, -2.5]));
        (common, bytes)
    }

    #[test]
    fn the_frame_round_trips_with_the_slaves_part() {
        let (common, bytes) = sample();
        let (read, mut part) = decode(&bytes, TAG, 3, GUID, "Test").expect("a good frame");
        assert_eq!(read, common);
        assert_eq!(part.f64_list(), Ok(vec![1.0, -2.5]));
        assert_eq!(part.finish(), Ok(()));
    }

    /// Every combination of the slave's flag and the experiment's optional bounds comes back as
    /// it went in; a tolerance that is not positive does not.
    #[test]
    fn every_flag_round_trips_alone() {
        for bits in 0..8u8 {
            let common = Common {
                phase: Phase::InitializationMode,
                experiment: Experiment {
                    tolerance: (bits & 2 != 0).then_some(1e-4),
                    start: -1.0,
                    stop: (bits & 4 != 0).then_some(9.0),
                },
                time: 0.0,
                flag: bits & 1 != 0,
            };
            let bytes = encode(TAG, 3, GUID, &common, |_| {});
            let (read, _) = decode(&bytes, TAG, 3, GUID, "Test").expect("a good frame");
            assert_eq!(read, common, "flags {bits}");
        }
        for tolerance in [0.0, -1e-6] {
            let (mut common, _) = sample();
            common.experiment.tolerance = Some(tolerance);
            let bytes = encode(TAG, 3, GUID, &common, |_| {});
            assert!(decode(&bytes, TAG, 3, GUID, "Test").is_err(), "{tolerance}");
        }
    }

    /// A list that claims more numbers than the rest of the state holds is refused as such
    /// before it is read, wherever it stands in the state.
    #[test]
    fn a_list_longer_than_the_state_is_refused_before_reading() {
        let (common, _) = sample();
        let bytes = encode(TAG, 3, GUID, &common, |out| {
            out.extend_from_slice(&3u32.to_le_bytes());
            out.extend_from_slice(&[0u8; 16]);
        });
        let (_, mut part) = decode(&bytes, TAG, 3, GUID, "Test").expect("a good frame");
        let why = part.f64_list().expect_err("three numbers in 16 bytes");
        assert!(why.contains("a list is longer than the buffer"), "{why}");
    }

    /// Every kind of damage is named: tag, version, GUID, checksum, truncation, trailing bytes.
    #[test]
    fn a_damaged_frame_says_what_is_wrong() {
        let (_, bytes) = sample();
        let why = |b: &[u8]| decode(b, TAG, 3, GUID, "Test").err().unwrap_or_default();
        assert!(why(&[b"XXXX", &bytes[4..]].concat()).contains("not a Test.fmu state"));
        assert!(decode(&bytes, TAG, 4, GUID, "Test").is_err_and(|e| e.contains("version 3")));
        assert!(decode(&bytes, TAG, 3, "{other}", "Test").is_err_and(|e| e.contains("GUID")));
        let mut flipped = bytes.clone();
        flipped[bytes.len() - 12] ^= 1;
        assert!(why(&flipped).contains("checksum"));
        assert!(why(&bytes[..bytes.len() - 3]).contains("truncated"));
        assert!(why(&[&bytes[..], &[0u8]].concat()).contains("unexpected bytes"));
        let (_, mut part) = decode(&bytes, TAG, 3, GUID, "Test").expect("good");
        assert_eq!(part.u32(), Ok(2), "the list's length");
        assert!(
            part.finish().is_err(),
            "a part read short has trailing bytes"
        );
    }
}
