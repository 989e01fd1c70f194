"""The scene the host tests (test_hosts.py: libcosim, test_hosts_ecospy.py: Ecos) run in each
host and in fmpy, and the comparison of their outputs."""
import numpy as np

DT = 0.01
T_END = 20.0
N = int(round(T_END / DT))
W = 5.6389          # rad/s
A = 0.005           # m
OUTPUTS = ["slosh.x", "force"]
RTOL = 1e-9


def base_acceleration(scale=1.0, shift=0):
    """base.a = -w^2 A sin(w t), sampled at the communication points t_k = k dt (the value held
    during step k); shift moves the samples by whole steps (for the can-fail checks)."""
    t = (np.arange(N) + shift) * DT
    return -W * W * A * scale * np.sin(W * t)


def run_fmpy(slave_factory, a, reals=None, ints=None):
    """The scene through fmpy, the reference host; parameters by name."""
    s = slave_factory(quiet=True)
    s.initialize({**(reals or {}), **(ints or {})})
    res = s.run(DT, {"base.a": a}, OUTPUTS)
    # res[name][0] is the value before the first step; the other hosts record after each step
    return {k: v[1:] for k, v in res.items()}


def rel_diff(x, y):
    return float(np.max(np.abs(np.asarray(x) - np.asarray(y))) / np.max(np.abs(y)))


def compare(host, fm):
    """max |host - fmpy| / max |fmpy| per output."""
    return {n: rel_diff(host[n], fm[n]) for n in OUTPUTS}


def bitwise(host, fm):
    return all(np.array_equal(host[n], fm[n]) for n in OUTPUTS)
