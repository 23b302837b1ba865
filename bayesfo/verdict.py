"""Moved to :mod:`bayesfo.output.verdict`; the old name stays an alias for one release."""

import importlib

from .output.verdict import *  # noqa: F401,F403

_moved = importlib.import_module("bayesfo.output.verdict")


def __getattr__(name):
    return getattr(_moved, name)
