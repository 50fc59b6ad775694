"""One BLAS for what hinges on the last bits of rounding: a computation run by ``run`` gives the
same result on every OpenBLAS kernel a machine can select and at any thread count.

NumPy's and SciPy's OpenBLAS pick their kernels by the CPU (SkylakeX with AVX-512, Haswell with
AVX2, Sandybridge, Prescott...; OPENBLAS_CORETYPE forces one) and round differently by kernel:
every matrix product, QR, Cholesky, SVD and eigenvalue call of the excitation's 450 x 24
regressor differs in its last bits between them, and so does scipy's SLSQP itself on an
objective made of elementwise NumPy alone (its C code calls BLAS). excite's optimiser takes
finite differences of its cost at steps of 1.5e-8, which turn the cost's 1e-13 (relative)
kernel noise into gradients 1e-4 apart: from the second iteration on the two paths part, and
they end at different trajectories (DEVELOPERS.md). What such a computation gives is therefore
computed on one kernel, REFERENCE, with one thread: here if this process's OpenBLAS runs it
(the threads limited by threadpoolctl for the call), else in a child process started with
OPENBLAS_CORETYPE=REFERENCE (about 1 s of start). Where REFERENCE cannot run (a CPU without AVX2
and FMA, another architecture) or NumPy has no OpenBLAS, the call runs here with one thread:
its result is then this machine's own.
"""

from __future__ import annotations

import copyreg
import io
import os
import pickle
import platform
import subprocess
import sys
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any

#: The OpenBLAS kernel (core type, as OPENBLAS_CORETYPE and threadpoolctl name it) of every
#: result that ``run`` computes: the kernel the docs' figures were made with (and Zen's).
REFERENCE = "Haswell"
#: The CPU flags (/proc/cpuinfo) that REFERENCE's kernels use.
REFERENCE_FLAGS = frozenset({"avx2", "fma"})


def kernels() -> list[tuple[str, int]]:
    """(kernel, threads) of each OpenBLAS library loaded in this process (NumPy's, SciPy's)."""
    from threadpoolctl import threadpool_info

    return [(str(info.get("architecture")), int(info["num_threads"])) for info in threadpool_info()
            if info.get("internal_api") == "openblas"]


def reference_runs_here() -> bool:
    """Whether every OpenBLAS library of this process runs REFERENCE (or there is none)."""
    return all(kernel == REFERENCE for kernel, _ in kernels())


def reference_can_run() -> bool:
    """Whether this CPU can run REFERENCE's kernels (x86-64 Linux with its flags)."""
    if platform.machine() not in ("x86_64", "AMD64"):
        return False
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return False
    flags = next((line.split(":", 1)[1].split() for line in text.splitlines() if line.startswith("flags")), [])
    return REFERENCE_FLAGS <= set(flags)


def run(function: Callable[..., Any], *args: Any, progress: Callable[[float], None] | None = None) -> Any:
    """``function(*args, progress)`` computed on REFERENCE with one BLAS thread (the module doc).
    In a child process, ``function`` must be importable by name and ``args`` picklable
    (mapping proxies included); ``progress(share)`` is called here with what the child reports,
    and the child's exception is raised here."""
    if reference_runs_here() or not reference_can_run():
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1, user_api="blas"):
            return function(*args, progress)
    return _in_child(function, args, progress)


def _proxy(items: dict) -> types.MappingProxyType:
    return types.MappingProxyType(items)


def _reduce_proxy(proxy: types.MappingProxyType) -> tuple:
    return (_proxy, (dict(proxy),))


def _dumps(value: object) -> bytes:
    """``value`` pickled, mapping proxies (the frozen configuration's) as copies of their dicts."""
    buffer = io.BytesIO()
    pickler = pickle.Pickler(buffer, protocol=pickle.HIGHEST_PROTOCOL)
    pickler.dispatch_table = {**copyreg.dispatch_table, types.MappingProxyType: _reduce_proxy}
    pickler.dump(value)
    return buffer.getvalue()


def _in_child(function: Callable[..., Any], args: tuple, progress: Callable[[float], None] | None) -> Any:
    env = {**os.environ, "OPENBLAS_CORETYPE": REFERENCE, "OPENBLAS_NUM_THREADS": "1"}
    root = str(Path(__file__).resolve().parents[1])      # this phantom_pin, whatever the child's path
    env["PYTHONPATH"] = os.pathsep.join([root, *filter(None, [env.get("PYTHONPATH")])])
    child = subprocess.Popen([sys.executable, "-c", "from phantom_pin._blas import _child; _child()"],
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env)
    assert child.stdin is not None and child.stdout is not None
    try:
        child.stdin.write(_dumps((function, args, progress is not None)))
        child.stdin.close()
        while True:
            kind, value = pickle.load(child.stdout)
            if kind == "progress":
                if progress is not None:
                    progress(value)
                continue
            child.wait()
            if kind == "error":
                raise value
            return value
    except EOFError:
        child.wait()
        raise RuntimeError(f"the child process on OpenBLAS {REFERENCE} ended with status {child.returncode} "
                           "and no result") from None
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


def _child() -> None:
    """The child's side: read (function, args, progress wanted) from stdin, send ("progress",
    share)... then ("result", value) or ("error", exception) to stdout."""
    out = sys.stdout.buffer
    sys.stdout = sys.stderr                    # a print of the function's cannot reach the pipe
    function, args, wanted = pickle.load(sys.stdin.buffer)

    def progress(share: float) -> None:
        out.write(_dumps(("progress", share)))
        out.flush()
    try:
        message = ("result", function(*args, progress if wanted else None))
    except Exception as error:  # noqa: BLE001 (raised again in the parent)
        message = ("error", error)
    out.write(_dumps(message))
    out.flush()
