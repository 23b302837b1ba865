"""Moved to :mod:`bayesfo.output.report`; the old name stays an alias for one release."""

from .output import report as _moved
from .output.report import *  # noqa: F401,F403


def __getattr__(name):
    return getattr(_moved, name)
