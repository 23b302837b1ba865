"""Where to measure next: the frequencies whose measurement would best settle a comparison's
model choice (:func:`design`, :mod:`bayesfo.planning.choice`) or determine one parameter, or all
of a structure's (:func:`design_parameter`, :mod:`bayesfo.planning.parameter`), which the
command plans where every structure fails the adequacy checks (:func:`all_inadequate`)."""

from .choice import COSTS, DECISIVE, Design, all_inadequate, design, seconds
from .parameter import ParameterDesign, design_parameter

__all__ = ["COSTS", "DECISIVE", "all_inadequate", "Design", "ParameterDesign", "design", "design_parameter",
           "seconds"]
