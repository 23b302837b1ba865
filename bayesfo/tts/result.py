"""The result of a master curve (:class:`MasterCurve`): shifts, laws, checks and the joint
posterior, with what follows from them (shift factors, the preferred law, the reduced data, the
shifts at any temperature within the isotherms)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..data import FrequencyResponse
from ..errors import InputError
from ..predictions.draws import Draws, master_draws
from .isotherms import _Isotherms, _reduced

#: A median isotherm residual (relative rms) above this says the master function does not
#: describe the isotherms at all (measurement noise is a few per cent at most).
MISFIT_RMS = 0.05
#: An isotherm whose relative residuals under the joint fit (rms) exceed this many times the
#: median isotherm's is named as one the master structure misses.
ISOTHERM_MISFIT = 3.0


# ---------------------------------------------------------------------------- result
@dataclass(frozen=True)
class MasterCurve:
    """A joint time–temperature superposition.

    Attributes
    ----------
    structure : str
        The master structure.
    temperatures : tuple of float
        The isotherms' temperatures [°C], ascending.
    reference_temperature : float
    shift_draws : ndarray, shape (n_draws, n_isotherms)
        Posterior draws of log10 a_T (0 at the reference).
    master_draws : ndarray, shape (n_draws, n_params)
        Posterior draws of the master structure's parameters (physical units, reduced time).
    posterior : PosteriorResult
        The joint posterior (structure, shifts, noise).
    log_evidence, log_evidence_err : float
        ln Z of the joint model (NaN where no route gave one).
    laws : dict
        ``{"wlf": {...}, "arrhenius": {...}}``: each law's parameters over the draws and its
        relative support (see the module).
    notes : tuple of str
    ranking : tuple of dict
        Every master structure fitted, best first: ``structure``, ``log_evidence``,
        ``log_evidence_err``, ``probability`` (equal prior odds), ``certified``, ``sampler``.
    vertical : {"none", "density", "free"}
        The vertical shift of the model (see the module).
    vertical_draws : ndarray, shape (n_draws, n_isotherms), or None
        Posterior draws of log10 b_T (0 at the reference; None without vertical shifts).
    master : Structure
        The master structure itself (its card), which predictions evaluate.
    law : {"free", "wlf", "arrhenius"}
        How the shifts were modelled (see :func:`mastercurve`).
    law_evidence : dict
        With ``law="auto"``: ``{"free" | "wlf" | "arrhenius": {"log_evidence",
        "log_evidence_err", "probability", "certified", "sampler"}}`` of the best master
        structure under each (probabilities from the ln Z of the certified ones); with
        shifts from the model-free master, of that master under each.
    shifts_from : {"smooth", "joint"}
        Where the shifts come from: the model-free master (:mod:`bayesfo.tts.smooth`), or the
        joint posterior with the master structure.
    vertical_evidence : dict
        With ``vertical="auto"``: the same as ``law_evidence`` for the vertical shifts
        (``"none"``, ``"density"``, ``"free"``).
    shift_evidence : dict
        With shifts from the model-free master: its ln Z, sampler, certificate, smoothness
        and noise (``hyperparameters``), and the isotherms whose shifts the data do not fix
        (``undetermined`` [°C]).
    """

    structure: str
    temperatures: tuple[float, ...]
    reference_temperature: float
    shift_draws: np.ndarray = field(repr=False)
    master_draws: np.ndarray = field(repr=False)
    posterior: object = field(repr=False)
    log_evidence: float
    log_evidence_err: float
    laws: dict
    data: FrequencyResponse = field(repr=False)
    isotherms: tuple = field(repr=False)
    notes: tuple[str, ...] = ()
    ranking: tuple = ()
    tts_checks: dict = field(default_factory=dict)
    vertical: str = "none"
    vertical_draws: np.ndarray | None = field(default=None, repr=False)
    master: object = field(default=None, repr=False)
    law: str = "free"
    law_evidence: dict = field(default_factory=dict)
    shifts_from: str = "joint"
    vertical_evidence: dict = field(default_factory=dict)
    shift_evidence: dict = field(default_factory=dict)

    @property
    def tts_valid(self) -> bool | None:
        """Whether superposition holds by the model-free tests of the isotherms
        (:mod:`bayesfo.tts.validity`): the van Gurp–Palmen test, and without vertical shifts
        in the model also the agreement of the shifts that G′, G″ and tan δ give (a vertical
        shift in the model accounts for their disagreement); None where neither could be
        made. ``tts_checks`` says which test failed, and where."""
        vgp = self.tts_checks.get("van_gurp_palmen")
        parts = self.tts_checks.get("shift_parts")
        found = [vgp["valid"]] if vgp is not None else []
        if parts is not None and self.vertical == "none":
            found.append(parts["consistent"])
        known = [v for v in found if v is not None]
        return None if not known else all(known)

    def misfit(self) -> str:
        """Whether the joint fit misses the isotherms, in a sentence (the median isotherm's
        relative rms over :data:`MISFIT_RMS`, or isotherms named by the isotherm-fit check);
        empty where it does not."""
        fit = self.tts_checks.get("isotherm_fit", {})
        missed = fit.get("misfit") or []
        rms = [r for r in fit.get("rms_relative", []) if r is not None]
        if rms and float(np.median(rms)) > MISFIT_RMS:
            return (f"The {'joint ' if self.shifts_from == 'joint' else ''}fit of "
                    f"{self.structure} misses the isotherms by "
                    f"{100 * min(rms):.2g}–{100 * max(rms):.2g} % rms (median "
                    f"{100 * float(np.median(rms)):.2g} %): it does not describe them; other "
                    "master functions (or 'spectrum', which needs no structure) may.")
        if missed:
            return (f"The {'joint ' if self.shifts_from == 'joint' else ''}fit of "
                    f"{self.structure} misses the isotherm(s) at "
                    f"{', '.join(f'{t:g}' for t in missed)} °C (relative residuals over "
                    f"{ISOTHERM_MISFIT:g} times the median isotherm's).")
        return ""

    @property
    def log_shift_mean(self) -> np.ndarray:
        return self.shift_draws.mean(axis=0)

    def master_data(self) -> FrequencyResponse:
        """The isotherms on the reduced frequency axis at the posterior mean shifts: a data
        set ``compare`` takes (σ adds the shifts' posterior spread to each point's own, where
        the data give σ)."""
        return _reduced(_Isotherms(self.isotherms, self.temperatures,
                                   self.temperatures.index(self.reference_temperature)),
                        self.log_shift_mean,
                        None if self.vertical_draws is None else self.vertical_draws.mean(0))

    def shift_factors(self) -> list[dict]:
        """``[{"temperature", "log10_aT": {mean, sd, hdi_low, hdi_high}, "log10_bT": ...}]``
        as ``summary.json`` holds them (log10 b_T = 0 without vertical shifts; a fixed one,
        the density correction, has sd 0)."""
        from ..inference import hdi

        def summary(x):
            lo, hi = (float(x[0]), float(x[0])) if np.ptp(x) == 0 else hdi(x, 0.94)
            return {"mean": float(x.mean()), "sd": float(x.std(ddof=1)), "hdi_low": lo,
                    "hdi_high": hi}

        vertical = (np.zeros_like(self.shift_draws) if self.vertical_draws is None
                    else self.vertical_draws)
        return [{"temperature": t, "log10_aT": summary(self.shift_draws[:, i]),
                 "log10_bT": summary(vertical[:, i])}
                for i, t in enumerate(self.temperatures)]

    def shift_law(self) -> dict:
        """``{"name", "reference_temperature", "parameters", "probabilities", "method"}``:
        the law with the larger support and its parameters."""
        probs = {k: v["probability"] for k, v in self.laws.items()}
        if self.law != "free":  # the law the joint posterior sampled
            return {"name": self.law, "reference_temperature": self.reference_temperature,
                    "parameters": self.laws[self.law]["parameters"], "probabilities": probs,
                    "method": f"the {self.law} law's parameters sampled with the "
                              + ("model-free master" if self.shifts_from == "smooth"
                                 else "master structure")
                              + " (summarised over the posterior draws)"}
        best = max(probs, key=probs.get)
        evidence = self.laws[best].get("probability_method", "").startswith("ln Z")
        return {"name": best, "reference_temperature": self.reference_temperature,
                "parameters": self.laws[best]["parameters"], "probabilities": probs,
                "method": ("ln Z of the model-free master with each law inside; parameters "
                           "fitted to each posterior draw of the shifts" if evidence else
                           "BIC of each law fitted to the posterior mean and covariance of "
                           "the shifts; parameters over the posterior draws")}

    def draws(self, structure: str | None = None, average: str | None = None, *,
              seed: int = 0, temperature: float | None = None) -> Draws:
        """The posterior draws that predictions, Prony series and long-time moduli evaluate:
        :data:`~bayesfo.predictions.draws.MAX_DRAWS` of the master structure, each with its
        own log10 a_T and log10 b_T at ``temperature`` [°C] (default the reference
        temperature; :meth:`shifts_at`).

        Raises
        ------
        InputError
            An ``average`` (a master curve has one structure), another ``structure``, or a
            temperature outside the isotherms'.
        """
        return master_draws(self, structure, average, seed=seed, temperature=temperature)

    def reduced_omega(self) -> np.ndarray:
        """The reduced angular frequencies a_T·ω [rad/s] of every point at the posterior mean
        shifts: the window at the reference temperature that the data cover."""
        return np.concatenate([d.omega * 10.0 ** m for d, m in
                               zip(self.isotherms, self.log_shift_mean, strict=True)])

    def shifts_at(self, temperature: float) -> tuple[np.ndarray, np.ndarray]:
        """Posterior draws of log10 a_T and log10 b_T at ``temperature`` [°C], paired with
        :attr:`master_draws` row by row.

        At an isotherm's temperature they are that isotherm's draws. Between two isotherms,
        each draw's log10 a_T is the preferred shift law (:meth:`shift_law`, posterior means)
        plus that draw's departure from the law, interpolated linearly in 1/T (kelvin)
        between the two isotherms: exact where the law holds, and following the shifts
        where it does not. Free vertical shifts are interpolated the same way (without a law);
        the density correction is exact at any temperature.

        Raises
        ------
        InputError
            A temperature outside the isotherms' range (a shift law extrapolated beyond the
            measured temperatures is a guess this does not make).
        """
        from .laws import arrhenius, wlf
        from .model import KELVIN

        try:
            t = float(temperature)
        except (TypeError, ValueError):
            raise InputError(f"temperature must be a number in °C, got {temperature!r}",
                             option="temperature") from None
        temps = np.asarray(self.temperatures, float)
        if not (np.isfinite(t) and temps[0] - 1e-9 <= t <= temps[-1] + 1e-9):
            raise InputError(f"temperature {t:g} °C is outside the isotherms "
                             f"({temps[0]:g} to {temps[-1]:g} °C): the master curve says "
                             "nothing measured there", option="temperature")
        vertical = (np.zeros_like(self.shift_draws) if self.vertical_draws is None
                    else self.vertical_draws)
        hi = int(np.clip(np.searchsorted(temps, t), 1, temps.size - 1))
        lo = hi - 1
        inv = 1.0 / (temps + KELVIN)
        f = (1.0 / (t + KELVIN) - inv[lo]) / (inv[hi] - inv[lo])
        law = self.shift_law()
        p = {k: v["mean"] for k, v in law["parameters"].items()}
        ref = self.reference_temperature

        def base(x):
            return (wlf(x, ref, p["C1"], p["C2"]) if law["name"] == "wlf"
                    else arrhenius(x, ref, p["Ea"]))

        off = self.shift_draws[:, [lo, hi]] - base(temps[[lo, hi]])
        a = base(t) + (1 - f) * off[:, 0] + f * off[:, 1]
        if self.vertical == "density":
            b = np.full(a.shape, np.log10((ref + KELVIN) / (t + KELVIN)))
        else:
            b = (1 - f) * vertical[:, lo] + f * vertical[:, hi]
        return a, b

    def __repr__(self) -> str:
        temps = self.temperatures
        return (f"<MasterCurve of {self.structure} at {self.reference_temperature:g} °C from "
                f"{len(temps)} isotherms ({min(temps):g} to {max(temps):g} °C); shifts: "
                + ("free" if self.law == "free" else self.law) + ">")

    def _repr_html_(self) -> str:
        from .notebook import mastercurve_html

        return mastercurve_html(self)

    def to_dict(self) -> dict:
        return {"structure": self.structure, "reference_temperature": self.reference_temperature,
                "temperatures": list(self.temperatures),
                "log_evidence": _num(self.log_evidence),
                "log_evidence_err": _num(self.log_evidence_err),
                "certified": bool(self.posterior.converged),
                "sampler": self.posterior.sampler,
                "parameters": {n: {k: _num(getattr(v, k)) for k in
                                   ("mean", "sd", "hdi_low", "hdi_high")}
                               for n, v in self.posterior.summary.items()
                               if not n.startswith(("log10_aT_", "log10_bT_"))},
                "vertical": self.vertical, "law": self.law,
                "law_evidence": self.law_evidence, "shifts_from": self.shifts_from,
                "vertical_evidence": self.vertical_evidence,
                "shift_evidence": self.shift_evidence,
                "structures": list(self.ranking),
                "shift_factors": self.shift_factors(), "shift_law": self.shift_law(),
                "laws": self.laws, "tts_valid": self.tts_valid, "tts_checks": self.tts_checks,
                "notes": list(self.notes)}


def _num(x):
    x = float(x)
    return x if math.isfinite(x) else None
