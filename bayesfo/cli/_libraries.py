"""The compiled libraries of a command, imported with Ctrl-C and SIGTERM held."""

from __future__ import annotations

from .._signals import held


def load_libraries(formats=()) -> None:
    """Import the compiled libraries that a comparison uses (with those that draw figures in
    ``formats``), with signals held: a Ctrl-C
    during the imports ends the command after them, cleanly, instead of breaking one."""
    with held():
        import emcee  # noqa: F401
        import netCDF4  # noqa: F401
        import scipy.optimize  # noqa: F401
        import scipy.special  # noqa: F401
        import scipy.stats  # noqa: F401

        from ..inference._arviz import preload

        preload()
        if formats:
            from ..plotting.output import preload as preload_plotting

            preload_plotting(formats)
