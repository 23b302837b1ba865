"""``python -m bayesfo.cli``: the command line."""

from . import script

script()
