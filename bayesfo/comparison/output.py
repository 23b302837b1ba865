"""Moved to :mod:`bayesfo.output.write`; the old name stays an alias for one release (resolved
on first use, so that ``comparison`` imports nothing of the output layer)."""


def __getattr__(name):
    import importlib

    return getattr(importlib.import_module("bayesfo.output.write"), name)
