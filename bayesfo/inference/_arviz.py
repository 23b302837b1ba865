"""arviz, imported without its announcement of a future refactor (a FutureWarning on import)."""

from __future__ import annotations

import warnings


def arviz():
    """The arviz module."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="ArviZ is undergoing", category=FutureWarning)
        import arviz as az
    return az
