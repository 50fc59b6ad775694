"""load(): a Description as a pinocchio RobotWrapper, in example-robot-data's style; load_files(): a
PhantomLoader's URDF/SRDF pair of files."""

from __future__ import annotations

from pathlib import Path

import pinocchio as pin

from phantom_pin._paths import DESCRIPTION_DIR
from phantom_pin.config import DEFAULT, MODELS, Config
from phantom_pin.description.build import Description, shipped
from phantom_pin.description.physical import check_urdf
from phantom_pin.dynamics._refusals import shown
from phantom_pin.dynamics.build import build_model, has_rotors, load_rotor_parameters
from phantom_pin.dynamics.build import gravity_of as gravity_of  # (where it lived before)
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import InvalidInputError, ParameterFileError


class PhantomLoader:
    """What load_files() reads: declared attributes only, as example-robot-data's loaders.

    Subclass and override an attribute to load a URDF/SRDF pair of your own (for
    example one written by ``phantom-pin urdf --set ...``).
    """

    #: The URDF with the parallelogram as mimic joints (joint1..3 = theta1..3).
    urdf_path: Path = MODELS[DEFAULT].urdf
    #: The SRDF with the named postures, rotor parameters and disabled collision pairs.
    srdf_path: Path = MODELS[DEFAULT].srdf
    #: Folders that resolve package:// URIs (the parent of phantom_description).
    package_dirs: tuple[Path, ...] = (DESCRIPTION_DIR.parent,)
    #: The SRDF posture that becomes ``robot.q0``.
    ref_posture: str = "resting"
    #: Read the SRDF's rotor_params into model.armature (rotor inertia x ratio^2, kg m^2).
    has_rotor_parameters: bool = True


def _first_line(error: Exception) -> str:
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    return lines[0] if lines else type(error).__name__


def load(description: Description | None = None) -> pin.RobotWrapper:
    """The PHANToM of a Description as a RobotWrapper: ``model`` is the mimic model (nq = nv = 3,
    joint1..3 = the report's theta1..3 in rad) with the configuration's gravity, with
    ``visual_model``, ``collision_model`` (every pair but the SRDF's disabled ones), the SRDF
    postures in ``model.referenceConfigurations``, ``q0`` = the ``resting`` posture (rad) and
    ``model.armature`` = the reflected rotor inertias (kg m^2). World = ``base_link``
    (REP-103: x forward, z up, origin at the shoulder).

    ``description``: phantom_pin.describe(name or folder, overrides=...), or None for the default
    model (premium_1_5, its committed files, as Phantom()). A model name is
    ``load(describe(name))``, a folder ``load(describe(folder))``, a Phantom's
    ``load(phantom.description)`` and a URDF/SRDF pair of files ``load_files(loader)``: anything
    else is refused with InvalidInputError naming ``description`` and that call.
    """
    if description is None:
        description = shipped()
    elif not isinstance(description, Description):
        raise InvalidInputError(f"expected a phantom_pin.Description or None, got {shown(description)}; "
                                f"{_load_call(description)}", argument="description")
    return _robot(PhantomLoader, description.urdf, description.srdf,  # checked by describe()
                  "description: the description's URDF", "description: the description's SRDF", description.config)


def _load_call(given: object) -> str:
    """The call that loads what load() was ``given`` and refused, for the refusal's message."""
    if isinstance(given, type) and issubclass(given, PhantomLoader):
        return "a PhantomLoader's files are load_files(loader)"
    if isinstance(given, str) and given in MODELS:
        return f"a named model is load(describe({given!r}))"
    if isinstance(given, (str, Path)):
        return "a configuration folder is load(describe(folder))"
    if isinstance(given, Phantom):
        return "a Phantom's is load(phantom.description)"
    return "a model name or a folder is load(describe(name or folder)), a URDF/SRDF pair load_files(loader)"


def load_files(loader: type[PhantomLoader] = PhantomLoader) -> pin.RobotWrapper:
    """The RobotWrapper (as load()'s) of the files a PhantomLoader (sub)class names: its
    ``urdf_path`` and ``srdf_path`` (the default: the premium_1_5 model's committed files), its
    ``package_dirs``, ``ref_posture`` (``q0``) and ``has_rotor_parameters``. A URDF of one's own
    keeps Pinocchio's gravity (9.81 m/s^2) and its SRDF's rotors. The URDF must pass
    physical.check_urdf. Raises ParameterFileError naming ``urdf_path`` or ``srdf_path`` for a
    missing, malformed or non-physical file; InvalidInputError naming ``loader`` for anything but
    a PhantomLoader class (a Description is load(description))."""
    if not (isinstance(loader, type) and issubclass(loader, PhantomLoader)):
        hint = "; a Description is load(description)" if isinstance(loader, Description) else \
            "; a model name or a folder is load(describe(name or folder))" if isinstance(loader, (str, Path)) else ""
        raise InvalidInputError(f"expected a PhantomLoader class (or subclass), got {shown(loader)}{hint}",
                                argument="loader")
    texts = []
    for name in ("urdf_path", "srdf_path"):
        path = Path(getattr(loader, name))
        if not path.is_file():
            raise ParameterFileError(f"{path} is not a file", argument=name)
        try:
            texts.append(path.read_text(encoding="utf-8"))
        except UnicodeDecodeError as error:
            raise ParameterFileError(f"{path} is not a text file", argument=name) from error
    urdf, srdf = texts
    urdf_name, srdf_name = f"urdf_path: {loader.urdf_path}", f"srdf_path: {loader.srdf_path}"
    check_urdf(urdf, urdf_name)
    return _robot(loader, urdf, srdf, urdf_name, srdf_name, None)  # no configuration: Pinocchio's g, its rotors


def _robot(loader: type[PhantomLoader], urdf: str, srdf: str, urdf_name: str, srdf_name: str,
           config: Config | None) -> pin.RobotWrapper:
    """The RobotWrapper of checked URDF and SRDF texts (named ``label: what`` in errors) with
    ``loader``'s other attributes and ``config``'s gravity and rotors (None: Pinocchio's, the SRDF's)."""
    package_dirs = [str(p) for p in loader.package_dirs]
    try:
        model = build_model(urdf, config)
        geometry = [pin.buildGeomFromUrdfString(model, urdf, kind, package_dirs=package_dirs)
                    for kind in (pin.GeometryType.COLLISION, pin.GeometryType.VISUAL)]
    except (RuntimeError, ValueError, AttributeError) as error:  # Pinocchio's, several lines
        label, what = urdf_name.split(": ", 1)
        raise ParameterFileError(f"Pinocchio cannot load {what} ({_first_line(error)})", argument=label) from error
    robot = pin.RobotWrapper(model, *geometry)
    try:
        pin.loadReferenceConfigurationsFromXML(robot.model, srdf, False)
        if loader.has_rotor_parameters and has_rotors(config):
            load_rotor_parameters(robot.model, srdf)
        robot.collision_model.addAllCollisionPairs()
        pin.removeCollisionPairsFromXML(robot.model, robot.collision_model, srdf, False)
    except (RuntimeError, ValueError, AttributeError) as error:
        label, what = srdf_name.split(": ", 1)
        raise ParameterFileError(f"Pinocchio cannot read {what} ({_first_line(error)})", argument=label) from error
    postures = [entry.key() for entry in robot.model.referenceConfigurations]
    if loader.ref_posture not in postures:
        raise InvalidInputError(
            f"{loader.ref_posture!r} is not a posture of the SRDF (it has {sorted(postures)})", argument="ref_posture")
    robot.q0 = robot.model.referenceConfigurations[loader.ref_posture].copy()
    robot.rebuildData()
    return robot
