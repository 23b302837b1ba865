"""Moved to :mod:`bayesfo.structures.response`; the old name stays an alias for one release."""

import importlib

from .structures.response import *  # noqa: F401,F403

_moved = importlib.import_module("bayesfo.structures.response")


def __getattr__(name):
    return getattr(_moved, name)
