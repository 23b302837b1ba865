"""Moved to :mod:`bayesfo.timeseries.records`; the old name stays an alias for one release."""

import importlib

from .timeseries.records import *  # noqa: F401,F403

_moved = importlib.import_module("bayesfo.timeseries.records")


def __getattr__(name):
    return getattr(_moved, name)
