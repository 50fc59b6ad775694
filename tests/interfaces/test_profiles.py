"""The drivers' profiles (interfaces/profiles.py): one for every driver of drivers.md, each fact
cited with the driver's file and line, and a frame map that mirrors an axis refused."""

import numpy as np
import pytest

from helpers import PROFILES
from phantom_pin.interfaces import profiles
from references import driver as ref


def test_every_driver_of_drivers_md_has_a_profile_with_its_sources():
    assert set(PROFILES) == set(ref.FORCE)
    for name in PROFILES:
        profile = profiles.load(name)
        assert profile.name == name and profile.sources and all("@" in s for s in profile.sources)


def test_every_profile_cites_its_sources_for_the_joint_states_and_the_force():
    """Each fact of a profile with the driver's file and line (owner/repo@commit path:lines, or a page of
    the OpenHaptics guide the driver ships)."""
    import re

    import yaml

    for name in PROFILES:
        node = yaml.safe_load((profiles.PROFILES_DIR / f"{name}.yaml").read_text())
        for section in ("joint_states", "force"):
            sources = node[section]["sources"]
            cited = r"[\w.-]+/[\w.-]+@[0-9a-f]{7}\b.*(:\d| p\.\d)"
            assert sources and all(re.match(cited, s) for s in sources.values()), (name, section, sources)


# -- what the mutation survivors of ../shared/data/mutants6.md got past (each against a reference) --
def test_a_profile_whose_frame_map_mirrors_an_axis_is_refused(tmp_path, monkeypatch):
    """Mutant 05. A frame change between right-handed frames is a rotation, det +1; a hand-written
    map with one axis negated (det -1, numpy's determinant) renders every force mirrored: the
    profile is refused with a ParameterFileError (a ValueError) naming to_openhaptics; the same
    file with the driver's own map loads."""
    import yaml

    from phantom_pin.exceptions import ParameterFileError

    node = yaml.safe_load((profiles.PROFILES_DIR / "phantom_touch_ros2.yaml").read_text())
    mirrored = [[1, 0, 0], [0, 1, 0], [0, 0, -1]]
    assert round(np.linalg.det(np.array(mirrored, dtype=float))) == -1
    monkeypatch.setattr(profiles, "PROFILES_DIR", tmp_path)
    (tmp_path / "phantom_touch_ros2.yaml").write_text(yaml.safe_dump(node))
    profiles.load.cache_clear()
    try:
        assert profiles.load("phantom_touch_ros2").force.to_openhaptics.tolist() == np.eye(3).tolist()
        node["force"]["to_openhaptics"] = mirrored
        (tmp_path / "phantom_touch_ros2.yaml").write_text(yaml.safe_dump(node))
        profiles.load.cache_clear()
        with pytest.raises(ParameterFileError) as error:
            profiles.load("phantom_touch_ros2")
        assert isinstance(error.value, ValueError) and "to_openhaptics" in str(error.value)
    finally:
        profiles.load.cache_clear()
