"""Material functions of a compared structure, or of an average over structures, with credible
bands from the certified posterior draws.

A card describes a compliance C(s) = J̄*(s) (the Laplace-domain creep compliance times s); the
complex modulus is G*(s) = 1/C(s). From them, for every posterior draw:

- storage and loss modulus G′(ω) = Re G*(iω), G″(ω) = Im G*(iω), loss tangent G″/G′;
- storage and loss compliance J′(ω) = Re C(iω), J″(ω) = −Im C(iω) (J* = J′ − iJ″);
- the magnitude of the complex viscosity |η*|(ω) = |G*(iω)|/ω;
- the relaxation modulus G(t) = L⁻¹[G*(s)/s](t) and the creep compliance J(t) = L⁻¹[C(s)/s](t)
  (:mod:`.laplace`; a flow term t/η or an unbounded G(t) near 0 come out as they are);
- the relaxation and retardation spectra H(τ) = Im G*(e^{iπ}/τ)/π and
  L(τ) = −Im C(e^{iπ}/τ)/π (the Stieltjes inversion of G(t) = G_e + ∫ H e^{−t/τ} d ln τ and
  J(t) = J_g + ∫ L (1 − e^{−t/τ}) d ln τ + t/η): continuous for fractional orders; a structure
  of integer orders has a discrete spectrum (lines at its relaxation times), which this
  continuous density cannot show (it is 0 between the lines).

The band of a quantity at each x is the highest-density interval of its values over the draws
(the posterior of the mean function; measurement noise is not added), the centre line their
median. Averages over structures mix the structures' draws in proportion to their weights: the
posterior model probabilities (Bayesian model averaging, ``"bma"``) or stacking weights on the
pointwise PSIS-LOO (``"stacking"``, arviz-stats).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..data.symbols import in_symbol
from ..errors import InputError
from . import laplace
from .draws import AVERAGES, MAX_DRAWS, Draws  # noqa: F401  (AVERAGES, MAX_DRAWS: named here too)

#: quantity: (the argument it takes, its symbol, the dimension of its values).
QUANTITIES = {
    "storage": ("omega", "G′", "modulus"),
    "loss": ("omega", "G″", "modulus"),
    "tan_delta": ("omega", "tan δ", "none"),
    "storage_compliance": ("omega", "J′", "compliance"),
    "loss_compliance": ("omega", "J″", "compliance"),
    "complex_viscosity": ("omega", "|η*|", "viscosity"),
    "relaxation_modulus": ("time", "G(t)", "modulus"),
    "creep_compliance": ("time", "J(t)", "compliance"),
    "relaxation_spectrum": ("tau", "H(τ)", "modulus"),
    "retardation_spectrum": ("tau", "L(τ)", "compliance"),
}
#: The unit of each kind of argument, and its name.
X_UNITS = {"omega": "rad/s", "time": "s", "tau": "s"}
X_NAMES = {"omega": "omega", "time": "t", "tau": "tau"}
#: Probability of the credible band (the highest-density interval, as everywhere in bayesfo).
BAND = 0.94
#: Draws evaluated at once in the time domain (the contour's nodes multiply the work).
_CHUNK = 250
#: Arguments evaluated at once: they are taken in chunks of this many, so that memory stays
#: bounded whatever their number (``--time 1e-6:1e6:100000``, the command line's largest
#: grid, took 22 GB in one piece; a chunk's contour values are 250 × 200 × 20 complex, 16 MB).
_X_CHUNK = 200
#: Largest number of values (draws × arguments) that a :class:`Prediction` keeps in
#: ``values``; beyond it ``values`` is None and only the band is kept (2000 draws × 100 000
#: times would be 1.6 GB).
MAX_KEPT_VALUES = 20_000_000


@dataclass(frozen=True)
class Prediction:
    """A material function with its credible band.

    Attributes
    ----------
    quantity : str
        One of :data:`QUANTITIES`.
    unit, x_unit : str
    x : ndarray
        Where it was evaluated (angular frequencies in rad/s, times or relaxation times in s).
    median, hdi_low, hdi_high : ndarray
        The median over the draws and the ends of their 94 % highest-density interval, per x.
    extrapolated : ndarray of bool
        Where x lies outside the window the data cover (ω outside [ω_min, ω_max]; t and τ
        outside [1/ω_max, 1/ω_min]); an x equal to an end of the window to rounding is inside.
    structure : str or None
        The structure predicted from; None for an average.
    weights : dict or None
        ``{structure: weight}`` of an average (``average`` says which weights).
    average : str or None
    notes : tuple of str
        What the user should know (an inadequate structure carrying weight, the two
        weightings disagreeing, a discrete spectrum).
    values : ndarray, shape (n_draws, n_x), or None
        The quantity for each draw used; None where they would be more than
        :data:`MAX_KEPT_VALUES` (the band is computed in chunks of the arguments).
    symbol : str
        The quantity's symbol in the letters of the data (E′, E(t), D(t) for tensile data;
        :mod:`bayesfo.data.symbols`).
    window : tuple of float or None
        The ends of that window, in the unit of x.
    temperature : float or None
        [°C] For a master curve: the temperature the function is at (the reference
        temperature unless another was asked for); None for a comparison.
    """

    quantity: str
    unit: str
    x: np.ndarray
    x_unit: str
    median: np.ndarray
    hdi_low: np.ndarray
    hdi_high: np.ndarray
    extrapolated: np.ndarray
    structure: str | None = None
    weights: dict | None = None
    average: str | None = None
    notes: tuple[str, ...] = ()
    values: np.ndarray = field(default=None, repr=False)
    symbol: str = ""
    window: tuple[float, float] | None = None
    temperature: float | None = None

    def __repr__(self) -> str:
        from ..structures.physical import in_brackets

        who = self.structure if self.weights is None else f"{self.average} average"
        x = np.asarray(self.x, float)
        span = f" ({x.min():.4g} to {x.max():.4g} {self.x_unit})" if x.size else ""
        return (f"<Prediction of {self.symbol or QUANTITIES[self.quantity][1]}"
                f"{in_brackets(self.unit)} from {who} at {x.size} points{span}"
                + (f", {int(np.sum(self.extrapolated))} extrapolated"
                   if np.any(self.extrapolated) else "") + ">")

    def _repr_html_(self) -> str:
        from .notebook import prediction_html

        return prediction_html(self)

    def to_dict(self) -> dict:
        """The JSON form (``bayesfo predict --json``): plain lists, NaN as None."""
        def plain(a):
            return [None if not math.isfinite(v) else float(v) for v in np.asarray(a, float)]

        out = {"quantity": self.quantity, "symbol": self.symbol or QUANTITIES[self.quantity][1],
               "unit": self.unit, "x": plain(self.x),
               "x_unit": self.x_unit, "median": plain(self.median),
               "hdi_low": plain(self.hdi_low), "hdi_high": plain(self.hdi_high),
               "extrapolated": [bool(v) for v in self.extrapolated]}
        if self.window is not None:
            out["window"] = [float(v) for v in self.window]
        if self.temperature is not None:
            out["temperature"] = float(self.temperature)
        if self.weights is None:
            out["structure"] = self.structure
        else:
            out["average"] = self.average
            out["weights"] = {k: float(v) for k, v in self.weights.items()}
        out["notes"] = list(self.notes)
        return out


def predict(result, quantity: str, x, *, structure: str | None = None,
            average: str | None = None, seed: int = 0,
            temperature: float | None = None) -> Prediction:
    """A material function of a comparison's structure, or of an average, or of a master
    curve, with its band.

    Parameters
    ----------
    result : Comparison or MasterCurve
        From :func:`bayesfo.compare`, :func:`bayesfo.mastercurve` or :func:`bayesfo.load`, on
        modulus or compliance data.
    quantity : str
        One of :data:`QUANTITIES`: ``storage``, ``loss``, ``tan_delta``,
        ``storage_compliance``, ``loss_compliance``, ``complex_viscosity`` (at angular
        frequencies), ``relaxation_modulus``, ``creep_compliance`` (at times),
        ``relaxation_spectrum``, ``retardation_spectrum`` (at relaxation times).
    x : array_like
        Angular frequencies [rad/s], times [s] or relaxation times [s], all > 0.
    structure : str, optional
        The structure to predict from (default: the best ranked); not with ``average``.
    average : {"bma", "stacking"}, optional
        Average over the ranked structures with posterior model probabilities or stacking
        weights.
    seed : int
        Seeds the choice of draws where a posterior has more than :data:`MAX_DRAWS`, and the
        mixing of an average.
    temperature : float, optional
        [°C] For a master curve: the material function at this temperature instead of the
        reference temperature, G(ω; T) = G_ref(a_T ω)/b_T and G(t; T) = G_ref(t/a_T)/b_T with
        each draw's own shifts (:meth:`~bayesfo.tts.MasterCurve.shifts_at`), so the band
        carries the shifts' uncertainty; within the isotherms' temperatures.

    Returns
    -------
    Prediction

    Raises
    ------
    InputError
        An unknown quantity or structure, x not positive and finite, data that are not a
        modulus or a compliance, an average with nothing to average, or a temperature outside
        a master curve's isotherms (or given for a comparison).

    Examples
    --------
    >>> import bayesfo as bf
    >>> result = bf.compare(bf.read("examples/data/adhesive_468mp/Tp020C.csv"), "voigt,zener")  # doctest: +SKIP
    >>> g_t = bf.predict(result, "relaxation_modulus", [0.01, 0.1, 1.0])  # doctest: +SKIP
    >>> g_t.median, g_t.hdi_low, g_t.hdi_high, g_t.unit  # doctest: +SKIP
    """
    quantity = _check_quantity(quantity)
    domain = QUANTITIES[quantity][0]
    x = _check_x(x, domain)
    data = result.data
    if data.kind not in ("modulus", "compliance"):
        raise InputError(f"predict: the data are a {data.kind} transfer function; material "
                         "functions follow from modulus or compliance data only", where="predict")
    if isinstance(result, Draws):
        if structure is not None or average is not None or temperature is not None:
            raise InputError("predict: draws are of one structure, average and temperature "
                             "already; give those to result.draws(...)", where="predict")
        return _predict(result, quantity, x)
    return _predict(result.draws(structure=structure, average=average, seed=seed,
                                 temperature=temperature), quantity, x)


#: How each kind of quantity scales with the vertical shift b_T and the horizontal a_T
#: (G(ω; T) = G_ref(a_T ω)/b_T): powers of (a_T, b_T).
_SCALING = {"modulus": (0, -1), "compliance": (0, 1), "viscosity": (1, -1), "none": (0, 0)}


def draws_values(draws: Draws, quantity: str, x) -> np.ndarray:
    """``quantity`` at ``x`` (checked, one dimension) for every draw of ``draws``: shape
    (n_draws, n_x). A master curve's draws are each evaluated at their own shifts,
    G(ω; T) = G_ref(a_T ω)/b_T and G(t; T) = G_ref(t/a_T)/b_T."""
    domain = QUANTITIES[quantity][0]
    if not draws.shifted:
        return np.concatenate([_evaluate(s, theta, quantity, x)
                               for _, s, theta in draws.parts if theta.shape[0]], axis=0)
    a = 10.0 ** draws.log_a[:, None]
    pa, pb = _SCALING[QUANTITIES[quantity][2]]
    ((_, structure, theta),) = draws.parts
    values = _evaluate(structure, theta, quantity, x[None, :] * a if domain == "omega"
                       else x[None, :] / a)
    if pa or pb:
        values = values * 10.0 ** (pa * draws.log_a + pb * draws.log_b)[:, None]
    return values


def _predict(draws: Draws, quantity: str, x) -> Prediction:
    """:func:`predict` of ``draws`` at checked ``x``."""
    domain = QUANTITIES[quantity][0]
    data = draws.data
    median, lo, hi, values = _chunked_band(lambda part: draws_values(draws, quantity, part),
                                           x, draws.n_draws)
    notes = list(draws.notes)
    if not draws.shifted:
        if quantity in ("relaxation_spectrum", "retardation_spectrum"):
            discrete = [n for n, s, _ in draws.parts
                        if s.integer and draws.weights[n] >= 1e-3]
            if discrete:
                notes.append(f"{', '.join(discrete)}: integer orders give a discrete spectrum "
                             "(lines at the relaxation times), which a continuous density "
                             "shows as 0 between them")
        undefined = np.flatnonzero(np.isnan(median))
        if undefined.size:
            shown = ", ".join(f"{v:.4g}" for v in x[undefined[:6]])
            notes.append(f"{_symbol(quantity, data)} is not finite for some draws at "
                         f"{X_NAMES[domain]} {shown}{' and more' if undefined.size > 6 else ''} "
                         f"{X_UNITS[domain]}: no value or band there")
    window = draws.window()
    return Prediction(
        quantity=quantity, unit=quantity_unit(quantity, data), x=x, x_unit=X_UNITS[domain],
        median=median, hdi_low=lo, hdi_high=hi, extrapolated=_outside(x, domain, window),
        structure=draws.structure,
        weights=dict(draws.weights) if draws.average is not None else None,
        average=draws.average, notes=tuple(notes), values=values,
        symbol=_symbol(quantity, data), window=_window(domain, window),
        temperature=draws.temperature)


# ---------------------------------------------------------------------------- checks
def _check_quantity(quantity) -> str:
    if quantity not in QUANTITIES:
        raise InputError(f"predict: unknown quantity {quantity!r}; one of "
                         + ", ".join(QUANTITIES), where="predict")
    return quantity


def _check_x(x, domain: str) -> np.ndarray:
    what = {"omega": "angular frequencies", "time": "times", "tau": "relaxation times"}[domain]
    try:
        x = np.atleast_1d(np.asarray(x, dtype=float))
    except (TypeError, ValueError):
        raise InputError(f"predict: the {what} must be numbers", where="predict") from None
    if x.ndim != 1 or x.size == 0:
        raise InputError(f"predict: give one or more {what}", where="predict")
    bad = ~np.isfinite(x) | (x <= 0)
    if bad.any():
        raise InputError(f"predict: the {what} must be finite and > 0; got {x[bad][0]:g}", where="predict")
    return x


# ---------------------------------------------------------------------------- evaluation
def evaluate(structure, theta, quantity: str, x) -> np.ndarray:
    """``quantity`` of ``structure`` for each parameter set of ``theta`` (physical units) at
    ``x``: shared by every set (shape (n_x,)) or each set's own (shape (n_sets, n_x), e.g.
    frequencies shifted by each draw's a_T). Returns shape (n_sets, n_x).

    Raises
    ------
    InputError
        An unknown quantity; ``x`` not finite and > 0, or per set with another number of rows
        than ``theta``.

    Examples
    --------
    A springpot relaxes as G(t) = c t^(−α)/Γ(1 − α):

    >>> import numpy as np
    >>> from bayesfo.structures import get_structure
    >>> g = evaluate(get_structure("springpot"), [2.0, 0.5], "relaxation_modulus", [1.0])
    >>> bool(np.isclose(g[0, 0], 2.0 / np.sqrt(np.pi)))
    True
    """
    if np.ndim(x) != 2:
        return evaluate_together(structure, theta, (quantity,), x)[quantity]
    quantity = _check_quantity(quantity)
    theta = np.atleast_2d(np.asarray(theta, float))
    per_set = np.asarray(x, dtype=float)
    if per_set.shape[0] != theta.shape[0] or per_set.shape[1] == 0:
        raise InputError(f"evaluate: x per parameter set must have one row per set "
                         f"({theta.shape[0]}) and one or more columns; got shape "
                         f"{per_set.shape}")
    _check_x(per_set.ravel(), QUANTITIES[quantity][0])
    with np.errstate(all="ignore"):
        return _evaluate(structure, theta, quantity, per_set)


def _evaluate(structure, theta, quantity: str, x) -> np.ndarray:
    """``quantity`` for each parameter set at ``x``: shared by all sets (shape (n_x,)) or each
    set's own (shape (n_sets, n_x), e.g. frequencies shifted by each draw's a_T)."""
    domain = QUANTITIES[quantity][0]
    own = np.ndim(x) == 2
    with np.errstate(all="ignore"):
        if domain == "omega":
            c = structure.laplace(theta, 1j * x, per_set=own)  # the compliance C(iω)
            g = 1.0 / c
            return {"storage": lambda: g.real, "loss": lambda: g.imag,
                    "tan_delta": lambda: g.imag / g.real,
                    "storage_compliance": lambda: c.real, "loss_compliance": lambda: -c.imag,
                    "complex_viscosity": lambda: np.abs(g) / x}[quantity]()
        if domain == "tau":
            c = structure.laplace(theta, -1.0 / x + 0j, per_set=own)  # upper side of the cut
            # s^α at s = e^{iπ}/τ: np.log of a negative real with +0 imaginary part is ln|s|+iπ.
            if quantity == "relaxation_spectrum":
                return (1.0 / c).imag / np.pi
            return -c.imag / np.pi
        return _time_domain(structure, theta, (quantity,), x)[0]


#: The time-domain quantities from the compliance's transform C(s): G(t) = L⁻¹[1/(s C(s))],
#: J(t) = L⁻¹[C(s)/s].
_FROM_COMPLIANCE = {"relaxation_modulus": lambda c, s: 1.0 / (c * s),
                    "creep_compliance": lambda c, s: c / s}


def _time_domain(structure, theta, quantities, x) -> np.ndarray:
    """The time-domain ``quantities`` at ``x`` (shared, shape (n_x,), or each set's own, shape
    (n_sets, n_x)) for each parameter set: shape (n_quantities, n_sets, n_x). C(s) is evaluated
    once on the inversion contour for all of them."""
    own = np.ndim(x) == 2
    maps = [_FROM_COMPLIANCE[q] for q in quantities]
    out = np.empty((len(quantities), theta.shape[0], np.shape(x)[-1]))
    for i in range(0, theta.shape[0], _CHUNK):
        part = theta[i:i + _CHUNK]

        def transform(s, part=part):
            c = structure.laplace(part, s, per_set=own)
            return np.stack([f(c, s) for f in maps])

        out[:, i:i + _CHUNK] = (laplace.invert_per_set(transform, x[i:i + _CHUNK]) if own
                                else laplace.invert(transform, x))
    return out


def evaluate_together(structure, theta, quantities, x) -> dict[str, np.ndarray]:
    """:func:`evaluate` for several ``quantities`` of one domain at the same ``x``: ``{quantity:
    values (n_sets, n_x)}``; G(t) and J(t) together invert one evaluation of C(s)."""
    quantities = [_check_quantity(q) for q in quantities]
    domains = {QUANTITIES[q][0] for q in quantities}
    if len(domains) != 1:
        raise InputError("evaluate_together: the quantities must share their argument "
                         f"(frequency, time or relaxation time); got {', '.join(quantities)}")
    domain = domains.pop()
    theta = np.atleast_2d(np.asarray(theta, float))
    x = _check_x(x, domain)
    if domain != "time":
        return {q: _evaluate(structure, theta, q, x) for q in quantities}
    with np.errstate(all="ignore"):
        values = _time_domain(structure, theta, quantities, x)
    return dict(zip(quantities, values, strict=True))


def _chunked_band(values_at, x, n_draws: int):
    """Median, HDI ends and (up to :data:`MAX_KEPT_VALUES`, else None) the values of
    ``values_at(part)`` (draws × part) over ``x``, taken in chunks of :data:`_X_CHUNK`
    arguments: each column's band is its own, so the chunks give the same band as one piece,
    in memory that does not grow with the number of arguments."""
    step = _X_CHUNK
    keep = n_draws * x.size <= MAX_KEPT_VALUES
    bands, kept = [], []
    for i in range(0, x.size, step):
        values = values_at(x[i:i + step])
        bands.append(_band(values))
        if keep:
            kept.append(values)
    median, lo, hi = (np.concatenate(parts) for parts in zip(*bands, strict=True))
    return median, lo, hi, (np.concatenate(kept, axis=1) if keep else None)


def _band(values) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Median and the ends of the 94 % HDI per column; NaN where a column has NaN draws."""
    from ..inference import hdi_columns

    with np.errstate(all="ignore"):
        median = np.median(values, axis=0)
        lo, hi = hdi_columns(values, BAND)
    bad = ~np.all(np.isfinite(values), axis=0)
    for a in (median, lo, hi):
        a[bad] = np.nan
    return median, lo, hi


#: Relative rounding within which an argument at an end of the measured window is inside it
#: (a grid such as ``--omega 0.001:1000:7`` gives 0.01 as 0.009999999999999998).
WINDOW_ROUNDING = 1e-9


def _window(domain: str, omega) -> tuple[float, float]:
    """The window the data cover, in the unit of the domain's argument."""
    w_lo, w_hi = float(np.min(omega)), float(np.max(omega))
    return (w_lo, w_hi) if domain == "omega" else (1.0 / w_hi, 1.0 / w_lo)


def _outside(x, domain: str, omega) -> np.ndarray:
    lo, hi = _window(domain, omega)
    return (x < lo * (1 - WINDOW_ROUNDING)) | (x > hi * (1 + WINDOW_ROUNDING))


def _symbol(quantity: str, data) -> str:
    """The quantity's symbol in the data's letters (E′ for a tensile modulus)."""
    return in_symbol(QUANTITIES[quantity][1], getattr(data, "symbol", "G"))


def quantity_unit(quantity: str, data) -> str:
    """The unit of ``quantity`` of a model fitted to ``data`` (its stress unit and kind)."""
    from ..structures.physical import parenthesized, stress_unit

    modulus = stress_unit(data.kind, data.units or "")
    kind = QUANTITIES[quantity][2]
    return {"modulus": modulus, "compliance": f"1/{parenthesized(modulus)}",
            "viscosity": f"{modulus} s", "none": ""}[kind]
