"""The libHD stand-in's build: an OpenHaptics-like tree that runs HDAPI programs against the
simulated device.

``build(directory, model)`` writes ``directory/include/HD/`` (hd.h and the headers it includes,
laid out as OpenHaptics' are, plus phantom_pin_sim.h, the hand's functions for tests) and
``directory/lib/libHD.so``, compiled with gcc from csrc/ (stand_in.c and a layout.h written
here from plant.py's constants, the Python interpreter that runs the device, and the default
model). Then ``gcc -I DIR/include prog.c -L DIR/lib -lHD`` builds an OpenHaptics program
unchanged, and it runs with ``LD_LIBRARY_PATH=DIR/lib`` (pyOpenHaptics loads the library by
name: the same variable). The library starts the device with the interpreter that built it
(PHANTOM_PIN_HD_PYTHON chooses another with phantom_pin installed).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from phantom_pin.exceptions import InvalidInputError, PhantomPinError
from phantom_pin.interfaces.openhaptics import protocol as plant

#: The C sources: csrc/HD/*.h (installed) and csrc/stand_in.c.
SOURCES = Path(__file__).parent / "csrc"
#: gcc's flags for the library (GNU C99: pthreads, posix_spawn, clock_nanosleep; every warning an error).
CFLAGS = ("-std=gnu99", "-O2", "-fPIC", "-shared", "-Wall", "-Wextra", "-Werror", "-pthread")


def headers() -> list[Path]:
    """The headers installed under DIR/include/HD, sorted by name."""
    return sorted((SOURCES / "HD").glob("*.h"))


def layout(model: str, python: str) -> str:
    """layout.h: plant.py's protocol offsets as C macros, the interpreter and the default model."""
    def quoted(text: str) -> str:
        return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'
    lines = ["/* Written by phantom_pin.interfaces.openhaptics.stand_in from plant.py: do not edit. */",
             f"#define PP_PYTHON {quoted(python)}", f"#define PP_MODEL {quoted(model)}",
             f"#define PP_COMMAND {plant.COMMAND}", f"#define PP_STATE {plant.STATE}",
             f"#define PP_INFO {len(plant.INFO_FIELDS)}",
             f"#define PP_QUIT ({plant.QUIT})", f"#define PP_DISABLED {plant.DISABLED}",
             f"#define PP_ENABLED {plant.ENABLED}"]
    lines += [f"#define PP_{name} {offset}" for name, offset in plant.COMMAND_LAYOUT.items() if name != "FLAG"]
    lines += [f"#define PP_{name} {offset}" for name, offset in plant.STATE_LAYOUT.items()]
    info = {"MAX_FORCE": "max_force", "MAX_CONTINUOUS_FORCE": "max_continuous_force", "MAX_STIFFNESS": "max_stiffness",
            "PEAK_TORQUE": "peak_torque1", "HAS_GIMBAL": "has_gimbal", "WORKSPACE": "workspace_min_x"}
    lines += [f"#define PP_{name} {plant.INFO_FIELDS.index(field)}" for name, field in info.items()]
    return "\n".join(lines) + "\n"


def build(directory: str | Path, model: str | Path, *, force: bool = False,
          python: str | None = None, argument: str = "directory", force_hint: str = "force=True") -> Path:
    """Write the stand-in into ``directory`` (module doc) for ``model`` (a model's name or a
    configuration folder: its default device; PHANTOM_PIN_HD_MODEL chooses another at run
    time) and return ``directory``. ``python``: the interpreter that runs the device (default:
    this one). Nothing is written on failure; existing files are refused unless ``force``.
    InvalidInputError naming ``argument`` (the folder) or ``model`` (``force_hint`` says how to
    overwrite); PhantomPinError when gcc is missing or fails."""
    from phantom_pin._validation import output_path
    from phantom_pin.description.build import description_of

    config = description_of(model, "model").config
    if config.actuation.openhaptics is None:
        raise InvalidInputError(f"the model {config.name!r} has no openhaptics section in actuation.yaml "
                                "(what OpenHaptics reports of it)", argument="model")
    target = Path(directory)
    if target.exists() and not target.is_dir():
        raise InvalidInputError(f"{target} is not a folder", argument=argument)
    if not target.parent.is_dir():
        raise InvalidInputError(f"folder {target.parent} does not exist", argument=argument)
    outputs = [target / "include" / "HD" / h.name for h in headers()] + [target / "lib" / "libHD.so"]
    for path in outputs:
        if path.parent.is_dir():
            output_path(path, force, argument, force_hint)
        elif path.parent.exists():
            raise InvalidInputError(f"{path.parent} is not a folder", argument=argument)
    compiler = shutil.which("gcc")
    if compiler is None:
        raise PhantomPinError("the stand-in is compiled with gcc, which is not on PATH (Debian: apt-get install gcc)")
    with tempfile.TemporaryDirectory(prefix="phantom_pin_hd_") as scratch:
        work = Path(scratch)
        name = config.name if str(model) == config.name else str(Path(model).resolve())
        (work / "layout.h").write_text(layout(name, python or sys.executable))
        library = work / "libHD.so"
        command = [compiler, *CFLAGS, "-I", str(SOURCES), "-I", str(work), str(SOURCES / "stand_in.c"),
                   "-o", str(library), "-lm"]
        done = subprocess.run(command, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            first = (done.stderr.strip().splitlines() or ["(no message)"])[0]
            raise PhantomPinError(f"gcc could not build the stand-in: {first}")
        (target / "include" / "HD").mkdir(parents=True, exist_ok=True)
        (target / "lib").mkdir(parents=True, exist_ok=True)
        for header in headers():
            shutil.copyfile(header, target / "include" / "HD" / header.name)
        shutil.copyfile(library, target / "lib" / "libHD.so")
    return target
