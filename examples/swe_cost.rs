//! The shallow-water scheme's cost per doStep and per cell and substep, without the FMI layer
//! (the figures of docs/SHALLOW_WATER.md): the lab tank at Lambda = 0.02 at resonance,
//! boundary-layer damping, 10 ms communication steps, from rest.
//!
//! `cargo run --release --example swe_cost -- [CELLS] [SECONDS] [ROUNDS]` (150 cells, 10 s, 5
//! rounds): per round the thread's CPU time (CLOCK_THREAD_CPUTIME_ID: other processes on the
//! machine do not count, though they share its caches) over the whole run; the median and the
//! least of the rounds per 10 ms doStep, the real-time factor that gives, the substeps per
//! simulated second (taken or not; how many of the run's were the positivity fallback's), the
//! time per cell and substep, the load average, and a hash of the final state (equal hashes:
//! bit-identical results).

use tld_fmu::physics::base::BaseAcceleration;
use tld_fmu::physics::geometry::Tank;
use tld_fmu::physics::laws;
use tld_fmu::physics::shallow_water::{Channel, Scratch};

fn arg<T: std::str::FromStr>(k: usize, default: T) -> Result<T, String> {
    match std::env::args().nth(k) {
        None => Ok(default),
        Some(s) => s.parse().map_err(|_| format!("argument {k}: {s}?")),
    }
}

/// The thread's CPU time [s].
fn cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: a valid pointer to a timespec, and a clock every Linux has.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + 1e-9 * ts.tv_nsec as f64
}

fn main() -> Result<(), String> {
    let cells: usize = arg(1, 150)?;
    let seconds: f64 = arg(2, 10.0)?;
    let rounds: usize = arg(3, 5)?;
    let tank = Tank::TABLE_2_1;
    let ch = Channel::new(tank.length, tank.depth, tank.g, cells);
    let w = tank.fundamental().omega;
    let amplitude = 0.02 * tank.length;
    let c = 2.0 * laws::boundary_layer_zeta(w, tank.depth, tank.breadth, 1e-6, 1.0) * w;
    let h = 0.01;
    let steps = (seconds / h).round() as usize;
    let mut per_step = vec![];
    let (mut substeps, mut fallbacks, mut hash) = (0, 0, 0u64);
    for _ in 0..rounds.max(1) {
        let (mut flow, mut scratch) = (ch.at_rest(), Scratch::new(cells));
        (substeps, fallbacks) = (0, 0);
        let started = cpu_seconds();
        for k in 0..steps {
            let (s, co) = (w * k as f64 * h).sin_cos();
            let a = w * w * amplitude;
            let base = BaseAcceleration {
                t0: 0.0,
                a: [-a * s, -a * w * co, a * w * w * s],
            };
            let done = ch
                .advance_in(&mut scratch, &mut flow, h, &base, c, u64::MAX)
                .map_err(|e| format!("step {k}: {e}"))?;
            substeps += done.substeps + done.rejected;
            fallbacks += done.fallbacks;
        }
        per_step.push((cpu_seconds() - started) / steps as f64);
        hash = flow
            .depth
            .iter()
            .chain(&flow.discharge)
            .fold(0u64, |h, v| h.wrapping_mul(31).wrapping_add(v.to_bits()));
    }
    per_step.sort_by(f64::total_cmp);
    let median = per_step[per_step.len() / 2];
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let load = load
        .split_whitespace()
        .take(3)
        .collect::<Vec<_>>()
        .join(" ");
    println!(
        "{cells} cells, {seconds} s, {rounds} rounds: CPU per 10 ms doStep median {:.2} us (least \
         {:.2}), {:.0}x real time, {:.0} substeps per s ({fallbacks} in the run by the fallback), {:.2} ns per cell and substep; load \
         average {load}; state hash {hash:016x}",
        1e6 * median,
        1e6 * per_step[0],
        h / median,
        substeps as f64 / seconds,
        1e9 * median * steps as f64 / (substeps as f64 * cells as f64)
    );
    Ok(())
}
