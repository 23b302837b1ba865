"""Deterministic identification: least-squares fits that seed the posterior sampler.

``optimize``: multi-start bounded nonlinear least squares of the complex residual on scaled data
(thesis §3.3, Problem 5), for every structure.
"""

from .optimize import FitResult, fit_structure

__all__ = ["FitResult", "fit_structure"]
