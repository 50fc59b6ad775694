"""phantom-pin codegen (cli/codegen.py): the header of --model with --set and --prefix, and on
bad input one line naming the option, exit 2, and no file."""

from helpers import OVERLAY, generated
from phantom_pin.cli import main


def test_cli_writes_the_header_and_refuses_bad_input(tmp_path, capsys):
    """phantom-pin codegen: the header of --model with --set and --prefix; on bad input one
    line naming the option, exit 2, and no file."""
    out = tmp_path / "arm.h"
    assert main(["codegen", "--model", "touch", "--prefix", "arm", "-o", str(out)]) == 0
    assert out.read_text() == generated("touch", prefix="arm")
    assert main(["codegen", "--model", "touch", "-o", str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    assert out.read_text() == generated("touch", prefix="arm")
    bad = tmp_path / "bad.h"
    assert main(["codegen", "--model", "touch", "--prefix", "9lives", "-o", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("phantom-pin: error: --prefix:") and err.count("\n") == 1
    assert main(["codegen", "--model", "touch", "--set", "links.forearm_link.mass=-1", "-o", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert main(["info", "--model", "touch", "--set", "links.forearm_link.mass=-1"]) == 2
    assert capsys.readouterr().err == err  # the same line as any command's describe()
    assert not bad.exists()
    sets = [argument for key, value in OVERLAY.items() for argument in ("--set", f"{key}={value!r}")]
    assert main(["codegen", "--model", "premium_1_5_cad", *sets, "-o", str(out), "--force"]) == 0
    assert out.read_text() == generated("premium_1_5_cad", overrides=OVERLAY)  # --set as overrides=


def test_a_missing_config_folder_is_blamed_on_config(tmp_path, capsys):
    assert main(["codegen", "--config", str(tmp_path / "none"), "-o", str(tmp_path / "a.h")]) == 2
    assert capsys.readouterr().err.startswith("phantom-pin: error: --config: ")
    assert not (tmp_path / "a.h").exists()
