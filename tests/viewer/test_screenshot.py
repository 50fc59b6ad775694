"""screenshot (viewer/screenshot.py): its refusals, before chromium runs, naming the argument; nothing written."""

import pytest

from phantom_pin import InvalidInputError
from phantom_pin.viewer.screenshot import screenshot


def test_screenshot_refuses_bad_arguments_naming_them(tmp_path):
    """Before chromium runs: a page that is no file, a size out of range, an existing PNG without
    force; nothing is written."""
    page, png = tmp_path / "page.html", tmp_path / "page.png"
    page.write_text("<html></html>")
    png.write_bytes(b"kept")
    target = tmp_path / "a.png"
    cases = ((tmp_path / "none.html", target, {}, "html"), (page, target, {"width": 0}, "width"),
             (page, target, {"height": 1.5}, "height"), (page, png, {}, "png"))
    for html, output, options, argument in cases:
        with pytest.raises(InvalidInputError) as error:
            screenshot(html, output, **options)
        assert error.value.argument == argument
    assert png.read_bytes() == b"kept" and not (tmp_path / "a.png").exists()
