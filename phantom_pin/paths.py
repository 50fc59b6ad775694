"""Where the shipped description package lives (source checkout or installed wheel)."""

from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent
#: robots/phantom_description: inside the wheel, or beside the package in a checkout.
DESCRIPTION_DIR = next(
    (p for p in (_PACKAGE / "robots" / "phantom_description",
                 _PACKAGE.parent / "robots" / "phantom_description") if p.is_dir()),
    _PACKAGE.parent / "robots" / "phantom_description")
CONFIG_DIR = DESCRIPTION_DIR / "config"
URDF_XACRO = DESCRIPTION_DIR / "urdf" / "phantom_1_5.urdf.xacro"
SRDF_XACRO = DESCRIPTION_DIR / "srdf" / "phantom_1_5.srdf.xacro"
URDF_PATH = DESCRIPTION_DIR / "urdf" / "phantom_1_5.urdf"
SRDF_PATH = DESCRIPTION_DIR / "srdf" / "phantom_1_5.srdf"
MJCF_PATH = DESCRIPTION_DIR / "mjcf" / "phantom_1_5.xml"
SCENE_PATH = DESCRIPTION_DIR / "mjcf" / "scene.xml"
