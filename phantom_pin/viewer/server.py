"""A meshcat server on 127.0.0.1, run as a child process that never outlives its owner."""

from __future__ import annotations

import atexit
import ctypes
import functools
import signal
import subprocess
import sys
from pathlib import Path

#: Seconds to wait for the child to exit after SIGTERM before it is killed.
_STOP_TIMEOUT = 5.0
#: The child: this file run as a script, so that it imports meshcat alone (as ``-m
#: phantom_pin.viewer.server`` it imported the whole package first: 1.1 s of CPU a start, against
#: 0.3 s); this module imports nothing of phantom_pin at its top for that reason.
_CHILD = f"import runpy; runpy.run_path({str(Path(__file__).resolve())!r}, run_name='__main__')"
_PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:  # runs in the child between fork and exec (Linux only)
    ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)


class MeshcatServer:
    """meshcat's ZMQ-to-websocket bridge in a child process, bound to 127.0.0.1.

    meshcat's own launcher serves its web page on every interface; this one binds
    both the ZMQ socket and the web server to the loopback interface. The child is
    stopped by ``stop()``, at interpreter exit (atexit), and on Linux also by the
    kernel when this process dies without running atexit (SIGKILL).

    Attributes: ``zmq_url`` (tcp://127.0.0.1:PORT, for meshcat.Visualizer),
    ``web_url`` (http://127.0.0.1:PORT/static/, for a browser), ``process``.
    """

    def __init__(self) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-u", "-c", _CHILD],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL,
            start_new_session=True,
            preexec_fn=_die_with_parent if sys.platform == "linux" else None)
        atexit.register(self.stop)
        urls = {}
        assert self.process.stdout is not None  # stdout=PIPE
        for _ in range(2):
            line = self.process.stdout.readline().decode().strip()
            key, _, value = line.partition("=")
            urls[key] = value
        if set(urls) != {"zmq_url", "web_url"}:
            from phantom_pin.exceptions import PhantomPinError

            self.stop()
            raise PhantomPinError(f"the meshcat server did not start (it printed {urls!r})")
        self.zmq_url, self.web_url = urls["zmq_url"], urls["web_url"]

    @property
    def running(self) -> bool:
        """True while the child process is alive."""
        return self.process.poll() is None

    def stop(self) -> None:
        """Terminate the child (SIGTERM, then SIGKILL after a few seconds); idempotent."""
        atexit.unregister(self.stop)
        if self.running:
            self.process.terminate()
            try:
                self.process.wait(_STOP_TIMEOUT)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        if self.process.stdout is not None:
            self.process.stdout.close()


def _serve() -> None:
    """Child side: run meshcat's bridge with its web server bound to 127.0.0.1."""
    from meshcat.servers.zmqserver import ZMQWebSocketBridge

    class LoopbackBridge(ZMQWebSocketBridge):
        def make_app(self):
            app = super().make_app()
            app.listen = functools.partial(app.listen, address="127.0.0.1")
            return app

    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    bridge = LoopbackBridge(host="127.0.0.1")
    print(f"zmq_url={bridge.zmq_url}", flush=True)
    print(f"web_url={bridge.web_url}", flush=True)
    bridge.run()


if __name__ == "__main__":
    _serve()
