"""The benchmark's shallow-water measures (bench/python/workprec/swe.py, issue #29): the rms
time-history error of force.mean relative to the reference's peak, and the cells and cost at
equal error interpolated between the measured counts, against closed forms."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench" / "python"))
from workprec.swe import at_equal_error, rms_err  # noqa: E402


def test_rms_err_is_the_rms_difference_over_the_reference_peak():
    t = np.linspace(0.0, 10.0, 100_001)
    ref = 2.0 * np.sin(t)
    # A constant offset c: rms c, peak 2.
    assert rms_err(ref + 0.1, ref) == pytest.approx(0.05, rel=1e-12)
    # A sine of amplitude e over whole periods: rms e/sqrt(2); peak of the reference 2.
    e = 0.04 * np.sin(2 * math.pi * t)
    assert rms_err(ref + e, ref) == pytest.approx(0.02 / math.sqrt(2), rel=1e-3)
    # Only the common length counts, and a sign flip of the error does not change it.
    assert rms_err(np.append(ref - 0.1, 99.0), ref) == pytest.approx(0.05, rel=1e-12)


def row(cells, err, ns_per_step, steps=100):
    return dict(cells=cells, rms_mean=err, ns=ns_per_step * steps, steps=steps)


def test_equal_error_interpolates_log_log_between_the_bracketing_counts():
    # error = 1/cells, cost per step = cells^2: exact on a log-log line.
    rows = [row(c, 1.0 / c, float(c) ** 2) for c in (50, 100, 200, 400)]
    cells, ns = at_equal_error(rows, 1.0 / 150.0)
    assert cells == pytest.approx(150.0, rel=1e-12)
    assert ns == pytest.approx(150.0**2, rel=1e-12)
    # Exactly at a measured count: that count.
    cells, ns = at_equal_error(rows, 1.0 / 200.0)
    assert (cells, ns) == (pytest.approx(200.0), pytest.approx(200.0**2))
    # Outside the measured errors: no answer, not an extrapolation.
    assert at_equal_error(rows, 1.0) is None
    assert at_equal_error(rows, 1e-4) is None
