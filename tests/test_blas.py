"""The kernel-sensitive steps of the identification give one result on every OpenBLAS kernel
(issue 50, 1): excite's trajectory, the friction speed threshold's choice and the links' standard
parameters, computed here and in a child process started with OPENBLAS_CORETYPE set to a kernel
that rounds differently, at two threads. The reference is the other kernel's result, not the
code's own formula.

Measured on the AMD EPYC of 2026-12 (DEVELOPERS.md): before phantom_pin._blas, SkylakeX and
Haswell gave excite's cost 1e-11 apart (relative 2e-13) at the very first point, SLSQP's
iterates were 1e-3 apart after its second iteration, and its trajectories ended entirely
different (theta(0) = (-0.81, 0.20, -0.34) rad against (0.89, 0.30, 0.75)); and a link's
|c|^2 by BLAS's dot left a URDF's iyy 1e-16 apart, a simulated device's encoder count 4.1 s
into its log, and identify's figures with it.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from phantom_pin import _blas

ROOT = Path(__file__).resolve().parents[2]

def kernel_sensitive() -> dict:
    """What this process computes on its own kernel: excite on the Touch (one start, 5 SLSQP
    iterations on 60 points: the paths parted at the second), then the friction speed threshold
    chosen on a 10 s log along it (the Touch's inverse dynamics with Coulomb friction on joint 3
    near its torque RMS, seeded 2 mN m noise); 200 seeded links' standard parameters (what a
    model's URDF and a simulated device's counts are made of); the Premium 1.5's general
    structure's base parameters in words (its pivots and their order: Sandybridge's pivoted QR
    chose others); and the kernels threadpoolctl says run."""
    from threadpoolctl import threadpool_info

    from phantom_pin import Phantom, describe
    from phantom_pin.description.inertial import Inertial
    from phantom_pin.identification import optimise
    from phantom_pin.identification.data.io import Log
    from phantom_pin.identification.fitting.selection import choose_min_speed
    from phantom_pin.identification.structure.structures import General

    device = Phantom(describe("touch", overrides={"actuation.friction.coulomb.joint3": 0.02}))
    design = optimise(Phantom.from_model("touch"), restarts=1, iterations=5, samples=60)
    t = np.arange(10001) / 1000
    theta, dtheta, ddtheta = design.trajectory(t)
    tau = device.inverse_dynamics(theta, dtheta, ddtheta) + device.config.actuation.friction.torque(dtheta)
    tau = tau + np.random.default_rng(3).normal(0, 0.002, tau.shape)
    chosen, scores, _ = choose_min_speed(Log(t, theta, tau), device, General(device), 20.0, "sampled", 0.0, None)
    rng = np.random.default_rng(4)
    tensor = (1e-4, 1e-6, 2e-6, 2e-4, 3e-6, 3e-4)
    links = [Inertial(0.1, tuple(rng.uniform(-0.05, 0.05, 3)), tensor).dynamic_parameters() for _ in range(200)]
    base = General(Phantom.from_model("premium_1_5")).base.describe()
    return {"links": [link.tolist() for link in links], "base": base,
            "kernels": sorted({i["architecture"] for i in threadpool_info() if i["internal_api"] == "openblas"}),
            "q0": design.trajectory.q0.tolist(), "a": design.trajectory.a.tolist(),
            "b": design.trajectory.b.tolist(), "theta": theta[::1000].tolist(), "condition": design.condition,
            "report": design.report_condition, "chosen": chosen, "scores": [scores[s] for s in sorted(scores)]}


#: The child process: kernel_sensitive() as JSON on stdout.
CHILD = (f"import json, sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); import test_blas; "
         "json.dump(test_blas.kernel_sensitive(), sys.stdout)")


def _other_kernel(here: str) -> str:
    """A kernel this CPU runs that rounds differently from ``here``: the reference where this
    process runs another; else SkylakeX (AVX-512, the issue's) where the CPU has it, Sandybridge
    (AVX) where not."""
    if here != _blas.REFERENCE:
        return _blas.REFERENCE
    flags = next((line.split(":", 1)[1].split() for line in Path("/proc/cpuinfo").read_text().splitlines()
                  if line.startswith("flags")), [])
    return "SkylakeX" if "avx512f" in flags else "Sandybridge"


@pytest.mark.skipif(not _blas.reference_can_run(), reason="needs an x86-64 CPU with AVX2 and FMA (the reference)")
def test_excite_and_the_threshold_are_the_same_on_two_kernels():
    """This process's kernel against another's, in a child with two threads (this one has
    conftest's one). The links' parameters bit for bit (Python floats), the base parameters'
    words alike (pivots and ties in a fixed order); the Fourier
    coefficients bit for bit (the optimisation runs on the reference kernel
    wherever it is called); the trajectory at the log's times within 1e-12 rad and the
    condition numbers within 1e-9 relative (evaluated on each child's own kernel); the same
    threshold, its scores within 1e-5 relative (held-out least squares on each kernel: up to
    4e-6 apart, Sandybridge against Haswell; 1e-13 SkylakeX against Haswell; selection's ties
    are 1 % and more)."""
    here, = {kernel for kernel, _ in _blas.kernels()}   # this process: one kernel (NumPy's and SciPy's alike)
    other = _other_kernel(here)
    env = {**os.environ, "OPENBLAS_CORETYPE": other, "OPENBLAS_NUM_THREADS": "2"}
    child = subprocess.Popen([sys.executable, "-c", CHILD], cwd=ROOT, env=env, text=True,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    first = kernel_sensitive()                     # here, meanwhile
    out, err = child.communicate(timeout=120)
    assert child.returncode == 0, err
    second = json.loads(out)
    assert first["kernels"] == [here] and second["kernels"] == [other], (here, second["kernels"])
    for key in ("q0", "a", "b", "links", "base"):
        assert first[key] == second[key], key
    np.testing.assert_allclose(first["theta"], second["theta"], rtol=0, atol=1e-12)
    for key in ("condition", "report"):
        assert first[key] == pytest.approx(second[key], rel=1e-9), key
    assert first["chosen"] == second["chosen"]
    np.testing.assert_allclose(first["scores"], second["scores"], rtol=1e-5)
