"""Prony series of a compared model for finite-element codes.

G(t) = G∞ + Σ g_i exp(−t/τ_i) with the τ_i fixed, ``per_decade`` of them per decade from two
decades below 1/ω_max to two decades above 1/ω_min, and G∞, g_i ≥ 0 fitted by non-negative least
squares to the posterior median of G′(ω) and G″(ω) (relative residuals, 20 frequencies per
decade over the data window widened by a decade each side). G∞ is 0 where the model relaxes
fully (a liquid: its long-time modulus, the limit of G(t) as t → ∞, is 0 for the median draw),
and the τ_i then reach a decade further; else G∞ is fitted with the terms; ``liquid`` forces
either. A fitted G∞ is the series' modulus beyond its longest relaxation time: a fractional
model still relaxing there (a springpot relaxes over every decade) has a long-time modulus
below it, which the files state beside it.

How well the series stands for the model is stated: the largest relative error of its G′, G″
and G(t) against the posterior medians over the data window, beside the half-width of the
model's own 94 % band of G(t) there (a series whose error is well inside the band adds nothing
the data could tell).

Formats: ``csv`` (``tau_s,g_i`` with ``#`` lines for G∞, G0, the unit and the errors), ``abaqus``
(``*VISCOELASTIC, TIME=PRONY``: g_i/G0, k_i = 0, τ_i; G0 in a comment, for ``*ELASTIC,
MODULI=INSTANTANEOUS``), ``ansys`` (``TB,PRONY,,,N,SHEAR`` and ``TBDATA`` pairs of α_i = g_i/G0
and τ_i) and ``lsdyna`` (``*MAT_GENERAL_VISCOELASTIC``, fixed 10-character fields: rows of G_i
and the decay constant β_i = 1/τ_i, G∞ as a row with β = 0, at most :data:`LSDYNA_MAX_TERMS`
rows; RO and BULK, which a shear measurement does not give, are left for the user).

A series fitted to a master curve is the material at the reference temperature, and its shift
law goes with it (the law of larger support, posterior means): Abaqus ``*TRS`` (``WLF``:
θ0, C1, C2; ``ARRHENIUS``: θ0, E0, R, θZ = −273.15 for temperatures in °C), ANSYS
``TB,SHIFT`` (``WLF``: T_r, C1, C2, whose log10 A = C1 (T − T_r)/(C2 + T − T_r) is the
inverse of a_T; Arrhenius as the two-constant Tool–Narayanaswamy form ``TN``: T_r and
E_a/R, in kelvin), and the csv's comment lines; the law's fit to the shifts and its
temperature range are stated beside it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

#: Gas constant [J/(mol K)] and the kelvin of 0 °C, for the Arrhenius shift law.
GAS_CONSTANT = 8.314462618
KELVIN = 273.15

FORMATS = ("csv", "abaqus", "ansys", "lsdyna")
#: Terms *MAT_GENERAL_VISCOELASTIC takes (the long-term modulus is one of them, with β = 0).
LSDYNA_MAX_TERMS = 18
#: Decades of relaxation times beyond the data window on each side.
TAU_MARGIN = 2
#: Decades of relaxation times added beyond 1/ω_min where G∞ = 0.
LIQUID_MARGIN = 1
#: A g_0 more than this many times the largest measured |G*| is named in the files as the
#: model's extrapolation.
EXTRAPOLATED = 1.5


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
        Largest relative error of the series' G* (|ΔG*|/|G*|), and of its G(t) (relative to
        G(t), or to 0.1 % of G0 where G(t) has relaxed below that), against the posterior
        medians over the window.
    band_rel_halfwidth : float
        The smallest relative half-width of the model's 94 % band of G(t) over the window.
    shift_law : dict or None
        For a master curve: ``{"name": "wlf" | "arrhenius", "reference_temperature",
        "parameters": {NAME: value}, "temperatures": (min, max), "chi2_per_dof"}`` (values
        in °C and J/mol, posterior means), written with the series.
    symbol : str
        The letter of the measured quantity (``"G"`` shear, ``"E"`` tensile; see
        :mod:`bayesfo.data.symbols`), which the files name.
    measured_max : float
        The largest |G*| the data give (NaN where unknown): a g_0 far above it is the model
        extrapolated past the highest measured frequency, and the files say so.
    model_g_inf : float
        The model's own long-time modulus, lim G(t) as t → ∞ (the median over the draws; 0 for
        a liquid; NaN where unknown), beside the series' ``g_inf``.
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
    g_inf_fixed: bool = False

    @property
    def g_0(self) -> float:
        """The instantaneous modulus G∞ + Σ g_i."""
        return float(self.g_inf + np.sum(self.g))

    def relaxation(self, t) -> np.ndarray:
        t = np.asarray(t, float)
        return self.g_inf + np.sum(self.g * np.exp(-t[..., None] / self.tau), axis=-1)

    def modulus(self, omega) -> np.ndarray:
        s = 1j * np.asarray(omega, float)[..., None] * self.tau
        return self.g_inf + np.sum(self.g * s / (1 + s), axis=-1)

    def text(self, fmt: str) -> str:
        """The series in ``fmt`` (one of :data:`FORMATS`)."""
        if fmt not in FORMATS:
            raise InputError(f"export: format must be one of {', '.join(FORMATS)}, got {fmt!r}")
        from ..data.symbols import mode as mode_of
        from ..data.symbols import modulus_symbol

        e, mode = modulus_symbol(self.symbol), mode_of(self.symbol)
        head = [f"Prony series of {self.source} (bayesfo), {mode} modulus {e} in "
                f"{self.unit or 'the data unit'}, as measured",
                f"fitted over t = {self.window[0]:.4g} to {self.window[1]:.4g} s (the data window)",
                *self._reach_text(),
                f"g_inf = {self.g_inf:.10g}", f"g_0 = {self.g_0:.10g}",
                *self.long_time_text(),
                f"max_rel_error = {max(self.max_rel_error_modulus, self.max_rel_error_relaxation):.3g}"
                f" ({e}', {e}'': {self.max_rel_error_modulus:.3g}; {e}(t): "
                f"{self.max_rel_error_relaxation:.3g}); the model's 94 % band of {e}(t) is at "
                f"least +-{self.band_rel_halfwidth:.3g} (relative) there"]
        head += self.extrapolation_text()
        if mode == "tensile" and fmt in ("abaqus", "ansys"):
            head.append("a tensile series: its ratios g_i/g_0 stand for the shear ratios the "
                        "code takes under a constant Poisson's ratio")
        law = self.shift_law
        if law is not None:
            head.append(self._law_text())
        if fmt == "csv":
            lines = [f"# {h}" for h in head] + ["tau_s,g_i"]
            lines += [f"{t:.10g},{g:.10g}" for t, g in zip(self.tau, self.g, strict=True)]
        elif fmt == "abaqus":
            lines = [f"** {h}" for h in head]
            # *ELASTIC takes Young's modulus and Poisson's ratio: a shear series' G0 is
            # E0 = 2 (1 + nu) G0 there; a tensile series' own G0 is E0.
            lines.append(f"** instantaneous modulus {e}0 = {self.g_0:.10g}: give "
                         + ("it" if mode == "tensile" else f"E0 = 2 (1 + nu) {e}0")
                         + " with Poisson's ratio nu in *ELASTIC, MODULI=INSTANTANEOUS")
            lines.append("*VISCOELASTIC, TIME=PRONY")
            lines += [f"{g / self.g_0:.10g}, 0., {t:.10g}"
                      for t, g in zip(self.tau, self.g, strict=True)]
            if law is not None:
                p, t_ref = law["parameters"], law["reference_temperature"]
                if law["name"] == "wlf":
                    lines += ["*TRS, DEFINITION=WLF", f"{t_ref:.10g}, {p['C1']:.10g}, "
                                                      f"{p['C2']:.10g}"]
                else:
                    lines += ["*TRS, DEFINITION=ARRHENIUS",
                              f"{t_ref:.10g}, {p['Ea']:.10g}, {GAS_CONSTANT:.10g}, {-KELVIN:.10g}"]
        elif fmt == "lsdyna":
            lines = self._lsdyna(head)
        else:  # ansys
            lines = [f"! {h}" for h in head]
            lines.append(f"! instantaneous modulus G0 = {self.g_0:.10g}")
            lines.append(f"TB,PRONY,1,,{self.tau.size},SHEAR")
            pairs = [v for t, g in zip(self.tau, self.g, strict=True)
                     for v in (g / self.g_0, t)]
            for start in range(0, len(pairs), 6):  # TBDATA takes six values per command
                chunk = ",".join(f"{v:.10g}" for v in pairs[start:start + 6])
                lines.append(f"TBDATA,{start + 1},{chunk}")
            if law is not None:
                p, t_ref = law["parameters"], law["reference_temperature"]
                if law["name"] == "wlf":
                    lines += ["TB,SHIFT,1,,3,WLF",
                              f"TBDATA,1,{t_ref:.10g},{p['C1']:.10g},{p['C2']:.10g}"]
                else:
                    lines += ["! Arrhenius as Tool-Narayanaswamy: ln A = (Ea/R) (1/T_r - 1/T), "
                              "T in kelvin", "TB,SHIFT,1,,2,TN",
                              f"TBDATA,1,{t_ref + KELVIN:.10g},{p['Ea'] / GAS_CONSTANT:.10g}"]
        return "\n".join(lines) + "\n"

    def _lsdyna(self, head: list[str]) -> list[str]:
        """*MAT_GENERAL_VISCOELASTIC in LS-DYNA's fixed 10-character fields."""
        rows = [(g, 1.0 / t) for t, g in zip(self.tau, self.g, strict=True)]
        if self.g_inf > 0:
            rows.append((self.g_inf, 0.0))
        if len(rows) > LSDYNA_MAX_TERMS:
            raise InputError(f"export: LS-DYNA's *MAT_GENERAL_VISCOELASTIC takes at most "
                             f"{LSDYNA_MAX_TERMS} terms (G_inf counts as one), this series has "
                             f"{len(rows)}; ask for fewer (terms {LSDYNA_MAX_TERMS - 1} or 1 per "
                             "decade)")

        def field(v: float) -> str:  # 4 significant digits: a blank keeps the fields apart
            return f"{v:10.3E}" if v != 0 else f"{0.0:10.1f}"

        lines = [f"$ {h}" for h in head]
        lines += ["$ GI: shear moduli in the data's unit (a tensile E series: divide each by "
                  "2(1+nu)); BETAI = 1/tau_i [1/s]; the row with BETAI = 0 is G_inf",
                  "$ RO (density) and BULK (bulk modulus) are not measured in shear: give them "
                  "in the units of your model"]
        if self.shift_law is not None:
            lines.append("$ TREF, A, B (the shift function) are left 0: enter the shift law "
                         "above in the convention of your LS-DYNA version")
        lines += ["*KEYWORD", "*MAT_GENERAL_VISCOELASTIC",
                  "$      MID        RO      BULK       PCF        EF      TREF         A"
                  "         B",
                  f"{1:>10d}" + " " * 20 + field(0.0) * 5,
                  "$     LCID        NT    BSTART     TRAMP     LCIDK       NTK   BSTARTK"
                  "    TRAMPK",
                  f"{0:>10d}{0:>10d}" + field(0.0) * 2 + f"{0:>10d}{0:>10d}" + field(0.0) * 2,
                  "$       GI     BETAI        KI    BETAKI"]
        lines += [field(g) + field(b) + field(0.0) * 2 for g, b in rows]
        lines.append("*END")
        return lines

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
        from ..data.symbols import modulus_symbol

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
        unit = f" {self.unit}" if self.unit else ""
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
                    f"{law['reference_temperature']:.10g} C, C1 = {p['C1']:.10g}, "
                    f"C2 = {p['C2']:.10g} C")
        else:
            form = (f"Arrhenius log10 a_T = Ea/(R ln 10) (1/T - 1/T_ref) in kelvin, T_ref = "
                    f"{law['reference_temperature']:.10g} C, Ea = {p['Ea']:.10g} J/mol")
        return (f"shift law: {form}; fitted to the shifts of isotherms at {lo:g} to {hi:g} C "
                f"(chi2/dof {law['chi2_per_dof']:.3g})")


def prony_series(result, *, per_decade: int = 2, liquid: bool | None = None,
                 structure: str | None = None, average: str | None = None,
                 seed: int = 0, terms: int | None = None) -> Prony:
    """A Prony series fitted to a comparison's structure (default the best ranked) or average.

    Parameters
    ----------
    result : Comparison or MasterCurve
        A master curve gives the series at its reference temperature, with its shift law.
    per_decade : int
        Relaxation times per decade (1 to 10).
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
    terms : int, optional
        The number of relaxation times (2 to 100, log-spaced over the same span) instead of
        ``per_decade``; terms whose weight comes out zero are dropped, so the series may have
        fewer.

    Returns
    -------
    Prony
    """
    from scipy.optimize import nnls

    from .functions import predict
    from .long_time import long_time_modulus

    if isinstance(per_decade, bool) or not isinstance(per_decade, int) or not 1 <= per_decade <= 10:
        raise InputError(f"export: terms per decade must be an integer from 1 to 10, got "
                         f"{per_decade!r}")
    if terms is not None and (isinstance(terms, bool) or not isinstance(terms, int)
                              or not 2 <= terms <= 100):
        raise InputError(f"export: the number of terms must be an integer from 2 to 100, got "
                         f"{terms!r}")
    master = hasattr(result, "shift_draws")
    window_omega = result.reduced_omega() if master else result.data.omega
    w_lo, w_hi = float(np.min(window_omega)), float(np.max(window_omega))
    omega = np.logspace(math.log10(w_lo) - 1, math.log10(w_hi) + 1,
                        int(20 * (math.log10(w_hi / w_lo) + 2)) + 1)
    kw = dict(structure=structure, average=average, seed=seed)
    storage = predict(result, "storage", omega, **kw)
    loss = predict(result, "loss", omega, **kw)
    g = storage.median + 1j * loss.median
    model_g_inf = float(np.median(long_time_modulus(result, **kw)))
    if liquid is None:
        liquid = model_g_inf == 0.0
    if not np.all(np.isfinite(g)):
        raise InputError("export: the model's modulus is not finite over the window")
    # The terms reach TAU_MARGIN decades past the window: a power-law spectrum (a springpot)
    # relaxes over every decade, and terms only over the window leave its edges short.
    # Without G∞, a term further out takes the relaxation beyond the longest time that G∞
    # would have stood for.
    lo_tau = 1 / (w_hi * 10**TAU_MARGIN)
    hi_tau = 10**(TAU_MARGIN + (LIQUID_MARGIN if liquid else 0)) / w_lo
    n = terms if terms is not None else int(round(math.log10(hi_tau / lo_tau) * per_decade)) + 1
    tau = np.logspace(math.log10(lo_tau), math.log10(hi_tau), n)
    s = 1j * omega[:, None] * tau
    basis = s / (1 + s)
    if not liquid:
        basis = np.column_stack([np.ones(omega.size), basis])
    weight = 1.0 / np.abs(g)
    a = np.vstack([(basis.real * weight[:, None]), (basis.imag * weight[:, None])])
    b = np.r_[g.real * weight, g.imag * weight]
    x, _ = nnls(a, b, maxiter=50 * a.shape[1])
    g_inf, terms = (0.0, x) if liquid else (float(x[0]), x[1:])
    keep = terms > 0
    window = (1.0 / w_hi, 1.0 / w_lo)
    fitted = Prony(tau=tau[keep], g=terms[keep], g_inf=g_inf, unit=storage.unit,
                   source=(f"the master curve of {result.structure} at "
                           f"{result.reference_temperature:g} C" if master
                           else storage.structure or f"{storage.average} average"),
                   window=window,
                   max_rel_error_modulus=math.nan, max_rel_error_relaxation=math.nan,
                   band_rel_halfwidth=math.nan)
    inside = (omega >= w_lo) & (omega <= w_hi)
    err_g = float(np.max(np.abs(fitted.modulus(omega[inside]) - g[inside]) / np.abs(g[inside])))
    t = np.logspace(math.log10(window[0]), math.log10(window[1]), 50)
    g_t = predict(result, "relaxation_modulus", t, **kw)
    # Relative to G(t), or to 0.1 % of G0 where G(t) has relaxed below it (a liquid's tail).
    scale = np.maximum(np.abs(g_t.median), 1e-3 * fitted.g_0)
    err_t = float(np.max(np.abs(fitted.relaxation(t) - g_t.median) / scale))
    half = float(np.min((g_t.hdi_high - g_t.hdi_low) / 2 / np.abs(g_t.median)))
    from dataclasses import replace

    data = result.master_data() if master else result.data
    measured = np.abs(data.response if data.kind == "modulus" else 1.0 / data.response)
    return replace(fitted, max_rel_error_modulus=err_g, max_rel_error_relaxation=err_t,
                   band_rel_halfwidth=half, shift_law=_shift_law(result) if master else None,
                   symbol=data.symbol, measured_max=float(np.max(measured)),
                   model_g_inf=model_g_inf, g_inf_fixed=bool(liquid))


def _shift_law(mc) -> dict:
    """The master curve's preferred shift law, as :class:`Prony` carries it."""
    law = mc.shift_law()
    return {"name": law["name"], "reference_temperature": float(law["reference_temperature"]),
            "parameters": {k: float(v["mean"]) for k, v in law["parameters"].items()},
            "temperatures": (float(min(mc.temperatures)), float(max(mc.temperatures))),
            "chi2_per_dof": float(mc.laws[law["name"]]["chi2_per_dof"])}
