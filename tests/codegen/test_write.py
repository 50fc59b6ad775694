"""write_header (codegen/write.py): never over a file without force, no temporary left."""

import pytest

from phantom_pin.codegen import write_header
from phantom_pin.exceptions import InvalidInputError


def test_the_writer_never_overwrites_without_force(tmp_path):
    target = tmp_path / "model.h"
    write_header("one", target)
    with pytest.raises(InvalidInputError):
        write_header("two", target)
    assert target.read_text() == "one"
    write_header("two", target, force=True)
    assert target.read_text() == "two"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.h"]  # no temporary left
