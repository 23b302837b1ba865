"""What follows from a compared model: material functions with credible bands, and averages
over structures (:func:`predict`)."""

from .functions import AVERAGES, QUANTITIES, Prediction, evaluate, predict

__all__ = ["AVERAGES", "QUANTITIES", "Prediction", "evaluate", "predict"]
