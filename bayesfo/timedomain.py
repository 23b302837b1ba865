"""Moved to :mod:`bayesfo.timeseries.timedomain`; the old name stays an alias for one release."""

from .timeseries import timedomain as _moved
from .timeseries.timedomain import *  # noqa: F401,F403


def __getattr__(name):
    return getattr(_moved, name)
