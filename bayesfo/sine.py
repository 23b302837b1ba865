"""Moved to :mod:`bayesfo.timeseries.sine`; the old name stays an alias for one release."""

from .timeseries import sine as _moved
from .timeseries.sine import *  # noqa: F401,F403


def __getattr__(name):
    return getattr(_moved, name)
