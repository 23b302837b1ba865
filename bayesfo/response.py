"""Moved to :mod:`bayesfo.structures.response`; the old name stays an alias for one release."""

from .structures import response as _moved
from .structures.response import *  # noqa: F401,F403


def __getattr__(name):
    return getattr(_moved, name)
