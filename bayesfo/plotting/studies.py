"""Figures of the thesis' Monte Carlo studies (``bayesfo.studies``)."""

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
