"""Each Phantom method against the bare Pinocchio call it wraps, as ratios measured in the
same run (interleaved rounds, medians: absolute times on a shared machine drift 2x), and
the batches; prints the targets of issue 11, met or not, and the table of docs/speed.md.

    python benchmarks/bench_dynamics.py [--rounds 15] [--batch 1000000]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time
import timeit

import numpy as np
import pinocchio as pin

from phantom_pin import Phantom
from phantom_pin import closed_form as cf
from phantom_pin.config.sampling import random_states


def interleaved(calls: list, rounds: int, number: int) -> list[float]:
    """Median time of one call of each of ``calls`` (µs), timed in alternation."""
    times: list[list[float]] = [[] for _ in calls]
    for _ in range(rounds):
        for call, record in zip(calls, times):
            record.append(timeit.timeit(call, number=number) / number * 1e6)
    return [statistics.median(t) for t in times]


def per_state(call, states: int, rounds: int) -> float:
    """Median time of ``call`` over ``rounds`` runs, per state (µs)."""
    runs = []
    for _ in range(rounds):
        start = time.perf_counter()
        call()
        runs.append(time.perf_counter() - start)
    return statistics.median(runs) / states * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rounds", type=int, default=15, help="interleaved rounds per row")
    parser.add_argument("--batch", type=int, default=1_000_000, help="states in closed_form's batch runs")
    args = parser.parse_args()
    phantom = Phantom()
    report = phantom.config.report  # the closed form's numbers (the report's)
    model, data = phantom.model, phantom.model.createData()
    tree, tree_data, coupling = phantom.coupling.tree, phantom.coupling.tree.createData(), phantom.coupling
    q, v, a = np.array([0.2, 0.4, 0.5]), np.array([0.5, -1.0, 1.5]), np.array([2.0, 1.0, -3.0])
    tip = model.getFrameId("tip")
    qt, vt, at = coupling.configuration(q), coupling.tangent(v), coupling.tangent(a)
    target = np.array([0.05, 0.02, 0.03])

    def one_frame_at(x):
        pin.forwardKinematics(model, data, x)
        return pin.updateFramePlacement(model, data, tip)

    def one_frame():  # one_frame_at(q) inline: the bare call pays no extra Python frame
        pin.forwardKinematics(model, data, q)
        return pin.updateFramePlacement(model, data, tip)

    def crba_nle():
        pin.crba(model, data, q)
        return pin.nonLinearEffects(model, data, q, v)

    rows = [  # method, Phantom call, bare call, its name, target ratio
        ("inverse_dynamics", lambda: phantom.inverse_dynamics(q, v, a),
         lambda: pin.rnea(model, data, q, v, a), "rnea", 1.4),
        ("mass_matrix", lambda: phantom.mass_matrix(q), lambda: pin.crba(model, data, q), "crba", 1.4),
        ("gravity", lambda: phantom.gravity(q), lambda: pin.computeGeneralizedGravity(model, data, q),
         "computeGeneralizedGravity", 1.4),
        ("spatial_jacobian", lambda: phantom.spatial_jacobian(q),
         lambda: pin.computeFrameJacobian(model, data, q, tip, pin.WORLD), "computeFrameJacobian", 1.4),
        ("body_jacobian", lambda: phantom.body_jacobian(q),
         lambda: pin.computeFrameJacobian(model, data, q, tip, pin.LOCAL), "computeFrameJacobian", 1.4),
        ("forward_kinematics", lambda: phantom.forward_kinematics(q), one_frame,
         "forwardKinematics + updateFramePlacement", 2.0),
        ("forward_dynamics", lambda: phantom.forward_dynamics(q, v, a), crba_nle,
         "crba + nonLinearEffects", 1.8),
        ("coriolis_matrix", lambda: phantom.coriolis_matrix(q, v),
         lambda: pin.computeCoriolisMatrix(tree, tree_data, qt, vt), "computeCoriolisMatrix (tree)", 3.0),
        ("inverse_dynamics_derivatives", lambda: phantom.inverse_dynamics_derivatives(q, v, a),
         lambda: pin.computeRNEADerivatives(tree, tree_data, qt, vt, at), "computeRNEADerivatives (tree)", 3.0),
        ("inverse_kinematics", lambda: phantom.inverse_kinematics(target),
         lambda: cf.inverse_kinematics(target, report), "closed_form.inverse_kinematics", 2.0),
    ]
    missed = []
    print(f"{os.cpu_count()} cores, {platform.machine()}, "
          f"Python {platform.python_version()}, pin {pin.__version__}, numpy {np.__version__}; "
          f"medians of {args.rounds} interleaved rounds\n")
    print("| method | Phantom [µs] | bare call | bare [µs] | ratio | target | |")
    print("|---|---:|---|---:|---:|---:|---|")
    for name, ours, bare, bare_name, limit in rows:
        number = 50 if name == "inverse_kinematics" else 2000
        t_ours, t_bare = interleaved([ours, bare], args.rounds, number)
        ratio = t_ours / t_bare
        met = ratio <= limit
        missed += [] if met else [name]
        print(f"| {name} | {t_ours:.2f} | {bare_name} | {t_bare:.2f} | {ratio:.2f} | <= {limit} | "
              f"{'met' if met else 'MISSED'} |")

    n = args.batch
    theta, dtheta, ddtheta = random_states(phantom.config.limits, n, seed=0)
    small = min(n, 20_000)  # the Python loops and the per-state Pinocchio methods
    q_, v_, a_ = theta[:small], dtheta[:small], ddtheta[:small]
    # a Python loop over the bare call, stacked by np.array into the (N, ...) array a batch
    # returns (the pose as its 4x4 matrix): the floor of a batch looping in Python
    loops = {
        "rnea": lambda: np.array([pin.rnea(model, data, x, y, z) for x, y, z in zip(q_, v_, a_)]),
        "crba": lambda: np.array([pin.crba(model, data, x) for x in q_]),
        "gravity": lambda: np.array([pin.computeGeneralizedGravity(model, data, x) for x in q_]),
        "crba + nle": lambda: [(pin.crba(model, data, x), pin.nonLinearEffects(model, data, x, y))
                               for x, y in zip(q_, v_)],
        "one frame": lambda: np.array([one_frame_at(x).homogeneous for x in q_]),
        "jacobian": lambda: np.array([pin.computeFrameJacobian(model, data, x, tip, pin.WORLD) for x in q_]),
        "coriolis (tree)": lambda: np.array([pin.computeCoriolisMatrix(tree, tree_data, x, y) for x, y in
                                             zip(coupling.configuration(q_), coupling.tangent(v_))]),
    }
    batches = [  # label, batched Phantom call, its bare loop
        ("inverse_dynamics", lambda: phantom.inverse_dynamics(q_, v_, a_), "rnea"),
        ("mass_matrix", lambda: phantom.mass_matrix(q_), "crba"),
        ("gravity", lambda: phantom.gravity(q_), "gravity"),
        ("forward_dynamics", lambda: phantom.forward_dynamics(q_, v_, a_), "crba + nle"),
        ("forward_kinematics", lambda: phantom.forward_kinematics(q_), "one frame"),
        ("spatial_jacobian", lambda: phantom.spatial_jacobian(q_), "jacobian"),
        ("coriolis_matrix", lambda: phantom.coriolis_matrix(q_, v_), "coriolis (tree)"),
    ]
    print(f"\nPhantom's batches, N = {small}, against a Python loop over the bare call, stacked "
          "into one array (rneaInParallel runs on every core)\n")
    print("| method | Phantom batch [µs/state] | loop over | loop [µs/state] | ratio |")
    print("|---|---:|---|---:|---:|")
    for label, call, loop in batches:
        t_ours, t_loop = (statistics.median(t) for t in zip(*[
            (per_state(call, small, 1), per_state(loops[loop], small, 1)) for _ in range(7)]))
        print(f"| {label} | {t_ours:.2f} | {loop} | {t_loop:.2f} | {t_ours / t_loop:.2f} |")

    # the baseline: the loop over rnea alone, not stacked
    loop_rnea = per_state(lambda: [pin.rnea(model, data, x, y, z) for x, y, z in zip(q_, v_, a_)], small, 3)
    print(f"\nclosed_form's batches, N = {n}, against the loop over the bare rnea "
          f"({loop_rnea:.2f} µs per state, {1 / loop_rnea:.2f} M states/s)\n")
    print("| batched call | µs per state | M states/s | x loop over rnea | target | |")
    print("|---|---:|---:|---:|---:|---|")
    for label, call in (("closed_form.inverse_dynamics", lambda: cf.inverse_dynamics(theta, dtheta, ddtheta, report)),
                        ("closed_form.mass_matrix", lambda: cf.mass_matrix(theta, report)),
                        ("closed_form.gravity", lambda: cf.gravity(theta, report)),
                        ("Phantom.inverse_dynamics (rneaInParallel)",
                         lambda: phantom.inverse_dynamics(theta, dtheta, ddtheta))):
        t = per_state(call, n, 5)
        speedup = loop_rnea / t
        closed = label.startswith("closed_form")
        status = ("met" if speedup >= 12 else "MISSED") if closed else ""
        missed += [label] if status == "MISSED" else []
        print(f"| {label} | {t:.3f} | {1 / t:.2f} | {speedup:.1f} | {'>= 12' if closed else ''} | {status} |")
    print(f"\ntargets missed: {', '.join(missed) if missed else 'none'}")


if __name__ == "__main__":
    main()
