"""Prony series of a compared model for finite-element codes.

G(t) = G∞ + Σ g_i exp(−t/τ_i) with the τ_i log-spaced from two decades below 1/ω_max to two
decades above 1/ω_min, and G∞, g_i ≥ 0 fitted by non-negative least squares to the posterior
median of G′(ω) and G″(ω) (relative residuals, 20 frequencies per decade over the data window
widened by a decade each side). The number of τ_i is by default the fewest whose series' G(t)
stays inside the model's own 94 % band at each of :data:`DENSE` log-spaced times over the data
window (more would describe the model more closely than the data know it); a number, or a
number per decade, may be given instead. G∞ is 0 where the model relaxes
fully (a liquid: its long-time modulus, the limit of G(t) as t → ∞, is 0 for the median draw),
and the τ_i then reach a decade further; else G∞ is fitted with the terms; ``liquid`` forces
either. A fitted G∞ is the series' modulus beyond its longest relaxation time: a fractional
model still relaxing there (a springpot relaxes over every decade) has a long-time modulus
below it, which the files state beside it.

How well the series stands for the model is stated, each error the largest over the data
window on a dense grid and named for what it measures: |ΔG(t)|/G(t) at :data:`DENSE` times,
|ΔG*|/|G*|, |ΔG′|/G′ and |ΔG″|/G″ at :data:`DENSE` frequencies; beside them the model's band
of G(t) and how far the series departs within it.

Formats (written by :mod:`.decks`): ``csv`` (``tau_s,g_i`` with ``#`` lines for G∞, G0,
the unit and the errors), ``abaqus`` (``*VISCOELASTIC, TIME=PRONY``: g_i/G0, k_i = 0, τ_i; G0 in a comment, for ``*ELASTIC,
MODULI=INSTANTANEOUS``), ``ansys`` (``TB,PRONY,,,N,SHEAR`` and ``TBDATA`` commands of three
values, α_i = g_i/G0 and τ_i in turn, as ANSYS's TBFT writes them) and ``lsdyna``
(``*MAT_GENERAL_VISCOELASTIC``, fixed 10-character fields: rows of G_i and the decay constant
β_i = 1/τ_i, G∞ as a row with β = 0, at most :data:`LSDYNA_MAX_TERMS` rows; RO and BULK,
which a shear or tensile measurement does not give, are left for the user). The ratios g_i/G0
that Abaqus and ANSYS take sum to at most :data:`RATIO_SUM_MAX` (a liquid's, which sum to 1,
are scaled by 1 − 1e-6): those codes refuse a sum of 1.

A series fitted to a master curve is the material at the reference temperature, and its shift
law goes with it (the law of larger support, posterior means): Abaqus ``*TRS`` (``WLF``:
θ0, C1, C2; ``ARRHENIUS``: θ0, E0, R, θZ = −273.15 for temperatures in °C), ANSYS
``TB,SHIFT`` (``WLF``: T_r, C1, C2, whose log10 A = C1 (T − T_r)/(C2 + T − T_r) is the
inverse of a_T; Arrhenius as the two-constant Tool–Narayanaswamy form ``TN``: T_r and
E_a/R, in kelvin), LS-DYNA's TREF, A, B (:meth:`Prony.lsdyna_shift`) and the csv's comment
lines; the law's fit to the shifts and its temperature range are stated beside it. A law the
evidence rejects (free shifts of larger ln Z under ``law="auto"``) is not written: the files
say so and list the isotherms' own shifts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..data.symbols import modulus_symbol
from ..errors import InputError
from .decks import (  # noqa: F401  (the formats and constants of the decks, named here too)
    DIGITS,
    FORMATS,
    GAS_CONSTANT,
    KELVIN,
    LSDYNA_MAX_TERMS,
    _has_unit,
    deck_text,
    lsdyna_shift,
)
from .functions import predict
from .long_time import long_time_modulus

#: Decades of relaxation times beyond the data window on each side.
TAU_MARGIN = 2
#: Decades of relaxation times added beyond 1/ω_min where G∞ = 0.
LIQUID_MARGIN = 1
#: A g_0 more than this many times the largest measured |G*| is named in the files as the
#: model's extrapolation.
EXTRAPOLATED = 1.5
#: A modulus ratio sum Abaqus and ANSYS take: Σ g_i/G0 < 1 (a relaxed modulus above zero);
#: the ratios written sum to at most this.
RATIO_SUM_MAX = 1 - 1e-6
#: Log-spaced times (and frequencies) over the data window the series is judged on.
DENSE = 2001



@dataclass(frozen=True)
class Prony:
    """A Prony series and how well it stands for the model.

    Attributes
    ----------
    tau, g : ndarray
        Relaxation times [s] and moduli [``unit``] of the terms (terms fitted to 0 are dropped).
    g_inf : float
        The series' long-time modulus (0 for a liquid).
    unit : str
    source : str
        The structure, or the average, it was fitted to.
    window : (float, float)
        The times [s] the data cover, 1/ω_max to 1/ω_min.
    max_rel_error_modulus, max_rel_error_relaxation : float
        Largest relative error of the series' G* (|ΔG*|/|G*| at :data:`DENSE` log-spaced
        frequencies over the window), and of its G(t) (relative to G(t), or to 0.1 % of G0
        where G(t) has relaxed below that, at :data:`DENSE` log-spaced times), against the
        posterior medians.
    band_rel_halfwidth : float
        The smallest relative half-width of the model's 94 % band of G(t) over the window.
    shift_law : dict or None
        For a master curve: ``{"name": "wlf" | "arrhenius", "reference_temperature",
        "parameters": {NAME: value}, "temperatures": (min, max), "chi2_per_dof"}`` (values
        in °C and J/mol, posterior means), written with the series; None where the evidence
        rejects every law (see ``shift_note``).
    symbol : str
        The letter of the measured quantity (``"G"`` shear, ``"E"`` tensile; see
        :mod:`bayesfo.data.symbols`), which the files name.
    measured_max : float
        The largest |G*| the data give (NaN where unknown): a g_0 far above it is the model
        extrapolated past the highest measured frequency, and the files say so.
    model_g_inf : float
        The model's own long-time modulus, lim G(t) as t → ∞ (the median over the draws; 0 for
        a liquid; NaN where unknown), beside the series' ``g_inf``.
    max_rel_error_storage, max_rel_error_loss : float
        Largest |ΔG′|/G′ and |ΔG″|/G″ at the :data:`DENSE` frequencies, each part on its own
        (G″ is small where G′ dominates, so its relative error can be far larger than G*'s).
    band_fraction : float
        The series' largest departure from the model's median G(t) over the window, as a
        fraction of the band's reach on that side: at most 1 where the series stays inside
        the model's 94 % band at every one of the :data:`DENSE` times.
    rule : str
        How the number of terms was chosen: ``"auto"`` (the fewest inside the band),
        ``"N terms"`` or ``"K per decade"``.
    max_terms : int or None
        The most terms ``"auto"`` could take (LS-DYNA's 18), None for no limit.
    shift_note : str
        For a master curve whose evidence rejects every shift law: why none is written.
    shift_table : tuple of (float, float)
        Then the isotherms' own shifts, (temperature [°C], log10 a_T) at posterior means.
    g_inf_fixed : bool
        Whether ``g_inf`` was held at 0 (a liquid, or ``liquid=True``) rather than fitted.
    """

    tau: np.ndarray
    g: np.ndarray
    g_inf: float
    unit: str
    source: str
    window: tuple[float, float]
    max_rel_error_modulus: float
    max_rel_error_relaxation: float
    band_rel_halfwidth: float
    shift_law: dict | None = None
    symbol: str = "G"
    measured_max: float = math.nan
    model_g_inf: float = math.nan
    max_rel_error_storage: float = math.nan
    max_rel_error_loss: float = math.nan
    band_fraction: float = math.nan
    rule: str = ""
    max_terms: int | None = None
    shift_note: str = ""
    shift_table: tuple = ()
    g_inf_fixed: bool = False

    @property
    def g_0(self) -> float:
        """The instantaneous modulus G∞ + Σ g_i."""
        return float(self.g_inf + np.sum(self.g))

    @property
    def inside_band(self) -> bool:
        """Whether the series' G(t) stays inside the model's 94 % band over the window."""
        return bool(self.band_fraction <= 1.0)

    def __repr__(self) -> str:
        e = modulus_symbol(self.symbol)
        unit = unit_suffix(self.unit)
        band = ("inside" if self.inside_band else "outside") if not math.isnan(
            self.band_fraction) else "not judged against"
        return (f"<Prony series of {self.source}: {self.tau.size} terms, {e}0 = "
                f"{self.g_0:.6g}{unit}, {e}_inf = {self.g_inf:.6g}{unit}; max |d{e}(t)|/{e}(t) "
                f"{self.max_rel_error_relaxation:.2g}, {band} the model's band>")

    def _repr_html_(self) -> str:
        from .notebook import prony_html

        return prony_html(self, unit_suffix(self.unit))

    def relaxation(self, t) -> np.ndarray:
        t = np.asarray(t, float)
        return self.g_inf + np.sum(self.g * np.exp(-t[..., None] / self.tau), axis=-1)

    def modulus(self, omega) -> np.ndarray:
        s = 1j * np.asarray(omega, float)[..., None] * self.tau
        return self.g_inf + np.sum(self.g * s / (1 + s), axis=-1)

    def ratios(self) -> np.ndarray:
        """g_i/G0 as Abaqus and ANSYS take them, written to :data:`DIGITS` digits: every
        one > 0 and their sum at most :data:`RATIO_SUM_MAX` (a liquid's ratios, which sum to
        1, are scaled down by 1e-6: those codes refuse Σ g_i/G0 ≥ 1)."""
        r = self.g / self.g_0
        total = float(np.sum(r))
        if total > RATIO_SUM_MAX:
            r = r * ((RATIO_SUM_MAX - 1e-9) / total)
        written = np.array([float(f"{v:.{DIGITS}g}") for v in r])
        while float(np.sum(written)) > RATIO_SUM_MAX:  # rounding up, at most a step or two
            written = np.array([float(f"{v:.{DIGITS}g}") for v in written * (1 - 1e-9)])
        return written

    def _ratio_text(self) -> list[str]:
        """What the ratios' sum stands for, where it had to be kept below 1."""
        if float(np.sum(self.g / self.g_0)) <= RATIO_SUM_MAX:
            return []
        return [f"the ratios g_i/g_0 are scaled by (1 - 1e-6) so that they sum to less than "
                f"1, as the code requires: its long-time modulus is then 1e-6 g_0 "
                f"({1e-6 * self.g_0:.3g}{unit_suffix(self.unit)}), where the series has "
                f"{self.g_inf:.6g}"]

    def error_text(self) -> list[str]:
        """The stated errors, each named for what it measures, and the band."""
        e = modulus_symbol(self.symbol)
        error = max(self.max_rel_error_modulus, self.max_rel_error_relaxation)
        lines = [f"max_rel_error = {error:.3g}: the larger of max |d{e}(t)|/{e}(t) and "
                 f"max |d{e}*|/|{e}*| below, over the data window",
                 f"max |d{e}(t)|/{e}(t) = {self.max_rel_error_relaxation:.3g} at {DENSE} "
                 f"log-spaced times (relative to {e}(t), or to 0.1 % of {e}0 where {e}(t) has "
                 "relaxed below that)",
                 f"max |d{e}*|/|{e}*| = {self.max_rel_error_modulus:.3g}, max |d{e}'|/{e}' = "
                 f"{self.max_rel_error_storage:.3g}, max |d{e}''|/{e}'' = "
                 f"{self.max_rel_error_loss:.3g}, each at {DENSE} log-spaced frequencies"]
        where = ("stays inside it at every time" if self.inside_band
                 else "leaves it")
        lines.append(f"the model's 94 % band of {e}(t) is at least +-"
                     f"{self.band_rel_halfwidth:.3g} (relative) over the window; the series "
                     f"{where} (largest departure {self.band_fraction:.3g} of the band's reach)")
        return lines

    def terms_text(self) -> list[str]:
        """How the number of terms was chosen."""
        n = self.tau.size
        if self.rule != "auto":
            return [f"{n} terms ({self.rule})"] if self.rule else []
        if self.inside_band:
            return [f"{n} terms: the fewest log-spaced relaxation times whose series stays "
                    "inside the model's 94 % band"]
        return [f"{n} terms: the most the card takes ({self.max_terms}, g_inf counted), and "
                "the series still leaves the model's 94 % band"]

    def text(self, fmt: str) -> str:
        """The series in ``fmt`` (one of :data:`FORMATS`; :func:`~.decks.deck_text`)."""

        return deck_text(self, fmt)

    def lsdyna_shift(self) -> tuple[float, float, float] | None:
        """TREF [K], A and B of *MAT_GENERAL_VISCOELASTIC for the shift law, None without one
        (:func:`~.decks.lsdyna_shift`: A = −C1 ln 10, B = C2 for WLF; A = E_a/R, B = 0 for
        Arrhenius)."""

        return lsdyna_shift(self)

    def _reach_text(self) -> list[str]:
        """Where the relaxation times lie against the data window: terms beyond it stand for
        the model's extrapolation, which lets the series follow it to the window's ends."""
        if not self.tau.size:
            return []
        lo, hi = float(np.min(self.tau)), float(np.max(self.tau))
        if lo >= self.window[0] and hi <= self.window[1]:
            return []
        return [f"relaxation times {lo:.4g} to {hi:.4g} s: those beyond the data window stand "
                "for the model's extrapolation there, so that the series follows the model to "
                "the window's ends"]

    def extrapolation_text(self) -> list[str]:
        """That g_0 is the model extrapolated past the highest measured frequency, where it lies
        more than :data:`EXTRAPOLATED` times above the largest measured |G*|; empty otherwise."""
        if not self.g_0 > EXTRAPOLATED * self.measured_max:
            return []
        e = modulus_symbol(self.symbol)
        return [f"{e}0 is the model's modulus {TAU_MARGIN} decades past the highest measured "
                f"frequency, {self.g_0 / self.measured_max:.3g} x the largest measured |{e}*| "
                f"({self.measured_max:.4g}): the ratios g_i/{e}0 that Abaqus and ANSYS take "
                "depend on that extrapolation"]

    def long_time_text(self) -> list[str]:
        """What g_inf stands for, beside the model's own long-time modulus."""
        model, longest = self.model_g_inf, float(np.max(self.tau)) if self.tau.size else math.nan
        if math.isnan(model):
            return []
        unit = unit_suffix(self.unit)
        if self.g_inf == 0.0:
            if model == 0.0:
                return ["g_inf = 0: the model relaxes fully (a liquid)"]
            if self.g_inf_fixed:
                return [f"g_inf = 0 as asked, where the model's long-time modulus is "
                        f"{model:.6g}{unit}"]
            return [f"g_inf was fitted as 0 (the terms carry the relaxation up to the longest "
                    f"relaxation time, {longest:.4g} s), where the model's long-time modulus "
                    f"is {model:.6g}{unit}"]
        what = ("relaxes fully (a liquid)" if model == 0.0
                else "does not settle (its G(t) grows without bound)" if math.isinf(model)
                else f"has the long-time modulus {model:.6g}{unit}")
        return [f"g_inf is the series' modulus beyond its longest relaxation time "
                f"({longest:.4g} s); the model {what}"]

    def _law_text(self) -> str:
        law = self.shift_law
        p = law["parameters"]
        lo, hi = law["temperatures"]
        if law["name"] == "wlf":
            form = (f"WLF log10 a_T = -C1 (T - T_ref)/(C2 + T - T_ref), T_ref = "
                    f"{law['reference_temperature']:.10g} °C, C1 = {p['C1']:.10g}, "
                    f"C2 = {p['C2']:.10g} °C")
        else:
            form = (f"Arrhenius log10 a_T = Ea/(R ln 10) (1/T - 1/T_ref) in kelvin, T_ref = "
                    f"{law['reference_temperature']:.10g} °C, Ea = {p['Ea']:.10g} J/mol")
        return (f"shift law: {form}; fitted to the shifts of isotherms at {lo:g} to {hi:g} °C "
                f"(chi2/dof {law['chi2_per_dof']:.3g})")


def prony_series(result, *, per_decade: int | None = None, liquid: bool | None = None,
                 structure: str | None = None, average: str | None = None,
                 seed: int = 0, terms: int | str | None = None,
                 max_terms: int | None = None) -> Prony:
    """A Prony series fitted to a comparison's structure (default the best ranked) or average.

    Parameters
    ----------
    result : Comparison or MasterCurve
        A master curve gives the series at its reference temperature, with its shift law.
    per_decade : int, optional
        Relaxation times per decade (1 to 10) instead of the fewest that suffice.
    liquid : bool, optional
        True: G∞ = 0 (a liquid relaxes completely); False: G∞ fitted with the terms; None
        (default): 0 where the model's long-time modulus is 0 for the median draw
        (:func:`~bayesfo.predictions.long_time.long_time_modulus`), else fitted.
    structure : str, optional
        The structure (default: the best ranked), as in :func:`bayesfo.predict`.
    average : {"bma", "stacking"}, optional
        An average over the structures instead, as in :func:`bayesfo.predict`.
    seed : int
        Seeds the draws used.
    terms : int or "auto", optional
        ``"auto"`` (the default unless ``per_decade`` is given): the fewest relaxation times,
        log-spaced over the span, whose series' G(t) stays inside the model's 94 % band at
        every one of :data:`DENSE` log-spaced times over the data window. An integer (2 to
        100): that many relaxation times over the same span. Either way terms whose weight
        comes out zero are dropped, so the series may have fewer.
    max_terms : int, optional
        With ``terms="auto"``: at most this many terms, G∞ counted as one where it is
        fitted (LS-DYNA's card takes 18); where none of those stays inside the band, the one
        that departs least from it.

    Returns
    -------
    Prony
    """
    if per_decade is not None and (isinstance(per_decade, bool) or not isinstance(per_decade, int)
                                   or not 1 <= per_decade <= 10):
        raise InputError(f"export: terms per decade must be an integer from 1 to 10, got "
                         f"{per_decade!r}", command_line="--per-decade must be an integer from 1 "
                         f"to 10, got {per_decade!r}")
    if terms is None:
        terms = "auto" if per_decade is None else None
    elif per_decade is not None:
        raise InputError("export: give the number of terms or terms per decade, not both",
                         command_line="give --terms or --per-decade, not both")
    if terms is not None and terms != "auto" and (isinstance(terms, bool)
                                                  or not isinstance(terms, int)
                                                  or not 2 <= terms <= 100):
        raise InputError(f"export: the number of terms must be 'auto' or an integer from 2 to "
                         f"100, got {terms!r}", command_line="--terms must be 'auto' or an "
                         f"integer from 2 to 100, got {terms!r}")
    if max_terms is not None and (isinstance(max_terms, bool) or not isinstance(max_terms, int)
                                  or max_terms < 2):
        raise InputError(f"export: max_terms must be an integer of at least 2, got "
                         f"{max_terms!r}", where="export")
    # The draws once: every function below is of these (at the reference temperature for a
    # master curve, whose window is then its reduced frequencies).
    draws = result.draws(structure=structure, average=average, seed=seed)
    master = draws.shifted  # a master curve's: its reduced data and its shift law go along
    w_lo, w_hi = float(np.min(draws.omega)), float(np.max(draws.omega))
    omega = np.logspace(math.log10(w_lo) - 1, math.log10(w_hi) + 1,
                        int(20 * (math.log10(w_hi / w_lo) + 2)) + 1)
    storage = predict(draws, "storage", omega)
    loss = predict(draws, "loss", omega)
    g = storage.median + 1j * loss.median
    model_g_inf = float(np.median(long_time_modulus(draws)))
    if liquid is None:
        liquid = model_g_inf == 0.0
    if not np.all(np.isfinite(g)):
        raise InputError("export: the model's modulus is not finite over the window", where="export")
    window = (1.0 / w_hi, 1.0 / w_lo)
    # The dense grids the series is judged on: its G(t) against the model's band at DENSE
    # times, its G′ and G″ against the medians at DENSE frequencies, both over the window.
    t = np.logspace(math.log10(window[0]), math.log10(window[1]), DENSE)
    g_t = predict(draws, "relaxation_modulus", t)
    w = np.logspace(math.log10(w_lo), math.log10(w_hi), DENSE)
    g_w = predict(draws, "storage", w).median + 1j * predict(draws, "loss", w).median
    # The terms reach TAU_MARGIN decades past the window: a power-law spectrum (a springpot)
    # relaxes over every decade, and terms only over the window leave its edges short.
    # Without G∞, a term further out takes the relaxation beyond the longest time that G∞
    # would have stood for.
    lo_tau = 1 / (w_hi * 10**TAU_MARGIN)
    hi_tau = 10**(TAU_MARGIN + (LIQUID_MARGIN if liquid else 0)) / w_lo

    def fit(n: int):
        tau = np.logspace(math.log10(lo_tau), math.log10(hi_tau), n)
        g_inf, weights = _nnls(g, omega, tau, liquid)
        keep = weights > 0
        tau, weights = tau[keep], weights[keep]
        series = g_inf + np.sum(weights * np.exp(-t[:, None] / tau), axis=1)
        return tau, weights, g_inf, _band_fraction(series, g_t)

    if terms == "auto":
        cap = max_terms if max_terms is not None else 100
        best = None
        for n in range(2, 101):
            found = fit(n)
            if found[0].size + (0 if liquid else 1) > cap:
                break
            if best is None or found[3] < best[3]:
                best = found
            if found[3] <= 1.0:
                best = found
                break
        tau, weights, g_inf, _ = best
        rule = "auto"
    else:
        n = terms if terms is not None else \
            int(round(math.log10(hi_tau / lo_tau) * per_decade)) + 1
        tau, weights, g_inf, _ = fit(n)
        rule = f"{terms} terms" if terms is not None else f"{per_decade} per decade"
    fitted = Prony(tau=tau, g=weights, g_inf=g_inf, unit=storage.unit,
                   source=(f"the master curve of {result.structure} at "
                           f"{result.reference_temperature:g} °C" if master
                           else storage.structure or f"{storage.average} average"),
                   window=window,
                   max_rel_error_modulus=math.nan, max_rel_error_relaxation=math.nan,
                   band_rel_halfwidth=math.nan)
    series_w = fitted.modulus(w)
    err_g = float(np.max(np.abs(series_w - g_w) / np.abs(g_w)))
    err_storage = float(np.max(np.abs(series_w.real - g_w.real) / np.abs(g_w.real)))
    err_loss = float(np.max(np.abs(series_w.imag - g_w.imag) / np.abs(g_w.imag)))
    # Relative to G(t), or to 0.1 % of G0 where G(t) has relaxed below it (a liquid's tail).
    scale = np.maximum(np.abs(g_t.median), 1e-3 * fitted.g_0)
    series_t = fitted.relaxation(t)
    err_t = float(np.max(np.abs(series_t - g_t.median) / scale))
    half = float(np.min((g_t.hdi_high - g_t.hdi_low) / 2 / np.abs(g_t.median)))
    data = result.master_data() if master else result.data
    measured = np.abs(data.response if data.kind == "modulus" else 1.0 / data.response)
    law, law_note, table = _shift_law(result) if master else (None, "", ())
    return replace(fitted, max_rel_error_modulus=err_g, max_rel_error_relaxation=err_t,
                   band_rel_halfwidth=half, shift_law=law,
                   symbol=data.symbol, measured_max=float(np.max(measured)),
                   model_g_inf=model_g_inf, max_rel_error_storage=err_storage,
                   max_rel_error_loss=err_loss, band_fraction=_band_fraction(series_t, g_t),
                   rule=rule, max_terms=max_terms, shift_note=law_note, shift_table=table,
                   g_inf_fixed=bool(liquid))


def _nnls(g: np.ndarray, omega: np.ndarray, tau: np.ndarray, liquid: bool):
    """G∞ (0 for a liquid) and the g_i ≥ 0 of the relaxation times ``tau`` by non-negative
    least squares on the relative residuals of G′ and G″ at ``omega``."""
    from scipy.optimize import nnls

    s = 1j * omega[:, None] * tau
    basis = s / (1 + s)
    if not liquid:
        basis = np.column_stack([np.ones(omega.size), basis])
    weight = 1.0 / np.abs(g)
    a = np.vstack([(basis.real * weight[:, None]), (basis.imag * weight[:, None])])
    b = np.r_[g.real * weight, g.imag * weight]
    x, _ = nnls(a, b, maxiter=50 * a.shape[1])
    return (0.0, x) if liquid else (float(x[0]), x[1:])


def _band_fraction(series: np.ndarray, band) -> float:
    """The series' largest departure from the band's median as a fraction of the band's
    reach on that side (the HDI's end): at most 1 where the series stays inside the band."""
    above = series - band.median
    reach = np.where(above >= 0, band.hdi_high - band.median, band.median - band.hdi_low)
    with np.errstate(divide="ignore", invalid="ignore"):
        frac = np.where(above == 0, 0.0, np.abs(above) / reach)
    return float(np.max(np.nan_to_num(frac, nan=np.inf, posinf=np.inf)))


def _shift_law(mc) -> tuple[dict | None, str, tuple]:
    """The master curve's preferred shift law as :class:`Prony` carries it, or None where the
    evidence rejects every law (free shifts of larger ln Z): then a note and the isotherms'
    own shifts, ``((T [°C], log10 a_T), ...)`` at their posterior means."""
    evidence = getattr(mc, "law_evidence", {}) or {}
    if mc.law == "free" and evidence and "free" in evidence and max(
            evidence, key=lambda k: evidence[k].get("probability") or 0.0) == "free":
        others = [k for k in evidence if k != "free"]
        z_free = evidence["free"].get("log_evidence")
        gaps = []
        for k in others:
            z = evidence[k].get("log_evidence")
            z = z if z is not None else evidence[k].get("log_evidence_upper")
            if z is not None and z_free is not None:
                gaps.append(f"{'WLF' if k == 'wlf' else 'Arrhenius'} {z_free - z:.0f} nats below")
        note = ("no shift law is written: the evidence prefers free shifts to every law ("
                + ", ".join(gaps) + "); the isotherms' own shifts follow as a table, to enter "
                "as tabular shifts or to interpolate between the measured temperatures")
        table = tuple((float(t), float(a)) for t, a in zip(mc.temperatures, mc.log_shift_mean,
                                                          strict=True))
        return None, note, table
    law = mc.shift_law()
    return ({"name": law["name"], "reference_temperature": float(law["reference_temperature"]),
             "parameters": {k: float(v["mean"]) for k, v in law["parameters"].items()},
             "temperatures": (float(min(mc.temperatures)), float(max(mc.temperatures))),
             "chi2_per_dof": float(mc.laws[law["name"]]["chi2_per_dof"])}, "", ())


def unit_suffix(unit: str) -> str:
    """`` unit`` to follow a number, or nothing where the data give no unit."""
    return f" {unit}" if _has_unit(unit) else ""
