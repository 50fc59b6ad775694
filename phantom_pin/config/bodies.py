"""The seven links of the URDF and the mechanism's five rigid bodies: the hinge pins carved
out of their neighbours (``carve``) and put back (``uncarve``)."""

from __future__ import annotations

from collections.abc import Mapping

from phantom_pin.config.types import Kinematics
from phantom_pin.inertial import Inertial, without_point_mass


def carve(bodies: Mapping[str, Inertial], pin: Inertial, kinematics: Kinematics) -> dict[str, Inertial]:
    """The seven links (LINKS) of the five bodies (BODIES) and a hinge pin (mass at its pivot,
    inertia about it): the pin's mass at its pivot out of crank_link (0, 0, -l3) and
    lower_bar_link (l1, 0, 0), the two pins' vertical moment out of turret_link; ``uncarve``
    is its inverse."""
    turret = bodies["turret_link"]
    return {
        "turret_link": Inertial(turret.mass, turret.com, (*turret.inertia[:5], turret.inertia[5] - 2 * pin.inertia[5])),
        "upper_arm_link": bodies["upper_arm_link"],
        "crank_link": without_point_mass(bodies["crank_link"], pin.mass, (0.0, 0.0, -kinematics.l3)),
        "crank_pin_link": pin,
        "lower_bar_link": without_point_mass(bodies["lower_bar_link"], pin.mass, (kinematics.l1, 0.0, 0.0)),
        "forearm_pin_link": pin,
        "forearm_link": bodies["forearm_link"],
    }


def uncarve(links: Mapping[str, Inertial], kinematics: Kinematics) -> dict[str, Inertial]:
    """The five bodies (BODIES) of seven links: ``carve`` undone (a point mass taken out with a
    negative mass is put back), for a model in the report's form as for one in full."""
    pin = links["crank_pin_link"]
    turret = links["turret_link"]
    return {
        "turret_link": Inertial(turret.mass, turret.com, (*turret.inertia[:5], turret.inertia[5] + 2 * pin.inertia[5])),
        "upper_arm_link": links["upper_arm_link"],
        "crank_link": without_point_mass(links["crank_link"], -pin.mass, (0.0, 0.0, -kinematics.l3)),
        "lower_bar_link": without_point_mass(links["lower_bar_link"], -pin.mass, (kinematics.l1, 0.0, 0.0)),
        "forearm_link": links["forearm_link"],
    }
