"""Physical consistency: the URDF check finds non-physical links, and the nearest consistent
parameters to an inconsistent estimate generate a URDF that passes it."""

import numpy as np
import pytest

from helpers import CONFIG, URDF_PATH
from phantom_pin import ParameterFileError, Phantom, describe
from phantom_pin.config.types import BODIES as BODIES_FULL
from phantom_pin.description.inertial import Inertial, problem
from phantom_pin.description.physical import check_urdf
from phantom_pin.identification.structure import parameterization as pz
from phantom_pin.identification.structure import physical
from phantom_pin.identification.structure.regressor import Regressor
from phantom_pin.identification.structure.structures import General, Report

DESCRIPTION = describe()
PHANTOM = Phantom(DESCRIPTION)
BODIES = Regressor(PHANTOM).bodies


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


def _report_target(x):
    """The report structure and the base parameters (constants, then the shipped friction) of x."""
    model = Report(PHANTOM)
    return model, model.matrix @ np.concatenate([x, model.friction_prior])


def test_nearest_consistent_parameters_keep_the_reachable_constants():
    x0 = pz.report_vector(CONFIG)
    bad = x0.copy()
    bad[pz.NAMES.index("segment_a.inertia.xx")] *= 3          # M33 up by 2 Iaxx: a real change
    model, target = _report_target(bad)
    x = model.nearest(target, 1.0 / np.abs(target), 1e-3)
    assert model.consistent(x) and physical.consistent(x[:-6], CONFIG)
    check_urdf(_urdf(x[:-6]), "the nearest consistent parameters' URDF")
    # M33 = Iaxx + Idfxx + ...: the fit moves Idfxx instead of making the forearm non-physical
    np.testing.assert_allclose(model.matrix @ x, target, rtol=1e-6)


def test_nearest_keeps_the_rotor_inertia_positive():
    """An estimate whose I_bexx is 0.3 times the report's (less than joint 2's rotor alone,
    J r2^2): the nearest consistent parameters must not buy it with a negative rotor inertia,
    and a negative J is never consistent."""
    x0 = pz.report_vector(CONFIG)
    bad = x0.copy()
    bad[pz.NAMES.index("segment_be.inertia.xx")] *= 0.3
    model, target = _report_target(bad)
    x = model.nearest(target, 1.0 / np.abs(target), 1e-3)
    assert x[pz.ROTOR] > 0 and physical.consistent(x[:-6], CONFIG)
    negative = x0.copy()
    negative[pz.ROTOR] = -1e-7
    assert not physical.consistent(negative, CONFIG)


def test_the_pseudo_inertia_is_positive_definite_exactly_when_the_link_is_physical():
    """Wensing, Kim and Slotine's law against the one physical check of a link (inertial.problem:
    mass, positive definite inertia, triangle inequality), on 2000 seeded random bodies around
    the boundary (products of inertia and centres of mass off every axis)."""
    rng = np.random.default_rng(8)
    agree = 0
    for _ in range(2000):
        moments = rng.uniform(0.1, 1.0, 3) * 1e-4
        moments[2] = (moments[0] + moments[1]) * rng.uniform(0.9, 1.1)        # near the triangle's edge
        rotation = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        tensor = rotation @ np.diag(moments) @ rotation.T
        body = Inertial(rng.uniform(0.01, 0.3), tuple(rng.normal(0, 0.05, 3)),
                        tuple(tensor[i, j] for i, j in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))))
        slack = (moments[0] + moments[1] - moments[2]) / moments[2]
        if abs(slack) < 1e-9:       # the check's own margin (TRIANGLE_SLACK) decides there
            continue
        positive = np.linalg.eigvalsh(physical.pseudo_inertia(body.dynamic_parameters())).min() > 0
        assert positive == (problem(body) is None), (slack, problem(body))
        agree += 1
    assert agree > 1900


def test_the_nearest_full_bodies_are_optimal_among_consistent_neighbours():
    """The general structure's projection of an estimate made inconsistent (the forearm's
    products of inertia and centre of mass far off its axis): the result is consistent, and no
    consistent point on 200 seeded random segments from it does better (the problem is convex:
    a point that no feasible direction improves is the optimum)."""
    model = General(PHANTOM)
    x0 = model.prior.copy()
    forearm = 10 * BODIES_FULL.index("forearm_link")
    bad = x0.copy()
    bad[forearm + 1:forearm + 4] += 0.3 * x0[forearm] * 0.05             # first moments 1.5 cm off
    bad[forearm + 5] += 3e-5                                              # Ixy
    assert not model.consistent(bad)
    target = model.matrix @ bad
    weights = 1.0 / np.maximum(np.abs(target), 1e-9)
    x = model.nearest(target, weights, 1e-3)
    assert model.consistent(x)

    def cost(v):
        return np.sum((weights * (model.matrix @ v - target)) ** 2) + 1e-6 * np.sum(((v - x0) / model.scale) ** 2)
    rng = np.random.default_rng(2)
    for _ in range(200):
        other = x + rng.normal(0, 1, len(x)) * model.scale * 1e-3
        for share in (1.0, 0.1, 0.01):
            candidate = x + share * (other - x)
            if model.consistent(candidate):
                assert cost(candidate) >= cost(x) * (1 - 1e-9)


def test_an_optimum_on_the_boundary_is_consistent_and_keeps_the_fit():
    """The general structure's projection where the optimum lies on the boundary (issue 42,
    L14): an estimate from a consistent model whose turret body has twice its inertia (about
    its centre of mass), which the data sees only in the turret's Izz (joint 1's axis). The
    unconstrained optimum shares that Izz among the combination's members and leaves the
    unseen Ixx and Iyy at the prior, breaking the turret's triangle inequality, so the barrier
    ends on the boundary. The result must pass the check (the bodies as the overlay writes
    them, the turret body with the pins' moment, and the links) and cost no more than the
    consistent model the estimate came from: the optimum does at least as well as any
    consistent point. Measured: 0.34 times its cost; a barrier on the tree's links alone ended
    with the turret body outside and stepped back towards the prior, 950 times."""
    model = General(PHANTOM)
    x0 = model.prior.copy()
    turret = 10 * BODIES_FULL.index("turret_link")
    body = Inertial.from_dynamic_parameters(x0[turret:turret + 10])
    xx, xy, xz, yy, yz, zz = body.inertia
    heavy = x0.copy()
    heavy[turret:turret + 10] = Inertial(body.mass, body.com, (2 * xx, xy, xz, 2 * yy, yz, 2 * zz)).dynamic_parameters()
    assert model.consistent(heavy)
    target = model.matrix @ heavy
    weights = 1.0 / np.maximum(np.abs(target), 1e-9)
    whitened = physical._Whitened(target, np.diag(weights), model.matrix, x0, model.scale, np.array([], int), 1e-3)
    assert not model.consistent(whitened.full(whitened.optimum))          # the optimum is on the boundary

    def cost(v):
        return np.sum((weights * (model.matrix @ v - target)) ** 2) + 1e-6 * np.sum(((v - x0) / model.scale) ** 2)
    x = model.nearest(target, weights, 1e-3)
    assert model.consistent(x)
    assert cost(x) <= cost(heavy), (cost(x), cost(heavy))
