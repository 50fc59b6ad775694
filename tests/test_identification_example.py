"""examples/identify_simulated.py runs headless, writes its figure, and the identified model
predicts the held-out measured torques far better than the report's parameters."""

from test_examples import figure, number, run


def test_identify_simulated_example(tmp_path):
    result = run("identify_simulated.py", tmp_path)
    assert result.returncode == 0, result.stderr
    figure(tmp_path / "identify_simulated.png")
    identified = number(r"identified (\S+) %", result.stdout)
    report = number(r"report (\S+) %,?\s*$", result.stdout.splitlines()[-2])
    assert identified < 5 and report > 3 * identified
