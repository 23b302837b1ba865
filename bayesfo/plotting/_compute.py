"""The numbers behind the figures, without matplotlib: posterior response bands, densities of
the fractional order, sampling coordinates.

Kept apart from the drawing code (as corner.py separates its computation from its wrapper) so
that tests can recompute what a figure shows and compare it with what was drawn.
"""

from __future__ import annotations

import math

import numpy as np

from ..comparison.table import ORDER_SYMBOLS
from ..comparison.table import order_parameter as from_names
from ..data.symbols import in_symbol, parameter_label
from ..errors import InputError
from ..structures.physical import in_brackets, physical_parameters, physical_units

#: The ranking figure draws at most this many structures (the best by the ranking); the rest
#: are named in a note under it (the report's table and ranking.csv hold every one).
RANKING_SHOWN = 12
#: The order figure draws the orders of at most this many structures (the best by the ranking
#: among those with a free order); the rest are named under it.
ORDER_STRUCTURES = 8

#: Upper bound on the posterior draws pushed through the model for bands.
N_DRAWS = 400
#: Points of the dense frequency grid of response curves.
N_GRID = 300
#: Structures drawn by default in the response figures (the best ones by the ranking).
DEFAULT_N_STRUCTURES = 3
#: Quantiles of the bands: 90 % (5–95 %) and 50 % (25–75 %) central intervals and the median.
BAND_PROBS = (0.05, 0.25, 0.5, 0.75, 0.95)


def ok_results(comparison) -> list:
    """Results with a posterior (neither failed nor left out by the evidence bound), in the
    order of the ranking."""
    by_name = {r.name: r for r in comparison.results
               if r.error is None and getattr(r, "posterior", True) is not None}
    return [by_name[n] for n in comparison.ranking if n in by_name]


def select_results(comparison, structures, default_n: int | None = DEFAULT_N_STRUCTURES) -> list:
    """The results to draw: the given names (or results), else the best ``default_n`` by the
    ranking (every structure for ``None``).

    Raises
    ------
    InputError
        If a name is not in the comparison or names a structure that failed.
    """
    ranked = ok_results(comparison)
    if structures is None:
        return ranked if default_n is None else ranked[:default_n]
    if isinstance(structures, str):
        structures = [structures]
    names = [getattr(s, "name", s) for s in structures]
    known = {r.name: r for r in comparison.results}
    out = []
    for n in names:
        if n not in known:
            raise InputError(
                f"argument 'structures': no structure '{n}' in the comparison; it has "
                + ", ".join(known)
            )
        if known[n].error is not None:
            raise InputError(f"argument 'structures': structure '{n}' failed: {known[n].error}")
        if getattr(known[n], "posterior", True) is None:
            raise InputError(f"argument 'structures': structure '{n}' was not sampled (its best "
                             "fit bounds its ln Z far below the leader's); compare with "
                             "sample='all' to draw it")
        out.append(known[n])
    if not out:
        raise InputError("argument 'structures' is empty")
    return out


def thin_indices(n_total: int, n_draws: int = N_DRAWS, seed: int = 0) -> np.ndarray:
    """Sorted indices of at most ``n_draws`` of ``n_total`` draws, without replacement."""
    if n_draws < 1:
        raise InputError(f"argument 'n_draws' must be at least 1, got {n_draws}")
    if n_total <= n_draws:
        return np.arange(n_total)
    rng = np.random.default_rng(seed)
    return np.sort(rng.choice(n_total, size=n_draws, replace=False))


def structure_draws(result, n_draws: int = N_DRAWS, seed: int = 0) -> np.ndarray:
    """Posterior draws of the structure parameters (physical units, noise columns dropped),
    thinned to at most ``n_draws`` with a seeded generator: shape (n, n_params)."""
    samples = result.posterior.samples[:, : result.structure.n_params]
    return samples[thin_indices(samples.shape[0], n_draws, seed)]


def response_draws(result, omega, kind: str, n_draws: int = N_DRAWS, seed: int = 0) -> np.ndarray:
    """The model response of thinned posterior draws at ``omega``: shape (n, n_freq), complex."""
    theta = structure_draws(result, n_draws, seed)
    return np.asarray(result.structure.response(theta, np.asarray(omega, float), kind))


def omega_grid(comparison, n: int = N_GRID) -> np.ndarray:
    """Log-spaced angular frequencies [rad/s] from the lowest to the highest measured one
    (fitted and held-out points)."""
    w = np.asarray(comparison.data.omega, float)
    if comparison.holdout is not None:
        w = np.concatenate([w, comparison.holdout.omega])
    return np.logspace(math.log10(w.min()), math.log10(w.max()), n)


def unwrapped_phase_deg(g: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Phase [deg] of ``g`` (..., n_freq), unwrapped along increasing ω and shifted by whole
    turns so that the phase at the lowest frequency lies in (−180, 180]."""
    order = np.argsort(omega)
    phase = np.unwrap(np.angle(np.asarray(g)[..., order]), axis=-1)
    first = phase[..., :1]
    phase = phase - 2 * np.pi * np.round((first - np.angle(np.exp(1j * first))) / (2 * np.pi))
    out = np.empty_like(phase)
    out[..., order] = phase
    return np.degrees(out)


def quantiles(values: np.ndarray, probs=BAND_PROBS) -> dict[float, np.ndarray]:
    """``{p: pointwise p-quantile over draws (axis 0)}``."""
    q = np.quantile(values, probs, axis=0)
    return {p: q[i] for i, p in enumerate(probs)}


def order_parameter(result) -> str | None:
    """Name of the free fractional order of a structure
    (:func:`bayesfo.comparison.table.order_parameter`), else None."""
    post = result.posterior
    return from_names(post.param_names if post is not None else result.structure.param_names)


def prior_density(prior: dict, x: np.ndarray) -> np.ndarray:
    """Density of a prior given as its ``to_dict()`` form at ``x``."""
    x = np.asarray(x, float)
    kind = prior.get("prior")
    if kind == "uniform":
        lo, hi = prior["low"], prior["high"]
        return np.where((x >= lo) & (x <= hi), 1.0 / (hi - lo), 0.0)
    if kind == "log-uniform":
        lo, hi = prior["low"], prior["high"]
        inside = (x >= lo) & (x <= hi)
        return np.where(inside, 1.0 / (np.where(inside, x, 1.0) * math.log(hi / lo)), 0.0)
    if kind == "normal":
        mu, sd = prior["mu"], prior["sd"]
        return np.exp(-0.5 * ((x - mu) / sd) ** 2) / (sd * math.sqrt(2 * math.pi))
    raise InputError(f"unknown prior type {kind!r}")


def prior_range(prior: dict, samples: np.ndarray) -> tuple[float, float]:
    """The prior's bounds, or for an unbounded prior the draws' range padded by 10 %."""
    if "low" in prior and "high" in prior:
        return float(prior["low"]), float(prior["high"])
    lo, hi = float(np.min(samples)), float(np.max(samples))
    pad = 0.1 * (hi - lo) if hi > lo else 1.0
    return lo - pad, hi + pad


#: Bandwidths beyond the outermost draws where :func:`density_1d` takes a kernel density as 0.
KDE_REACH = 10.0


def density_1d(samples: np.ndarray, lo: float, hi: float, n_grid: int = 400):
    """Kernel density of ``samples`` on [lo, hi], reflected at both ends so that it integrates
    to one over the interval.

    The grid combines an even grid over [lo, hi] with a fine one over the draws (±4 bandwidths),
    so that a sharply determined order is resolved as well as a broad one. Draws that are all
    equal give a narrow triangle of unit area.

    Returns
    -------
    grid, density : ndarray
    """
    from scipy import stats

    x = np.asarray(samples, float)
    if x.size == 0:
        raise InputError("a density needs at least one draw")
    if np.ptp(x) <= 0:
        # All draws equal (a parameter pinned by its constraints): a narrow triangle of unit
        # area instead of a kernel density, which needs spread.
        c, h = float(x[0]), 1e-3 * (hi - lo)
        grid = np.unique(np.clip(np.r_[np.linspace(lo, hi, n_grid), c - h, c, c + h], lo, hi))
        return grid, np.maximum(0.0, 1.0 - np.abs(grid - c) / h) / h
    kde = stats.gaussian_kde(x)
    bw = float(np.sqrt(kde.covariance[0, 0]))
    fine = np.linspace(max(lo, x.min() - 4 * bw), min(hi, x.max() + 4 * bw), n_grid)
    grid = np.unique(np.concatenate([np.linspace(lo, hi, n_grid), fine]))
    # Reflection keeps the mass that a kernel puts beyond a hard prior bound. Points farther
    # than KDE_REACH bandwidths from every draw get 0: each kernel is below exp(-50) of its
    # peak there. A narrow posterior on a wide prior leaves most of the even grid and of its
    # reflections there, whose kernel sums are then skipped.
    points = np.concatenate([grid, 2 * lo - grid, 2 * hi - grid])
    near = (points >= x.min() - KDE_REACH * bw) & (points <= x.max() + KDE_REACH * bw)
    values = np.zeros(points.size)
    if near.any():
        values[near] = kde(points[near])
    dens = values.reshape(3, grid.size).sum(axis=0)
    return grid, dens


def sampling_coordinates(result):
    """Posterior draws in the coordinates of the summaries: log10 of parameters with a
    log-uniform prior, the parameter itself otherwise.

    Returns
    -------
    values : ndarray, shape (n_draws, ndim)
    labels : list of str
        Mathtext labels with the unit of each parameter where it has one
        (``log$_{10}$ $b_{0}$ [1/Pa]`` for log coordinates, :func:`result_units`).
    is_log : ndarray of bool
    """
    post = result.posterior
    priors = result.criteria.priors or {}
    is_log = np.array([priors.get(n, {}).get("prior") == "log-uniform" for n in post.param_names])
    values = to_coordinates(post.samples, is_log)
    units = result_units(result)
    symbol = result_symbol(result)
    labels = [_label(n, log, units.get(n, ""), symbol) for n, log in zip(post.param_names, is_log)]
    return values, labels, is_log


class Coordinates:
    """The parameters that the figures of one structure draw, and how to get them from the
    sampled parameters (:func:`natural_coordinates`).

    Attributes
    ----------
    names : list of str
        The parameters drawn, in order.
    labels : list of str
        Mathtext labels with units (``log$_{10}$`` where the axis is logarithmic).
    is_log : ndarray of bool
        Whether each is drawn as log10.
    physical : bool
        Whether they are the structure's physical parameters (else the card's, as sampled).
    """

    def __init__(self, names, labels, is_log, convert, physical: bool):
        self.names, self.labels, self.is_log = list(names), list(labels), np.asarray(is_log)
        self._convert, self.physical = convert, physical

    def values(self, theta) -> np.ndarray:
        """Rows of sampled parameters (``posterior.param_names`` order; physical units) as
        rows of the drawn parameters, in their units (not yet log10); NaN where a row has
        none (e.g. the noise of a least-squares fit)."""
        theta = np.atleast_2d(np.asarray(theta, float))
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            return self._convert(theta)

    def coordinates(self, theta) -> np.ndarray:
        """:meth:`values` in the drawn coordinates (log10 where :attr:`is_log`; NaN, not
        drawn, for a value that is not positive there, e.g. an inadmissible linear fit)."""
        values = self.values(theta)
        if self.physical:
            values = np.where(self.is_log & ~(values > 0), np.nan, values)
        return to_coordinates(values, self.is_log)


def natural_coordinates(result) -> Coordinates:
    """The parameters that a structure's corner and trace figures draw: in the form natural to
    the data, as the report's tables and the verdict name them. For modulus data and a
    structure with a physical picture, its physical parameters (moduli, quasi-properties and
    orders, e.g. G_e, c_q, q of the fractional Voigt, named E_e for tensile data; not the
    derived times), each positive one on a log10 axis; otherwise the card's parameters as sampled
    (:func:`sampling_coordinates`). The noise parameters follow, as sampled."""
    post = result.posterior
    s = result.structure
    phys = getattr(result, "physical", None)
    if phys is None or phys.get("natural_form") != "physical":
        _, labels, is_log = sampling_coordinates(result)
        return Coordinates(post.param_names, labels, is_log, lambda theta: theta, False)
    kind, unit = result.data_kind, result.data_units
    units = physical_units(s, kind, unit, derived=False)
    k = s.n_params
    noise = [n for n in post.param_names if n not in s.param_names]
    at = [post.param_names.index(n) for n in s.param_names]
    at_noise = [post.param_names.index(n) for n in noise]

    def convert(theta):
        vals = physical_parameters(s, theta[:, at], kind, unit, derived=False)
        return np.column_stack([vals[n][0] for n in units] + [theta[:, i] for i in at_noise])

    draws = convert(np.asarray(post.samples, float)) if k else np.empty((0, 0))
    priors = result.criteria.priors or {}
    orders = set(s.exponent_params) | set(ORDER_SYMBOLS)
    is_log = [n not in orders and bool(np.all(draws[:, i] > 0)) for i, n in enumerate(units)]
    is_log += [priors.get(n, {}).get("prior") == "log-uniform" for n in noise]
    sampled_units = result_units(result)
    symbol = result_symbol(result)
    labels = ([_label(n, log, u, symbol) for (n, u), log in zip(units.items(), is_log)]
              + [_label(n, log, sampled_units.get(n, ""), symbol)
                 for n, log in zip(noise, is_log[len(units):])])
    return Coordinates([*units, *noise], labels, is_log, convert, True)


def result_symbol(result) -> str:
    """The letter of the measured quantity of the data a result was run on
    (:attr:`bayesfo.comparison.StructureResult.data_symbol`; ``"G"`` when it does not say)."""
    symbol = getattr(result, "data_symbol", "G")
    return symbol if isinstance(symbol, str) else "G"


def result_units(result) -> dict[str, str]:
    """``{parameter: unit}`` of a result's sampled parameters, from the kind and unit of the
    data it was run on (:attr:`bayesfo.comparison.StructureResult.units`); empty when the
    result does not know them."""
    units = getattr(result, "units", None)
    return dict(units) if isinstance(units, dict) else {}


GREEK_ORDERS = ("alpha", "beta", "gamma", "delta", "kappa", "nu", "eta", "tau", "sigma")


def unit_mathtext(unit: str) -> str:
    """A unit as mathtext: exponents raised, orders in Greek (``Pa s^q`` → ``Pa s$^{q}$``,
    ``s^(beta-alpha)`` → ``s$^{\\beta-\\alpha}$``); a ``$`` of the unit itself is escaped.

    Examples
    --------
    >>> unit_mathtext("s^q/Pa")
    's$^{q}$/Pa'
    """
    import re

    text = str(unit).replace("$", r"\$")

    def power(match):
        expo = (match.group(1) or match.group(2)).replace("*", "")
        expo = re.sub(r"[A-Za-z_]+", lambda m: "\\" + m.group(0) if m.group(0) in GREEK_ORDERS
                      else m.group(0), expo)
        return f"$^{{{expo}}}$"

    return re.sub(r"\^(?:\(([^()]*)\)|([A-Za-z0-9_.+-]+))", power, text)


def unit_suffix(unit: str) -> str:
    """`` [unit]`` in mathtext, or nothing for a parameter without a unit."""
    return in_brackets(unit_mathtext(unit) if unit else "")


def to_coordinates(theta, is_log) -> np.ndarray:
    """``theta`` (physical units) in the coordinates of :func:`sampling_coordinates`."""
    theta = np.asarray(theta, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(is_log, np.log10(np.abs(theta)), theta)


def decade_exponent(x) -> int:
    """Power of ten to divide ``x`` by for readable tick labels: 0 when the bulk of |x| lies
    between 0.01 and 1000, else the decade of its largest magnitude."""
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if not x.size:
        return 0
    m = float(np.max(np.abs(np.quantile(x, [0.01, 0.99]))))
    if m == 0.0:
        return 0
    e = math.floor(math.log10(m))
    return 0 if -2 <= e <= 2 else e


def scaled_label(label: str, exponent: int) -> str:
    """``label`` with the factor of :func:`decade_exponent` (``b$_{0}$ (×10$^{-5}$)``)."""
    return label if exponent == 0 else f"{label} (×10$^{{{exponent}}}$)"


GREEK = {"alpha": r"\alpha", "beta": r"\beta", "sigma": r"\sigma", "sigma_rel": r"\sigma_{rel}",
         "gamma": r"\gamma", "delta": r"\delta", "kappa": r"\kappa", "eta": r"\eta",
         "tau": r"\tau", "nu": r"\nu"}


def param_symbol(name: str) -> str:
    """Mathtext of a parameter name: ``a1`` → ``$a_{1}$``, ``beta`` → ``$\\beta$``,
    ``c_alpha`` → ``$c_{\\alpha}$``, ``G_e`` → ``$G_{e}$``."""
    if name in GREEK:
        return f"${GREEK[name]}$"
    head, _, sub = name.partition("_")
    if sub and head:
        return f"${GREEK.get(head, head)}_{{{GREEK.get(sub, sub)}}}$"
    head = name.rstrip("0123456789")
    tail = name[len(head):]
    return f"${head}_{{{tail}}}$" if tail and head else f"${name}$"


def _label(name: str, log: bool, unit: str = "", symbol: str = "G") -> str:
    """The axis label of a parameter: its name in the letters of data measured as ``symbol``
    (``G_e`` → ``$E_{e}$`` for tensile data), log10 where drawn so, and its unit."""
    sym = param_symbol(parameter_label(name, symbol))
    return (f"log$_{{10}}$ {sym}" if log else sym) + unit_suffix(in_symbol(unit, symbol))


#: Two curves that differ by less than this fraction of their axis' span at every point are
#: drawn within a line width of each other (a 1.2 pt line on an axes of about 150 pt).
COINCIDE_FRACTION = 0.008


def coincident_groups(curves: dict, span: float, fraction: float = COINCIDE_FRACTION
                      ) -> list[list[str]]:
    """Groups (of two or more names, in the order given) of curves that coincide on a figure.

    Parameters
    ----------
    curves : dict of str to ndarray
        The curves in the plotted coordinates (log10 for a logarithmic axis), all of one shape;
        complex values are points of a plane with equal axes.
    span : float
        The span of the axis (or the larger span of the two equal axes), in the same coordinates.
    fraction : float
        Curves closer than ``fraction * span`` at every point coincide.

    Returns
    -------
    list of list of str

    Examples
    --------
    >>> coincident_groups({"a": np.zeros(3), "b": np.full(3, 1e-3), "c": np.ones(3)}, 1.0)
    [['a', 'b']]
    """
    tol = fraction * float(span) if np.isfinite(span) and span > 0 else 0.0
    groups: list[list[str]] = []
    for name, y in curves.items():
        y = np.asarray(y)
        for g in groups:
            ref = np.asarray(curves[g[0]])
            if ref.shape == y.shape and bool(np.all(np.abs(y - ref) <= tol)):
                g.append(name)
                break
        else:
            groups.append([name])
    return [g for g in groups if len(g) > 1]


def legend_name(result) -> str:
    """A structure's name in a legend, marked where the posterior predictive checks reject it
    (``"maxwell (misfits)"``; ``"(small misfit)"`` within 2° and 3.5 %; ``"(misfit hidden by
    noise)"`` where a pass rests on points its fitted noise swamps), so that a curve in a Bode,
    Nyquist or residual figure is not read as a description of the data it fails."""
    fits = getattr(result, "fits", None)
    return result.name + {"no": " (misfits)", "small": " (small misfit)",
                          "partly": " (misfit hidden by noise)"}.get(fits, "")


def join_names(names) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    names = list(names)
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def coincidence_note(groups_by_panel: dict) -> str:
    """One sentence naming the structures whose curves coincide: ``{panel: groups}`` from
    :func:`coincident_groups`; a group is named once, with the panels where it coincides unless
    it coincides in all of them. Empty when nothing coincides."""
    panels = list(groups_by_panel)
    where: dict[tuple, list[str]] = {}
    for panel, groups in groups_by_panel.items():
        for g in groups:
            where.setdefault(tuple(g), []).append(panel)
    parts = []
    for g, ps in where.items():
        text = f"{join_names(g)} coincide"
        if len(ps) < len(panels):
            text += " in " + join_names(ps)
        parts.append(text)
    return "; ".join(parts)


#: Above this many decades of |G| the Nyquist diagram is drawn with a logarithmic radius.
NYQUIST_LOG_DECADES = 2.0


def magnitude_decades(*responses) -> float:
    """Decades spanned by the nonzero |G| of the given responses (0 for none)."""
    mags = np.concatenate([np.abs(np.asarray(g)).ravel() for g in responses if g is not None])
    mags = mags[np.isfinite(mags) & (mags > 0)]
    if mags.size == 0:
        return 0.0
    return float(np.log10(mags.max() / mags.min()))
