"""The identification's second stage, the model's structure and regressor: the joint-torque
regressor (regressor), base parameters (base), the report's parameters and constants
(parameterization, constants), physical consistency (physical), the two structures a fit takes
(structures), the prior (prior) and what is computed once per Description (cache). Imports the
data stage at most."""

from phantom_pin.identification.structure.base import base_parameters
from phantom_pin.identification.structure.prior import SPREAD
from phantom_pin.identification.structure.regressor import Regressor
from phantom_pin.identification.structure.structures import STRUCTURES, General, Report, Structure

__all__ = ["Regressor", "base_parameters", "Structure", "General", "Report", "STRUCTURES", "SPREAD"]
