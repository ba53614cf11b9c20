"""Shared fixtures. ctest (tests/checks/python.cmake) sets TASE_CLI and
TASE_SIM to the programs of the build; run by hand, they are looked up on
the PATH."""

import os
import shutil

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def _program(env, name):
    path = os.environ.get(env) or shutil.which(name)
    if not path:
        pytest.skip("%s not found (set %s)" % (name, env))
    return path


@pytest.fixture(scope="session")
def tase_cli():
    return _program("TASE_CLI", "tase")


@pytest.fixture(scope="session")
def tase_sim(tase_cli):
    path = _program("TASE_SIM", "tase-sim")
    os.environ["TASE_SIM"] = path
    return path


@pytest.fixture
def sim(tase_sim):
    import tase

    with tase.sim.start() as s:
        yield s
