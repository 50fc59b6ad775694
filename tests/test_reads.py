"""One configuration is read once: after describe() and Phantom(), the excitation and the
identification of a 20 s log read no parameter file, run no xacro and parse no URDF (before: one estimate() read
the YAML files 420 times, ran xacro 44 times and parsed the URDF 44 times)."""

from collections import Counter

import numpy as np
import pinocchio as pin
import xacro

from phantom_pin import Phantom, describe
from phantom_pin.config import files
from phantom_pin.identification.data import io
from phantom_pin.identification.fitting import estimation, excitation
from phantom_pin.identification.structure import constants


def test_excite_and_identify_read_nothing_after_describe(monkeypatch):
    description = describe()
    phantom = Phantom(description)
    counts = Counter()

    def counted(name, function):
        def wrapper(*args, **kwargs):
            counts[name] += 1
            return function(*args, **kwargs)
        return wrapper

    monkeypatch.setattr(files, "read_yaml", counted("yaml", files.read_yaml))
    monkeypatch.setattr(xacro, "process_file", counted("xacro", xacro.process_file))
    for name in ("buildModelFromXML", "buildModelFromUrdf"):
        monkeypatch.setattr(pin, name, counted(name, getattr(pin, name)))
    result = excitation.optimise(phantom, iterations=3, restarts=1)
    t = np.arange(20001) / 1000.0                                   # 20 s at 1 kHz
    theta, dtheta, ddtheta = result.trajectory(t)
    tau = constants.regressor(theta, dtheta, ddtheta, description) @ constants.nominal(description)
    fit = estimation.estimate(io.Log(t, theta, tau), phantom, structure="report", timing="sampled")
    assert counts == Counter()
    # the noise-free log of the configuration's own model gives back its constants, to the
    # error of estimate()'s central differences of the filtered angles (0.2 % on K2, K3)
    np.testing.assert_allclose(fit.beta[:8], constants.nominal(description)[:8], rtol=5e-3)
