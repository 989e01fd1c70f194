"""Shared fixtures for the TLD.fmu test suite.

The FMU is expected at <repo>/target/fmu/TLD.fmu (built by the Rust side). If it is missing,
every test that needs it FAILS (not skips) with a message saying so; the tests of the reference
solutions (test_reference.py) still run.

`Slave` (tld_fmu.slave) drives one FMU instance through fmpy's low-level FMU2Slave API.
"""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import pytest

from tld_fmu.paths import BUILDING_FMU
from tld_fmu.paths import FMU as FMU_PATH   # the build's output; TLD_FMU_PATH overrides it
from tld_fmu.slave import Slave


def _require_fmu() -> Path:
    if not FMU_PATH.is_file():
        pytest.fail(
            f"TLD.fmu not found at {FMU_PATH}: build it first (the Rust build writes "
            f"target/fmu/TLD.fmu); these tests cannot run without it.",
            pytrace=False,
        )
    return FMU_PATH


@pytest.fixture(scope="session")
def fmu_path() -> Path:
    return _require_fmu()


@pytest.fixture(scope="session")
def building_path() -> Path:
    if not BUILDING_FMU.is_file():
        pytest.fail(f"Building.fmu not found at {BUILDING_FMU}: build it first (scripts/package)",
                    pytrace=False)
    return BUILDING_FMU


@pytest.fixture(scope="session", params=["TLD", "Building"])
def any_fmu(request) -> Path:
    """Each FMU of the workspace in turn: the checks every FMU must pass."""
    return _require_fmu() if request.param == "TLD" else request.getfixturevalue("building_path")


@pytest.fixture(scope="session")
def model_description(fmu_path):
    from fmpy import read_model_description
    return read_model_description(str(fmu_path))


@pytest.fixture(scope="session")
def unzipdir(fmu_path):
    from fmpy import extract
    d = tempfile.mkdtemp(prefix="tld_fmu_")
    extract(str(fmu_path), d)
    yield d
    shutil.rmtree(d, ignore_errors=True)


@pytest.fixture(scope="session")
def variables(model_description):
    return {v.name: v for v in model_description.modelVariables}


@pytest.fixture
def slave_factory(model_description, unzipdir, variables):
    """slave_factory(**kw) -> Slave; all slaves made in a test are freed at its end."""
    made = []

    def make(**kw):
        s = Slave(model_description, unzipdir, variables, **kw)
        made.append(s)
        return s

    yield make
    for s in made:
        s.close()


# parameters that make the four models differ in the host-comparison scenes: the S^2 model's mass exchange
# (set, not left to its default from the NSD law, so the scenes do not change with A_e or that law;
# Omega = 1 would make it the linear model until an impact), and an Auto threshold at which it
# steps linearly part of the time (at the default it matches Nonlinear to ~1e-14)
MODELS_APART = {"slamming.Omega": 0.9, "auto.threshold": 1e-2}
