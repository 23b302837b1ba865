"""Moved to :mod:`bayesfo.timeseries.timedomain`; the old name stays an alias for one release."""

import importlib

from .timeseries.timedomain import *  # noqa: F401,F403

_moved = importlib.import_module("bayesfo.timeseries.timedomain")


def __getattr__(name):
    return getattr(_moved, name)
