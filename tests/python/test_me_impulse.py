"""Issue 27: S^2's impact impulses in a Model Exchange coupling. Building.fmu and TLD.fmu
(model = SloshingSlamming) in one ODE system integrated by one solver (DOP853), the TLD's wall
contact functions located as state events, and at each event FMI 2.0's event iteration over
the two FMUs (python/tld_fmu/me_master.py): TLD.fmu's discrete output impact.impulse ->
Building's discrete input tld.impulse (the floor's velocity jumps by M^-1 times the change),
Building's tld.v.jump -> TLD's base.v.jump (the liquid keeps its absolute velocity).

Against the monolithic reference (python/tld_fmu/impacts.py: the same equations written from
MODEL.md, the impacts located and the impulse applied to both bodies), over whole histories,
one storey and three; total momentum (floors with the inactive liquid, sloshing mass, impact
mass) across every impact; and the same coupling with the discrete connection left open (the
impulses lost), whose error is what the transfer removes. The scene: python/tld_fmu/me_impulse.py."""
from __future__ import annotations

import numpy as np
import pytest

from tld_fmu.me_impulse import SCENES, errors, run


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_impulses_reach_the_structure_in_model_exchange(fmu_path, scene):
    me, ref, ev = run(scene, fmu_path)
    open_me, open_ref, _ = run(scene, fmu_path, transfer=False)
    e, e_open = errors(me, ref), errors(open_me, ref)
    impulses = np.diff(np.concatenate([[0.0], ev[:, 2]]))
    balance = np.abs(ev[:, 1] - ev[:, 0]) / np.abs(impulses)
    print(f"\n{scene}: {len(me['events'])} events ({len(ref['events'])} in the reference), "
          f"impulses {np.min(np.abs(impulses)):.2e}..{np.max(np.abs(impulses)):.2e} N s; "
          + ", ".join(f"{k} {v:.1e}" for k, v in e.items())
          + f"; momentum across each impact: largest change {np.max(balance):.1e} of its impulse"
          + "\n  without the transfer: " + ", ".join(f"{k} {v:.1e}" for k, v in e_open.items()))
    assert len(ref["events"]) > 15
    np.testing.assert_allclose(me["events"], ref["events"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(ev[:, 2][-1], np.sum(ref["impulses"]), rtol=1e-6)
    assert max(e.values()) < 1e-6, e
    assert np.max(balance) < 1e-9
    # What the transfer removes: the open coupling misses the reference by orders more.
    assert e_open["roof.x"] > 1e3 * e["roof.x"]
