"""interfaces.openhaptics.protocol: the command and state layouts against their fields' sizes
(contiguous, covering COMMAND and STATE doubles, packed by Python's struct in native order as the
C side's double arrays), and the record written here with struct read back by read_record, with
its refusals naming ``path``."""

import struct

import numpy as np
import pytest

from phantom_pin import InvalidInputError
from phantom_pin.interfaces.openhaptics import protocol

#: Each field's doubles, as the module's doc gives them.
COMMAND_SIZES = {"FLAG": 1, "FORCE": 3, "TORQUE": 3, "PERIOD": 1, "HAND": 3, "FRAMED": 1}
STATE_SIZES = {"JOINT": 3, "GIMBAL": 3, "POSITION": 3, "VELOCITY": 3, "TRANSFORM": 16}


@pytest.mark.parametrize("layout, sizes, total, extra", [
    (protocol.COMMAND_LAYOUT, COMMAND_SIZES, protocol.COMMAND, 0),
    (protocol.STATE_LAYOUT, STATE_SIZES, protocol.STATE, 1),        # then the plant's failure flag
])
def test_the_layouts_are_contiguous_and_cover_the_records(layout, sizes, total, extra):
    assert list(layout) == list(sizes)
    offset = 0
    for name, size in sizes.items():
        assert layout[name] == offset, name
        offset += size
    assert offset + extra == total
    assert struct.calcsize(f"={total}d") == 8 * total


def test_the_flags_and_the_ready_lines_fields():
    assert (protocol.QUIT, protocol.DISABLED, protocol.ENABLED) == (-1, 0, 1)
    assert len(protocol.INFO_FIELDS) == 13 and len(set(protocol.INFO_FIELDS)) == 13
    assert len(protocol.RECORD_COLUMNS) == 31 and len(set(protocol.RECORD_COLUMNS)) == 31


def test_a_record_written_with_struct_reads_back(tmp_path):
    rows = np.random.default_rng(17).normal(size=(4, len(protocol.RECORD_COLUMNS)))
    path = tmp_path / "record.bin"
    path.write_bytes(protocol.RECORD_HEADER.encode() + b"".join(struct.pack("=31d", *row) for row in rows))
    read = protocol.read_record(path)
    assert list(read) == list(protocol.RECORD_COLUMNS)
    for i, name in enumerate(protocol.RECORD_COLUMNS):
        np.testing.assert_array_equal(read[name], rows[:, i])
    assert read["t"].flags.writeable                     # copies, not views of the bytes
    empty = tmp_path / "empty.bin"
    empty.write_bytes(protocol.RECORD_HEADER.encode())
    assert all(len(column) == 0 for column in protocol.read_record(empty).values())


@pytest.mark.parametrize("content, match", [
    (b"phantom_pin stand-in record: tick\n", "not a stand-in record of this version"),
    (None, "cannot read it"),
    ("truncated", "not a stand-in record of this version"),
])
def test_a_bad_record_is_refused_naming_path(tmp_path, content, match):
    path = tmp_path / "record.bin"
    if content == "truncated":
        content = protocol.RECORD_HEADER.encode() + struct.pack("=31d", *range(31))[:-8]
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(InvalidInputError, match=match) as refused:
        protocol.read_record(path)
    assert refused.value.argument == "path"
