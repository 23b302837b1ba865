"""Where to measure next: the frequencies whose measurement would best settle a comparison's
model choice (:func:`design`, :mod:`bayesfo.planning.choice`) or determine one parameter
(:func:`design_parameter`, :mod:`bayesfo.planning.parameter`)."""

from .choice import COSTS, DECISIVE, Design, design, seconds
from .parameter import ParameterDesign, design_parameter

__all__ = ["COSTS", "DECISIVE", "Design", "ParameterDesign", "design", "design_parameter",
           "seconds"]
