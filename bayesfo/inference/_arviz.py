"""The diagnostics and the posterior container, from the ArviZ libraries (arviz-base, arviz-stats).

Draws and everything stored beside them (pointwise log-likelihood, posterior predictive, observed
data, sample statistics) live in an :class:`xarray.DataTree` with ArviZ's groups; the statistics
are arviz-stats' array functions, given plain arrays:

- :func:`rhat_max`, :func:`ess_min`: rank-normalised split R-hat, bulk and tail ESS;
- :func:`hdi`: highest-density interval of a sample;
- :func:`psis`: Pareto-smoothed importance weights and their k̂;
- :func:`loo`, :func:`waic`: the predictive criteria from the pointwise log-likelihood.
"""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np

#: xarray's NetCDF engine: netCDF4 (the netCDF-C library), faster than h5netcdf per
#: posterior, written and read (h5netcdf's cost is per variable; BENCHMARKS.md, "NetCDF files
#: through netCDF-C"); the files are the same NetCDF-4/HDF5 either way.
ENGINE = "netcdf4"

#: The quantiles of the tail ESS (ArviZ's: the 5 % and 95 % quantiles).
TAIL_PROB = (0.05, 0.95)


def _stats():
    from arviz_stats.base import array_stats

    return array_stats


def _by_parameter(chains) -> np.ndarray:
    """(chain, draw, parameter) → (parameter, chain, draw); a 2-D array is one parameter."""
    a = np.asarray(chains, dtype=float)
    return a[None] if a.ndim == 2 else np.moveaxis(a, -1, 0)


def rhat_max(chains) -> float:
    """The largest rank-normalised split R-hat over the parameters of ``chains`` (chain, draw,
    parameter)."""
    return float(np.max(_stats().rhat(_by_parameter(chains))))


def ess_min(chains, method: str = "bulk") -> float:
    """The smallest bulk (``method="bulk"``) or tail (``"tail"``) effective sample size over
    the parameters of ``chains`` (chain, draw, parameter; (chain, draw) for one quantity)."""
    kwargs = {"prob": TAIL_PROB} if method == "tail" else {}
    return float(np.min(_stats().ess(_by_parameter(chains), method=method, **kwargs)))


def ess_draws(x) -> float:
    """Effective size of one sequence of draws of a scalar (one chain)."""
    return ess_min(np.asarray(x, dtype=float).reshape(1, -1))


def hdi(x, prob: float) -> tuple[float, float]:
    """The ``prob`` highest-density interval of the draws ``x`` (one dimension)."""
    lo, hi = _stats().hdi(np.asarray(x, dtype=float), prob)
    return float(lo), float(hi)


def hdi_columns(values, prob: float) -> tuple[np.ndarray, np.ndarray]:
    """The ``prob`` highest-density interval of each column of ``values`` (draws along the
    rows); NaN for a column with a draw that is not finite."""
    values = np.asarray(values, dtype=float)
    lo = np.full(values.shape[1], np.nan)
    hi = np.full(values.shape[1], np.nan)
    ok = np.all(np.isfinite(values), axis=0)
    if ok.any():
        ends = np.asarray(_stats().hdi(values[:, ok], prob, axis=0))
        lo[ok], hi[ok] = ends[..., 0], ends[..., 1]
    return lo, hi


def psis(log_w) -> tuple[np.ndarray, float]:
    """Pareto-smoothed log importance weights (normalised) and the Pareto k̂ of their tail
    (inf where the tail is flat and cannot be fitted: the weights are then not certified)."""
    # arviz-stats smooths the ratios 1/p of a log-likelihood p (leave-one-out): ratios w are
    # passed as the log-likelihood -log w.
    log_w = np.asarray(log_w, dtype=float)
    try:
        smoothed, k_hat = _stats().psislw(-log_w)
    except ValueError:  # a tail of equal weights: nothing to smooth, and no certificate
        from scipy.special import logsumexp

        return log_w - logsumexp(log_w), math.inf
    return np.asarray(smoothed), float(k_hat)


def loo(tree):
    """PSIS-LOO from the ``log_likelihood`` group of ``tree`` (variable ``G``, per frequency):
    arviz-stats' ``ELPDData`` (``elpd``, ``se``, ``pareto_k``, ``elpd_i``); where the tail of
    the importance ratios is flat and no Pareto fit exists, the same fields undefined (NaN, and
    k̂ = inf)."""
    from arviz_stats import loo as _loo

    try:
        return _loo(tree, pointwise=True, var_name="G")
    except ValueError:  # the pointwise log-likelihood's tail is flat (a hopeless misfit)
        n = tree.log_likelihood["G"].shape[-1]
        return SimpleNamespace(elpd=math.nan, se=math.nan, pareto_k=np.full(n, math.inf),
                               elpd_i=np.full(n, math.nan))


def waic(log_lik) -> tuple[float, float]:
    """WAIC (elpd scale) and its standard error from the pointwise log-likelihood, draws along
    every axis but the last (Watanabe 2010; Vehtari, Gelman & Gabry 2017, eq. 11-13)."""
    from scipy.special import logsumexp

    ll = np.asarray(log_lik, dtype=float)
    ll = ll.reshape(-1, ll.shape[-1])
    lppd = logsumexp(ll, axis=0) - np.log(ll.shape[0])
    elpd_i = lppd - ll.var(axis=0)
    return float(elpd_i.sum()), float(np.sqrt(elpd_i.size * elpd_i.var()))


def from_dict(groups: dict, *, coords: dict | None = None, dims: dict | None = None):
    """A DataTree with ArviZ's groups from ``{group: {name: array}}``."""
    from arviz_base import from_dict as _from_dict

    return _from_dict(groups, coords=coords, dims=dims)


def group_names(tree) -> tuple[str, ...]:
    """The groups (child nodes) of a DataTree."""
    return tuple(tree.children)


def open_tree(path: Path, keep: dict | None = None, sizes: dict | None = None,
              max_elements: int | None = None):
    """A DataTree read from a NetCDF file (arviz 1.x or 0.x), loaded into memory and the file
    closed.

    With ``keep`` (``{group: names}``), only those groups and variables are read (what else
    the file holds is never loaded); with ``sizes`` (``{dimension: length or None}``, and
    ``"draws"``: chains × draws), a kept variable along another dimension or of another length
    is refused before it is read, and so is one of more than ``max_elements`` values.

    Raises
    ------
    ValueError
        A variable whose dimensions or size are not those expected (the message names it).
    """
    import xarray as xr

    with xr.open_datatree(path, engine=ENGINE) as tree:
        if keep is None:
            return tree.load()
        groups = {}
        for group, names in keep.items():
            if group not in tree.children:
                continue
            ds = tree[group].to_dataset()
            ds = ds[[n for n in names if n in ds.data_vars]]
            for name, var in ds.variables.items():
                where = f"variable '{group}/{name}'"
                for dim, length in var.sizes.items():
                    if sizes is not None and dim not in sizes:
                        raise ValueError(f"{where} has a dimension '{dim}' that bayesfo does "
                                         "not write")
                    if sizes is not None and sizes[dim] is not None and sizes[dim] != length:
                        raise ValueError(f"{where} has {length} values along '{dim}', where "
                                         f"summary.json says {sizes[dim]}")
                draws = var.sizes.get("chain", 1) * var.sizes.get("draw", 1)
                if (sizes is not None and sizes.get("draws") is not None
                        and {"chain", "draw"} <= set(var.dims) and draws != sizes["draws"]):
                    raise ValueError(f"{where} holds {draws} draws, where summary.json says "
                                     f"{sizes['draws']}")
                if max_elements is not None and var.size > max_elements:
                    raise ValueError(f"{where} has {var.size} values, more than the "
                                     f"{max_elements} bayesfo reads")
            groups[group] = ds.load()
        return xr.DataTree.from_dict(groups)


def external_storage(path: Path) -> str | None:
    """The first dataset of an HDF5 file whose values lie outside it (external or virtual
    storage: reading it would read another file), or None; None also where h5py is not
    installed (then only the variables bayesfo names are read, see :func:`open_tree`)."""
    try:
        import h5py
    except ImportError:
        return None
    found = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and (obj.external or obj.is_virtual):
            found.append(name)
            return True
        return None

    try:
        with h5py.File(path, "r") as f:
            f.visititems(visit)
    except Exception:  # h5py cannot read it (its HDF5 differs from netCDF-C's): not checked
        return None
    return found[0] if found else None


def write_tree(tree, path) -> None:
    """Write a DataTree to NetCDF (HDF5, one group per ArviZ group).

    The file is built in memory (netCDF-C's in-memory file) and then written with plain file
    writes: HDF5 writing to a file system that fills up under it (another process took the
    space after the free-space check of :func:`~bayesfo.inference.results.save_netcdf`)
    crashes the process (segmentation fault) instead of raising, while a plain write raises
    ``OSError`` (``ENOSPC``) that the command reports.
    """
    try:
        import dask
    except ImportError:  # a plain install: xarray writes without a scheduler to ask
        data = tree.to_netcdf(engine=ENGINE)
    else:
        # Inside a Dask worker xarray would take a distributed lock named after the target,
        # which an in-memory file has not; the arrays are in memory, so the local scheduler's
        # lock serves.
        with dask.config.set(scheduler="synchronous"):
            data = tree.to_netcdf(engine=ENGINE)
    with open(path, "wb") as f:
        f.write(data)


def preload() -> None:
    """Import the ArviZ libraries and xarray now, not on first use."""
    import arviz_base  # noqa: F401
    import arviz_stats  # noqa: F401
    import xarray  # noqa: F401
