"""Time–temperature superposition (master curves) as one joint posterior of a master structure
and the isotherms' shift factors, with the WLF and Arrhenius laws fitted to the shifts."""

from .joint import MasterCurve, ShiftedStructure, mastercurve
from .laws import arrhenius, wlf

__all__ = ["MasterCurve", "ShiftedStructure", "arrhenius", "mastercurve", "wlf"]
