"""Moved to :mod:`bayesfo.output.report`; the old name stays an alias for one release."""

import importlib

from .output.report import *  # noqa: F401,F403

_moved = importlib.import_module("bayesfo.output.report")


def __getattr__(name):
    return getattr(_moved, name)
