"""Moved to :mod:`bayesfo.timeseries.sine`; the old name stays an alias for one release."""

import importlib

from .timeseries.sine import *  # noqa: F401,F403

_moved = importlib.import_module("bayesfo.timeseries.sine")


def __getattr__(name):
    return getattr(_moved, name)
