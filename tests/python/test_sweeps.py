"""Harmonic balance (tld-freqresp) against slow time-domain sweeps through the FMU (issue:
up and down sweeps must jump where harmonic balance says, within 1 % for eta = 2).

VERIFY.md's example: a = 0.25 m, zeta = 0.02 constant, eta = 2, phi = 1, A = 3 mm. The sweep
holds each frequency for 60 s (settling time 4.6 / (zeta w_f) = 41 s), keeps the phase of the
base motion continuous, and measures the amplitude over the last 10 s of each hold."""
import json
import subprocess

import numpy as np

from tld_fmu import reference as R
from tld_fmu.paths import cargo_executable

A = 0.003
ZETA = 0.02


def harmonic_balance():
    exe = cargo_executable("tld-freqresp")   # tools/, built by cargo if missing or stale
    out = subprocess.run([str(exe), "--eta", "2", "--phi", "1", "--zeta", str(ZETA), "--A", str(A),
                          "--json"], capture_output=True, text=True, check=True).stdout
    return json.loads(out)


def sweep(slave_factory, ratios, hold=60.0, dt=0.01):
    p = R.TLD(eta=2.0, phi=1.0, damping=R.DAMPING_CONSTANT, zeta=ZETA)
    s = slave_factory(quiet=True)
    s.initialize(p.fmu_parameters())
    phase, amps = 0.0, []
    n = int(round(hold / dt))
    for r in ratios:
        w = r * p.omega_f
        ph = phase + w * dt * np.arange(n)
        out = s.run(dt, {"base.a": -w * w * A * np.sin(ph)}, ["slosh.x"])
        phase = ph[-1] + w * dt
        amps.append(np.max(np.abs(out["slosh.x"][-int(10.0 / dt):])))
    return np.array(amps)


def jump(ratios, amps, threshold, falling):
    """Midpoint of the first pair of neighbouring frequencies across which the amplitude drops
    (falling) or rises through `threshold`, an amplitude between the two stable branches."""
    above = amps > threshold
    crossing = above[:-1] & ~above[1:] if falling else ~above[:-1] & above[1:]
    assert crossing.any(), f"no jump across {threshold}: {amps}"
    k = int(np.argmax(crossing))
    return 0.5 * (ratios[k] + ratios[k + 1])


def test_up_and_down_sweeps_jump_where_harmonic_balance_says(slave_factory):
    hb = harmonic_balance()
    peak, fold = hb["peak"]["w_ratio"], hb["fold"]["w_ratio"]
    up = np.concatenate([np.arange(1.00, 1.14, 0.02), np.arange(1.14, 1.2001, 0.005)])
    down = np.concatenate([np.arange(1.26, 1.10, -0.02), np.arange(1.10, 1.0399, -0.005)])
    # 4 cm separates the branches near both jumps (HB: lower <= 2.7 cm, upper >= 6 cm there).
    j_up = jump(up, sweep(slave_factory, up), 0.04, falling=True)
    j_down = jump(down, sweep(slave_factory, down), 0.04, falling=False)
    print(f"sweep up jumps down at {j_up:.4f} (harmonic balance: peak {peak:.4f}); "
          f"sweep down jumps up at {j_down:.4f} (fold {fold:.4f})")
    assert abs(j_up / peak - 1) < 0.01
    assert abs(j_down / fold - 1) < 0.01


def test_three_amplitudes_coexist_at_1_10(slave_factory):
    """At w/w_f = 1.10 harmonic balance has two stable amplitudes (and an unstable one between):
    reached from below (upper branch) and from above (lower branch) by the FMU, within 1 %."""
    hb = harmonic_balance()
    row = min(hb["branches"], key=lambda b: abs(b[0] - 1.10))
    stable = sorted(x for x, st in row[1] if st)
    assert len(stable) == 2, row
    from_below = sweep(slave_factory, np.arange(1.00, 1.1001, 0.02))[-1]
    from_above = sweep(slave_factory, np.arange(1.26, 1.0999, -0.02))[-1]
    print(f"w/w_f 1.10: FMU {from_above:.5f} and {from_below:.5f} m; HB {stable}")
    assert abs(from_above / stable[0] - 1) < 0.01
    assert abs(from_below / stable[1] - 1) < 0.01
