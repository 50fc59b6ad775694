"""The regressor in the report's coordinates against Phantom.inverse_dynamics: its friction
columns, its batch and single states, the known parameters' zero torque, what each column is
(the report parameters' affine map against the generated URDF: test_parameterization.py)."""

import numpy as np
import pytest

from helpers import seeded_states
from phantom_pin import Phantom
from phantom_pin.identification.structure import parameterization as pz
from phantom_pin.identification.structure.regressor import Regressor


@pytest.fixture(scope="module")
def regressor():
    return Regressor(Phantom())


def test_regressor_times_shipped_parameters_is_inverse_dynamics(regressor):
    theta, dtheta, ddtheta = seeded_states(regressor, 1000, 0)
    tau = Phantom().inverse_dynamics(theta, dtheta, ddtheta)
    predicted = regressor(theta, dtheta, ddtheta) @ regressor.parameters()
    assert np.abs(predicted - tau).max() <= 1e-12 * np.abs(tau).max()


def test_friction_columns_follow_the_actuation_law(regressor):
    theta, dtheta, ddtheta = seeded_states(regressor, 50, 1)
    viscous, coulomb = np.array([1e-3, 2e-3, 3e-3]), np.array([0.01, 0.02, 0.03])
    law = viscous * dtheta + coulomb * np.sign(dtheta)
    rigid = regressor(theta, dtheta, ddtheta) @ regressor.parameters()
    with_friction = regressor(theta, dtheta, ddtheta) @ regressor.parameters(viscous, coulomb)
    np.testing.assert_allclose(with_friction - rigid, law, rtol=0, atol=1e-15)


def test_the_coulomb_column_is_the_full_level_at_any_rate():
    """The simulator's sliding law: 1e-6 rad/s already meets the whole Coulomb torque (the
    smoothed tanh(dtheta / 0.1 rad/s) of before gave 1e-5 of it); 0 at rest."""
    regressor = Regressor(Phantom())
    column = regressor(np.zeros(3), np.array([1e-6, -1e-6, 0.0]), np.zeros(3))[:, regressor.friction][:, 3:]
    np.testing.assert_array_equal(np.diag(column), [1.0, -1.0, 0.0])


def test_single_state_equals_the_batch_row(regressor):
    theta, dtheta, ddtheta = seeded_states(regressor, 3, 2)
    np.testing.assert_array_equal(regressor(theta[1], dtheta[1], ddtheta[1]),
                                  regressor(theta, dtheta, ddtheta)[1])




def test_the_known_parameters_give_no_torque(regressor):
    """The hinge pins' compensation and the base's fixed mass and x/z inertias cancel."""
    _, offset = pz.affine_map(regressor.phantom.description, regressor.bodies)
    y = regressor.stacked(*seeded_states(regressor, 200, 4))
    assert np.abs(y[:, :len(offset)] @ offset).max() < 1e-12  # N m, against torques of 0.1 N m



def test_every_column_is_what_its_name_says(regressor):
    """rotor_j is ddtheta_j on joint j, viscous_j is dtheta_j, coulomb_j is sign(dtheta_j), each
    on joint j only."""
    theta, dtheta, ddtheta = seeded_states(regressor, 20, 9)
    y = regressor(theta, dtheta, ddtheta)
    for j in range(3):
        for name, expected in ((f"rotor{j + 1}", ddtheta[:, j]), (f"viscous{j + 1}", dtheta[:, j]),
                               (f"coulomb{j + 1}", np.sign(dtheta[:, j]))):
            column = y[:, :, regressor.names.index(name)]
            np.testing.assert_allclose(column[:, j], expected, rtol=1e-15, atol=0)
            assert not np.delete(column, j, axis=1).any()
