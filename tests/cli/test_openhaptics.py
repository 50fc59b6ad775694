"""phantom-pin openhaptics-sim build (cli/openhaptics.py): writes the stand-in's tree, never over
it without --force, nothing on failure."""



def test_the_command_builds_refuses_to_overwrite_and_writes_nothing_on_failure(tmp_path):
    """`openhaptics-sim build DIR`: writes the tree; again without --force: one line, exit 2, the
    files untouched; --force rewrites; a folder that cannot be made, an unknown model: exit 2 and
    nothing written."""
    from helpers import run_cli
    code, out, _ = run_cli("--model", "touch", "openhaptics-sim", "build", tmp_path / "sim")
    assert code == 0 and "libHD.so" in out
    library = tmp_path / "sim" / "lib" / "libHD.so"
    stamp = library.stat().st_mtime_ns
    code, _, err = run_cli("--model", "touch", "openhaptics-sim", "build", tmp_path / "sim")
    assert code == 2 and len(err.strip().splitlines()) == 1 and "--force" in err
    assert library.stat().st_mtime_ns == stamp
    assert run_cli("--model", "touch", "openhaptics-sim", "build", tmp_path / "sim", "--force")[0] == 0
    for arguments in (("openhaptics-sim", "build", tmp_path / "missing" / "sim"),
                      ("--model", "nope", "openhaptics-sim", "build", tmp_path / "other")):
        code, _, err = run_cli(*arguments)
        assert code == 2 and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "missing").exists() and not (tmp_path / "other").exists()
