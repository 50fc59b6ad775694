"""The identification's third stage, fitting: the log filtered (filtering), weighted least
squares (least_squares), instrumental variables (instruments), what is chosen from the log
(selection), the refusals (checks), the held-out prediction (prediction), the estimate and its
Fit (estimation, fit), gravity from rest postures (static) and the excitation that a fit needs
(excitation). Imports the data and structure stages at most."""

from phantom_pin.identification.fitting.checks import RefusedError, refusal
from phantom_pin.identification.fitting.estimation import Fit, estimate
from phantom_pin.identification.fitting.excitation import Excitation, continuous_effort, optimise
from phantom_pin.identification.fitting.filtering import CUTOFF
from phantom_pin.identification.fitting.selection import MIN_SPEEDS
from phantom_pin.identification.fitting.static import Gravity, Rest, estimate_gravity, rest_of

__all__ = ["estimate", "Fit", "CUTOFF", "MIN_SPEEDS", "RefusedError", "refusal", "optimise", "Excitation",
           "continuous_effort", "Rest", "Gravity", "rest_of", "estimate_gravity"]
