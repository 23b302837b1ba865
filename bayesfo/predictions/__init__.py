"""What follows from a compared model: its posterior draws (:class:`Draws`, which a comparison
and a master curve give alike), material functions with credible bands, and averages
over structures (:func:`predict`), the long-time modulus (:func:`long_time_modulus`), and
Prony series for finite-element codes (:func:`prony_series`)."""

from .draws import Draws
from .functions import AVERAGES, QUANTITIES, Prediction, evaluate, predict
from .long_time import equilibrium_modulus, long_time_modulus
from .prony import FORMATS, Prony, prony_series

__all__ = ["AVERAGES", "Draws", "FORMATS", "QUANTITIES", "Prediction", "Prony", "equilibrium_modulus",
           "evaluate", "long_time_modulus", "predict", "prony_series"]
