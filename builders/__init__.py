"""clearance.builders: the mechanism catalogue. Builders return pure-data `Mechanism`s.

This package never imports MuJoCo.
"""

from clearance.builders.slider_crank import SLIDER_CRANK_JOINTS, rpm, slider_crank

__all__ = ["slider_crank", "SLIDER_CRANK_JOINTS", "rpm"]
