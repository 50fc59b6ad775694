"""load(): the shipped description as a pinocchio RobotWrapper, in example-robot-data's style."""

from __future__ import annotations

from pathlib import Path

import pinocchio as pin

from phantom_pin.exceptions import InvalidInputError, ParameterFileError
from phantom_pin.paths import DESCRIPTION_DIR, SRDF_PATH, URDF_PATH
from phantom_pin.physical import check_urdf


class PhantomLoader:
    """What load() reads: declared attributes only, as example-robot-data's loaders.

    Subclass and override an attribute to load a URDF/SRDF pair of your own (for
    example one written by ``phantom-pin urdf --set ...``).
    """

    #: The URDF with the parallelogram as mimic joints (joint1..3 = theta1..3).
    urdf_path: Path = URDF_PATH
    #: The SRDF with the named postures, rotor parameters and disabled collision pairs.
    srdf_path: Path = SRDF_PATH
    #: Folders that resolve package:// URIs (the parent of phantom_description).
    package_dirs: tuple[Path, ...] = (DESCRIPTION_DIR.parent,)
    #: The SRDF posture that becomes ``robot.q0``.
    ref_posture: str = "resting"
    #: Read the SRDF's rotor_params into model.armature (rotor inertia x ratio^2, kg m^2).
    has_rotor_parameters: bool = True


def _first_line(error: Exception) -> str:
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    return lines[0] if lines else type(error).__name__


def load(loader: type[PhantomLoader] = PhantomLoader) -> pin.RobotWrapper:
    """The PHANToM 1.5 as a RobotWrapper: ``model`` is the mimic model (nq = nv = 3,
    joint1..3 = the report's theta1..3 in rad), with ``visual_model``,
    ``collision_model`` (every pair but the SRDF's disabled ones), the SRDF postures in
    ``model.referenceConfigurations``, ``q0`` = the ``ref_posture`` (rad) and
    ``model.armature`` = the reflected rotor inertias (kg m^2). World = ``base_link``
    (REP-103: x forward, z up, origin at the shoulder).

    The URDF must pass physical.check_urdf. Raises ParameterFileError naming
    ``urdf_path`` or ``srdf_path`` for a missing, malformed or non-physical file.
    """
    for name in ("urdf_path", "srdf_path"):
        if not Path(getattr(loader, name)).is_file():
            raise ParameterFileError(f"{name}: {getattr(loader, name)} is not a file")
    urdf, srdf = str(loader.urdf_path), str(loader.srdf_path)
    try:
        check_urdf(Path(urdf).read_text(encoding="utf-8"), f"urdf_path: {urdf}")
    except UnicodeDecodeError as error:
        raise ParameterFileError(f"urdf_path: {urdf} is not a text file") from error
    try:
        robot = pin.RobotWrapper.BuildFromURDF(urdf, [str(p) for p in loader.package_dirs], mimic=True)
    except (RuntimeError, ValueError, AttributeError) as error:  # Pinocchio's, several lines
        raise ParameterFileError(f"urdf_path: Pinocchio cannot load {urdf} ({_first_line(error)})") from error
    try:
        pin.loadReferenceConfigurations(robot.model, srdf, False)
        if loader.has_rotor_parameters:
            pin.loadRotorParameters(robot.model, srdf, False)
        robot.collision_model.addAllCollisionPairs()
        pin.removeCollisionPairs(robot.model, robot.collision_model, srdf, False)
    except (RuntimeError, ValueError, AttributeError) as error:
        raise ParameterFileError(f"srdf_path: Pinocchio cannot read {srdf} ({_first_line(error)})") from error
    postures = [entry.key() for entry in robot.model.referenceConfigurations]
    if loader.ref_posture not in postures:
        raise InvalidInputError(
            f"ref_posture: {loader.ref_posture!r} is not a posture of {Path(loader.srdf_path).name} "
            f"(it has {sorted(postures)})")
    robot.q0 = robot.model.referenceConfigurations[loader.ref_posture].copy()
    robot.rebuildData()
    return robot
