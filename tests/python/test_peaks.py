"""tld_fmu.peaks: reported peaks come from a refinement to a stated tolerance, not from the grid.

The known answer: a damped SDOF oscillator under harmonic base acceleration of constant amplitude
a_0, x'' + 2 zeta w_n x' + w_n^2 x = -a_0 sin(w t), has the steady displacement amplitude
|x| = a_0 / sqrt((w_n^2 - w^2)^2 + (2 zeta w_n w)^2), largest at w = w_n sqrt(1 - 2 zeta^2), where
|x| = a_0 / (2 zeta sqrt(1 - zeta^2) w_n^2)."""
import math

import numpy as np
import pytest

from tld_fmu import peaks

W_N, A_0 = 5.636, 1.0


def amplitude(w, zeta):
    return A_0 / math.hypot(W_N ** 2 - w ** 2, 2 * zeta * W_N * w)


def exact_peak(zeta):
    return W_N * math.sqrt(1 - 2 * zeta ** 2), A_0 / (2 * zeta * math.sqrt(1 - zeta ** 2) * W_N ** 2)


@pytest.mark.parametrize("zeta", [0.02, 0.1, 0.3])
def test_refined_peak_matches_the_closed_form_and_the_grid_does_not(zeta):
    xtol = 1e-4 * W_N
    grid = np.linspace(0.8, 1.2, 9) * W_N          # 0.05 w_n apart, as the building example had
    ys = [amplitude(w, zeta) for w in grid]
    w_peak, x_peak = exact_peak(zeta)
    p = peaks.refine_peak(lambda w: amplitude(w, zeta), grid, ys, xtol=xtol)
    print(f"\nzeta {zeta}: exact {w_peak:.6f} rad/s, {x_peak:.6g}; refined {p.x:.6f}, {p.y:.6g} "
          f"({len(p.points)} evaluations); grid {p.grid_x:.6f}, {p.grid_y:.6g}")
    assert p.bounded
    assert abs(p.x - w_peak) <= xtol
    # the height is second order in the frequency error: 1e-6 relative is far inside it
    assert abs(p.y - x_peak) <= 1e-6 * x_peak
    # without the refinement the answer is off by more than the tolerance: the test can fail
    assert abs(p.grid_x - w_peak) > xtol
    assert abs(p.grid_y - x_peak) > 1e-6 * x_peak
    # golden section: the bracket (2 grid spacings) shrinks by 0.618 per evaluation
    assert len(p.points) <= math.ceil(math.log(0.1 * W_N / (2 * xtol)) / math.log(1 / (1 - peaks.R))) + 2


def test_two_peaks_of_a_tuned_damper_are_both_refined_in_lockstep():
    """A 2-DOF structure + tuned mass: two resonance peaks, each refined; the batch evaluator
    sees one point per active search per call."""
    m, k, c = 1.0, 1.0, 0.002
    mu, f, zd = 0.05, 1 / 1.05, 0.02
    md, kd = mu * m, mu * m * f ** 2
    cd = 2 * zd * math.sqrt(kd * md)

    def gain(w):
        K = np.array([[k + kd - m * w ** 2 + 1j * w * (c + cd), -kd - 1j * w * cd],
                      [-kd - 1j * w * cd, kd - md * w ** 2 + 1j * w * cd]])
        return abs(np.linalg.solve(K, [m, md])[0])

    fine = np.linspace(0.8, 1.2, 400_001)
    g = np.array([gain(w) for w in fine[::100]])
    grid = np.linspace(0.8, 1.2, 17)
    batches = []

    def evaluate(batch):
        batches.append(len(batch))
        return [gain(x) for _, x in batch]

    found = peaks.refine_curves({"tmd": (grid, [gain(w) for w in grid])}, evaluate, xtol=1e-5)["tmd"]
    assert len(found) == 2 and max(batches) == 2
    coarse = fine[::100]
    for p in found:
        near = (coarse > p.x - 0.01) & (coarse < p.x + 0.01)
        i = np.argmax(np.where(near, g, -1))
        w = fine[max(0, 100 * i - 200):100 * i + 200]
        best = w[np.argmax([gain(x) for x in w])]      # the peak on a 1e-6 grid
        assert abs(p.x - best) <= 1e-5 + 1e-6
        assert p.y >= p.grid_y


def test_a_maximum_at_the_grid_edge_is_flagged_not_refined():
    p = peaks.refine_peak(lambda w: amplitude(w, 0.05), np.linspace(0.5, 0.9, 5) * W_N)
    assert not p.bounded and p.points == [] and p.x == pytest.approx(0.9 * W_N)
    assert "EDGE" in peaks.describe(p)


def test_golden_search_refuses_a_non_bracket():
    g = peaks.golden_search(1.0, 0.5, 2.0, 0, 1, 0, 1e-3)
    with pytest.raises(ValueError):
        next(g)
