"""Shared fixtures (one Phantom, seeded random states inside the joint limits) and the pytest
markers of the Debian packages some tests need. What tests import lives in helpers.py."""

import shutil
import subprocess

import numpy as np
import pytest

from helpers import CONFIG, N_STATES
from phantom_pin import Phantom
from phantom_pin.config.sampling import random_states


@pytest.fixture(scope="session")
def phantom() -> Phantom:
    return Phantom()


@pytest.fixture(scope="session")
def limits() -> tuple[np.ndarray, np.ndarray]:
    p = CONFIG.limits
    return np.array(p.lower), np.array(p.upper)


@pytest.fixture()
def states():
    """N_STATES seeded (theta, dtheta, ddtheta) inside the joint limits (config.sampling.random_states)."""
    return random_states(CONFIG.limits, N_STATES, seed=20261121)


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
