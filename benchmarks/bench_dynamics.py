"""Latency of each Phantom method beside the raw Pinocchio call it wraps and closed_form,
and batched inverse-dynamics throughput. Prints a Markdown table (the README's).

    python benchmarks/bench_dynamics.py [--batch 1000000]
"""

from __future__ import annotations

import argparse
import time
import timeit

import numpy as np
import pinocchio as pin

from phantom_pin import Phantom, closed_form as cf
from phantom_pin.parameters import random_states


def per_call(function, repeat: int = 7, number: int = 2000) -> float:
    """Best-of-``repeat`` mean time of one call, in microseconds."""
    return min(timeit.repeat(function, repeat=repeat, number=number)) / number * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--batch", type=int, default=1_000_000, help="states in the batch run")
    args = parser.parse_args()
    phantom = Phantom()
    model, data = phantom.model, phantom.model.createData()
    tree, tree_data, coupling = phantom.coupling.tree, phantom.coupling.tree.createData(), phantom.coupling
    q, v, a = np.array([0.2, 0.4, 0.5]), np.array([0.5, -1.0, 1.5]), np.array([2.0, 1.0, -3.0])
    tip = model.getFrameId("tip")
    qt, vt, at = coupling.configuration(q), coupling.tangent(v), coupling.tangent(a)
    rows = [  # method, Phantom call, raw Pinocchio call it wraps, closed_form call
        ("inverse_dynamics", lambda: phantom.inverse_dynamics(q, v, a),
         lambda: pin.rnea(model, data, q, v, a), lambda: cf.inverse_dynamics(q, v, a)),
        ("mass_matrix", lambda: phantom.mass_matrix(q), lambda: pin.crba(model, data, q),
         lambda: cf.mass_matrix(q)),
        ("gravity", lambda: phantom.gravity(q), lambda: pin.computeGeneralizedGravity(model, data, q),
         lambda: cf.gravity(q)),
        ("coriolis_matrix", lambda: phantom.coriolis_matrix(q, v),
         lambda: pin.computeCoriolisMatrix(tree, tree_data, qt, vt), lambda: cf.coriolis_matrix(q, v)),
        ("forward_kinematics", lambda: phantom.forward_kinematics(q),
         lambda: pin.framesForwardKinematics(model, data, q), lambda: cf.forward_kinematics(q)),
        ("spatial_jacobian", lambda: phantom.spatial_jacobian(q),
         lambda: pin.computeFrameJacobian(model, data, q, tip, pin.WORLD), lambda: cf.spatial_jacobian(q)),
        ("body_jacobian", lambda: phantom.body_jacobian(q),
         lambda: pin.computeFrameJacobian(model, data, q, tip, pin.LOCAL), lambda: cf.body_jacobian(q)),
        ("forward_dynamics", lambda: phantom.forward_dynamics(q, v, a),
         lambda: pin.crba(model, data, q), None),
        ("inverse_dynamics_derivatives", lambda: phantom.inverse_dynamics_derivatives(q, v, a),
         lambda: pin.computeRNEADerivatives(tree, tree_data, qt, vt, at), None),
        ("inverse_kinematics", lambda: phantom.inverse_kinematics([0.05, 0.02, 0.03]),
         None, lambda: cf.inverse_kinematics([0.05, 0.02, 0.03])),
    ]
    print(f"pin {pin.__version__}, numpy {np.__version__}, {phantom.threads} OpenMP threads\n")
    print("| method | Phantom [µs] | raw Pinocchio call [µs] | ratio | closed_form [µs] |")
    print("|---|---:|---:|---:|---:|")
    ratios = {}
    for name, ours, raw, closed in rows:
        number = 20 if name == "inverse_kinematics" else 2000
        t_ours = per_call(ours, number=number)
        t_raw = per_call(raw) if raw else float("nan")
        t_closed = per_call(closed, number=number) if closed else float("nan")
        ratios[name] = t_ours / t_raw
        print(f"| {name} | {t_ours:.2f} | {t_raw:.2f} | {t_ours / t_raw:.2f} | {t_closed:.2f} |")

    theta, dtheta, ddtheta = random_states(phantom.parameters, args.batch, seed=0)
    timings = {}
    for label, call in (("Phantom.inverse_dynamics", phantom.inverse_dynamics),
                        ("closed_form.inverse_dynamics", cf.inverse_dynamics)):
        best = float("inf")
        for _ in range(3):
            start = time.perf_counter()
            call(theta, dtheta, ddtheta)
            best = min(best, time.perf_counter() - start)
        timings[label] = args.batch / best / 1e6
    print(f"\n| batched inverse dynamics, N = {args.batch} | M states/s |\n|---|---:|")
    for label, rate in timings.items():
        print(f"| {label} | {rate:.2f} |")
    print(f"\ntarget Phantom.inverse_dynamics <= 2x raw rnea: {ratios['inverse_dynamics']:.2f}x "
          f"({'met' if ratios['inverse_dynamics'] <= 2 else 'MISSED'})")
    rate = timings["Phantom.inverse_dynamics"]
    print(f"target batch >= 1 M states/s: {rate:.2f} M/s ({'met' if rate >= 1 else 'MISSED'})")


if __name__ == "__main__":
    main()
