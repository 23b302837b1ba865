"""What follows from a compared model: material functions with credible bands, and averages
over structures (:func:`predict`), and Prony series for finite-element codes
(:func:`prony_series`)."""

from .functions import AVERAGES, QUANTITIES, Prediction, evaluate, predict
from .prony import FORMATS, Prony, prony_series

__all__ = ["AVERAGES", "FORMATS", "QUANTITIES", "Prediction", "Prony", "evaluate", "predict",
           "prony_series"]
