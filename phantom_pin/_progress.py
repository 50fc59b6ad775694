"""Progress of long work on stderr, for the command line: a one-line bar with the share done and
the estimated time left, shown only after ``delay`` seconds, only on a terminal, never with
``--quiet``. Nothing of it reaches stdout (JSON and CSV stay clean)."""

from __future__ import annotations

import sys
import time
from typing import TextIO

#: Seconds of work before the bar appears: quick commands print nothing.
DELAY = 2.0
#: Seconds between redraws.
INTERVAL = 0.2
WIDTH = 30


class Progress:
    """``update(done)`` with ``done`` out of ``total`` units (samples, states, iterations);
    ``close()`` ends the line. ``enabled`` None means: when ``stream`` is a terminal."""

    def __init__(self, label: str, total: float, enabled: bool | None = None, stream: TextIO | None = None,
                 delay: float | None = None) -> None:
        self.label, self.total = label, float(total)
        self.delay = DELAY if delay is None else delay
        self.stream = sys.stderr if stream is None else stream
        self.enabled = self.stream.isatty() if enabled is None else enabled
        self.start = time.monotonic()
        self.last = -1.0
        self.shown = False

    def update(self, done: float) -> None:
        if not self.enabled or self.total <= 0:
            return
        now = time.monotonic()
        elapsed = now - self.start
        if elapsed < self.delay or now - self.last < INTERVAL:
            return
        self.last, self.shown = now, True
        share = min(max(done / self.total, 0.0), 1.0)
        left = elapsed * (1 - share) / share if share > 0 else float("inf")
        bar = "=" * int(WIDTH * share) + ">" + " " * (WIDTH - int(WIDTH * share))
        eta = f"{left:.0f} s left" if left != float("inf") else "estimating"
        self.stream.write(f"\r{self.label} [{bar[:WIDTH + 1]}] {100 * share:5.1f} % {eta}   ")
        self.stream.flush()

    def close(self) -> None:
        if self.shown:
            self.stream.write("\n")
            self.stream.flush()
            self.shown = False
