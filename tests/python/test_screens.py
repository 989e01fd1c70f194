"""damping = Screens through the FMU boundary (fmpy): zeta.effective against MODEL.md 11's closed
forms evaluated here from the tank and the screens (C_l of Baines & Peterson, K of the fundamental
shallow-water mode, the boundary layers of section 8), for the sinusoidal form (the default) and
the random form (screens.response = Random, or its Integer alias for hosts that cannot set
enumerations), and Random refused with a tracked amplitude."""
import math

import pytest
from fmpy.fmi1 import FMICallException

from tld_fmu import reference as R

A, B, H = 0.25, 0.32, 0.021
SCREENS = {"damping": "Screens", "screens.count": 2, "screens.solidity": 0.5,
           "screens.spacing": 0.05, "amplitude": "Fixed", "A_e": 0.002, "model": "Linear"}


def law():
    """(zeta_BL, K): the boundary layers' zeta and the screens' zeta_s per metre of response."""
    g = R.geometry(a=A, b=B, h=H)
    omega = g["omega_f"]
    zeta_bl = math.sqrt(1e-6 * omega / 2) * (1 + 2 * H / B + 1.0) / (2 * omega * H)
    s = 0.5
    c_c = 0.405 * math.exp(-math.pi * s) + 0.595
    c_l = (1 / (c_c * (1 - s)) - 1) ** 2
    cubes = sum(abs(math.sin(math.pi * x / A)) ** 3 for x in (0.4 * A, 0.6 * A))
    k = (2 / 3) * c_l * (g["mass.slosh"] / g["mass.liquid"]) / A * cubes
    return zeta_bl, k


def zeta_of(slave_factory, params):
    s = slave_factory()
    s.initialize(params)
    return s.get("zeta.effective")


def test_sinusoidal_is_the_default_and_the_resonant_form(slave_factory):
    zeta_bl, k = law()
    want = (zeta_bl + math.sqrt(zeta_bl ** 2 + 2 * k * 0.002)) / 2
    # the same expression evaluated twice in double precision: operation order only (1e-12)
    assert zeta_of(slave_factory, SCREENS) == pytest.approx(want, rel=1e-12)
    assert zeta_of(slave_factory, {**SCREENS, "screens.response": "Sinusoidal"}) == \
        zeta_of(slave_factory, SCREENS)


@pytest.mark.parametrize("how", [{"screens.response": "Random"}, {"screens.response_id": 2}])
def test_random_takes_a_e_as_the_rms_response(slave_factory, how):
    zeta_bl, k = law()
    want = zeta_bl + 3 * math.sqrt(math.pi / 8) * k * 0.002
    assert zeta_of(slave_factory, {**SCREENS, **how}) == pytest.approx(want, rel=1e-12)


def test_random_with_a_tracked_amplitude_is_refused(slave_factory):
    s = slave_factory()
    with pytest.raises(FMICallException):
        s.initialize({**SCREENS, "screens.response": "Random", "amplitude": "Tracked"})
    assert any("amplitude = Fixed" in msg for _, _, msg in s.messages), s.messages
