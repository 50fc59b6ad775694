"""Physical consistency: the URDF check finds non-physical links, and the nearest consistent
parameters to an inconsistent estimate generate a URDF that passes it."""

import numpy as np
import pytest

from conftest import CONFIG, URDF_PATH
from phantom_pin import ParameterFileError, Phantom, describe
from phantom_pin.description.physical import check_urdf
from phantom_pin.identification import constants, physical
from phantom_pin.identification import parameterization as pz
from phantom_pin.identification.regressor import Regressor

DESCRIPTION = describe()
BODIES = Regressor(Phantom(DESCRIPTION)).bodies


def _urdf(x):
    """The URDF describe() generates for the report parameters x (ParameterFileError if not physical)."""
    return describe(overrides=pz.overrides(x, CONFIG)).urdf


def test_shipped_urdf_is_physical():
    check_urdf(URDF_PATH.read_text(), "the shipped URDF")
    affine, offset = pz.affine_map(DESCRIPTION, BODIES)
    assert physical.consistent(pz.report_vector(CONFIG), CONFIG)


def test_non_physical_links_are_found():
    x = pz.report_vector(CONFIG)
    rotor2 = x[pz.ROTOR] * 11.6**2
    lumped = x.copy()
    lumped[pz.NAMES.index("segment_be.inertia.xx")] = 0.5 * rotor2     # less than the rotor alone
    with pytest.raises(ParameterFileError,
                       match="upper_arm_link: inertia at the centre of mass is not positive definite"):
        _urdf(lumped)
    rod = x.copy()
    yy, zz = rod[pz.NAMES.index("segment_a.inertia.yy")], rod[pz.NAMES.index("segment_a.inertia.zz")]
    rod[pz.NAMES.index("segment_a.inertia.xx")] = 1.001 * (yy + zz)     # just past the boundary
    with pytest.raises(ParameterFileError, match="forearm_link: .*triangle inequality"):
        _urdf(rod)
    affine, offset = pz.affine_map(DESCRIPTION, BODIES)
    assert not physical.consistent(lumped, CONFIG) and not physical.consistent(rod, CONFIG)


def test_nearest_consistent_parameters_keep_the_reachable_constants():
    affine, offset = pz.affine_map(DESCRIPTION, BODIES)
    x0 = pz.report_vector(CONFIG)
    c = constants.constants_matrix(DESCRIPTION)
    bad = x0.copy()
    bad[pz.NAMES.index("segment_a.inertia.xx")] *= 3          # M33 up by 2 Iaxx: a real change
    target = c @ bad
    x = physical.nearest(target, 1.0 / np.abs(target), c, x0, affine, offset, CONFIG)
    assert physical.consistent(x, CONFIG)
    check_urdf(_urdf(x), "the nearest consistent parameters' URDF")
    # M33 = Iaxx + Idfxx + ...: the fit moves Idfxx instead of making the forearm non-physical
    np.testing.assert_allclose(c @ x, target, rtol=1e-6)


def test_nearest_keeps_the_rotor_inertia_positive():
    """An estimate whose I_bexx is 0.3 times the report's (less than joint 2's rotor alone,
    J r2^2): the nearest consistent parameters must not buy it with a negative rotor inertia,
    and a negative J is never consistent."""
    affine, offset = pz.affine_map(DESCRIPTION, BODIES)
    x0 = pz.report_vector(CONFIG)
    c = constants.constants_matrix(DESCRIPTION)
    bad = x0.copy()
    bad[pz.NAMES.index("segment_be.inertia.xx")] *= 0.3
    target = c @ bad
    x = physical.nearest(target, 1.0 / np.abs(target), c, x0, affine, offset, CONFIG)
    assert x[pz.ROTOR] > 0 and physical.consistent(x, CONFIG)
    negative = x0.copy()
    negative[pz.ROTOR] = -1e-7
    assert not physical.consistent(negative, CONFIG)
