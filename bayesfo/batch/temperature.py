"""Moved to :mod:`bayesfo.data.temperature`; the old name stays an alias for one release."""

import importlib

from ..data.temperature import *  # noqa: F401,F403

_moved = importlib.import_module("bayesfo.data.temperature")


def __getattr__(name):
    return getattr(_moved, name)
