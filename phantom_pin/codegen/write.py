"""Writing a generated header: never over an existing file without ``force``, nothing on failure."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from phantom_pin._validation import output_path


def write_header(text: str, path: str | Path, force: bool = False, name: str = "path",
                 force_hint: str = "force=True") -> Path:
    """Write ``text`` to ``path`` atomically (a temporary file in the same folder, then a
    rename): InvalidInputError naming ``name`` if ``path`` is a folder, its folder does not
    exist, or it exists and not ``force``. Returns the Path written."""
    output = output_path(path, force, name, force_hint)
    handle, temporary = tempfile.mkstemp(dir=output.parent, prefix=f".{output.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as stream:
            stream.write(text)
        os.replace(temporary, output)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return output
