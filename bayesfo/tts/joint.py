"""Time–temperature superposition: :func:`mastercurve`, the entry point, and the joint route.

By default (``shifts="smooth"``) the shifts come from the model-free master
(:mod:`bayesfo.tts.smooth`, chosen among noise models, vertical shifts and laws by
:mod:`bayesfo.tts.shifts`) and the master structures are fitted to the isotherms so shifted
(:mod:`bayesfo.tts.conditional`). The joint route (``shifts="joint"``), described below, fits
a master structure and every isotherm's horizontal shift log10 a_T as one posterior, on all
isotherms' complex data at once.

Isotherm i, measured at temperature T_i, is modelled as the master function at reduced
frequency: G_i(ω) = G_master(a_T,i · ω) / b_T,i, with a_T = b_T = 1 at the reference
temperature. The parameters are the master structure's, one log10 a_T per other isotherm
(uniform prior over ±:data:`~bayesfo.tts.model.SHIFT_RANGE` decades, or ± the largest seed
shift plus :data:`~bayesfo.tts.model.SHIFT_MARGIN` where the isotherms span more: no bound on
the step between neighbours, and a shift the data do not fix, over a featureless plateau, comes
out wide rather than pinned) and the noise. The vertical factor b_T is 1 (``vertical="none"``), the
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
from dataclasses import dataclass

import numpy as np

from ..data import FrequencyResponse
from ..errors import InputError
from ..inference.bound import model_probabilities
from ..parallel import check_workers
from .isotherms import _Isotherms, _isotherms, _reduced, _seed_shifts  # noqa: F401
from .laws import _fit_laws
from .model import LAWS, SHIFT_MARGIN, SHIFT_RANGE, ShiftedStructure
from .result import ISOTHERM_MISFIT, MasterCurve, _num
from .shifts import BOUND_MARGIN
from .smooth_posterior import UNDETERMINED
from .spectrum import NAME as SPECTRUM
from .spectrum import Spectrum

#: The vertical shifts ``mastercurve`` knows.
VERTICAL = ("none", "density", "free")
#: Where the shifts come from: the model-free master, or each structure's joint posterior.
SHIFTS_FROM = ("smooth", "joint")
#: The noise models of a master curve.
NOISE_MODELS = ("relative_parts", "proportional", "constant", "known")
#: Free vertical shifts beyond this many decades (a factor of 1.26) exceed the density and
#: temperature ratios they stand for: a note says they likely absorb a misfit of the master.
VERTICAL_PLAUSIBLE = 0.1
#: A law whose χ²/dof against the shifts' posterior exceeds this misses them: a note says so
#: (the 99.9 % point of χ²/dof for 5 degrees of freedom is 4.1).
LAW_MISS = 4.0
#: Isotherms from which ``law="auto"`` also fits the laws inside the posterior: with fewer,
#: WLF has as many parameters as there are shifts, and the comparison says nothing.
AUTO_LAWS_MIN = 4
#: A shift law whose best joint fit lies this many nats below the free shifts' ln Z is not
#: sampled (``law="auto"``): ln Z ≤ max ln L for any normalised prior, so its posterior
#: probability is below e^-LAW_BOUND_MARGIN, and certifying a posterior that far behind (often
#: by the tempered ladder: the law pulls its parameters against their bounds) would cost more
#: than all the rest.
LAW_BOUND_MARGIN = BOUND_MARGIN  # the one bound margin (bayesfo.inference.bound)


@dataclass(frozen=True)
class _Bounded:
    """A shift law not sampled: its best joint fit's log-likelihood (maximum-likelihood noise),
    which bounds its ln Z from above."""

    law: str
    log_likelihood: float


# ---------------------------------------------------------------------------- the fit
def mastercurve(isotherms, structures="zener", *, reference_temperature: float | None = None,
                noise: str = "auto", vertical: str = "auto", law: str = "auto",
                shifts: str = "smooth", seed: int = 0, workers: int = 1) -> MasterCurve:
    """One joint posterior of a master structure and the isotherms' shifts; with several
    structures, each is fitted and the one of highest ln Z is returned, with the ranking.

    Parameters
    ----------
    isotherms : sequence
        ``(FrequencyResponse, temperature [°C])`` pairs, or :class:`bayesfo.data.Isotherm`
        objects (``bayesfo.data.read_isotherms`` of a TRIOS, pyvisco or temperature-column file).
    structures : str, Structure or sequence
        The master function: a structure of the library, or several (a comma list or a
        sequence), ranked by ln Z on the joint data as ``compare`` ranks them; ``"spectrum"``
        is a discrete relaxation spectrum with a smoothness prior, which needs no structure
        (:mod:`bayesfo.tts.spectrum`).
    reference_temperature : float, optional
        [°C]; an isotherm's temperature (default: the middle isotherm).
    noise : {"auto", "relative_parts", "proportional", "constant", "known"}
        ``relative_parts`` (independent relative noise of G′ and G″, a rheometer's) and
        ``proportional`` (complex noise proportional to |G*|) suit data spanning decades, as
        isotherms do; ``"auto"`` (default) chooses between the two by the ln Z of the
        model-free master, and the structures are fitted with the model chosen (with
        ``shifts="joint"``, ``"auto"`` is ``"proportional"``). ``constant`` and ``known``
        apply to the structures; the model-free master then chooses its own.
    vertical : {"auto", "none", "density", "free"}
        The vertical shift b_T: none; the density correction b_T = T_ref/T [K] (constant
        density); or one free log10 b_T per isotherm (see the module). ``"auto"`` (default)
        chooses among the three by the ln Z of the model-free master (with
        ``shifts="joint"``, ``"auto"`` is ``"none"``).
    law : {"auto", "free", "wlf", "arrhenius"}
        The horizontal shifts: one free log10 a_T per isotherm (``"free"``), or those of the
        WLF or Arrhenius law with its parameters sampled jointly (``"wlf"``,
        ``"arrhenius"``). ``"auto"`` ranks the master structures with free shifts, then fits
        the best one with each law too and keeps the model of highest ln Z among the three
        (a law is kept only where its posterior is certified); ``law_evidence`` says how
        the three compare. With fewer than :data:`AUTO_LAWS_MIN` isotherms, ``"auto"`` is
        ``"free"``.
    shifts : {"smooth", "joint"}
        Where the shifts come from. ``"smooth"`` (default): a model-free master function
        (smooth curves of ln G′ and ln G″ against log10 a_T ω, integrated out in closed form;
        :mod:`bayesfo.tts.smooth`), whose posterior of the shifts does not depend on a
        structure describing the data; the vertical shift and the law are chosen by its ln Z
        (:mod:`bayesfo.tts.shifts`), and each master structure is then fitted to the isotherms
        so shifted (:mod:`bayesfo.tts.conditional`: its ln Z ranks the structures, its draws
        are paired with the shifts' draws). A structure that cannot be fitted is dropped with
        its reason (``ranking``); where none can, the relaxation spectrum is the master.
        ``"joint"``: the shifts sampled jointly with each master structure (below).
    seed : int
    workers : int
        Processes fitting the master structures side by side, and then the best one under
        each shift law: 1 (default) fits them one after the other in this process; 0 one
        process per CPU. The numbers do not depend on it.

    Returns
    -------
    MasterCurve

    Raises
    ------
    InputError
        Fewer than two isotherms, a missing or repeated temperature, isotherms of different
        kinds or units, a reference temperature without an isotherm, an unknown option, or
        ``workers`` not a non-negative integer.
    """
    check_workers(workers)  # before the isotherms are read and the model-free master runs
    if vertical not in ("auto", *VERTICAL):
        raise InputError(f"vertical must be one of auto, {', '.join(VERTICAL)}, got "
                         f"{vertical!r}")
    if law not in ("auto", *LAWS):
        raise InputError(f"law must be one of auto, {', '.join(LAWS)}, got {law!r}")
    if shifts not in SHIFTS_FROM:
        raise InputError(f"shifts must be one of {', '.join(SHIFTS_FROM)}, got {shifts!r}")
    names = master_names(structures)
    iso = _isotherms(isotherms, reference_temperature)
    _warn_negative_loss(iso)
    _warn_temperature_gap(iso)
    if noise not in ("auto", *NOISE_MODELS):
        raise InputError(f"noise must be one of auto, {', '.join(NOISE_MODELS)}, got {noise!r}")
    if shifts == "smooth":
        return _on_smooth_shifts(iso, names, noise, vertical, law, seed, workers)
    vertical = "none" if vertical == "auto" else vertical
    noise = "proportional" if noise == "auto" else noise
    first = "free" if law == "auto" else law
    auto_laws = law == "auto" and len(iso.temperatures) >= AUTO_LAWS_MIN
    from ..parallel import executor

    with executor(workers, max(len(names), 2 if auto_laws else 1)) as pool:
        fits = [f.result() for f in [pool.submit(_fit_one, iso, s, noise, seed, vertical, first)
                                     for s in names]]
        return _conclude(iso, fits, "auto" if auto_laws else first, vertical,
                         lambda best, hows, ceiling: [f.result() for f in [
                             pool.submit(_fit_one, iso, names[best], noise, seed, vertical, how,
                                         ceiling) for how in hows]])


def _conclude(iso, fits, law, vertical, fit_laws) -> MasterCurve:
    """The ranking of the master structures (``fits``, free shifts or the law asked for),
    the best one's shift law chosen by evidence where ``law`` is ``"auto"`` (its fits under
    the laws from ``fit_laws(best, hows, ceiling)``: a law whose best fit stays below
    ``ceiling`` comes back :class:`_Bounded`), and the model-free tests of superposition."""
    z = np.array([f.log_evidence if math.isfinite(f.log_evidence) else -np.inf for f in fits])
    best = int(np.argmax(z))
    p = model_probabilities(z)
    ranking = tuple(
        {"structure": f.structure, "log_evidence": _num(f.log_evidence),
         "log_evidence_err": _num(f.log_evidence_err), "probability": _num(pi),
         "certified": bool(f.posterior.converged), "sampler": f.posterior.sampler}
        for f, pi in sorted(zip(fits, p, strict=True), key=lambda fp: -fp[0].log_evidence
                            if math.isfinite(fp[0].log_evidence) else np.inf))
    from dataclasses import replace

    chosen = fits[best]
    law_evidence, law_notes = {}, []
    if law == "auto":
        ceiling = (chosen.log_evidence - LAW_BOUND_MARGIN if math.isfinite(chosen.log_evidence)
                   else None)
        chosen, law_evidence, law_notes = _choose_law(
            chosen, dict(zip(LAW_FITS, fit_laws(best, LAW_FITS, ceiling), strict=True)))
    checks, notes = _checks(iso, chosen, vertical)
    return replace(chosen, ranking=ranking, tts_checks=checks,
                   notes=tuple(list(chosen.notes) + law_notes + notes),
                   law_evidence=law_evidence)


def _checks(iso, chosen: MasterCurve, vertical: str) -> tuple[dict, list]:
    """The model-free tests of superposition and the isotherms' fit of ``chosen``:
    ``(tts_checks, notes)``."""
    from .validity import (
        describe,
        describe_joint_against_parts,
        describe_parts,
        joint_against_parts,
        shifts_by_part,
        van_gurp_palmen,
    )

    vgp = van_gurp_palmen(iso.data, iso.temperatures, log_vertical=(
        None if chosen.vertical_draws is None else chosen.vertical_draws.mean(axis=0)))
    parts = shifts_by_part(iso.data, iso.temperatures)
    against = joint_against_parts(parts, chosen.shift_draws)
    checks = {"van_gurp_palmen": vgp, "shift_parts": parts, "joint_against_parts": against,
              "isotherm_fit": chosen.tts_checks["isotherm_fit"]}
    notes = []
    if vgp["valid"] is not True:
        notes.append(describe(vgp))
    if vgp["valid"] is None and parts["consistent"] is None:
        notes.append("superposition untested (tts_valid null): no neighbouring isotherms share "
                     "values of |G*|, G′, G″ or tan δ, so the shifts come from the master "
                     "function alone, not from overlapping data")
    if parts["consistent"] is False:
        notes.append(describe_parts(parts) + (
            "" if vertical == "none" else " (the model's vertical shifts account for the "
                                          "former)"))
    if against["apart"] and vertical == "none" and chosen.shifts_from == "joint":
        notes.append(describe_joint_against_parts(against, chosen.structure, chosen.law))
    misfit = checks["isotherm_fit"]["misfit"]
    if misfit:
        notes.append(f"the fit of {chosen.structure} misses the isotherm(s) at "
                     f"{', '.join(f'{t:g}' for t in misfit)} °C: their relative residuals "
                     f"(of |G*|, G′ or G″) are over {ISOTHERM_MISFIT:g} times the median "
                     "isotherm's")
    return checks, notes


def _on_smooth_shifts(iso, names, noise: str, vertical: str, law: str, seed: int,
                      workers: int) -> MasterCurve:
    """The master curve whose shifts come from the model-free master (see
    :func:`mastercurve`)."""
    from dataclasses import replace

    from ..parallel import executor
    from .shifts import smooth_shifts

    shifts0 = _seed_shifts(iso)
    reach = max(SHIFT_RANGE, float(np.max(np.abs(shifts0))) + SHIFT_MARGIN)
    with executor(workers, max(len(names), 3)) as pool:
        sh = smooth_shifts(iso, vertical=vertical, law=law, seed=seed,
                           noise=noise if noise in ("relative_parts", "proportional")
                           else "auto", submit=None if workers == 1 else pool.submit)
        noise = sh.noise if noise == "auto" else noise
        # Each structure's best fit first; the best one is sampled, then the others whose
        # best fit reaches within BOUND_MARGIN nats of its ln Z (ln Z ≤ max ln L: the rest
        # have posterior probability below e^-BOUND_MARGIN and are set aside with the bound).
        best = dict(zip(names, [f.result() for f in [
            pool.submit(_try_best, iso, s, noise, seed, sh) for s in names]], strict=True))
        dropped = {_name(s): why for s, why in best.items() if isinstance(why, str)}
        fitted = {s: b for s, b in best.items() if not isinstance(b, str)}
        fits, bounded = [], {}
        if fitted:
            order = sorted(fitted, key=lambda s: -fitted[s][1])
            lead = _try_on_shifts(iso, order[0], noise, seed, sh, reach, fitted[order[0]][0])
            rest = order[1:]
            if isinstance(lead, str):
                dropped[_name(order[0])] = lead
                ceiling = -np.inf
            else:
                fits.append(lead)
                ceiling = (lead.log_evidence - BOUND_MARGIN if math.isfinite(lead.log_evidence)
                           else -np.inf)
            bounded = {_name(s): fitted[s][1] for s in rest if fitted[s][1] < ceiling}
            todo = [s for s in rest if fitted[s][1] >= ceiling]
            for s, f in zip(todo, [f.result() for f in [
                    pool.submit(_try_on_shifts, iso, s, noise, seed, sh, reach, fitted[s][0])
                    for s in todo]], strict=True):
                if isinstance(f, str):
                    dropped[_name(s)] = f
                else:
                    fits.append(f)
        if not fits and not bounded and SPECTRUM not in names:
            spectrum = _try_on_shifts(iso, SPECTRUM, noise, seed, sh, reach)
            if isinstance(spectrum, MasterCurve):
                fits = [spectrum]
            else:
                dropped[SPECTRUM] = spectrum
    if not fits:
        raise InputError("no master function could be fitted to the shifted isotherms: "
                         + "; ".join(f"{k}: {v}" for k, v in dropped.items()))
    z = np.array([f.log_evidence if math.isfinite(f.log_evidence) else -np.inf for f in fits])
    best = int(np.argmax(z))
    p = model_probabilities(z)
    ranking = [{"structure": f.structure, "log_evidence": _num(f.log_evidence),
                "log_evidence_err": _num(f.log_evidence_err), "probability": _num(pi),
                "certified": bool(f.posterior.converged), "sampler": f.posterior.sampler}
               for f, pi in sorted(zip(fits, p, strict=True), key=lambda fp: -fp[0].log_evidence
                                   if math.isfinite(fp[0].log_evidence) else np.inf)]
    top = z[best] if np.isfinite(z[best]) else None
    ranking += [{"structure": k, "log_evidence": None, "log_evidence_err": None,
                 "log_evidence_upper": _num(v),
                 "probability": (None if top is None else
                                 _num(math.exp(min(0.0, v - top)) / float(np.nansum(
                                     np.exp(z - z[best]))))),
                 "probability_upper": True, "certified": False, "sampler": "not sampled"}
                for k, v in bounded.items()]
    ranking += [{"structure": k, "log_evidence": None, "log_evidence_err": None,
                 "probability": None, "certified": False, "sampler": "dropped", "dropped": v}
                for k, v in dropped.items()]
    chosen = fits[best]
    notes = [f"the shifts come from a model-free master (smooth curves of ln G′ and ln G″ "
             f"against log10 a_T ω, integrated out), not from {chosen.structure}: its misfit "
             f"cannot move them; {chosen.structure} is fitted to the isotherms so shifted"]
    notes += list(sh.notes)
    notes += [f"{k} was not sampled: its best fit reaches a log-likelihood of {v:.1f}, which "
              f"bounds its ln Z from above, {z[best] - v:.0f} nats below the ln Z of "
              f"{chosen.structure}" for k, v in bounded.items()]
    notes += [f"{k} was dropped: {v}" for k, v in dropped.items()]
    gone = sh.posterior.undetermined()
    if gone:
        notes.append("the data do not fix the shift of the isotherm(s) at "
                     + ", ".join(f"{iso.temperatures[i]:g}" for i in gone)
                     + f" °C (94 % interval wider than {UNDETERMINED:g} decade): it slides "
                       "along a featureless stretch of the master curve; it is left out of the "
                       "fits of the shift laws")
    if chosen.vertical == "free":
        mean_b = chosen.vertical_draws.mean(axis=0)
        far = [i for i in range(mean_b.size) if abs(mean_b[i]) > VERTICAL_PLAUSIBLE]
        if far:
            notes.append("the free vertical shifts reach "
                         + ", ".join(f"{mean_b[i]:+.2f} decades (b_T = {10.0 ** mean_b[i]:.2g} "
                                     f"at {iso.temperatures[i]:g} °C)" for i in far)
                         + f", beyond the density and temperature ratios they stand "
                           f"for (±{VERTICAL_PLAUSIBLE:g}): there the isotherms' shapes "
                           "differ, which superposition does not explain (see the van "
                           "Gurp–Palmen test)")
    chosen = replace(chosen, shifts_from="smooth", vertical_evidence=sh.vertical_evidence,
                     shift_evidence=_shift_evidence(sh))
    checks, check_notes = _checks(iso, chosen, chosen.vertical)
    laws = _laws_once(chosen.laws, sh.law_evidence)
    return replace(chosen, ranking=tuple(ranking), tts_checks=checks, laws=laws,
                   notes=tuple(notes + list(chosen.notes) + check_notes),
                   law_evidence=sh.law_evidence)


def _shift_evidence(sh) -> dict:
    """What ``summary.json`` says of the model-free master chosen."""
    post = sh.posterior
    names = post.model.param_names
    hyper = {n: float(np.median(post.draws[:, j])) for j, n in enumerate(names)
             if n.startswith(("smoothness_", "sigma_"))}
    return {"master": "smooth", "vertical": sh.vertical, "law": sh.law, "noise": sh.noise,
            "noise_evidence": sh.noise_evidence,
            "log_evidence": _num(post.log_evidence),
            "log_evidence_err": _num(post.log_evidence_err),
            "max_log_likelihood": _num(post.max_log_likelihood), "sampler": post.sampler,
            "certified": bool(post.converged), "pareto_k": _num(post.k_hat),
            "ess": _num(post.ess), "hyperparameters": hyper,
            "undetermined": [post.model.temperatures[i] for i in post.undetermined()]}


def _laws_once(laws: dict, law_evidence: dict) -> dict:
    """The laws fitted to the shifts, their probabilities those of the evidence where the
    laws were weighed inside the model (one probability per law in a run), else BIC's."""
    out = {k: dict(v) for k, v in laws.items()}
    weighed = {k: v for k, v in law_evidence.items() if k in out}
    if len(weighed) == len(out):
        for k in out:
            out[k]["probability"] = weighed[k]["probability"]
            out[k]["probability_upper"] = bool(weighed[k].get("probability_upper", False))
            out[k]["probability_method"] = ("ln Z of the model-free master with the law inside "
                                            "(beside free shifts: law_evidence)")
    else:
        for k in out:
            out[k]["probability_method"] = "BIC of the law fitted to the shifts' posterior"
    return out


def _name(structure) -> str:
    return structure if isinstance(structure, str) else structure.name


def _try_best(iso, structure, noise, seed, sh):
    """:func:`~bayesfo.tts.conditional.best_on_shifts`, or the reason it failed (a string)."""
    from .conditional import best_on_shifts

    try:
        return best_on_shifts(iso, structure, noise, seed, sh)
    except InputError as exc:
        return str(exc)


def _try_on_shifts(iso, structure, noise, seed, sh, reach, modes=None):
    """:func:`~bayesfo.tts.conditional.fit_on_shifts`, or the reason it failed (a string)."""
    from .conditional import fit_on_shifts

    try:
        return fit_on_shifts(iso, structure, noise, seed, sh, reach, modes)
    except InputError as exc:
        return str(exc)


def _warn_negative_loss(iso) -> None:
    """Warn of isotherms with points of negative loss, as ``compare`` and ``inspect`` do: no
    passive master function fits them."""
    import warnings

    from ..errors import DataWarning

    for data, t in zip(iso.data, iso.temperatures, strict=True):
        bad = data.omega[data.dissipation_violations()]
        if bad.size:
            shown = ", ".join(f"{w:.4g}" for w in bad[:6]) + (
                f" and {bad.size - 6} more" if bad.size > 6 else "")
            loss = "Im J > 0" if data.kind == "compliance" else "Im G < 0"
            warnings.warn(f"the isotherm at {t:g} °C ({data.label}): {bad.size} of "
                          f"{data.n_frequencies} points have negative loss ({loss}), impossible "
                          f"for a passive {data.kind}, at omega = {shown} rad/s; no passive "
                          "master function can fit them", DataWarning, stacklevel=3)


#: Neighbouring isotherms further apart than this [°C] are warned of: a temperature in kelvin
#: read as °C (293.15 beside 10 °C) gave a master curve with WLF C1 0.80.
TEMPERATURE_GAP = 200.0


def _warn_temperature_gap(iso) -> None:
    import warnings

    from ..errors import DataWarning

    temps = sorted(float(t) for t in iso.temperatures)
    for low, high in zip(temps, temps[1:]):
        if high - low > TEMPERATURE_GAP:
            warnings.warn(f"the isotherms at {low:g} and {high:g} °C are {high - low:g} °C "
                          "apart, with none between: is a temperature in kelvin read as °C? "
                          "(write '293.15 K', not '293.15')", DataWarning, stacklevel=3)


def master_names(structures) -> list:
    """The master functions asked for: structures of the library (names resolved as
    ``compare`` resolves them) and ``"spectrum"`` (:mod:`bayesfo.tts.spectrum`)."""
    from ..structures import resolve_structures

    if isinstance(structures, str):
        parts = [p.strip() for p in structures.split(",") if p.strip()]
        rest = ",".join(p for p in parts if p.lower() != SPECTRUM)
        names = resolve_structures(rest) if rest else []
        return ([SPECTRUM] if any(p.lower() == SPECTRUM for p in parts) else []) + list(names)
    return [structures] if not isinstance(structures, (list, tuple)) else list(structures)


#: The shift laws that ``law="auto"`` fits the best master structure with, beside free shifts.
LAW_FITS = ("wlf", "arrhenius")


def _choose_law(free: MasterCurve, laws: dict) -> tuple:
    """The model of highest ln Z among free shifts (``free``) and the WLF and Arrhenius laws
    (``laws``: ``{law: MasterCurve or _Bounded}``), a law only where its posterior is
    certified; with ``law_evidence`` and a note. A :class:`_Bounded` law enters with its
    upper bound: ``log_evidence`` None, ``log_evidence_upper`` and a ``probability`` that is
    an upper bound (``probability_upper`` true)."""
    sampled = {k: f for k, f in laws.items() if not isinstance(f, _Bounded)}
    bounded = {k: f for k, f in laws.items() if isinstance(f, _Bounded)}
    fits = {"free": free, **sampled}
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
    notes = []
    for k, b in bounded.items():
        evidence[k] = {"log_evidence": None, "log_evidence_err": None,
                       "log_evidence_upper": _num(b.log_likelihood),
                       "probability": math.exp(min(0.0, b.log_likelihood - z[top])) / total,
                       "probability_upper": True, "certified": False, "sampler": "not sampled"}
        notes.append(f"{name[k]} was not sampled: its best joint fit reaches a log-likelihood "
                     f"of {b.log_likelihood:.1f}, which bounds its ln Z from above, "
                     f"{z[top] - b.log_likelihood:.0f} nats below the ln Z of {name[top]}")
    evidence = {k: evidence[k] for k in ("free", *LAW_FITS) if k in evidence}
    if len(z) < 2:  # every law bounded
        runner = max(bounded, key=lambda k: bounded[k].log_likelihood)
        how = f"ln Z over {z[top] - bounded[runner].log_likelihood:.0f} above {name[runner]}"
    else:
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
    return fits[top], evidence, [note, *notes]


def _fit_one(iso: _Isotherms, structure, noise: str, seed: int,
             vertical: str = "none", law: str = "free",
             ceiling: float | None = None) -> MasterCurve | _Bounded:
    """The joint posterior with one master structure; :class:`_Bounded` instead where the
    best joint fit's log-likelihood (maximum-likelihood noise) stays below ``ceiling``."""
    from scipy.optimize import least_squares

    from ..identify.optimize import fit_structure
    from ..inference import Likelihood, certified_posterior
    from ..inference import preload_arviz as preload
    from ..inference.transform import Transform as _Transform
    from ..parallel import settle_worker
    from ..structures import Scaling, get_structure
    from ..structures.response import dissipation_grid

    settle_worker(preload)  # in a pool's worker: its libraries out of the collector, once

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
    # No shift the seeds reach is pinned at the prior's edge.
    reach = max(SHIFT_RANGE, float(np.max(np.abs(shifts0))) + SHIFT_MARGIN)
    shifted = ShiftedStructure(master, iso.temperatures, iso.reference, iso.point_isotherm,
                               dissipation_grid(w.min(), w.max()), vertical, law, reach)
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
    if ceiling is not None:
        theta = best[0][None, :]
        if lik.noise_param:
            theta = np.column_stack([theta, lik.noise_estimate(theta)])
        log_l = float(lik(theta)[0])
        if log_l < ceiling:
            return _Bounded(law, log_l)
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
