"""Where the description package lives (source checkout or installed wheel); the files of
each model are declared in phantom_pin.config.models."""

from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent
#: robots/phantom_description: inside the wheel, or beside the package in a checkout.
DESCRIPTION_DIR = next(
    (p for p in (_PACKAGE / "robots" / "phantom_description",
                 _PACKAGE.parent / "robots" / "phantom_description") if p.is_dir()),
    _PACKAGE.parent / "robots" / "phantom_description")
#: The driver profiles: one YAML file per public ROS driver, named after its repository.
PROFILES_DIR = DESCRIPTION_DIR / "config" / "drivers"
