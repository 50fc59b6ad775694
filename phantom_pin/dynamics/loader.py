"""load(): a description as a pinocchio RobotWrapper, in example-robot-data's style."""

from __future__ import annotations

from pathlib import Path

import pinocchio as pin

from phantom_pin._paths import DESCRIPTION_DIR
from phantom_pin.config import DEFAULT, MODELS, Config
from phantom_pin.description.build import Description, description_of
from phantom_pin.description.physical import check_urdf
from phantom_pin.dynamics.build import build_model, has_rotors, load_rotor_parameters
from phantom_pin.dynamics.build import gravity_of as gravity_of  # (where it lived before)
from phantom_pin.exceptions import InvalidInputError, ParameterFileError


class PhantomLoader:
    """What load() reads: declared attributes only, as example-robot-data's loaders.

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


def load(source: type[PhantomLoader] | Description | str = PhantomLoader) -> pin.RobotWrapper:
    """The PHANToM as a RobotWrapper: ``model`` is the mimic model (nq = nv = 3,
    joint1..3 = the report's theta1..3 in rad), with ``visual_model``,
    ``collision_model`` (every pair but the SRDF's disabled ones), the SRDF postures in
    ``model.referenceConfigurations``, ``q0`` = the ``ref_posture`` (rad) and
    ``model.armature`` = the reflected rotor inertias (kg m^2). World = ``base_link``
    (REP-103: x forward, z up, origin at the shoulder).

    ``source`` is a PhantomLoader (sub)class, whose files are read (the default: the
    premium_1_5 model's committed files), a model name (phantom_pin.models(): its committed
    files), or a Description (phantom_pin.describe; a configuration folder of one's own is
    ``load(describe(folder))``), whose texts are used with PhantomLoader's other attributes.
    The URDF must pass physical.check_urdf. Raises ParameterFileError naming
    ``urdf_path`` or ``srdf_path`` for a missing, malformed or non-physical file.
    """
    if isinstance(source, Path) or (isinstance(source, str) and source not in MODELS):
        raise InvalidInputError(f"expected a PhantomLoader class, a model name ({', '.join(MODELS)}) or a "
                                f"Description, got {source!r}; for a configuration folder use "
                                "load(describe(folder))", argument="source")
    if isinstance(source, (Description, str)):
        description = description_of(source, "source")
        loader, urdf, srdf = PhantomLoader, description.urdf, description.srdf  # checked by describe()
        urdf_name, srdf_name = "source: the description's URDF", "source: the description's SRDF"
        config: Config | None = description.config
    elif isinstance(source, type) and issubclass(source, PhantomLoader):
        loader = source
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
        config = None  # a URDF file of one's own keeps Pinocchio's g and its rotors
    else:
        raise InvalidInputError(f"expected a PhantomLoader class, a model name, a configuration "
                                f"folder or a Description, got {source!r}", argument="source")
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
