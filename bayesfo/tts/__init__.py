"""Time–temperature superposition (master curves) as one joint posterior of a master structure
and the isotherms' shift factors, with the WLF and Arrhenius laws fitted to the shifts."""

from .joint import mastercurve
from .laws import arrhenius, wlf
from .model import ShiftedStructure
from .result import MasterCurve

__all__ = ["MasterCurve", "ShiftedStructure", "arrhenius", "mastercurve", "wlf"]
