"""The SRDF's groups and disabled collision pairs, checked against the URDF's geometry.

Distances come from Pinocchio's collision library (coal) on the URDF's collision geometry;
the states are seeded, in the URDF's joint box (where "Never" must hold) or also inside the
coupled stops of the configuration's joint_limits.yaml (where every pair must be apart), for
every model.
"""

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest

from helpers import inside_stops
from phantom_pin._paths import DESCRIPTION_DIR
from phantom_pin.config import MODELS, models


@pytest.fixture(scope="module", params=models())
def shipped(request):
    return MODELS[request.param]


@pytest.fixture(scope="module")
def geometry(shipped):
    model = pin.buildModelFromUrdf(str(shipped.urdf), mimic=True)
    collision = pin.buildGeomFromUrdf(model, str(shipped.urdf), pin.GeometryType.COLLISION,
                                      package_dirs=[str(DESCRIPTION_DIR.parent)])
    collision.addAllCollisionPairs()
    return model, collision, shipped


def _disabled(shipped, reason: str) -> set[frozenset[str]]:
    srdf = ET.parse(shipped.srdf).getroot()
    return {frozenset((p.get("link1"), p.get("link2"))) for p in srdf.iter("disable_collisions")
            if p.get("reason") == reason}


def _distances(model, collision, theta: np.ndarray) -> dict[frozenset[str], float]:
    """Smallest distance (m) between each two links' collision geometry at theta."""
    data, geometry_data = model.createData(), collision.createData()
    # a stylus gimbal (the Touch's) at its zero: its parts are drawn, not collision geometry
    pin.computeDistances(model, data, collision, geometry_data, np.concatenate([theta, np.zeros(model.nq - 3)]))
    out: dict[frozenset[str], float] = {}
    for k, pair in enumerate(collision.collisionPairs):
        links = frozenset(model.frames[collision.geometryObjects[i].parentFrame].name
                          for i in (pair.first, pair.second))
        if len(links) == 2:
            out[links] = min(out.get(links, np.inf), geometry_data.distanceResults[k].min_distance)
    return out


def test_arm_group_lists_the_three_actuated_joints(shipped):
    srdf = ET.parse(shipped.srdf).getroot()
    (group,) = [g for g in srdf.iter("group") if g.get("name") == "arm"]
    assert [j.get("name") for j in group.findall("joint")] == ["joint1", "joint2", "joint3"]
    assert group.find("chain") is None


def test_adjacent_pairs_are_joined_by_a_joint_or_a_pin_without_geometry(shipped):
    urdf = ET.parse(shipped.urdf).getroot()
    parent = {j.find("child").get("link"): j.find("parent").get("link") for j in urdf.findall("joint")}
    with_geometry = {link.get("name") for link in urdf.findall("link") if link.find("collision") is not None}
    for pair in _disabled(shipped, "Adjacent"):
        a, b = sorted(pair)
        hops = {parent.get(a), parent.get(parent.get(a), None), parent.get(b), parent.get(parent.get(b), None)}
        joined = (parent.get(a) == b or parent.get(b) == a
                  or (parent.get(a) not in with_geometry and parent.get(parent.get(a)) == b)
                  or (parent.get(b) not in with_geometry and parent.get(parent.get(b)) == a))
        assert joined, f"{a} and {b} are not adjacent ({hops})"


def test_never_pairs_never_touch_anywhere_in_the_joint_box(geometry):
    model, collision, shipped = geometry
    never = _disabled(shipped, "Never")
    assert never
    rng = np.random.default_rng(11)
    worst = {pair: np.inf for pair in never}
    for theta in rng.uniform(model.lowerPositionLimit[:3], model.upperPositionLimit[:3], (3000, 3)):
        distances = _distances(model, collision, theta)
        for pair in never:
            worst[pair] = min(worst[pair], distances[pair])
    assert min(worst.values()) > 0, worst


def test_every_pair_is_apart_inside_the_stops_and_the_checked_ones_touch_outside(geometry):
    """Inside the coupled stops no two links touch; the pairs left checked are those that
    do touch somewhere in the box outside the stops (they flag unreachable states)."""
    model, collision, shipped = geometry
    for theta in inside_stops(1000, seed=12, config_dir=shipped.config):
        distances = _distances(model, collision, theta)
        assert min(distances.values()) > 0, (theta, min(distances, key=distances.get))
    disabled = _disabled(shipped, "Never") | _disabled(shipped, "Adjacent")
    rng = np.random.default_rng(13)
    box = rng.uniform(model.lowerPositionLimit[:3], model.upperPositionLimit[:3], (60000, 3))
    inside = {tuple(theta) for theta in inside_stops(60000, seed=13, pool=box, config_dir=shipped.config)}
    outside = [theta for theta in box if tuple(theta) not in inside]
    touched = set()
    for theta in outside[:3000]:
        touched |= {pair for pair, distance in _distances(model, collision, theta).items() if distance < 0}
    checked = set(_distances(model, collision, np.zeros(3))) - disabled
    assert checked <= touched, checked - touched
