"""The meshcat server child: loopback only, serves the viewer, never outlives its owner.
Sockets and processes are read from the kernel (Linux /proc), not from the server's report."""

import os
import signal
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

from phantom_pin.viewer.server import MeshcatServer

LOOPBACK_V4, LISTEN = "0100007F", "0A"


def listening_addresses(pid: int) -> list[str]:
    """Local addresses (hex ip:port) of the TCP sockets ``pid`` listens on, from /proc."""
    inodes = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        target = os.readlink(fd)
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    addresses = []
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            if fields[3] == LISTEN and fields[9] in inodes:
                addresses.append(fields[1])
    return addresses


def gone(pid: int, within: float = 10.0) -> bool:
    """True once no process ``pid`` exists (zombies of our own children count as gone)."""
    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        try:
            state = Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0]
        except FileNotFoundError:
            return True
        if state == "Z":
            return True
        time.sleep(0.05)
    return False


def test_listens_on_loopback_only_and_serves_the_viewer():
    server = MeshcatServer()
    try:
        addresses = listening_addresses(server.process.pid)
        assert len(addresses) == 2  # the ZMQ socket and the web server
        assert all(a.split(":")[0] == LOOPBACK_V4 for a in addresses), addresses
        assert server.web_url.startswith("http://127.0.0.1:") and server.zmq_url.startswith("tcp://127.0.0.1:")
        with urllib.request.urlopen(server.web_url, timeout=10) as response:
            assert response.status == 200 and b"meshcat" in response.read().lower()
    finally:
        server.stop()
    assert gone(server.process.pid)
    server.stop()  # idempotent


def _owner(ending: str) -> tuple[subprocess.Popen, int]:
    """A Python process that starts a server, prints its pid, then ``ending``."""
    code = ("from phantom_pin.viewer.server import MeshcatServer\n"
            "import sys, time\n"
            "server = MeshcatServer()\n"
            "print(server.process.pid, flush=True)\n" + ending)
    owner = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    return owner, int(owner.stdout.readline())


def test_server_stops_when_its_owner_exits_without_closing():
    owner, pid = _owner("sys.exit(0)\n")
    assert owner.wait(30) == 0
    assert gone(pid)


def test_server_stops_when_its_owner_is_killed():
    owner, pid = _owner("time.sleep(60)\n")
    assert not gone(pid, within=0.2)
    owner.send_signal(signal.SIGKILL)
    owner.wait(30)
    assert gone(pid)
