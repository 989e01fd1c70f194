"""canSerializeFMUstate: a state serialised in one process restores in a fresh process and a
different instance, and the continued run is bit-identical to the uninterrupted one."""
import subprocess
import sys
import textwrap

import numpy as np

from tld_fmu import reference as R

# The child process: load the FMU, restore the state from a file, continue, print the results.
CHILD = textwrap.dedent("""
    import numpy as np
    from tld_fmu.slave import Slave
    from fmpy import read_model_description, extract
    md = read_model_description({fmu!r})
    variables = {{v.name: v for v in md.modelVariables}}
    s = Slave(md, extract({fmu!r}), variables, name="restored-elsewhere", quiet=True)
    data = open({state!r}, "rb").read()
    state = s.fmu.deSerializeFMUstate(data)
    s.fmu.setFMUstate(state)
    s.fmu.freeFMUstate(state)
    s.time = float({t!r})
    a = np.load({inputs!r})
    out = s.run({dt!r}, {{"base.a": a}}, ["slosh.x", "slosh.v", "energy.input", "A_e.estimate"])
    np.save({result!r}, np.column_stack([out[k] for k in ["slosh.x", "slosh.v", "energy.input", "A_e.estimate"]]))
""")


def test_state_restores_in_another_process(slave_factory, fmu_path, tmp_path):
    p = R.TLD(eta=2.5)
    dt, n1, n2 = 0.01, 700, 900
    w = 1.1 * p.omega_f
    t = dt * np.arange(n1 + n2)
    a = -w * w * 0.004 * np.sin(w * t)
    s = slave_factory(quiet=True)
    s.initialize({**p.fmu_parameters(), "amplitude": "Tracked"})
    s.run(dt, {"base.a": a[:n1]}, ["slosh.x"])
    state = s.fmu.getFMUstate()
    (tmp_path / "state.bin").write_bytes(s.fmu.serializeFMUstate(state))
    s.fmu.freeFMUstate(state)
    t_saved = s.time
    names = ["slosh.x", "slosh.v", "energy.input", "A_e.estimate"]
    out = s.run(dt, {"base.a": a[n1:]}, names)
    uninterrupted = np.column_stack([out[k] for k in names])
    np.save(tmp_path / "inputs.npy", a[n1:])
    code = CHILD.format(fmu=str(fmu_path),
                        state=str(tmp_path / "state.bin"), t=t_saved, inputs=str(tmp_path / "inputs.npy"),
                        dt=dt, result=str(tmp_path / "result.npy"))
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    restored = np.load(tmp_path / "result.npy")
    assert restored.shape == uninterrupted.shape
    # bit-identical, not merely close
    assert np.array_equal(restored.view(np.uint64), uninterrupted.view(np.uint64))
    assert np.max(np.abs(uninterrupted[:, 0])) > 1e-3  # the run really sloshes
