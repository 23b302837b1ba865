"""Moved to :mod:`bayesfo.timeseries.records`; the old name stays an alias for one release."""

from .timeseries import records as _moved
from .timeseries.records import *  # noqa: F401,F403


def __getattr__(name):
    return getattr(_moved, name)
