"""The generated C header against Pinocchio's own C++ and against the Python API, in one run:
ns per call of gravity and inverse dynamics, and the ratios (the numbers of docs/servo-loop.md).

The header (phantom-pin codegen) and Pinocchio's computeGeneralizedGravity and rnea are timed
in one C++ program compiled with g++ -O2: Pinocchio's calls are the pin wheel's own compiled
library (libpinocchio_default, explicit template instantiation) through the headers the wheel
installs under site-packages/cmeel.prefix, with Debian's Eigen (libeigen3-dev: the wheel ships
no Eigen headers). Pinocchio 4.1 cannot deserialize a mimic model (segmentation fault, in
Python too), so the program loads the tree model (Model.saveToBinary) and builds the mimic model
with Pinocchio's buildMimicModel from the URDF's <mimic> tags, then sets the armature; it checks
that both agree to 1e-12 before timing. The Python API is timed with timeit (Phantom.gravity,
Phantom.inverse_dynamics on one state). Each timing is the median of interleaved rounds.

    python benchmarks/bench_codegen.py [--model premium_1_5] [--rounds 15]
"""

from __future__ import annotations

import argparse
import platform
import statistics
import subprocess
import sys
import sysconfig
import tempfile
import timeit
from pathlib import Path

import numpy as np

from phantom_pin import Phantom
from phantom_pin.codegen import header
from phantom_pin.config.sampling import random_states

PREFIX = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix"
EIGEN = Path("/usr/include/eigen3")
STATES = 1024

PROGRAM = r"""
#include <pinocchio/multibody.hpp>
#include <pinocchio/serialization.hpp>
#include <pinocchio/algorithm/model.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>
#include "model.h"

typedef std::chrono::steady_clock Clock;
static volatile double sink;

template <class F> static double ns_per_call(F f, int n, int repeat) {
  Clock::time_point start = Clock::now();
  for (int r = 0; r < repeat; ++r) for (int k = 0; k < n; ++k) f(k);
  return std::chrono::duration<double, std::nano>(Clock::now() - start).count() / (double(n) * repeat);
}

int main(int argc, char **argv) {
  // argv: tree.bin states.txt rounds armature(3) [mimicked mimicking scaling offset]...
  pinocchio::Model tree, model;
  tree.loadFromBinary(argv[1]);
  int rounds = std::atoi(argv[3]);
  std::vector<pinocchio::JointIndex> mimicked, mimicking;
  std::vector<double> scaling, offset;
  for (int i = 7; i + 3 < argc; i += 4) {
    mimicked.push_back(std::atoi(argv[i])); mimicking.push_back(std::atoi(argv[i + 1]));
    scaling.push_back(std::atof(argv[i + 2])); offset.push_back(std::atof(argv[i + 3]));
  }
  pinocchio::buildMimicModel(tree, mimicked, mimicking, scaling, offset, model);
  model.gravity = tree.gravity;
  for (int j = 0; j < 3; ++j) model.armature[j] = std::atof(argv[4 + j]);
  pinocchio::Data data(model);
  std::FILE *file = std::fopen(argv[2], "r");
  int n = 0;
  if (std::fscanf(file, "%d", &n) != 1) return 2;
  std::vector<double> s(9 * n);
  for (int i = 0; i < 9 * n; ++i) if (std::fscanf(file, "%lf", &s[i]) != 1) return 2;
  std::fclose(file);
  std::vector<Eigen::VectorXd> q(n), v(n), a(n);
  for (int k = 0; k < n; ++k) {
    q[k] = Eigen::Map<Eigen::Vector3d>(&s[9 * k]); v[k] = Eigen::Map<Eigen::Vector3d>(&s[9 * k + 3]);
    a[k] = Eigen::Map<Eigen::Vector3d>(&s[9 * k + 6]);
  }
  double worst = 0;  // relative, per state
  for (int k = 0; k < n; ++k) {
    double g[3], t[3];
    phantom_gravity(&s[9 * k], g);
    phantom_inverse_dynamics(&s[9 * k], &s[9 * k + 3], &s[9 * k + 6], t);
    Eigen::Vector3d pg = pinocchio::computeGeneralizedGravity(model, data, q[k]);
    Eigen::Vector3d pt = pinocchio::rnea(model, data, q[k], v[k], a[k]);
    for (int i = 0; i < 3; ++i) {
      worst = std::fmax(worst, std::fabs(g[i] - pg[i]) / pg.cwiseAbs().maxCoeff());
      worst = std::fmax(worst, std::fabs(t[i] - pt[i]) / pt.cwiseAbs().maxCoeff());
    }
  }
  std::printf("agreement %.3g\n", worst);
  pinocchio::Data tree_data(tree);
  std::vector<Eigen::VectorXd> qt(n), vt(n), at(n);  // the tree's coordinates: q_tree = G theta
  for (int k = 0; k < n; ++k) {
    qt[k].setZero(tree.nq); vt[k].setZero(tree.nv); at[k].setZero(tree.nv);
    for (int j = 0; j < 3; ++j) {
      int t = tree.joints[tree.getJointId("joint" + std::to_string(j + 1))].idx_q();
      qt[k][t] = q[k][j]; vt[k][t] = v[k][j]; at[k][t] = a[k][j];
    }
    for (size_t m = 0; m < mimicked.size(); ++m) {
      int from = tree.joints[mimicked[m]].idx_q(), to = tree.joints[mimicking[m]].idx_q();
      qt[k][to] = scaling[m] * qt[k][from] + offset[m];
      vt[k][to] = scaling[m] * vt[k][from]; at[k][to] = scaling[m] * at[k][from];
    }
  }
  std::vector<double> out(3 * n);
  std::vector<std::vector<double>> times(6);
  for (int r = 0; r < rounds; ++r) {
    times[0].push_back(ns_per_call([&](int k) { phantom_gravity(&s[9 * k], &out[3 * k]); }, n, 20));
    times[1].push_back(ns_per_call([&](int k) {
      phantom_inverse_dynamics(&s[9 * k], &s[9 * k + 3], &s[9 * k + 6], &out[3 * k]); }, n, 20));
    times[2].push_back(ns_per_call([&](int k) {
      sink = pinocchio::computeGeneralizedGravity(model, data, q[k])[1]; }, n, 20));
    times[3].push_back(ns_per_call([&](int k) { sink = pinocchio::rnea(model, data, q[k], v[k], a[k])[1]; }, n, 20));
    times[4].push_back(ns_per_call([&](int k) {
      out[3 * k] = 1e-3 * s[9 * k] + s[9 * k + 1] * s[9 * k + 2]; }, n, 20));  // loop and memory alone
    times[5].push_back(ns_per_call([&](int k) {
      sink = pinocchio::rnea(tree, tree_data, qt[k], vt[k], at[k])[1]; }, n, 20));
  }
  sink = out[0];
  for (auto &t : times) { std::sort(t.begin(), t.end()); std::printf("%.2f\n", t[t.size() / 2]); }
  return 0;
}
"""


def compile_program(folder: Path, text: str) -> Path:
    (folder / "model.h").write_text(text)
    (folder / "bench.cpp").write_text(PROGRAM)
    command = ["g++", "-O2", "-std=c++17", "bench.cpp", "-o", "bench",
               "-isystem", str(PREFIX / "include"), "-isystem", str(EIGEN),
               "-DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION", "-DBOOST_MPL_LIMIT_LIST_SIZE=30",
               "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30", "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
               f"-L{PREFIX / 'lib'}", "-lpinocchio_default", "-lboost_serialization",
               f"-Wl,-rpath,{PREFIX / 'lib'}"]
    subprocess.run(command, cwd=folder, check=True)
    return folder / "bench"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--model", default="premium_1_5")
    parser.add_argument("--rounds", type=int, default=15)
    args = parser.parse_args()
    phantom = Phantom.from_model(args.model)
    theta, dtheta, ddtheta = random_states(phantom.config.limits, STATES, seed=30)
    tree = phantom.coupling.tree
    mimic = []
    for tag in phantom.coupling.mimics.values():
        mimic += [str(tree.getJointId(tag.primary)), str(tree.getJointId(tag.joint)),
                  repr(tag.multiplier), repr(tag.offset)]
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        tree.saveToBinary(str(folder / "tree.bin"))
        rows = np.hstack([theta, dtheta, ddtheta])
        lines = [" ".join(f"{x:.17g}" for x in row) for row in rows]
        (folder / "states.txt").write_text(f"{STATES}\n" + "\n".join(lines))
        program = compile_program(folder, header(args.model))
        result = subprocess.run([str(program), "tree.bin", "states.txt", str(args.rounds),
                                 *(repr(float(a)) for a in phantom.model.armature), *mimic],
                                cwd=folder, check=True, capture_output=True, text=True).stdout.split("\n")
    agreement = float(result[0].split()[1])
    c_gravity, c_id, pin_gravity, pin_rnea, baseline, tree_rnea = (float(x) for x in result[1:7])
    q, v, a = theta[0], dtheta[0], ddtheta[0]
    py = []
    for _ in range(args.rounds):
        py.append((timeit.timeit(lambda: phantom.gravity(q), number=2000) / 2000 * 1e9,
                   timeit.timeit(lambda: phantom.inverse_dynamics(q, v, a), number=2000) / 2000 * 1e9))
    py_gravity, py_id = (statistics.median(column) for column in zip(*py))
    print(f"{args.model}: {platform.machine()}, Python {platform.python_version()}, g++ -O2; "
          f"header vs Pinocchio C++ agree to {agreement:.1e} (relative, {STATES} states); "
          f"loop and memory alone {baseline:.1f} ns")
    print("| call | header (C) | Pinocchio C++ | Python API | Pinocchio C++ / header | Python / header |")
    print("|---|---|---|---|---|---|")
    for what, c, p, y in (("gravity", c_gravity, pin_gravity, py_gravity),
                          ("inverse dynamics", c_id, pin_rnea, py_id)):
        print(f"| {what} | {c:.1f} ns | {p:.1f} ns | {y:.0f} ns | {p / c:.1f}x | {y / c:.0f}x |")
    print(f"(for scale: Pinocchio's rnea on the {tree.njoints - 1}-joint tree model without mimic joints, "
          f"before the projection G^T tau: {tree_rnea:.1f} ns, {tree_rnea / c_id:.1f}x the header)")
    if agreement > 1e-12:
        sys.exit(f"the header and Pinocchio's C++ disagree: {agreement:.3g}")


if __name__ == "__main__":
    main()
