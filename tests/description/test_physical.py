"""The one physical check of a link where it guards: the configuration (so `phantom-pin urdf`,
describe() and Phantom.from_folder(folder)), and physical.check_urdf of a URDF given to load()."""

import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from helpers import CONFIG_DIR, SRDF_PATH, URDF_PATH
from phantom_pin import ParameterFileError, Phantom
from phantom_pin.cli import main
from phantom_pin.config import MODELS
from phantom_pin.config.files import FILES, apply_overrides, read_documents
from phantom_pin.description.inertial import TRIANGLE_SLACK
from phantom_pin.description.physical import check_urdf
from phantom_pin.dynamics.loader import PhantomLoader, load_files

#: Overrides that write a non-physical link (the issue's list), and the link they break.
NON_PHYSICAL = [
    ("segment_a.inertia.xx=1e-3", "forearm_link: principal moments"),          # triangle
    ("segment_be.inertia.xx=1e5", "upper_arm_link: principal moments"),        # triangle
    ("segment_be.com=-0.2", "upper_arm_link: inertia at the centre of mass is not positive"),
    ("actuation.motor.rotor_inertia=1e-4", "turret_link: inertia at the centre of mass is not positive"),
    ("segment_g.mass=-1", "segment_g.mass must be positive"),
    ("segment_g.mass=0", "segment_g.mass must be positive"),
    ("segment_g.inertia_xx=-1", "segment_g.inertia_xx must be positive"),
    ("tip_ball.diameter=-1", "forearm_link: visual sphere radius must be positive"),
]


def _link(mass: str, ixx: float, iyy: float, izz: float, ixy: float = 0.0) -> str:
    return (f'<robot name="r"><link name="frame_only"/><link name="l"><inertial><mass value="{mass}"/>'
            f'<inertia ixx="{ixx!r}" ixy="{ixy!r}" ixz="0" iyy="{iyy!r}" iyz="0" izz="{izz!r}"/>'
            f'</inertial></link></robot>')


@pytest.mark.parametrize("override, message", NON_PHYSICAL)
def test_urdf_command_refuses_non_physical_links_and_writes_nothing(tmp_path, capsys, override, message):
    target = tmp_path / "phantom.urdf"
    code = main(["urdf", "-o", str(target), "--set", override])
    err = capsys.readouterr().err
    assert code == 2 and message in err and err.count("\n") == 1 and not target.exists()


@pytest.mark.parametrize("override, message", NON_PHYSICAL[:5])
def test_phantom_refuses_a_non_physical_configuration(tmp_path, override, message):
    key, value = override.split("=")
    config = tmp_path / "config"
    shutil.copytree(CONFIG_DIR, config)
    documents = apply_overrides(read_documents(config), {key: float(value)})  # well-formed YAML
    for arg, name in FILES.items():
        (config / name).write_text(yaml.safe_dump(documents[arg]))
    with pytest.raises(ParameterFileError, match=message):
        Phantom.from_folder(config)


def test_load_refuses_a_non_physical_urdf(tmp_path):
    urdf = tmp_path / "phantom.urdf"
    urdf.write_text(URDF_PATH.read_text().replace('<mass value="0.0202"/>', '<mass value="-0.0202"/>'))
    loader = type("Negative", (PhantomLoader,), {"urdf_path": urdf, "srdf_path": SRDF_PATH})
    with pytest.raises(ParameterFileError, match="urdf_path: .*forearm_link: mass must be positive"):
        load_files(loader)


def test_shipped_urdf_and_pure_frames_pass():
    check_urdf(URDF_PATH.read_text())
    check_urdf('<robot name="r"><link name="a"/></robot>')


def test_triangle_inequality_at_its_stated_tolerance():
    """A thin rod 1e-9 relative inside the triangle boundary (a + b - c = 1e-9 c) passes, and
    so does one only 2 TRIANGLE_SLACK inside; one on the boundary (c = a + b, which MuJoCo
    may refuse after rounding: tests/description/test_inertial.py), 1e-10 past it (which the former law,
    c - (a + b) <= 1e-9 c, accepted) or 1e-6 past it fails; rotating the tensor
    (off-diagonal terms) does not change the verdict."""
    assert TRIANGLE_SLACK == 1e-12
    for c in (1.0 / (1 + 1e-9), 1.0 / (1 + 2 * TRIANGLE_SLACK)):
        check_urdf(_link("1", 0.5, 0.5, c))
    for c in (1.0, 1.0 + 1e-10, 1.0 + 1e-6):
        with pytest.raises(ParameterFileError, match="link l: .*triangle"):
            check_urdf(_link("1", 0.5, 0.5, c))
    # principal moments (1, 2) in the x-y plane rotated by 45 degrees about z, with izz:
    # (1, 2, 2.9) is valid, (1, 2, 3.1) is not, though the diagonal (1.5, 1.5, 3.1) looks valid
    check_urdf(_link("1", 1.5, 1.5, 2.9, ixy=0.5))
    with pytest.raises(ParameterFileError, match="triangle"):
        check_urdf(_link("1", 1.5, 1.5, 3.1, ixy=0.5))
    with pytest.raises(ParameterFileError, match="not positive definite"):
        check_urdf(_link("1", 1.0, 1.0, 1.0, ixy=1.5))   # moments -0.5, 1, 2.5


@pytest.mark.parametrize("mass, message", [("0", "mass must be positive"), ("-1", "mass must be positive"),
                                           ("nan", "must be finite numbers"), ("abc", "needs .* a mass")])
def test_mass_must_be_a_positive_number(mass, message):
    with pytest.raises(ParameterFileError, match=f"link l: .*{message}"):
        check_urdf(_link(mass, 1.0, 1.0, 1.0))


@pytest.mark.parametrize("geometry", ['<box size="0.1 0 0.1"/>', '<cylinder radius="0.1" length="-1"/>',
                                      '<sphere radius="inf"/>', '<box size="0.1 0.1"/>'])
def test_sizes_must_be_positive(geometry):
    urdf = f'<robot name="r"><link name="g"><collision><geometry>{geometry}</geometry></collision></link></robot>'
    with pytest.raises(ParameterFileError, match="link g: collision .* must be positive"):
        check_urdf(urdf)


def test_malformed_xml_is_a_parameter_file_error():
    with pytest.raises(ParameterFileError, match="mine.urdf: not well-formed XML"):
        check_urdf("<robot", str(Path("mine.urdf")))


def test_check_urdf_reads_each_product_of_inertia_into_its_place():
    """ixx 1, iyy 2, izz 1.5 with ixz 0.6: principal moments 0.6, 1.9, 2 (physical); read with
    ixz and iyz exchanged they would be 1, 1.1, 2.4, which break the triangle inequality."""
    link = ('<link name="l"><inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="1"/>'
            '<inertia ixx="1" ixy="0" ixz="0.6" iyy="2" iyz="0" izz="1.5"/></inertial></link>')
    check_urdf(f'<robot name="r">{link}</robot>', "test")
    swapped = link.replace('ixz="0.6"', 'ixz="0"').replace('iyz="0"', 'iyz="0.6"')
    with pytest.raises(ParameterFileError, match="triangle inequality"):
        check_urdf(f'<robot name="r">{swapped}</robot>', "test")


def test_a_length_that_leaves_the_lower_bar_unphysical_is_named(cli):
    """A length that leaves a link the hinge pin is carved out of non-physical is named with the
    link's keys, in one line: `--set l1=...` on the Touch names the lower bar, its principal
    moments and l1 (the pin's distance). The hinge pin (mass mp) is carved out of the lower bar
    (mass mc, transverse inertia I about its centre, l1 long) at its end, l1 / 2 from the centre:
    by the parallel-axis theorem what is left has I - mp mc (l1 / 2)^2 / (mc - mp) about its own
    centre, and the same axial moment Izz (the pin sits on the axis): a body while twice the
    first is at least Izz (the triangle inequality), up to the l1 below."""
    physical = yaml.safe_load((MODELS["touch"].config / "physical_parameters.yaml").read_text())
    mc, inertia, axial, mp = (physical["segment_c"]["mass"], physical["segment_c"]["inertia"]["xx"],
                              physical["segment_c"]["inertia"]["zz"], physical["hinge_pin"]["mass"])
    longest = 2 * np.sqrt((inertia - axial / 2) * (mc - mp) / (mp * mc))      # 0.1661 m
    code, _, err = cli("--model", "touch", "--set", f"l1={longest * 0.999}", "fk", "0", "0", "0")
    assert code == 0 and err == "", err
    l1 = 0.2
    code, out, err = cli("--model", "touch", "--set", f"l1={l1}", "fk", "0", "0", "0")
    left = inertia - mp * mc * (l1 / 2) ** 2 / (mc - mp)
    assert (code, out) == (2, "") and err.count("\n") == 1 and "link lower_bar_link" in err
    assert f"principal moments {left:.6g}, {left:.6g}, {axial:.6g} kg m^2)" in err
    assert err.endswith("(from segment_c.mass, segment_c.inertia, hinge_pin.mass, l1 (the hinge pin's distance; "
                        "the inertias do not follow it))\n"), err
    code, _, _ = cli("--model", "touch", "--set", f"l1={longest * 1.001}", "fk", "0", "0", "0")
    assert code == 2
