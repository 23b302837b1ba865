"""Moved to :mod:`bayesfo.output.verdict`; the old name stays an alias for one release."""

from .output import verdict as _moved
from .output.verdict import *  # noqa: F401,F403


def __getattr__(name):
    return getattr(_moved, name)
