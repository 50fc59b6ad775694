"""phantom-pin feel: its numbers against the report's closed form at the nominal posture, its
--plot page (self-contained, never overwritten without --force, nothing written on failure) and
its refusals (one line, exit 2, naming the option)."""

import json

import numpy as np
import pytest

from phantom_pin import closed_form
from phantom_pin.config import read


def test_the_nominal_measures_are_the_closed_forms(cli):
    """At theta = 0 (the default) the Premium 1.5's J is diag(l1, l1, l2) and M diagonal (eq. 10
    and the closed form): the axis masses are M_ii / lever^2 (g), the breakaway forces the
    Coulomb torque over the lever (N); text and JSON say the same, with units."""
    report = read("premium_1_5").report
    m = np.diag(closed_form.mass_matrix(np.zeros(3), report))
    levers = np.array([report.l1, report.l1, report.l2])
    code, out, err = cli("feel", "--json")
    data = json.loads(out)
    assert code == 0 and err == "" and data["posture"] == "zero" and data["theta"] == [0.0, 0.0, 0.0]
    np.testing.assert_allclose(data["axis_masses"], 1e3 * m / levers**2, rtol=1e-12)
    np.testing.assert_allclose(data["breakaway_along"], 0.01 / levers, rtol=1e-12)
    assert data["units"]["axis_masses"] == "g" and data["nominal_max_force"] == 8.5
    code, out, _ = cli("feel")
    axis_line = next(line for line in out.splitlines() if "along x, y, z" in line)
    assert code == 0 and axis_line.endswith(" g") and "77.31 52.49 32.25" in axis_line
    assert "HD_NOMINAL_MAX_FORCE 8.5 N" in out and "cm^3" in out and "orthogonal arms" in out


def test_the_plot_page_is_written_once_and_only_with_force_again(tmp_path, cli):
    page = tmp_path / "feel.html"
    code, out, err = cli("--model", "touch", "feel", "--theta", "0", "0.5", "0.5", "--plot", str(page))
    text = page.read_text()
    assert code == 0 and "wrote" in err and "<script" not in text and "http" not in text.split("<svg", 1)[0]
    for gid in ("apparent-mass-xy", "apparent-mass-zy", "workspace-box-xz", "workspace-tip-xy"):
        assert f'id="{gid}"' in text, gid
    page.write_text("kept")
    code, _, err = cli("--model", "touch", "feel", "--plot", str(page))
    assert code == 2 and err.count("\n") == 1 and "--plot" in err and page.read_text() == "kept"
    code, _, _ = cli("--model", "touch", "feel", "--plot", str(page), "--force")
    assert code == 0 and page.read_text() != "kept"


@pytest.mark.parametrize("argv, option, says", [
    (["feel", "--theta", "0", "0", "9"], "--theta", "outside the stops"),
    (["--model", "touch", "feel", "--theta", "0", "1.74", str(1.5 * np.pi - 1.74)], "--theta", "singular"),
    (["feel", "--speed", "0"], "--speed", "> 0"),
    (["feel", "--theta", "0", "0"], "--theta", "expected 3 arguments"),
])
def test_bad_input_is_one_line_exit_2_and_writes_nothing(tmp_path, cli, argv, option, says):
    page = tmp_path / "feel.html"
    code, out, err = cli(*argv, "--plot", str(page))
    assert code == 2 and out == "" and err.count("\n") == 1 and option in err and says in err
    assert not page.exists()
