"""phantom_pin._progress: a bar on stderr for long work, only on a terminal, never with --quiet."""

import io
import time

from phantom_pin import _progress as progress
from phantom_pin._progress import Progress
from phantom_pin.cli import main


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_the_bar_appears_after_the_delay_and_ends_its_line():
    stream = Terminal()
    bar = Progress("work", 4, stream=stream, delay=0.05)
    bar.update(1)                      # before the delay: nothing
    assert stream.getvalue() == ""
    time.sleep(0.06)
    bar.update(2)
    bar.close()
    text = stream.getvalue()
    assert text.startswith("\rwork [") and " 50.0 % " in text and "s left" in text and text.endswith("\n")


def test_no_bar_off_a_terminal_or_when_disabled():
    for stream, enabled in ((io.StringIO(), None), (Terminal(), False)):
        bar = Progress("work", 4, stream=stream, enabled=enabled, delay=0.0)
        bar.update(2)
        bar.close()
        assert stream.getvalue() == ""


def test_check_shows_progress_on_a_terminal_unless_quiet(capsys, monkeypatch):
    """With the delay set to zero: check on a terminal draws the bar on stderr (stdout keeps
    its report), and --quiet draws nothing."""
    monkeypatch.setattr(progress, "DELAY", 0.0)
    monkeypatch.setattr(progress, "INTERVAL", 0.0)
    monkeypatch.setattr("phantom_pin.dynamics.verification.CHUNK", 100)
    monkeypatch.setattr("sys.stderr.isatty", lambda: True, raising=False)
    assert main(["check", "-n", "500"]) == 0
    out, err = capsys.readouterr()
    assert "all checks pass" in out and "\rcheck [" in err and err.endswith("\n")
    assert main(["--quiet", "check", "-n", "500"]) == 0
    assert capsys.readouterr().err == ""


def test_long_work_reports_its_share_done():
    """simulate once per sample and 1 at the end (before, the bar stopped at 99.8 %), excite's
    optimiser once per SLSQP iteration, estimate at its stages: shares in [0, 1], never
    decreasing."""
    import numpy as np

    from phantom_pin import Phantom, describe, simulate
    from phantom_pin.identification.fitting import excitation

    shares = []
    result = simulate([0.0, 0.3, 0.4], 0.05, progress=shares.append)
    assert len(shares) == len(result.t) + 1 and shares[0] == 0 and shares[-2:] == [50 / 51, 1.0]
    seen = []
    excitation.optimise(Phantom(describe()), 5.0, 3, samples=30, iterations=4, restarts=2, progress=seen.append)
    for values in (shares, seen):
        assert np.all(np.diff(values) >= 0) and 0 <= values[0] and values[-1] <= 1
    assert len(seen) >= 2
