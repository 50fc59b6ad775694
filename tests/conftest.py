"""Shared fixtures (one Phantom, seeded random states inside the joint limits, the command line run
in-process, the Touch's six-joint model, a copy of a configuration folder), the pytest markers
of the Debian packages some tests need, and the groups the xdist workers keep together. What
tests import lives in helpers.py."""

import os
import shutil
import subprocess
from collections.abc import Callable

import pytest

# One BLAS thread in the test processes and the scripts they start, set before NumPy loads
# OpenBLAS: the identification's SVDs and least squares on tall (3N, P) matrices took 3 to 5
# times the CPU with OpenBLAS's threads on a 2-core machine (an `identify` of a 20 s log: 5.8 s
# of CPU against 1.1 s), and with the xdist workers filling the cores a script's threads could
# take minutes (`check -n 2e7` took 64 s to answer Ctrl-C). The xdist workers inherit it. (excite
# limits its own optimisation to one thread on one kernel wherever it runs: phantom_pin._blas.)
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# SymPy's cache unbounded, set before SymPy loads (its default keeps 1000 results): the C headers'
# generation (codegen) takes 18 % less CPU (8.2 s against 6.7 s for the three models), the same bytes.
os.environ.setdefault("SYMPY_CACHE_SIZE", "none")

import numpy as np  # after the setting above

# The fixtures import helpers (Pinocchio, the package) when first used: pytest's own process,
# which hands the tests to the xdist workers, needs none of it and starts them a second sooner.


@pytest.fixture(scope="session")
def phantom():
    from phantom_pin import Phantom

    return Phantom()


@pytest.fixture(scope="session")
def limits() -> tuple[np.ndarray, np.ndarray]:
    from helpers import CONFIG

    p = CONFIG.limits
    return np.array(p.lower), np.array(p.upper)


@pytest.fixture()
def cli() -> Callable[..., tuple[int, str, str]]:
    """phantom-pin in this process: ``cli(*arguments)`` gives (exit code, stdout, stderr)
    (helpers.run_cli)."""
    from helpers import run_cli

    return run_cli


@pytest.fixture()
def states():
    """N_STATES seeded (theta, dtheta, ddtheta) inside the joint limits (config.sampling.random_states)."""
    from helpers import CONFIG, N_STATES
    from phantom_pin.config.sampling import random_states

    return random_states(CONFIG.limits, N_STATES, seed=20261121)


@pytest.fixture()
def folder(tmp_path):
    """A copy of premium_1_5's configuration folder (tmp_path/config), to edit."""
    from phantom_pin.config import MODELS

    shutil.copytree(MODELS["premium_1_5"].config, tmp_path / "config")
    return tmp_path / "config"


@pytest.fixture(scope="module")
def six():
    """The Touch's six-joint model built from its committed URDF by Pinocchio alone (helpers.Six):
    the reference of the arm's dynamics with the gimbal held at given angles."""
    from helpers import Six

    return Six()


def _sdformat() -> bool:
    found = shutil.which("g++") and shutil.which("pkg-config")
    return bool(found) and subprocess.run(["pkg-config", "--exists", "sdformat12"]).returncode == 0


#: The Debian packages some tests need (pytest markers), how to tell they are there, and the
#: one line said when one is missing: the test fails with it (CI installs them all and runs
#: every test; nothing is skipped).
REQUIREMENTS = {
    "chromium": (lambda: bool(shutil.which("chromium")),
                 "Debian's chromium renders the viewer's HTML: apt-get install chromium (.ci/run installs it)"),
    "sdformat": (_sdformat, "Gazebo's URDF parser is missing: apt-get install libsdformat-dev g++ pkg-config "
                            "(.ci/run installs them)"),
    "colcon": (lambda: bool(shutil.which("colcon", path="/usr/bin") and shutil.which("cmake")),
               "Debian's colcon and ament_cmake build the ROS 2 package: apt-get install colcon "
               "python3-colcon-cmake ament-cmake cmake (.ci/run installs them)"),
}


def pytest_runtest_setup(item: pytest.Item) -> None:
    for marker in item.iter_markers():
        if marker.name in REQUIREMENTS:
            present, missing = REQUIREMENTS[marker.name]
            if not present():
                pytest.fail(missing, pytrace=False)


#: Tests kept on one pytest-xdist worker, in the order collected (pyproject's addopts: -n auto
#: --dist loadgroup; every other test is handed out one by one): a group name for each test
#: whose node id contains the key (a test file's path under tests/). A module whose
#: module-scoped fixture (or a cache of its helpers, shared with another module) is expensive
#: computes it once, not once per worker
#: (codegen/test_generate.py, test_servo.py and cli/test_codegen.py: their headers, generated once per
#: arguments (helpers.generated); the SymPy derivations of
#: references.cad and phantom_pin.report.derivation); the ROS 2 node tests over loopback run one
#: at a time.
GROUPS = {
    "identification/structure/test_structures.py::": "identification_general",
    "identification/structure/test_prior.py::": "lab_log",
    "identification/data/test_timing.py::": "lab_log",
    "identification/verdict/test_result.py::": "identification_end_to_end",
    "identification/fitting/test_instruments.py::": "instruments",  # closed_loop(): 60 s simulated, 2-3 s
    "identification/data/test_bags.py::": "bags",                   # report_csv: an identify
    "viewer/test_viewer.py::": "viewer",                            # two meshcat servers and their robots
    "description/test_srdf.py::": "srdf",                           # each model's collision geometry
    "integration/test_interop.py::": "interop",                     # each model's Drake plant
    "integration/test_gazebo.py::": "gazebo",
    "codegen/test_generate.py::": "codegen",
    "codegen/test_servo.py::": "codegen",
    "cli/test_codegen.py::": "codegen",
    "openhaptics/test_stand_in.py::": "stand_in",                   # each model's stand-in and programs, built once
    "config/test_cad_model.py::": "cad_model",
    "report/test_derivation.py::": "derivation",
    "ros2/test_node.py::test_the_node_": "ros2",
    "integration/test_drivers_ros2.py::test_the_stylus_floats": "ros2",
    "integration/test_drivers_ros2.py::test_without_the_node": "ros2",
}

def group(nodeid: str) -> str | None:
    """The GROUPS name of a test's node id, or None."""
    return next((name for key, name in GROUPS.items() if key in nodeid), None)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: object) -> object:
    """--dist loadgroup with GROUPS (pytest-xdist's own marks no longer reach the node ids under
    pytest 9): each group is one unit of work, the largest handed out first; every other test
    is its own."""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class GroupScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return group(nodeid) or nodeid

    config.option.loadscopereorder = True
    return GroupScheduling(config, log)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """A test that renders in chromium is slow too (a browser per page: 1-3 s of CPU each):
    pytest -m "not slow" leaves them to CI."""
    for item in items:
        if item.get_closest_marker("chromium") is not None:
            item.add_marker(pytest.mark.slow)
