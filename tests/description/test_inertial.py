"""The one physical check of a link (phantom_pin.description.inertial), its tolerance against MuJoCo (the
strictest consumer, loading the generated MJCF at the boundary), and links given in full
against the report's adapter."""

import shutil

import mujoco
import numpy as np
import pytest
import yaml

from phantom_pin import ParameterFileError, config, describe
from phantom_pin.cli import main
from phantom_pin.config import MODELS
from phantom_pin.description.inertial import TRIANGLE_SLACK, Inertial, problem, slack

SHIPPED = MODELS["premium_1_5"]


def _diagonal(mass, com, xx, yy, zz, about_origin=False):
    """A body of diagonal inertia (kg m^2, base_link axes) about its COM, or about the link
    origin moved to the COM by the parallel-axis theorem."""
    c = np.array(com, dtype=float)
    tensor = np.diag([xx, yy, zz]) - (mass * (c @ c * np.eye(3) - np.outer(c, c)) if about_origin else 0.0)
    inertia = {"xx": float(tensor[0, 0]), "xy": 0.0, "xz": 0.0, "yy": float(tensor[1, 1]), "yz": 0.0,
               "zz": float(tensor[2, 2])}
    return {"mass": mass, "com": list(com), "inertia": inertia}


def test_the_report_as_five_bodies_in_full_gives_the_report_adapters_links(tmp_path):
    """The report's segments written by hand as five bodies in full (report axes (x, y, z) =
    base (y, z, x); BE and DF printed about the shoulder; the rotors moved to the armature)
    give, through the links-in-full path and its generic carving of the hinge pins, the links
    of the report's adapter (report.parameters.links) to rounding."""
    folder = tmp_path / "config"
    shutil.copytree(SHIPPED.config, folder)
    c = config.read()
    p, (j1, j2, j3) = c.report, c.actuation.armature
    raw = yaml.safe_load((SHIPPED.config / "physical_parameters.yaml").read_text())
    g = raw["segment_g"]
    bodies = {
        "turret_link": _diagonal(g["mass"], (0, 0, 0), g["inertia_zz"], g["inertia_xx"], p.Ibaseyy - j1),
        "upper_arm_link": _diagonal(p.mbe, (p.l5, 0, 0), p.Ibezz, p.Ibexx - j2, p.Ibeyy, about_origin=True),
        "crank_link": _diagonal(p.mdf, (0, 0, p.l6), p.Idfzz, p.Idfxx - j3, p.Idfyy, about_origin=True),
        "lower_bar_link": _diagonal(p.mc, (p.l1 / 2, 0, 0), p.Iczz, p.Icxx, p.Icyy),
        "forearm_link": _diagonal(p.ma, (0, 0, p.l3 - p.l2 / 2), p.Iazz, p.Iaxx, p.Iayy),
    }
    (folder / "physical_parameters.yaml").write_text(
        yaml.safe_dump({"gravity": 9.81, "links": bodies, "housing": raw["housing"], "hinge_pin": raw["hinge_pin"]}))
    full = config.read(folder)
    assert full.report is None
    for name, link in c.links.items():
        other = full.links[name]
        assert other.mass == pytest.approx(link.mass, rel=1e-15), name
        np.testing.assert_allclose(other.com, link.com, rtol=1e-14, atol=1e-17, err_msg=name)
        np.testing.assert_allclose(other.tensor, link.tensor, rtol=1e-12, atol=1e-18, err_msg=name)


def _loads_in_mujoco(mjcf: str) -> bool:
    try:
        mujoco.MjModel.from_xml_string(mjcf)
    except ValueError:
        return False
    return True


@pytest.mark.parametrize("factor, accepted", [(10.0, True), (1.5, True), (0.5, False), (0.0, False), (-1e3, False)])
def test_the_boundary_of_the_triangle_inequality_is_the_same_for_us_and_mujoco(factor, accepted):
    """The forearm (a thin rod: 0.38 % slack) moved to slack = factor * TRIANGLE_SLACK through
    segment_a.inertia.xx (its URDF iyy): describe() accepts exactly what loads in MuJoCo."""
    a, b = config.read().report.Iayy, config.read().report.Iazz  # URDF izz and ixx of the forearm
    largest = (a + b) / (1 + factor * TRIANGLE_SLACK)
    if accepted:
        description = describe(overrides={"segment_a.inertia.xx": largest})
        assert _loads_in_mujoco(description.mjcf)
    else:
        with pytest.raises(ParameterFileError, match="link forearm_link: .*triangle inequality"):
            describe(overrides={"segment_a.inertia.xx": largest})


def test_rotated_links_at_the_boundary_load_in_mujoco():
    """With products of inertia MuJoCo's own eigen-decomposition decides, and rounds: every
    link the check accepts (slack 2 TRIANGLE_SLACK, 40 random orientations) loads from the
    generated MJCF (premium_1_5_cad's forearm, given in full); links 1e-12 c past the
    boundary are refused by the check."""
    rng = np.random.default_rng(7)
    a, b = 1.843e-7, 4.864e-5
    for _ in range(40):
        q = rng.normal(size=4)
        w, x, y, z = q / np.linalg.norm(q)
        rotation = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                             [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                             [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
        for share, physical in ((2 * TRIANGLE_SLACK, True), (-TRIANGLE_SLACK, False)):
            tensor = rotation @ np.diag([a, b, (a + b) / (1 + share)]) @ rotation.T
            keys = dict(zip(("xx", "xy", "xz", "yy", "yz", "zz"), (tensor[0, 0], tensor[0, 1], tensor[0, 2],
                                                                   tensor[1, 1], tensor[1, 2], tensor[2, 2])))
            overrides = {f"links.forearm_link.inertia.{k}": float(v) for k, v in keys.items()}
            if physical:
                assert _loads_in_mujoco(describe("premium_1_5_cad", overrides=overrides).mjcf)
            else:
                with pytest.raises(ParameterFileError, match="link forearm_link"):
                    describe("premium_1_5_cad", overrides=overrides)


def test_the_issue_example_is_refused_with_one_line_and_nothing_written(tmp_path, capsys):
    """Before: `mjcf --set segment_a.inertia.xx=4.8824300001e-05` exited 0 and MuJoCo refused
    the file ("inertia must satisfy A + B >= C")."""
    output = tmp_path / "x.xml"
    assert main(["mjcf", "-o", str(output), "--set", "segment_a.inertia.xx=4.8824300001e-05"]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "forearm_link" in error and "triangle inequality" in error
    assert not output.exists()


@pytest.mark.parametrize("inertial, message", [
    (Inertial(0.0, (0, 0, 0), (1e-4, 0, 0, 1e-4, 0, 1e-4)), "mass must be positive"),
    (Inertial(1.0, (0, 0, float("nan")), (1e-4, 0, 0, 1e-4, 0, 1e-4)), "finite"),
    (Inertial(1.0, (0, 0, 0), (1e-4, 2e-4, 0, 1e-4, 0, 1e-4)), "not positive definite"),
    (Inertial(1.0, (0, 0, 0), (1e-4, 0, 0, 1e-4, 0, 3e-4)), "triangle inequality"),
])
def test_the_check_names_the_problem(inertial, message):
    assert message in problem(inertial)


def test_dynamic_parameters_are_pinocchios():
    """Inertial.dynamic_parameters (about the link origin) equals Pinocchio's
    Inertia.toDynamicParameters of the same body, and from_dynamic_parameters inverts it."""
    import pinocchio as pin

    link = Inertial(0.3, (0.01, -0.02, 0.05), (2e-4, 1e-5, -2e-5, 3e-4, 3e-5, 2.5e-4))
    body = pin.Inertia(link.mass, np.array(link.com), link.tensor)
    np.testing.assert_allclose(link.dynamic_parameters(), body.toDynamicParameters(), rtol=1e-13, atol=1e-19)
    back = Inertial.from_dynamic_parameters(link.dynamic_parameters())
    np.testing.assert_allclose([back.mass, *back.com, *back.inertia], [link.mass, *link.com, *link.inertia],
                               rtol=1e-10, atol=1e-18)
    assert slack(link.tensor) > 0


def test_the_triangle_margin_is_relative_to_the_largest_moment():
    """a + b - c = 2e-12 c at the scale of a hinge pin's moments (1e-6 kg m^2): physical (an
    absolute margin of 1e-12 kg m^2 would refuse it); 0.5e-12 c is not."""
    a, b = 0.4e-6, 0.6e-6
    for share, physical in ((2e-12, True), (0.5e-12, False)):
        c = (a + b) / (1 + share)
        link = Inertial(0.01, (0.0, 0.0, 0.0), (a, 0.0, 0.0, b, 0.0, c))
        assert (problem(link) is None) == physical, (share, problem(link))


def test_a_zero_principal_moment_is_not_physical():
    link = Inertial(0.01, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1e-6, 0.0, 1e-6))   # a rod: a = 0, b = c
    assert "not positive definite" in problem(link)
