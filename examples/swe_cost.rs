//! The shallow-water scheme's cost per cell and stage, without the FMI layer (the figures of
//! docs/SHALLOW_WATER.md): the lab tank at Lambda = 0.02 at resonance, boundary-layer
//! damping, 10 ms communication steps, from rest.
//!
//! `cargo run --release --example swe_cost -- [CELLS] [SECONDS]` (150 cells, 10 s): wall time
//! per simulated second, the real-time factor, the substeps per simulated second, the time per
//! cell and stage, and a hash of the final state (equal hashes: bit-identical results).

use std::time::Instant;
use tld_fmu::physics::base::BaseAcceleration;
use tld_fmu::physics::geometry::Tank;
use tld_fmu::physics::laws;
use tld_fmu::physics::shallow_water::{Channel, STAGE_COUNT, Scratch};

fn arg<T: std::str::FromStr>(k: usize, default: T) -> Result<T, String> {
    match std::env::args().nth(k) {
        None => Ok(default),
        Some(s) => s.parse().map_err(|_| format!("argument {k}: {s}?")),
    }
}

fn main() -> Result<(), String> {
    let cells: usize = arg(1, 150)?;
    let seconds: f64 = arg(2, 10.0)?;
    let tank = Tank::TABLE_2_1;
    let ch = Channel::new(tank.length, tank.depth, tank.g, cells);
    let w = tank.fundamental().omega;
    let amplitude = 0.02 * tank.length;
    let c = 2.0 * laws::boundary_layer_zeta(w, tank.depth, tank.breadth, 1e-6, 1.0) * w;
    let (mut flow, mut scratch) = (ch.at_rest(), Scratch::new(cells));
    let h = 0.01;
    let steps = (seconds / h).round() as usize;
    let mut substeps = 0;
    let started = Instant::now();
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
    }
    let elapsed = started.elapsed().as_secs_f64();
    let hash = flow
        .depth
        .iter()
        .chain(&flow.discharge)
        .fold(0u64, |h, v| h.wrapping_mul(31).wrapping_add(v.to_bits()));
    println!(
        "{cells} cells, {seconds} s: {:.3} ms per simulated s, {:.0}x real time, {:.0} substeps \
         per s, {:.2} ns per cell and stage, state hash {hash:016x}",
        1e3 * elapsed / seconds,
        seconds / elapsed,
        substeps as f64 / seconds,
        1e9 * elapsed / (STAGE_COUNT as f64 * substeps as f64 * cells as f64)
    );
    Ok(())
}
