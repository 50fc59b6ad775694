"""check(): a Phantom against the report's closed form, and the closed form against the
appendix's printed torques, at seeded random states inside the joint limits."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from phantom_pin.config.sampling import random_states
from phantom_pin.description.gimbal import arm_only
from phantom_pin.dynamics._refusals import refusal
from phantom_pin.dynamics.phantom import Phantom
from phantom_pin.exceptions import InvalidInputError
from phantom_pin.report import appendix, closed_form
from phantom_pin.report.parameters import ReportParameters

#: States evaluated at a time: memory stays bounded (tens of MB) whatever the count.
CHUNK = 10_000
#: Most states check() evaluates: about 4 minutes at the measured 13 microseconds per state.
MAX_STATES = 20_000_000
#: Relative tolerance of Phantom against the closed form (both exact up to roundoff).
TOLERANCE = 1e-9
#: Phantom's methods compared, with their number of arguments (theta, dtheta, ddtheta).
METHODS = {"forward_kinematics": 1, "spatial_jacobian": 1, "body_jacobian": 1, "mass_matrix": 1,
           "coriolis_matrix": 2, "gravity": 1, "inverse_dynamics": 3}


@dataclass(frozen=True)
class Row:
    """One comparison: its name, its largest error (None where it does not apply) and its tolerance."""

    check: str
    max_error: float | None
    tolerance: float

    @property
    def passed(self) -> bool:
        return self.max_error is None or self.max_error <= self.tolerance


@dataclass(frozen=True)
class Report:
    """What check() found: ``states`` random states of ``seed``, one Row per comparison."""

    states: int
    seed: int
    rows: tuple[Row, ...]

    @property
    def passed(self) -> bool:
        return all(row.passed for row in self.rows)

    def as_dict(self) -> dict:
        return {"states": self.states, "seed": self.seed, "checks": [dataclasses.asdict(r) for r in self.rows],
                "passed": self.passed}


def _checked(phantom: Phantom, states: int) -> tuple[Phantom, ReportParameters]:
    """check's arguments checked (its doc): the Phantom to check (the arm alone of one with a
    stylus gimbal) and its report parameters."""
    if not isinstance(phantom, Phantom):
        raise refusal("Phantom", "a phantom_pin.Phantom", phantom, "phantom")
    if isinstance(states, bool) or not isinstance(states, int | np.integer) or states < 1:
        raise InvalidInputError(f"expected a whole number of states >= 1, got {states!r}", argument="states")
    if states > MAX_STATES:
        raise InvalidInputError(f"{states} states is more than {MAX_STATES:.0e} (about 4 minutes); check fewer",
                                argument="states")
    p = phantom.config.report
    if p is None:
        given = (" with the --params/--set overrides (links in full, as identify's general overlay writes them)"
                 if phantom.config.overridden else "")
        raise InvalidInputError(f"the model {phantom.config.name}{given} is not written in the report's terms, "
                                "so the closed form does not apply (tests/config/test_cad_model.py checks a model in "
                                "full against an independent derivation)", argument="phantom")
    if phantom.config.gimbal is not None:  # the report's arm has no stylus: check the arm alone
        phantom = Phantom(arm_only(phantom.description))
    return phantom, p


def check(phantom: Phantom, states: int = 1000, seed: int = 0,
          progress: Callable[[float], None] | None = None) -> Report:
    """Compare ``phantom`` with the report's closed form at ``states`` random states (seed
    ``seed``) inside its joint limits, CHUNK at a time: the largest error of each method
    relative to the closed form's largest value (tolerance TOLERANCE); and, where the
    parameters are the report's, the closed form against the appendix's printed Tau1-Tau3
    (error over the printed rounding, tolerance 1). ``progress(done)`` gets the states done.
    A model with a stylus gimbal (the Touch) is checked without it (description.gimbal.arm_only):
    the report has none; tests/description/test_gimbal.py checks the gimbal's load against its own laws.

    Raises InvalidInputError naming ``states`` outside 1..MAX_STATES, and naming ``phantom``
    for anything but a Phantom (a model name: check(Phantom.from_model(model))) or a model not
    written in the report's terms (no closed form applies).
    """
    phantom, p = _checked(phantom, states)
    worst = {name: [0.0, 0.0] for name in METHODS}  # max |ours - reference|, max |reference|
    applies = appendix.applies(p)
    as_appendix = dataclasses.replace(p, Iayy=appendix.APPENDIX_IAYY)
    excess = 0.0
    generator = np.random.default_rng(seed)
    for start in range(0, states, CHUNK):
        if progress is not None:
            progress(start)
        batch = random_states(phantom.config.limits, min(CHUNK, states - start), generator)
        for name, count in METHODS.items():
            ours = getattr(phantom, name)(*batch[:count])
            reference = getattr(closed_form, name)(*batch[:count], p)
            worst[name][0] = max(worst[name][0], float(np.abs(ours - reference).max()))
            worst[name][1] = max(worst[name][1], float(np.abs(reference).max()))
        if applies:
            printed, bound = appendix.torques(*batch)
            excess = max(excess, float((np.abs(closed_form.inverse_dynamics(*batch, as_appendix)
                                                - printed) / bound).max()))
    rows = [Row(f"Phantom.{name} vs closed form (relative)", error / (scale or 1.0), TOLERANCE)
            for name, (error, scale) in worst.items()]
    rows.append(Row("closed form vs appendix Tau1-3 (error / printed rounding)", excess if applies else None, 1.0))
    return Report(states, seed, tuple(rows))
