"""The fast paths against the slow ones: single-state float64 shortcuts, batches
checked once, closed_form's chunked batches; and the Pinocchio facts they rely on."""

import warnings

import numpy as np
import pinocchio as pin
import pytest

from helpers import REPORT, URDF_PATH, relative_error
from phantom_pin import Device, InvalidInputError
from phantom_pin import closed_form as cf
from phantom_pin.dynamics.coupling import Coupling
from phantom_pin.dynamics.phantom import solve_spd
from phantom_pin.interfaces import conventions

# method, number of (3,) arguments; inverse_kinematics takes positions (below)
METHODS = [("forward_kinematics", 1), ("spatial_jacobian", 1), ("body_jacobian", 1),
           ("mass_matrix", 1), ("gravity", 1), ("potential_energy", 1), ("coriolis_matrix", 2),
           ("inverse_dynamics", 3), ("forward_dynamics", 3), ("inverse_dynamics_derivatives", 3)]


def _arguments(states, method, count):
    values = list(states[:count])
    if method == "forward_dynamics":
        values[2] = cf.inverse_dynamics(*states, REPORT)
    return values


def _stacked(result):
    return np.stack(result) if isinstance(result, tuple) else result


@pytest.mark.parametrize("convention", ["default", "WORLD"])
def test_crba_binding_returns_the_full_symmetric_matrix(phantom, states, convention):
    """Phantom.mass_matrix returns pin.crba's result as it is, and simulate's plant reads crba in
    the WORLD convention (the faster one, DEVELOPERS.md) as it is: the binding fills the lower
    triangle (data.M holds only the upper one). Bit-identical to the symmetrised matrix over
    every state and within 1e-13 of the closed form (eqs 81-85); a Pinocchio returning the
    upper triangle alone fails here (and against closed_form in test_phantom.py)."""
    data = phantom.model.createData()
    extra = () if convention == "default" else (pin.Convention.WORLD,)
    for theta in states[0]:
        m = pin.crba(phantom.model, data, theta, *extra)
        assert m[1, 2] != 0
        np.testing.assert_array_equal(m, np.triu(m) + np.triu(m, 1).T)
        assert relative_error(m, cf.mass_matrix(theta, REPORT)) < 1e-13


@pytest.mark.parametrize("method, count", METHODS)
def test_batches_equal_single_states_and_closed_form(phantom, states, method, count):
    values = [v[:300] for v in _arguments(states, method, count)]
    function = getattr(phantom, method)
    batch = _stacked(function(*values))
    single = np.stack([_stacked(function(*row)) for row in zip(*values)])
    if isinstance(function(*values), tuple):
        single = np.moveaxis(single, 1, 0)
    assert relative_error(batch, single) < 1e-12
    # any leading axes, lists and integer arrays take the checked path to the same numbers
    shaped = _stacked(function(*(v.reshape(10, 30, 3) for v in values)))
    np.testing.assert_array_equal(shaped.reshape(batch.shape), batch)
    listed = _stacked(function(*(v[7].tolist() for v in values)))
    np.testing.assert_array_equal(listed, _stacked(function(*(v[7] for v in values))))
    if hasattr(cf, method):
        reference = getattr(cf, method)(*values, REPORT)
        if method == "potential_energy":
            batch, reference = batch - batch[0], reference - reference[0]
        assert relative_error(batch, reference) < 1e-9


def test_single_state_inputs_other_than_float64_give_the_same_numbers(phantom):
    theta = np.array([0, 1, -1])
    for method in ("forward_kinematics", "spatial_jacobian", "body_jacobian", "mass_matrix", "gravity"):
        function = getattr(phantom, method)
        expected = function(theta.astype(float))
        for value in (theta, theta.tolist(), tuple(theta), theta.astype(np.float32)):
            np.testing.assert_array_equal(function(value), expected)
        with pytest.raises(InvalidInputError, match=r"^theta: expected shape \(3,\) or \(\.\.\., 3\)"):
            function(theta.astype(float)[:, None])


@pytest.mark.parametrize("method, count", METHODS + [("inverse_kinematics", 1)])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_nan_or_inf_in_any_component_raises_naming_the_argument(phantom, method, count, bad):
    """Single states (the fast paths) and batches; no RuntimeWarning on the way."""
    base = np.array([0.05, 0.02, 0.03]) if method == "inverse_kinematics" else np.array([0.2, 0.4, 0.5])
    name = "position" if method == "inverse_kinematics" else None
    for argument in range(count):
        for component in range(3):
            for batch in (False, True):
                values = [np.tile(base, (4, 1)) if batch else base.copy() for _ in range(count)]
                values[argument][..., component] = bad
                if name is None:
                    name_ = ("theta", "dtheta", "tau" if method == "forward_dynamics" else "ddtheta")[argument]
                else:
                    name_ = name
                with warnings.catch_warnings():
                    warnings.simplefilter("error")
                    with pytest.raises(InvalidInputError, match=f"^{name_}: contains NaN or inf"):
                        getattr(phantom, method)(*values)


@pytest.mark.parametrize("method, count", METHODS)
def test_every_argument_of_a_wrong_shape_is_refused_by_name(phantom, method, count):
    """The fast paths unpack x.tolist() into three (ValueError for (1, 3) and (4,), lists
    that isfinite refuses for (3, 1)); eigenpy itself would take a (3, 1) array as a
    3-vector. Each argument in turn, the others fine: the checked path names it, and (1, 3)
    everywhere is a batch of one state, equal to the single state."""
    base = np.array([0.2, 0.4, 0.5])
    names = ("theta", "dtheta", "tau" if method == "forward_dynamics" else "ddtheta")
    function = getattr(phantom, method)
    for argument in range(count):
        for wrong in (base[:, None], np.append(base, 0.1), base + 1j):
            values = [base] * count
            values[argument] = wrong
            expected = "expected real numbers" if wrong.dtype.kind == "c" else r"expected shape \(3,\)"
            with pytest.raises(InvalidInputError, match=f"^{names[argument]}: {expected}"):
                function(*values)
    one = _stacked(function(*[base] * count))
    batch = function(*[base[None]] * count)
    batch = np.stack([b[0] for b in batch]) if isinstance(batch, tuple) else batch[0]
    assert relative_error(batch, one) < 1e-12  # a batch solves and projects otherwise: rounding


def test_batches_still_check_shapes_and_overflow(phantom):
    with pytest.raises(InvalidInputError, match="^arguments must have the same shape"):
        phantom.forward_dynamics(np.zeros((4, 3)), np.zeros((4, 3)), np.zeros((5, 3)))
    with pytest.raises(InvalidInputError, match="^theta: expected shape"):
        phantom.mass_matrix(np.zeros((4, 2)))
    big = np.full((4, 3), 1e200)
    for call in (lambda: phantom.forward_dynamics(np.zeros((4, 3)), big, np.zeros((4, 3))),
                 lambda: phantom.inverse_dynamics_derivatives(np.zeros((4, 3)), big, np.zeros((4, 3))),
                 lambda: phantom.inverse_dynamics(np.zeros((4, 3)), big, np.zeros((4, 3))),
                 lambda: phantom.inverse_dynamics_derivatives(np.array([0.2, 0.4, 0.5]), np.full(3, 1e308),
                                                              np.zeros(3)),
                 lambda: phantom.forward_dynamics(np.zeros(3), np.zeros(3), np.full(3, 1e307))):
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # the error says it; no RuntimeWarning on the way
            with pytest.raises(InvalidInputError, match="too large, the result overflows"):
                call()


def test_closed_form_batches_span_chunks_and_equal_single_states(states):
    """50000 states: they cross the chunk boundaries of closed_form.inverse_dynamics (8192)."""
    theta, dtheta, ddtheta = (np.concatenate([s] * 50) for s in states)
    tau = cf.inverse_dynamics(theta, dtheta, ddtheta, REPORT)
    m, c, n = cf.mass_matrix(theta, REPORT), cf.coriolis_matrix(theta, dtheta, REPORT), cf.gravity(theta, REPORT)
    expected = np.einsum("nij,nj->ni", m, ddtheta) + np.einsum("nij,nj->ni", c, dtheta) + n
    assert relative_error(tau, expected) < 1e-12
    for k in (0, 8191, 8192, 16384, 49999):
        np.testing.assert_allclose(cf.inverse_dynamics(theta[k], dtheta[k], ddtheta[k], REPORT), tau[k],
                                   rtol=1e-13, atol=1e-15)
        np.testing.assert_array_equal(cf.mass_matrix(theta[k], REPORT), m[k])
        np.testing.assert_array_equal(cf.gravity(theta[k], REPORT), n[k])
    shaped = cf.inverse_dynamics(*(s.reshape(500, 100, 3) for s in (theta, dtheta, ddtheta)), REPORT)
    np.testing.assert_array_equal(shaped.reshape(-1, 3), tau)


def testsolve_spd_solves_and_refuses_what_is_not_positive_definite():
    rng = np.random.default_rng(5)
    for _ in range(100):
        a = rng.normal(size=(3, 3))
        m = a @ a.T + 0.1 * np.eye(3)
        r = rng.normal(size=3)
        np.testing.assert_allclose(solve_spd(m.tolist(), r.tolist()), np.linalg.solve(m, r), rtol=1e-9)
    for m in (np.diag([1.0, -1.0, 1.0]), np.zeros((3, 3)), np.full((3, 3), np.nan), -np.eye(3)):
        assert solve_spd(m.tolist(), [1.0, 2.0, 3.0]) is None


def test_forward_dynamics_still_refuses_a_mass_matrix_that_is_not_positive_definite(phantom, monkeypatch):
    theta = np.array([0.2, 0.4, 0.5])
    monkeypatch.setattr(pin, "crba", lambda model, data, q: -np.eye(3))
    for values in ((theta, theta, theta), (np.tile(theta, (2, 1)),) * 3):
        with pytest.raises(np.linalg.LinAlgError):
            phantom.forward_dynamics(*values)


def test_projection_by_the_kronecker_product_equals_two_products():
    coupling = Coupling(URDF_PATH.read_text())
    g = coupling.matrix
    a = np.random.default_rng(6).normal(size=(7, 7))
    np.testing.assert_allclose(coupling.project(a), g.T @ a @ g, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(coupling.project(np.asfortranarray(a)), g.T @ a @ g, rtol=1e-14, atol=1e-15)
    q = np.array([0.1, -0.2, 0.3])
    np.testing.assert_array_equal(coupling.configuration(q), g @ q)


@pytest.mark.parametrize("method, count", METHODS)
def test_fast_paths_return_fresh_arrays(phantom, method, count):
    """A single state's result is not overwritten by the next call (no view of Pinocchio's data)."""
    function = getattr(phantom, method)
    first = [np.array([0.1, 0.2, 0.3])] * count
    result = _stacked(function(*first))
    kept = result.copy()
    function(*[-x for x in first])
    np.testing.assert_array_equal(result, kept)


@pytest.mark.parametrize("method, third", [("inverse_dynamics", "ddtheta"), ("forward_dynamics", "tau"),
                                           ("gravity", None), ("mass_matrix", None),
                                           ("forward_kinematics", None), ("spatial_jacobian", None),
                                           ("body_jacobian", None)])
def test_shape_only_fast_paths_take_what_the_checked_path_takes(phantom, method, third):
    """These fast paths check shapes and let eigenpy convert: int, float32 and object
    arrays of numbers give the numbers of the checked path; complex and (3, 1) are refused by
    name, and booleans (which eigenpy would take, L9) in every argument, below."""
    function = getattr(phantom, method)
    count = 1 if third is None else 3
    theta = np.array([0, 1, -1])
    for value in (theta, theta.astype(np.float32), theta.astype(object), theta.tolist()):
        expected = function(*[np.asarray(value).astype(float)] * count)
        np.testing.assert_array_equal(function(*[value] * count), expected)
    with pytest.raises(InvalidInputError, match=r"^theta: expected shape \(3,\) or \(\.\.\., 3\)"):
        function(theta[:, None], *[theta] * (count - 1))
    with pytest.raises(InvalidInputError, match=f"^{third or 'theta'}: expected real numbers"):
        function(*[theta] * (count - 1), theta + 1j)


DEVICE = Device()
BOOLEANS = [np.array([True, False, True]), [True, False, True], np.array([True, False, True], dtype=object),
            np.array([[True, False, True]] * 2), np.array([[[True, False, True]]] * 2)]


@pytest.mark.parametrize("method, count", METHODS)
@pytest.mark.parametrize("booleans", range(len(BOOLEANS)))
def test_booleans_in_any_argument_are_refused_by_name(phantom, method, count, booleans):
    """L9: gravity([True, False, True]) computed at (1, 0, 1) rad. Booleans are no angles,
    rates or torques: each argument in turn (the others fine, of the same batch shape), as an
    array, a list, an object array, a batch and a batch of batches, single (the fast paths,
    where eigenpy takes booleans) and batched, is refused naming that argument."""
    value = BOOLEANS[booleans]
    names = ("theta", "dtheta", "tau" if method == "forward_dynamics" else "ddtheta")
    fine = np.full(np.shape(value), 0.3)
    for argument in range(count):
        values = [fine] * count
        values[argument] = value
        with pytest.raises(InvalidInputError, match=f"^{names[argument]}: expected real numbers, got booleans"):
            getattr(phantom, method)(*values)
        getattr(phantom, method)(*[v.astype(float) if isinstance(v, np.ndarray) else np.array(v, float)
                                   for v in values])  # the same numbers as floats are taken


@pytest.mark.parametrize("function, count", [("forward_kinematics", 1), ("mass_matrix", 1), ("gravity", 1),
                                             ("coriolis_matrix", 2), ("inverse_dynamics", 3),
                                             ("inverse_kinematics", 1)])
def test_closed_form_refuses_booleans_by_name(function, count):
    """L9 in the closed form too (it validates through the same as_states)."""
    names = ("position",) if function == "inverse_kinematics" else ("theta", "dtheta", "ddtheta")
    for argument in range(count):
        values = [np.array([0.01, 0.2, 0.1])] * count
        values[argument] = np.array([True, False, True])
        with pytest.raises(InvalidInputError, match=f"^{names[argument]}: expected real numbers, got booleans"):
            getattr(cf, function)(*values, REPORT)


@pytest.mark.parametrize("call, name", [(lambda d, b: d.friction(b), "dtheta"),
                                        (lambda d, b: d.motor_currents(b), "tau"),
                                        (lambda d, b: d.stop_torque(b, np.zeros(3)), "theta"),
                                        (lambda d, b: conventions.joint_state_from_theta(b), "theta"),
                                        (lambda d, b: conventions.openhaptics_torque_from_tau(b), "tau")])
def test_the_device_and_the_drivers_refuse_booleans_by_name(call, name):
    """L9 beyond the dynamics: the Device and the drivers' conversions."""
    with pytest.raises(InvalidInputError, match=f"^{name}: expected real numbers, got booleans"):
        call(DEVICE, np.array([True, False, True]))


@pytest.mark.parametrize("method, count", METHODS)
def test_batches_with_several_leading_axes_keep_them(phantom, states, method, count):
    """L9: a batch may have any number of leading axes (..., 3), as the docs now say: each
    result keeps them, and equals the single states' results row by row (against the closed
    form where it has the method, to 1e-9 relative)."""
    values = [v[:24].reshape(2, 3, 4, 3) for v in _arguments(states, method, count)]
    result = getattr(phantom, method)(*values)
    for one in (result if isinstance(result, tuple) else (result,)):
        assert one.shape[:3] == (2, 3, 4)
    index = (1, 2, 3)
    single = _stacked(getattr(phantom, method)(*(v[index] for v in values)))
    np.testing.assert_allclose(_stacked(result)[(slice(None),) * isinstance(result, tuple) + index], single,
                               rtol=1e-12, atol=1e-15)
    if hasattr(cf, method):
        reference = getattr(cf, method)(*values, REPORT)
        assert reference.shape == np.shape(result)
        if method != "potential_energy":
            assert relative_error(result, reference) < 1e-9
