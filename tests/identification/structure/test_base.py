"""Base parameters: the numerical rank of the general and the report-structured regressor,
and the report-structured base against the report's constants of eqs 81-94."""


import numpy as np
import pytest

from helpers import CONFIG, three_frequency_log
from helpers import seeded_states as _states
from phantom_pin import Phantom, describe
from phantom_pin.identification.structure import base, constants
from phantom_pin.identification.structure import parameterization as pz
from phantom_pin.identification.structure.base import base_parameters
from phantom_pin.identification.structure.regressor import Regressor
from phantom_pin.identification.structure.structures import Structured

REGRESSOR = Regressor(Phantom())
DESCRIPTION = REGRESSOR.phantom.description


def states(n, seed):
    return _states(REGRESSOR, n, seed)


@pytest.fixture(scope="module")
def structured():
    return Structured(REGRESSOR)


def test_general_model_has_26_base_parameters():
    regressor = REGRESSOR
    base = base_parameters(regressor.stacked(*states(300, 5)), regressor.names)
    # 20 inertial combinations (the report's 8 + 6 products of inertia + 6 off-plane first
    # moments) and the 6 friction coefficients
    assert base.rank == 26
    assert sum(name.startswith(("viscous", "coulomb")) for name in np.array(base.names)[list(base.independent)]) == 6


def test_report_structure_base_is_the_report_constants(structured):
    phi = structured(*states(300, 6))[0].reshape(-1, len(structured.names))
    x0 = pz.report_vector(CONFIG)
    base = base_parameters(phi, structured.names, np.concatenate([np.abs(x0), [1e-3] * 6]))
    assert base.rank == 14
    c = constants.constants_matrix(DESCRIPTION)
    assert np.linalg.matrix_rank(c) == 8
    # every constant is a combination of the base parameters and vice versa: the same span
    rigid = base.matrix[:, :20]
    rigid = rigid[np.abs(rigid).sum(axis=1) > 0]
    for a, b in ((c, rigid), (rigid, c)):
        coefficients = np.linalg.lstsq(b.T, a.T, rcond=None)[0]
        assert np.abs(b.T @ coefficients - a.T).max() <= 1e-10 * np.abs(a).max()





def test_sample_stays_inside_the_regressors_own_limits():
    """Before, base.sample ignored its regressor and sampled the shipped limits: with joint1
    limited to 0.2 rad (box and stop), a third of the shipped box's theta1 lies above it."""
    narrow = Regressor(Phantom(describe(overrides={"joint1.upper": 0.2, "joint_limits.stops.joint1.upper": 0.2})))
    theta = base.sample(narrow, 300, seed=3)[0]
    assert theta[:, 0].max() <= 0.2 and (narrow.phantom.config.limits.slack(theta) >= 0).all()
    wide = base.sample(REGRESSOR, 300, seed=3)[0]
    assert wide[:, 0].max() > 0.2  # the shipped limits reach beyond: the test can tell them apart


def test_a_smooth_excitation_shows_all_26_base_parameters():
    """On a three-frequency trajectory (helpers.three_frequency_log, sampled at
    50 Hz) the weakest of the 26 base parameters pivots at about 1e-5 of the strongest: the
    rank keeps it (a tolerance of 1e-4 would give 25)."""
    data = three_frequency_log()
    rates = np.gradient(data.theta, data.t, axis=0)
    accelerations = np.gradient(rates, data.t, axis=0)
    keep = slice(0, None, 20)
    regressor = Regressor(Phantom())
    stacked = regressor.stacked(data.theta[keep], rates[keep], accelerations[keep])
    assert base_parameters(stacked, regressor.names).rank == 26


def test_the_device_has_the_trees_base_parameters_but_the_hinge_pins():
    """The general structure's base (x: the five bodies, the rotor inertia, friction; the pins
    fixed) has 24 parameters: the tree's 26 less the pins' own first moments along their bars,
    which the tree identifies separately and the device fixes (config: hinge_pin)."""
    from phantom_pin.identification.structure.structures import General

    general = General(REGRESSOR.phantom)
    tree = base_parameters(REGRESSOR.stacked(*states(300, 5)), REGRESSOR.names)
    pins = [name for name in np.array(tree.names)[list(tree.independent)] if "pin_link" in name]
    assert general.base.rank == 24 and tree.rank == 26
    assert sorted(pins) == ["crank_pin_link.mx", "forearm_pin_link.mx"], pins
    # the general base's columns span what the tree's span once the pins' columns are removed
    y = REGRESSOR.stacked(*states(200, 9))
    keep = [i for i in tree.independent if "pin_link" not in REGRESSOR.names[i]]
    phi = (y @ general.affine)[:, general.independent]
    assert np.linalg.matrix_rank(np.hstack([y[:, keep], phi]), tol=1e-9 * np.abs(y).max()) == 24
