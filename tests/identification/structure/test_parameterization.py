"""identification.structure.parameterization: the report parameters' affine map (from the
configuration alone) against the URDF that describe() generates through xacro and Pinocchio
reads, and against the report's closed form; x and its ReportParameters and --params keys
against the configuration's report numbers; the refusals naming their argument."""

import numpy as np
import pytest

from helpers import CONFIG, seeded_states
from phantom_pin import InvalidInputError, Phantom, closed_form, config, describe
from phantom_pin.dynamics.coupling import Coupling
from phantom_pin.identification.structure import parameterization as pz
from phantom_pin.identification.structure.regressor import Regressor

REGRESSOR = Regressor(Phantom())


def _urdf_parameters(x: np.ndarray) -> np.ndarray:
    """pi without friction of the URDF that describe() generates for the report parameters x:
    Pinocchio's tree inertias, then J r_i^2."""
    description = describe(overrides=pz.overrides(x, CONFIG))
    tree = Coupling(description.urdf).tree
    ratios = np.array(description.config.actuation.ratios)
    inertial = [tree.inertias[i].toDynamicParameters() for i in range(1, tree.njoints)]
    return np.concatenate(inertial + [x[pz.ROTOR] * ratios**2])


def test_affine_map_reproduces_the_generated_urdf():
    description = REGRESSOR.phantom.description
    affine, offset = pz.affine_map(description, REGRESSOR.bodies)
    x0 = pz.report_vector(description.config)
    # each parameter 0.2 % below its value, another point than the map's (0.1 % above); more
    # would leave the thin forearm rod (Izz 0.4 % of Ixx = Iyy) non-physical, which describe() refuses
    for k in range(len(x0)):
        x = x0.copy()
        x[k] *= 0.998
        urdf_pi = _urdf_parameters(x)
        assert np.abs(affine @ x + offset - urdf_pi).max() <= 1e-12 * np.abs(urdf_pi).max(), pz.NAMES[k]


def test_affine_map_times_the_regressor_is_the_closed_form_at_other_parameters():
    """Y (A x + b) is the report's closed-form inverse dynamics of x (which counts the rotors
    inside I_bexx, I_dfxx and I_baseyy, as the report prints them), at x moved 5-15 % from the
    shipped values, rotor inertia J included: the map splits each rotor out of its link as
    J r^2 and back into the armature, exactly."""
    description = REGRESSOR.phantom.description
    affine, offset = pz.affine_map(description, REGRESSOR.bodies)
    x = pz.report_vector(description.config) * np.random.default_rng(7).uniform(0.85, 1.15, len(pz.NAMES))
    theta, dtheta, ddtheta = seeded_states(REGRESSOR, 200, 8)
    pi = np.concatenate([affine @ x + offset, np.zeros(6)])      # no friction
    tau = closed_form.inverse_dynamics(theta, dtheta, ddtheta, pz.report_parameters(x, description.config))
    predicted = REGRESSOR(theta, dtheta, ddtheta) @ pi
    assert np.abs(predicted - tau).max() <= 1e-11 * np.abs(tau).max()


def test_x_round_trips_through_the_report_numbers_and_the_params_keys():
    """report_vector reads the report's numbers (first moments m l5 and m l6 by hand);
    report_parameters gives them back, l5 = (m l5) / m exactly as the report prints it (1e-15);
    overrides names each --params key once, the centres of mass as l5 and l6 (m)."""
    p = CONFIG.report
    x = pz.report_vector(CONFIG)
    assert x[pz.NAMES.index("segment_be.first_moment")] == p.mbe * p.l5
    assert x[pz.NAMES.index("segment_df.first_moment")] == p.mdf * p.l6
    assert [x[k] for k in pz.MASSES] == [p.ma, p.mc, p.mbe, p.mdf]
    assert x[pz.ROTOR] == CONFIG.actuation.rotor[0]
    back = pz.report_parameters(x, CONFIG)
    for name in ("ma", "Iaxx", "Icyy", "Ibezz", "mdf", "Idfxx", "Ibaseyy", "l1", "l2", "g"):
        assert getattr(back, name) == getattr(p, name), name
    assert back.l5 == pytest.approx(p.l5, rel=1e-15) and back.l6 == pytest.approx(p.l6, rel=1e-15)
    keys = pz.overrides(x, CONFIG)
    assert keys["segment_be.com"] == pytest.approx(p.l5, rel=1e-15)
    assert keys["segment_df.com"] == pytest.approx(p.l6, rel=1e-15)
    assert "segment_be.first_moment" not in keys and keys["segment_a.mass"] == p.ma
    assert len(keys) == len(pz.NAMES)


def test_a_model_not_in_the_reports_terms_is_refused_naming_its_argument():
    """The CAD model's links are given in full: report_of names ``model``, tree_parameters
    ``description``."""
    cad = config.read("premium_1_5_cad")
    with pytest.raises(InvalidInputError, match="not written in the report's terms") as refused:
        pz.report_vector(cad)
    assert refused.value.argument == "model"
    description = describe("premium_1_5_cad")
    with pytest.raises(InvalidInputError) as refused:
        pz.tree_parameters(pz.report_vector(CONFIG), description, REGRESSOR.bodies)
    assert refused.value.argument == "description"
