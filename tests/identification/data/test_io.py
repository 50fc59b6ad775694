"""identification.io's CSV files: written, the bytes np.savetxt writes; read, in every dialect it
takes, the numbers Python's float() reads from the text, bit for bit, whichever way it parses them
(NumPy at once, or line by line where a value is quoted); a bad line is named."""

import numpy as np
import pytest

from phantom_pin.exceptions import LogError
from phantom_pin.identification.data import io

HEADER = "t,theta1,theta2,theta3,tau1,tau2,tau3"


def _table(rng: np.random.Generator) -> np.ndarray:
    return np.column_stack([np.arange(3000) / 1000, rng.normal(0, 0.5, (3000, 3)), rng.normal(0, 0.1, (3000, 3))])


@pytest.mark.parametrize("dialect", ["plain", "spaces", "semicolons", "quoted"])
def test_every_dialect_reads_the_numbers_pythons_float_reads(tmp_path, dialect):
    table = _table(np.random.default_rng(3))
    texts = [[f"{v:.17g}" for v in row] for row in table]
    separator = ";" if dialect == "semicolons" else ","
    if dialect == "spaces":
        texts = [[f" {v} " for v in row] for row in texts]
    if dialect == "quoted":
        texts = [[f'"{v}"' for v in row] for row in texts]
    path = tmp_path / "log.csv"
    path.write_text("\n".join([HEADER.replace(",", separator)] + [separator.join(row) for row in texts]) + "\n")
    log = io.read_log(path)
    expected = np.array([[float(v.strip().strip('"')) for v in row] for row in texts])
    assert np.array_equal(np.column_stack([log.t, log.theta, log.tau]), expected)


@pytest.mark.parametrize("bad, message", [("1,2", "line 4 has 2 values, the header 7"),
                                          ("0.002,0,0,0,0,0,x", "line 4 holds a value that is not a number"),
                                          ("0.002,0,0,0,0,,0", "line 4 holds a value that is not a number")])
def test_a_bad_line_is_named(tmp_path, bad, message):
    path = tmp_path / "log.csv"
    path.write_text(f"{HEADER}\n0,0,0,0,0,0,0\n0.001,0,0,0,0,0,0\n{bad}\n0.003,0,0,0,0,0,0\n")
    with pytest.raises(LogError, match=message):
        io.read_log(path)


@pytest.mark.parametrize("shape", [(25001, 7), (5, 1), (7,), (0, 7)])
def test_a_written_csv_is_what_numpys_savetxt_writes_byte_for_byte(tmp_path, shape):
    """io.write_csv against np.savetxt(fmt="%.17g") itself, on seeded numbers of every size
    (subnormal, 1e300, -0.0, integers; more rows than one chunk): the same bytes, header
    included, and no header line for no columns, as savetxt."""
    rng = np.random.default_rng(4)
    table = rng.normal(size=shape) * 10.0 ** rng.integers(-310, 300, shape)
    if table.size:
        table.flat[: min(3, table.size)] = [-0.0, 3.0, 5e-324][: min(3, table.size)]
    columns = tuple(f"c{k}" for k in range(shape[1] if len(shape) == 2 else 1))
    io.write_csv(tmp_path / "ours.csv", columns, table)
    np.savetxt(tmp_path / "numpy.csv", table, delimiter=",", header=",".join(columns), comments="", fmt="%.17g")
    assert (tmp_path / "ours.csv").read_bytes() == (tmp_path / "numpy.csv").read_bytes()
    io.write_csv(tmp_path / "bare.csv", (), table)
    np.savetxt(tmp_path / "bare_numpy.csv", table, delimiter=",", comments="", fmt="%.17g")
    assert (tmp_path / "bare.csv").read_bytes() == (tmp_path / "bare_numpy.csv").read_bytes()
