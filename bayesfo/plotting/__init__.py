"""Figures. The only part of bayesfo that imports matplotlib.

Plot functions take results (plain dicts or result objects), accept ``ax=``, and return what
they drew.
"""

from __future__ import annotations

import numpy as np


def _axes(ax=None, projection=None):
    import matplotlib.pyplot as plt

    if ax is not None:
        return ax.figure, ax
    fig = plt.figure(figsize=(5.0, 3.8), constrained_layout=True)
    return fig, fig.add_subplot(projection=projection)


def plot_rmse_surface(surface: dict, ax=None):
    """Thesis Figure 3.2: RMSE against G_noise over σ and q, as a colour map of log10 RMSE.

    Parameters
    ----------
    surface : dict
        The result of :func:`bayesfo.studies.rmse_surface`.
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.collections.QuadMesh
        The drawn mesh (its array holds log10 RMSE, shape (n_sigma, n_q)).
    """
    fig, ax = _axes(ax)
    q = np.asarray(surface["q"])
    sigma = np.asarray(surface["sigma"])
    z = np.log10(np.asarray(surface["rmse"]))
    mesh = ax.pcolormesh(q, sigma * 1e3, z, shading="nearest", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label=r"$\log_{10}$ RMSE vs $G_\mathrm{noise}$")
    ax.set_xlabel("commensurate order $q$")
    ax.set_ylabel(r"noise level $\sigma$ [$10^{-3}$]")
    ax.set_title(f"Method {surface['method']}, n = {surface['n']}, m = {surface['m']}")
    return mesh


def save_figure(fig, path) -> None:
    """Save ``fig`` to ``path`` (format from the suffix) through a temporary file."""
    import os
    import tempfile
    from pathlib import Path

    from .._io import publish

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=200)
        publish(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
