"""A page (the viewer's exported HTML, a plot) rendered to a PNG by Debian's headless chromium.

WebGL runs through SwiftShader (``--use-gl=swiftshader``: no GPU needed); chromium's own
background traffic (updates, sync, accounts) is switched off and every host name resolves to
nothing, so that rendering a page sends no request off the machine (DEVELOPERS.md, "meshcat
0.3.2 and chromium")."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

from phantom_pin._validation import output_path
from phantom_pin.exceptions import InvalidInputError, PhantomPinError

#: Milliseconds of the page's (virtual) clock before the screenshot: the viewer's scene commands
#: run in order within it.
VIRTUAL_TIME_MS = 2000
#: Seconds before a chromium run is given up.
TIMEOUT_S = 120


def chromium_command(html: Path, png: Path, width: int, height: int, profile: Path) -> list[str]:
    """The command line of headless chromium that screenshots ``html`` into ``png`` at
    ``width`` x ``height`` pixels, with ``profile`` as its (throw-away) user-data folder.
    PhantomPinError if chromium is not installed."""
    chromium = shutil.which("chromium")
    if chromium is None:
        raise PhantomPinError("chromium not found: install Debian's chromium (apt-get install chromium)")
    return [chromium, "--headless", "--no-sandbox", "--use-gl=swiftshader", "--enable-unsafe-swiftshader",
            f"--window-size={width},{height}", "--disable-background-networking", "--disable-component-update",
            "--disable-sync", "--no-first-run", "--disable-quic", "--host-resolver-rules=MAP * ~NOTFOUND",
            f"--user-data-dir={profile}", f"--virtual-time-budget={VIRTUAL_TIME_MS}", f"--screenshot={png}",
            html.resolve().as_uri()]


def screenshot(html: Path | str, png: Path | str, *, width: int = 800, height: int = 600,
               force: bool = False) -> Path:
    """Render the page ``html`` (a file) to ``png`` (width x height pixels) with headless
    chromium; an existing ``png`` is kept unless ``force``, and nothing is written on failure.
    InvalidInputError naming ``html``, ``png``, ``width`` or ``height``; PhantomPinError if
    chromium is missing or fails. Returns the PNG's path."""
    page = Path(html)
    if not page.is_file():
        raise InvalidInputError(f"{page} is not a file", argument="html")
    for name, value in (("width", width), ("height", height)):
        if not (isinstance(value, int) and 16 <= value <= 8192):
            raise InvalidInputError(f"expected a whole number of pixels in [16, 8192], got {value!r}", argument=name)
    output = output_path(png, force, "png")
    with tempfile.TemporaryDirectory() as folder:
        shot = Path(folder) / "shot.png"
        command = chromium_command(page, shot, width, height, Path(folder) / "profile")
        try:
            subprocess.run(command, check=True, capture_output=True, timeout=TIMEOUT_S)
        except (subprocess.CalledProcessError, subprocess.TimeoutExpired) as error:
            raise PhantomPinError(f"chromium failed on {page}: {error}") from error
        if not shot.is_file():
            raise PhantomPinError(f"chromium wrote no screenshot of {page}")
        shutil.copyfile(shot, output)
    return output
