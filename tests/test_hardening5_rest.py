"""Issue 42 (Hardening 5), the rest: the files the command line writes and reads (nothing
written on failure; the model and convention a trajectory or log was written for), and the
stylus gimbal's angles in every dynamics function, simulate and the command line. Each test
compares with something independent of the code under test: the file system itself, the
six-joint Touch built by Pinocchio from the URDF, finite differences, energy."""

import os
import stat

import pytest


@pytest.mark.parametrize("output, scene", [("model.xml", "/dev/full"), ("/dev/full", "scene.xml")])
def test_mjcf_writes_neither_file_when_one_cannot_be_written(tmp_path, cli, output, scene):
    """`mjcf -o A --scene /dev/full` wrote A, then failed on the scene: nothing may be written
    on failure. Either file unwritable (a full device): the folder stays empty, one line names
    the option whose file failed."""
    paths = [p if p.startswith("/dev") else str(tmp_path / p) for p in (output, scene)]
    code, out, err = cli("mjcf", "-o", paths[0], "--scene", paths[1], "--force")
    option = "--scene" if scene.startswith("/dev") else "--output"
    assert (code, out, err) == (2, "", f"phantom-pin: error: {option}: cannot write /dev/full (No space left on "
                                       "device)\n")
    assert list(tmp_path.iterdir()) == []


def test_written_files_take_the_umask_and_an_overwritten_file_keeps_its_mode(tmp_path, cli):
    """The files are staged beside their targets and renamed into place: a new file gets the
    mode open() would give it (0666 less the umask), an overwritten one keeps its own, and no
    temporary file is left behind."""
    mask = os.umask(0o027)
    try:
        assert cli("mjcf", "-o", tmp_path / "m.xml", "--scene", tmp_path / "s.xml")[0] == 0
        os.chmod(tmp_path / "s.xml", 0o600)
        (tmp_path / "s.xml").write_text("old\n")
        assert cli("mjcf", "-o", tmp_path / "m.xml", "--scene", tmp_path / "s.xml", "--force")[0] == 0
    finally:
        os.umask(mask)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.xml", "s.xml"]
    assert stat.S_IMODE((tmp_path / "m.xml").stat().st_mode) == 0o640
    assert stat.S_IMODE((tmp_path / "s.xml").stat().st_mode) == 0o600
    assert "m.xml" in (tmp_path / "s.xml").read_text()
