"""phantom-pin's main() (cli/app.py): the parser's one-line refusals with exit code 2, and the
exit codes of a closed output pipe (141) and of Ctrl-C, in a process of its own."""

import json
import os
import signal
import subprocess
import sys
import time

import pytest


@pytest.mark.parametrize("argv, message", [
    (["ik", "0", "0.3", "0.3"], "outside the reachable shell"),
    (["fk", "0", "0"], "required"),
    (["fk", "0", "nan", "0"], "theta: contains NaN"),
    (["check", "-n", "0"], "-n"),
    (["bogus"], "invalid choice"),
])
def test_bad_arguments_give_one_line_and_exit_code_2(cli, argv, message):
    code, _, err = cli(*argv)
    assert code == 2 and message in err and err.count("\n") == 1


def _popen(*argv):
    return subprocess.Popen([sys.executable, "-m", "phantom_pin.cli", *argv],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_closed_output_pipe_ends_quietly():
    """phantom-pin info | head -1: the reader goes away; no traceback, exit 141 (128 + SIGPIPE)."""
    process = _popen("info")
    process.stdout.close()
    assert process.wait(60) == 141
    assert process.stderr.read() == ""


def _cpu_seconds(pid: int) -> float:
    fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _peak_rss_mb(pid: int) -> float:
    status = open(f"/proc/{pid}/status").read()
    return int(status.split("VmHWM:")[1].split()[0]) / 1024


@pytest.mark.slow
def test_huge_check_runs_in_bounded_memory_and_ctrl_c_gives_one_line():
    """check -n 2e7, the most it takes (2 TiB of states at once before, for 1e11): after 3 s of
    CPU (its start, about 0.6 s, then a dozen of its 10 000-state chunks, about 0.18 s each; its
    2e7 states' angles alone are 480 MB) its peak memory is below 400 MB; Ctrl-C then ends it
    with one line and exit 130 (128 + SIGINT). The command starts with SIGINT's default
    disposition, whatever pytest's own (a pytest started in the background ignores SIGINT, its
    children inherit that, and Python then leaves SIGINT ignored: check ran on, as any program
    whose parent ignores SIGINT does)."""
    process = subprocess.Popen([sys.executable, "-m", "phantom_pin.cli", "check", "-n", "20000000"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 120
        while _cpu_seconds(process.pid) < 3.0 and process.poll() is None and time.monotonic() < deadline:
            time.sleep(0.2)
        assert process.poll() is None, process.stderr.read()
        assert _peak_rss_mb(process.pid) < 400
        process.send_signal(signal.SIGINT)
        assert process.wait(60) == 130
    finally:
        process.kill()
    assert process.stderr.read() == "phantom-pin: interrupted\n"


@pytest.mark.parametrize("unbuffered", ["1", None])
def test_simulate_into_a_pipe_closed_part_way_exits_141(unbuffered):
    """Output into a pipe that its reader closes part way exits 141, without a word, buffered or
    with PYTHONUNBUFFERED=1 (as Docker images set it: unbuffered, Python writes the 219 kB at once
    and the reader's exit leaves a short write, not an error); docs/cli.md says 141. Read in full,
    the output is a whole JSON document of duration x rate + 1 samples."""
    import os
    import subprocess
    import sys

    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"} | (
        {"PYTHONUNBUFFERED": unbuffered} if unbuffered else {})
    argv = [sys.executable, "-m", "phantom_pin.cli", "simulate", "--theta0", "0", "0.3", "0.4", "--duration", "1"]
    process = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    assert len(process.stdout.read(10)) == 10
    process.stdout.close()
    assert process.wait(120) == 141 and process.stderr.read() == b""
    process.stderr.close()
    whole = subprocess.run(argv, capture_output=True, env=env, check=True, timeout=120)
    assert len(whole.stdout) > 2**16 and len(json.loads(whole.stdout)["t"]) == 1001
