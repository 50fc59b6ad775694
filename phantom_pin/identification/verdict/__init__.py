"""The identification's last stage, the verdict and its outputs: ``identify`` and its
Identification (result: the report in words, the refusal), the fit as a --params overlay
(overlays) and the HTML page of a fit (page). Imports the earlier stages."""

from phantom_pin.identification.verdict.overlays import gravity_overlay, overlay, stylus_keys
from phantom_pin.identification.verdict.page import report_page
from phantom_pin.identification.verdict.result import Identification, identify

__all__ = ["identify", "Identification", "overlay", "gravity_overlay", "stylus_keys", "report_page"]
