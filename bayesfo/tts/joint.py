"""Time–temperature superposition as one posterior: a master structure and every isotherm's
horizontal shift log10 a_T, on all isotherms' complex data at once.

Isotherm i, measured at temperature T_i, is modelled as the master function at reduced
frequency: G_i(ω) = G_master(a_T,i · ω) / b_T,i, with a_T = b_T = 1 at the reference
temperature. The parameters are the master structure's, one log10 a_T per other isotherm
(uniform prior over ±:data:`~bayesfo.tts.model.SHIFT_RANGE` decades: no bound on the step
between neighbours, and a shift the data do not fix, over a featureless plateau, comes out wide
rather than pinned) and the noise. The vertical factor b_T is 1 (``vertical="none"``), the
density correction of entropic elasticity b_T = T_ref/T in kelvin with a constant density
(``"density"``), or one log10 b_T per other isotherm (``"free"``, uniform over
±:data:`~bayesfo.tts.model.VERTICAL_RANGE` decades); compliances scale the other way,
J_i(ω) = b_T,i J_master(a_T,i · ω). The model is :class:`~bayesfo.tts.model.ShiftedStructure`.
The posterior and ln Z come from :func:`bayesfo.inference.certified_posterior`, as in ``compare``.

Seeds: the shift between neighbouring isotherms that best overlays their log|G*| and phase
(where their reduced windows overlap), then the master structure fitted to the data so
reduced, then a joint least-squares fit of everything.

The shift laws, WLF and Arrhenius, are fitted to the posterior draws of the shifts
(:mod:`bayesfo.tts.laws`). Whether superposition holds at all is tested on the isotherms
themselves, without a model (:mod:`bayesfo.tts.validity`), and each isotherm's residuals under
the joint fit name those the master structure misses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..data import FrequencyResponse
from ..errors import InputError
from .laws import _fit_laws
from .model import LAWS, ShiftedStructure
from .spectrum import NAME as SPECTRUM
from .spectrum import Spectrum

#: The vertical shifts ``mastercurve`` knows.
VERTICAL = ("none", "density", "free")
#: Free vertical shifts beyond this many decades (a factor of 1.26) exceed the density and
#: temperature ratios they stand for: a note says they likely absorb a misfit of the master.
VERTICAL_PLAUSIBLE = 0.1
#: A law whose χ²/dof against the shifts' posterior exceeds this misses them: a note says so
#: (the 99.9 % point of χ²/dof for 5 degrees of freedom is 4.1).
LAW_MISS = 4.0
#: Isotherms from which ``law="auto"`` also fits the laws inside the posterior: with fewer,
#: WLF has as many parameters as there are shifts, and the comparison says nothing.
AUTO_LAWS_MIN = 4
#: An isotherm whose relative residuals under the joint fit (rms) exceed this many times the
#: median isotherm's is named as one the master structure misses.
ISOTHERM_MISFIT = 3.0


# ---------------------------------------------------------------------------- inputs
@dataclass(frozen=True)
class _Isotherms:
    """The isotherms in order of temperature, checked."""

    data: tuple[FrequencyResponse, ...]
    temperatures: tuple[float, ...]
    reference: int

    @cached_property
    def joint(self) -> FrequencyResponse:
        omega = np.concatenate([d.omega for d in self.data])
        response = np.concatenate([d.response for d in self.data])
        sigma = (np.concatenate([d.sigma for d in self.data])
                 if all(d.sigma is not None for d in self.data) else None)
        first = self.data[0]
        return FrequencyResponse(
            omega, response, sigma, kind=first.kind, units=first.units,
            name=f"{first.label.split(',')[0]}: {len(self.data)} isotherms, "
                 f"{min(self.temperatures):g} to {max(self.temperatures):g} °C",
            source=first.source, distinct_frequencies=False, symbol=first.symbol)

    @cached_property
    def point_isotherm(self) -> np.ndarray:
        return np.concatenate([np.full(d.n_frequencies, i) for i, d in enumerate(self.data)])


def _isotherms(isotherms, reference_temperature) -> _Isotherms:
    """Check and sort the isotherms: (FrequencyResponse, temperature) pairs or objects with
    ``data`` and ``temperature`` (:class:`bayesfo.data.Isotherm`)."""
    pairs = []
    for k, item in enumerate(isotherms):
        if hasattr(item, "data") and hasattr(item, "temperature"):
            data, temperature = item.data, item.temperature
        else:
            try:
                data, temperature = item
            except (TypeError, ValueError):
                raise InputError(f"isotherm {k + 1}: give (FrequencyResponse, temperature in °C) "
                                 "or an Isotherm of bayesfo.read_isotherms") from None
        if not isinstance(data, FrequencyResponse):
            raise InputError(f"isotherm {k + 1}: the data must be a FrequencyResponse")
        if temperature is None or not math.isfinite(float(temperature)):
            raise InputError(f"isotherm {k + 1} ({data.label}): no temperature; give each "
                             "isotherm's temperature in °C")
        pairs.append((data, float(temperature)))
    if len(pairs) < 2:
        raise InputError(f"a master curve needs two or more isotherms, got {len(pairs)}")
    pairs.sort(key=lambda p: p[1])
    temps = [t for _, t in pairs]
    for a, b in zip(temps, temps[1:]):
        if abs(a - b) < 0.5:
            raise InputError(f"two isotherms at {a:g} and {b:g} °C: temperatures must differ "
                             "(by 0.5 °C or more); merge or drop one")
    kinds = {d.kind for d, _ in pairs}
    if len(kinds) > 1 or kinds & {"generic"}:
        raise InputError("the isotherms must all be modulus or all compliance data, got "
                         + ", ".join(sorted(kinds)))
    units = {d.units for d, _ in pairs}
    if len(units) > 1:
        raise InputError("the isotherms are in different units (" + ", ".join(sorted(units))
                         + "); convert them to one")
    if reference_temperature is None:
        ref = len(pairs) // 2
    else:
        ref = int(np.argmin([abs(t - reference_temperature) for t in temps]))
        if abs(temps[ref] - reference_temperature) > 0.5:
            raise InputError(f"reference temperature {reference_temperature:g} °C: no isotherm "
                             f"there; the isotherms are at {', '.join(f'{t:g}' for t in temps)} °C")
    return _Isotherms(tuple(d for d, _ in pairs), tuple(temps), ref)


# ---------------------------------------------------------------------------- seeds
def _pair_shift(lower: FrequencyResponse, upper: FrequencyResponse) -> float:
    """log10 of the factor by which ``upper``'s frequencies are multiplied to lie on
    ``lower``'s curve (log|G*| and phase overlaid where the two overlap), by a grid search."""
    def curve(d):
        order = np.argsort(d.omega)
        return (np.log10(d.omega[order]), np.log10(np.abs(d.response[order])),
                np.angle(d.response[order]))

    xl, ml, pl = curve(lower)
    xu, mu, pu = curve(upper)
    span = max(xl.max(), xu.max()) - min(xl.min(), xu.min())
    best, best_cost = 0.0, np.inf
    for d in np.arange(-span - 2.0, span + 2.0, 0.02):
        x = xu + d
        inside = (x >= xl.min()) & (x <= xl.max())
        if inside.sum() < 2:
            continue
        cost = (np.mean((np.interp(x[inside], xl, ml) - mu[inside]) ** 2)
                + np.mean((np.interp(x[inside], xl, pl) - pu[inside]) ** 2))
        # Fewer overlapping points are worth less: a shift that overlays one point trivially
        # must not beat one that overlays the whole sweep.
        cost *= 1.0 + 1.0 / inside.sum()
        if cost < best_cost:
            best, best_cost = float(d), cost
    return best


def _seed_shifts(iso: _Isotherms) -> np.ndarray:
    """log10 a_T of each isotherm from the pairwise overlays, 0 at the reference."""
    n = len(iso.data)
    steps = [_pair_shift(iso.data[i], iso.data[i + 1]) for i in range(n - 1)]
    shifts = np.zeros(n)
    for i in range(iso.reference + 1, n):
        shifts[i] = shifts[i - 1] + steps[i - 1]
    for i in range(iso.reference - 1, -1, -1):
        shifts[i] = shifts[i + 1] - steps[i]
    return shifts


def _reduced(iso: _Isotherms, log_shifts, log_vertical=None) -> FrequencyResponse:
    """The isotherms on one reduced frequency axis (a_T ω), each multiplied by b_T (a
    compliance divided by it), sorted; points that land on the same frequency averaged."""
    j = iso.joint
    omega = j.omega * 10.0 ** np.asarray(log_shifts)[iso.point_isotherm]
    b = np.ones_like(omega) if log_vertical is None else \
        10.0 ** np.asarray(log_vertical)[iso.point_isotherm]
    scale = b if j.kind == "modulus" else 1.0 / b
    order = np.argsort(omega)
    omega, response = omega[order], (j.response * scale)[order]
    keep = np.r_[True, np.diff(omega) > 1e-12 * omega[1:]]
    groups = np.cumsum(keep) - 1
    n = groups[-1] + 1
    r = np.zeros(n, complex)
    np.add.at(r, groups, response)
    r /= np.bincount(groups)
    sigma = None
    if j.sigma is not None:
        s2 = np.zeros(n)
        np.add.at(s2, groups, (j.sigma * scale)[order] ** 2)
        sigma = np.sqrt(s2) / np.bincount(groups)
    return FrequencyResponse(omega[keep], r, sigma, kind=j.kind, units=j.units,
                             name=f"master curve of {j.label}", source=j.source,
                             symbol=j.symbol)


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
        structure under each (probabilities from the ln Z of the certified ones).
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
        from ..inference._arviz import hdi

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
                    "method": f"the {self.law} law's parameters sampled with the master "
                              "structure (summarised over the posterior draws)"}
        best = max(probs, key=probs.get)
        return {"name": best, "reference_temperature": self.reference_temperature,
                "parameters": self.laws[best]["parameters"], "probabilities": probs,
                "method": "BIC of each law fitted to the posterior mean and covariance of the "
                          "shifts; parameters over the posterior draws"}

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
            raise InputError(f"temperature must be a number in °C, got {temperature!r}") from None
        temps = np.asarray(self.temperatures, float)
        if not (np.isfinite(t) and temps[0] - 1e-9 <= t <= temps[-1] + 1e-9):
            raise InputError(f"temperature {t:g} °C is outside the isotherms "
                             f"({temps[0]:g} to {temps[-1]:g} °C): the master curve says "
                             "nothing measured there")
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
                "law_evidence": self.law_evidence,
                "structures": list(self.ranking),
                "shift_factors": self.shift_factors(), "shift_law": self.shift_law(),
                "laws": self.laws, "tts_valid": self.tts_valid, "tts_checks": self.tts_checks,
                "notes": list(self.notes)}


def _num(x):
    x = float(x)
    return x if math.isfinite(x) else None


# ---------------------------------------------------------------------------- the fit
def mastercurve(isotherms, structures="zener", *, reference_temperature: float | None = None,
                noise: str = "proportional", vertical: str = "none", law: str = "auto",
                seed: int = 0) -> MasterCurve:
    """One joint posterior of a master structure and the isotherms' shifts; with several
    structures, each is fitted and the one of highest ln Z is returned, with the ranking.

    Parameters
    ----------
    isotherms : sequence
        ``(FrequencyResponse, temperature [°C])`` pairs, or :class:`bayesfo.data.Isotherm`
        objects (``bayesfo.read_isotherms`` of a TRIOS, pyvisco or temperature-column file).
    structures : str, Structure or sequence
        The master function: a structure of the library, or several (a comma list or a
        sequence), ranked by ln Z on the joint data as ``compare`` ranks them; ``"spectrum"``
        is a discrete relaxation spectrum with a smoothness prior, which needs no structure
        (:mod:`bayesfo.tts.spectrum`).
    reference_temperature : float, optional
        [°C]; an isotherm's temperature (default: the middle isotherm).
    noise : {"proportional", "constant", "known"}
        ``proportional`` suits data spanning decades (as isotherms do).
    vertical : {"none", "density", "free"}
        The vertical shift b_T: none; the density correction b_T = T_ref/T [K] (constant
        density); or one free log10 b_T per isotherm (see the module).
    law : {"auto", "free", "wlf", "arrhenius"}
        The horizontal shifts: one free log10 a_T per isotherm (``"free"``), or those of the
        WLF or Arrhenius law with its parameters sampled jointly (``"wlf"``,
        ``"arrhenius"``). ``"auto"`` ranks the master structures with free shifts, then fits
        the best one with each law too and keeps the model of highest ln Z among the three
        (a law is kept only where its posterior is certified); ``law_evidence`` says how
        the three compare. With fewer than :data:`AUTO_LAWS_MIN` isotherms, ``"auto"`` is
        ``"free"``.
    seed : int

    Returns
    -------
    MasterCurve

    Raises
    ------
    InputError
        Fewer than two isotherms, a missing or repeated temperature, isotherms of different
        kinds or units, a reference temperature without an isotherm.
    """
    if vertical not in VERTICAL:
        raise InputError(f"vertical must be one of {', '.join(VERTICAL)}, got {vertical!r}")
    if law not in ("auto", *LAWS):
        raise InputError(f"law must be one of auto, {', '.join(LAWS)}, got {law!r}")
    names = _master_names(structures)
    iso = _isotherms(isotherms, reference_temperature)
    first = "free" if law == "auto" else law
    fits = [_fit_one(iso, s, noise, seed, vertical, first) for s in names]
    z = np.array([f.log_evidence if math.isfinite(f.log_evidence) else -np.inf for f in fits])
    best = int(np.argmax(z))
    p = np.exp(z - z[best]) if np.isfinite(z[best]) else np.full(z.size, np.nan)
    p = p / np.nansum(p)
    ranking = tuple(
        {"structure": f.structure, "log_evidence": _num(f.log_evidence),
         "log_evidence_err": _num(f.log_evidence_err), "probability": _num(pi),
         "certified": bool(f.posterior.converged), "sampler": f.posterior.sampler}
        for f, pi in sorted(zip(fits, p, strict=True), key=lambda fp: -fp[0].log_evidence
                            if math.isfinite(fp[0].log_evidence) else np.inf))
    from dataclasses import replace

    from .validity import describe, describe_parts, shifts_by_part, van_gurp_palmen

    chosen = fits[best]
    law_evidence, law_notes = {}, []
    if law == "auto" and len(iso.temperatures) >= AUTO_LAWS_MIN:
        chosen, law_evidence, law_notes = _choose_law(
            iso, names[best], chosen, lambda how: _fit_one(iso, names[best], noise, seed,
                                                           vertical, how))
    vgp = van_gurp_palmen(iso.data, iso.temperatures)
    parts = shifts_by_part(iso.data, iso.temperatures)
    checks = {"van_gurp_palmen": vgp, "shift_parts": parts,
              "isotherm_fit": chosen.tts_checks["isotherm_fit"]}
    notes = list(chosen.notes) + law_notes
    if vgp["valid"] is not True:
        notes.append(describe(vgp))
    if parts["consistent"] is False:
        notes.append(describe_parts(parts) + (
            "" if vertical == "none" else " (the model's vertical shifts account for the "
                                          "former)"))
    misfit = checks["isotherm_fit"]["misfit"]
    if misfit:
        notes.append(f"the joint fit of {chosen.structure} misses the isotherm(s) at "
                     f"{', '.join(f'{t:g}' for t in misfit)} °C: their relative residuals are "
                     f"over {ISOTHERM_MISFIT:g} times the median isotherm's")
    return replace(chosen, ranking=ranking, tts_checks=checks, notes=tuple(notes),
                   law_evidence=law_evidence)


def _master_names(structures) -> list:
    """The master functions asked for: structures of the library (names resolved as
    ``compare`` resolves them) and ``"spectrum"`` (:mod:`bayesfo.tts.spectrum`)."""
    from ..structures import resolve_structures

    if isinstance(structures, str):
        parts = [p.strip() for p in structures.split(",") if p.strip()]
        rest = ",".join(p for p in parts if p.lower() != SPECTRUM)
        names = resolve_structures(rest) if rest else []
        return ([SPECTRUM] if any(p.lower() == SPECTRUM for p in parts) else []) + list(names)
    return [structures] if not isinstance(structures, (list, tuple)) else list(structures)


def _choose_law(iso: _Isotherms, structure, free: MasterCurve, fit) -> tuple:
    """The model of highest ln Z among free shifts (``free``, fitted) and the WLF and
    Arrhenius laws (``fit(law)``), a law only where its posterior is certified; with
    ``law_evidence`` and a note."""
    fits = {"free": free, **{how: fit(how) for how in ("wlf", "arrhenius")}}
    z = {k: f.log_evidence if math.isfinite(f.log_evidence) and f.posterior.converged
         else -np.inf for k, f in fits.items()}
    z["free"] = free.log_evidence if math.isfinite(free.log_evidence) else -np.inf
    top = max(z, key=z.get)
    if not np.isfinite(z[top]):
        return free, {}, []
    p = {k: math.exp(v - z[top]) for k, v in z.items()}
    total = sum(p.values())
    evidence = {k: {"log_evidence": _num(fits[k].log_evidence),
                    "log_evidence_err": _num(fits[k].log_evidence_err),
                    "probability": p[k] / total, "certified": bool(fits[k].posterior.converged),
                    "sampler": fits[k].posterior.sampler} for k in fits}
    name = {"free": "free shifts", "wlf": "the WLF law", "arrhenius": "the Arrhenius law"}
    runner = max((k for k in z if k != top), key=z.get)
    gap = z[top] - z[runner]
    how = f"ln Z {gap:.1f} above {name[runner]}" if np.isfinite(gap) else \
        f"{name[runner]} gave no certified ln Z"
    if top == "free":
        note = (f"the shifts follow neither shift law over all isotherms: free shifts are "
                f"supported ({how}); the shift factors are each isotherm's own")
    else:
        note = (f"the shifts follow {name[top]} ({how}): the shift factors are the law's, "
                "sampled with the master structure")
    return fits[top], evidence, [note]


def _fit_one(iso: _Isotherms, structure, noise: str, seed: int,
             vertical: str = "none", law: str = "free") -> MasterCurve:
    """The joint posterior with one master structure."""
    from scipy.optimize import least_squares

    from ..identify.optimize import fit_structure
    from ..inference import Likelihood, certified_posterior
    from ..inference.transform import _Transform
    from ..structures import Scaling, get_structure
    from ..structures.response import dissipation_grid

    spectral = structure == SPECTRUM or isinstance(structure, Spectrum)
    if not spectral:
        master = get_structure(structure) if isinstance(structure, str) else structure
    joint = iso.joint
    scaling = Scaling.from_data(joint)
    shifts0 = _seed_shifts(iso)
    # The master's dissipation is checked over the reduced window the seeds span, widened.
    reduced0 = _reduced(iso, shifts0)
    w = reduced0.omega / scaling.omega_ref
    if spectral:  # its relaxation times span the reduced window the seeds give, widened
        master = Spectrum.over(w.min(), w.max())
    shifted = ShiftedStructure(master, iso.temperatures, iso.reference, iso.point_isotherm,
                               dissipation_grid(w.min(), w.max()), vertical, law)
    lik = Likelihood(shifted, joint, noise=noise, scaling=scaling)
    # Master seeds on the reduced data, then everything jointly (least squares on relative
    # residuals, in the sampling coordinates: logs of the log-uniform parameters).
    if spectral:
        modes = master.seed(FrequencyResponse(w, reduced0.response / scaling.g_ref,
                                              kind=joint.kind))[None, :]
    else:
        fit = fit_structure(master, reduced0, rng=seed, seed_methods=True, scaling=scaling)
        modes = master.to_scaled(master.to_physical(
            np.atleast_2d(fit.optima if fit.optima.size else fit.theta_scaled), fit.scaling),
            scaling)
    shift_cols = _law_start(iso, shifts0, shifted) if law != "free" else \
        np.delete(shifts0, iso.reference)
    if vertical == "free":
        shift_cols = np.r_[shift_cols, np.zeros(len(shifted.shifted))]
    tr = _Transform(lik)
    k_all = shifted.n_params
    log, lo, hi = tr.log[:k_all], tr.lo_u[:k_all], tr.hi_u[:k_all]
    g = lik.g_scaled

    def to_theta(u):
        return np.where(log, np.exp(u), u)

    def residuals(u):
        model = lik.model(to_theta(u)[None, :])[0]
        r = (model - g) / np.abs(g)
        return np.r_[r.real, r.imag] if np.all(np.isfinite(r)) else np.full(2 * g.size, 1e3)

    best = None
    for mode in modes[:4]:
        theta0 = np.r_[mode, shift_cols]
        with np.errstate(divide="ignore"):
            u0 = np.where(log, np.log(np.abs(theta0)), theta0)
        u0 = np.clip(u0, lo + 1e-9, hi - 1e-9)
        sol = least_squares(residuals, u0, bounds=(lo, hi), x_scale="jac",
                            max_nfev=max(400, 40 * k_all))
        theta = to_theta(sol.x)
        if shifted.admissible(theta, joint.kind) and (best is None or sol.cost < best[1]):
            best = (theta, sol.cost)
    notes = []
    if best is None:
        raise InputError(f"no admissible joint fit of {master.name} to the isotherms; try "
                         "another structure")
    found = certified_posterior(lik, best[0][None, :], sampler="auto", seed=seed)
    notes.extend(found.notes)
    post = found.posterior
    if not post.converged:
        notes.append(f"{master.name}: the joint posterior is not certified "
                     f"({'; '.join(post.messages)})")
    physical = np.asarray(post.samples)
    k = master.n_params
    # Each isotherm's relative residual (rms over its points) of the posterior median model
    # (the median of the curves over draws: a spectrum's parameters taken one by one at their
    # medians make a curve no draw has).
    rows = np.random.default_rng(seed).choice(post.samples_scaled.shape[0],
                                              size=min(200, post.samples_scaled.shape[0]),
                                              replace=False)
    curves = lik.model(post.samples_scaled[rows, :k_all])
    fitted = np.median(curves.real, axis=0) + 1j * np.median(curves.imag, axis=0)
    rel = np.abs(fitted - g) / np.abs(g)
    rms = np.array([math.sqrt(float(np.mean(rel[iso.point_isotherm == i] ** 2)))
                    for i in range(len(iso.data))])
    isotherm_fit = {"temperatures": list(iso.temperatures), "rms_relative": rms.tolist(),
                    "misfit": [t for t, r in zip(iso.temperatures, rms, strict=True)
                               if r > ISOTHERM_MISFIT * np.median(rms)]}
    shift_draws = shifted.log_shifts(physical[:, :k_all])
    ev = found.evidence
    laws = _fit_laws(shift_draws, iso.temperatures, iso.reference, seed)
    preferred = max(laws, key=lambda name: laws[name]["probability"])
    if laws[preferred]["chi2_per_dof"] > LAW_MISS:
        law = laws[preferred]
        notes.append(f"the {'WLF' if preferred == 'wlf' else 'Arrhenius'} law, the better of the two, "
                     f"misses the shifts beyond their uncertainty (chi2/dof "
                     f"{law['chi2_per_dof']:.3g}; most at {law['worst_temperature']:g} °C, by "
                     f"{law['worst_deviation']:+.2f} decades): neither law holds over the whole "
                     "range (e.g. WLF above the glass transition only)")
    vertical_draws = None if vertical == "none" else shifted.log_vertical(physical[:, :k_all])
    if vertical == "free":
        mean_b = vertical_draws.mean(axis=0)
        worst = int(np.argmax(np.abs(mean_b)))
        if abs(mean_b[worst]) > VERTICAL_PLAUSIBLE:
            notes.append(
                f"{master.name}: the free vertical shifts reach {mean_b[worst]:+.2f} decades "
                f"(b_T = {10.0 ** mean_b[worst]:.2g} at {iso.temperatures[worst]:g} °C), beyond "
                f"the density and temperature ratios they stand for (±{VERTICAL_PLAUSIBLE:g}): "
                "they likely absorb a misfit of the master structure; compare the ln Z with "
                "vertical='none' or 'density', and other structures")
    return MasterCurve(
        structure=master.name, temperatures=iso.temperatures,
        reference_temperature=iso.temperatures[iso.reference], shift_draws=shift_draws,
        master_draws=physical[:, :k], posterior=post,
        log_evidence=math.nan if ev is None else ev.log_z,
        log_evidence_err=math.nan if ev is None else ev.log_z_err, laws=laws, data=joint,
        isotherms=iso.data, notes=tuple(notes), tts_checks={"isotherm_fit": isotherm_fit},
        vertical=vertical, vertical_draws=vertical_draws,
        master=master.physical(scaling) if spectral else master, law=shifted.law)


def _law_start(iso: _Isotherms, shifts0, shifted: ShiftedStructure) -> np.ndarray:
    """The shift law's parameters fitted to the seed shifts, inside their priors."""
    from scipy.optimize import least_squares

    from .laws import arrhenius, wlf

    temps = np.asarray(iso.temperatures, float)
    t_ref = temps[iso.reference]
    bounds = np.array([p.prior.bounds for p in shifted.horizontal], float)
    if shifted.law == "arrhenius":
        basis = arrhenius(temps, t_ref, 1.0)
        start = np.array([float(basis @ shifts0 / (basis @ basis))])
    else:
        c2 = min(max(51.6, bounds[1, 0] + 10.0), bounds[1, 1])
        sol = least_squares(lambda q: wlf(temps, t_ref, q[0], q[1]) - shifts0, [10.0, c2],
                            bounds=(bounds[:, 0] + 1e-9, bounds[:, 1] - 1e-9))
        start = sol.x
    return np.clip(start, bounds[:, 0] * (1 + 1e-9) + 1e-12, bounds[:, 1] * (1 - 1e-9))
