"""The compiled libraries of a command, imported with Ctrl-C and SIGTERM held."""

from __future__ import annotations

import gc

from .._signals import held


def load_libraries(formats=()) -> None:
    """Import the compiled libraries that a comparison uses (with those that draw figures in
    ``formats``), with signals held: a Ctrl-C
    during the imports ends the command after them, cleanly, instead of breaking one.

    The objects that exist by then (the modules' functions, classes and tables, the data
    read) live as long as the command: they are frozen out of the garbage collector
    (:func:`gc.freeze`), whose full collections would otherwise walk them again and again in
    this process and in the worker processes forked from it (BENCHMARKS.md, "The libraries
    frozen out of the collector"). :func:`bayesfo.cli.main` puts them back when the command returns."""
    with held():
        from ..output.write import preload

        preload(formats)
    gc.freeze()
