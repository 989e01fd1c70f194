//! tld-study: the design-study master (python/tld_fmu/study.py's native engine). It dlopens
//! TLD.fmu's binary and drives it through the fmi2 C API, as any host does, running batches of
//! co-simulations of a shear building with dampers on it (the coupling of
//! python/tld_fmu/building.py, operation for operation), and answers with each run's peak
//! response. `tld-study --help` describes the protocol.

mod fmu;
mod master;
mod protocol;

use std::io::{BufRead, Write};

use clap::Parser;

/// Runs batches of TLD.fmu co-simulations (a shear building under harmonic ground motion with
/// dampers on its floors) for the design studies of scripts/sweep.py, at the FMU's speed.
///
/// Reads requests from standard input, one JSON object a line, and answers each with one JSON
/// line on standard output:
///
///   {"load": {"library": PATH, "guid": GUID, "resources": URI, "vr": {NAME: VR, ...}}}
///     dlopen the FMU's binary; VR names base.a, base.v, base.x, force, force.mean and
///     mass.inactive (from the modelDescription). Answer {"loaded": PATH} or {"error": ...}.
///
///   {"runs": [RUN, ...]}
///     co-simulate each run on this process's FMU instances (reused through fmi2Reset). RUN:
///     {"name", "minv", "c", "k", "dampers": [{"floor", "params": [{"vr", "real"|"integer"|
///     "boolean"}], "inactive"}], "ground": {"w", "amplitude"}, "step", "duration", "tail",
///     "derivatives", optional "timing"}. Answer {"results": [{"peak": [max |X| per floor over
///     the tail], "steps", "instances", "do_step_seconds" (the time inside fmi2DoStep, measured
///     with "timing": true)} or {"error": "NAME: why"}, ...]}: a failed run loses no other.
///
/// Non-finite numbers may be given as the strings "NaN", "Infinity", "-Infinity"; a NaN result
/// is null. Ends at the end of its input.
#[derive(Parser, Debug)]
#[command(name = "tld-study", version)]
struct Args {}

fn main() {
    let _args = Args::parse();
    let stdin = std::io::stdin();
    let stdout = std::io::stdout();
    let mut server = protocol::Server::default();
    for (i, line) in stdin.lock().lines().enumerate() {
        let reply = match line {
            Ok(l) if l.trim().is_empty() => continue,
            Ok(l) => server.handle(&l),
            Err(e) => protocol::error_line(&format!("request line {}: {e}", i + 1)),
        };
        let mut out = stdout.lock();
        if writeln!(out, "{reply}").and_then(|()| out.flush()).is_err() {
            // the reader is gone: nothing left to answer
            return;
        }
    }
}
