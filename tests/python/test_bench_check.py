"""The work-precision benchmark's scene check (tld_fmu.scenes.check_scenes, which makes
scripts/bench exit with an error): it refuses a deliberately wrong scene and passes the right one.

The wrong scene is the one issue #26 found published: the coupled scene 5 with the FMU at its
default amplitude = Tracked (the damping following the motion) while its reference holds the
fixed A_e; the right one sets amplitude = Fixed as the scene says. Both run the scene's
co-simulation master for 3 s at 10 ms, the FMU through fmpy at a tight tolerance, the reference
and its own check (twice the substeps) as the benchmark computes them."""
from __future__ import annotations

import dataclasses

from tld_fmu.scenes import (FmpyDamper, FmuInfo, RefDamper, check_scenes, coupled_master,
                            make_scenes, ref_substeps, rel_err)

DT = 0.01
N = 300


def scene_failures(sc, fi, slave_factory):
    subs = ref_substeps(sc, DT)
    ref, _ = coupled_master(RefDamper(sc.p, subs), sc.coupled, DT, N, sc.p.m0)
    chk, _ = coupled_master(RefDamper(sc.p, 2 * subs), sc.coupled, DT, N, sc.p.m0)
    s = slave_factory()
    s.initialize({**fi.scene_params(sc), "solver": "DormandPrince853", "solver.tolerance": 1e-13})
    d = FmpyDamper(s, "base.a", ["slosh.x", "slosh.v", "force"])
    x, _ = coupled_master(d, sc.coupled, DT, N, s.get("mass.inactive"))
    refs = {(sc.key, DT): dict(check=rel_err(ref, chk))}
    rows = [dict(scene=sc.key, dt=DT, impl="TLD.fmu", status="ok", window=False,
                 err=rel_err(x, ref))]
    return check_scenes(refs, rows)


def test_scene_check_refuses_a_wrong_scene_and_passes_the_right_one(fmu_path, slave_factory):
    fi = FmuInfo(fmu_path)
    s5 = next(sc for sc in make_scenes(quick=True) if sc.kind == "coupled")
    assert s5.fmu_params == {"amplitude": "Fixed"}
    assert scene_failures(s5, fi, slave_factory) == []
    wrong = dataclasses.replace(s5, fmu_params={})
    failures = scene_failures(wrong, fi, slave_factory)
    assert len(failures) == 1 and "do not simulate the same scene" in failures[0], failures
    # no successful run at all is a failure too
    assert check_scenes({("s", DT): dict(check=1e-15)}, []) != []
