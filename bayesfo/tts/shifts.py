"""The shifts of a master curve from the model-free master (:mod:`bayesfo.tts.smooth`): the
vertical shift (none, the density correction, free) and the horizontal law (free shifts, WLF,
Arrhenius) each chosen by ln Z, with the same rule for the ones not worth sampling as the
structures': ln Z ≤ max ln L under any normalised prior, so a model whose best fit lies more
than :data:`~bayesfo.tts.joint.LAW_BOUND_MARGIN` nats below the leader's ln Z is set aside
with that bound.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..inference.bound import BOUND_MARGIN  # the one bound margin (10 nats)
from .isotherms import _seed_shifts, _vertical_seeds
from .model import SHIFT_MARGIN, SHIFT_RANGE, VERTICAL_RANGE
from .smooth import NOISE, SmoothMaster
from .smooth_posterior import (
    ShiftPosterior,
    _proposal_cov,
    best_fit,
    sample_shifts,
    start_of,
)

#: The vertical shifts that ``vertical="auto"`` chooses among, and the laws of ``law="auto"``.
VERTICALS = ("none", "density", "free")
LAWS = ("free", "wlf", "arrhenius")
#: Vertical options of at least this probability are averaged over where the evidence leaves
#: more than one open (below it an option's share of the draws would be a handful).
AVERAGE_MIN = 0.01
#: Isotherms from which ``law="auto"`` also weighs the laws (fewer: WLF has as many
#: constants as there are shifts to test it).
AUTO_LAWS_MIN = 4

_NAMES = {"relative_parts": "relative noise of each part",
          "proportional": "noise proportional to |G*|", "free": "free shifts", "wlf": "the WLF law", "arrhenius": "the Arrhenius law",
          "none": "no vertical shift", "density": "the density correction",
          "free_vertical": "free vertical shifts"}


@dataclass(frozen=True)
class Shifts:
    """The shifts' posterior chosen by evidence.

    Attributes
    ----------
    posterior : ShiftPosterior
        Of the model chosen (a mixture where the shifts are averaged over vertical options).
    vertical, law, noise : str
        The model chosen; ``vertical`` is ``"free"`` where the shifts are averaged over
        several vertical options (its draws then hold each option's values; the notes say
        which, with their probabilities).
    vertical_evidence, law_evidence : dict
        ``{option: {"log_evidence", "log_evidence_err", "probability", "certified",
        "sampler"}}`` of the options weighed (``log_evidence_upper`` and
        ``probability_upper`` for one set aside by its best fit); empty where one was asked.
    notes : tuple of str
    """

    posterior: ShiftPosterior
    vertical: str
    law: str
    vertical_evidence: dict = field(default_factory=dict)
    law_evidence: dict = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    noise: str = "relative_parts"
    noise_evidence: dict = field(default_factory=dict)


def _z(post: ShiftPosterior) -> float:
    return post.log_evidence if post.converged and math.isfinite(post.log_evidence) \
        else -math.inf


def _weigh(posts: dict, bounded: dict, what: str) -> tuple[str, dict, list]:
    """The option of highest ln Z among ``posts`` (``{option: ShiftPosterior}``) and those set
    aside (``{option: max ln L}``): ``(chosen, evidence, notes)``."""
    z = {k: _z(p) for k, p in posts.items()}
    top = max(z, key=z.get)
    if not math.isfinite(z[top]):  # no ln Z: the best fit decides, and says so
        top = max(posts, key=lambda k: posts[k].max_log_likelihood)
        return top, {}, [f"no ln Z could be certified for {what}; {_label(top, what)} has the "
                         "best fit"]
    weights = {k: math.exp(v - z[top]) for k, v in z.items()}
    weights.update({k: math.exp(min(0.0, b - z[top])) for k, b in bounded.items()})
    total = sum(weights.values())
    evidence = {}
    for k, p in posts.items():
        evidence[k] = {"log_evidence": p.log_evidence if math.isfinite(p.log_evidence) else None,
                       "log_evidence_err": (p.log_evidence_err
                                            if math.isfinite(p.log_evidence_err) else None),
                       "probability": (weights[k] / total if math.isfinite(z[k]) else None),
                       "certified": bool(p.converged),
                       "sampler": p.sampler, "max_log_likelihood": p.max_log_likelihood}
    notes = []
    for k, b in bounded.items():
        evidence[k] = {"log_evidence": None, "log_evidence_err": None,
                       "log_evidence_upper": b, "probability": weights[k] / total,
                       "probability_upper": True, "certified": False,
                       "sampler": "not sampled", "max_log_likelihood": b}
        notes.append(f"{_label(k, what)} was not sampled: its best fit reaches a "
                     f"log-likelihood of {b:.1f}, which bounds its ln Z from above, "
                     f"{z[top] - b:.0f} nats below the ln Z of {_label(top, what)}")
    others = {k: v for k, v in z.items() if k != top}
    others.update(bounded)
    if others:
        runner = max(others, key=others.get)
        gap = z[top] - others[runner]
        how = (f"ln Z {'over ' if runner in bounded else ''}{gap:.1f} above "
               f"{_label(runner, what)}" if math.isfinite(gap)
               else f"{_label(runner, what)} gave no certified ln Z")
        notes.insert(0, f"{what}: {_label(top, what)} ({how})")
    return top, evidence, notes


def _label(option: str, what: str) -> str:
    return _NAMES["free_vertical"] if option == "free" and what.startswith("vertical") \
        else _NAMES[option]


def smooth_shifts(iso, *, vertical: str = "auto", law: str = "auto", noise: str = "auto",
                  seed: int = 0, submit=None) -> Shifts:
    """The shifts of the isotherms ``iso`` (:class:`~bayesfo.tts.isotherms._Isotherms`) under
    the model-free master, the noise model, the vertical shift and the law chosen by ln Z
    where ``"auto"`` (the noise model and the vertical shift together, with free shifts;
    then the laws).

    ``submit(function, *args)`` runs the models' fits side by side (a pool's ``submit``; it
    returns futures); without it they run here one after the other.
    """
    seeds = _seed_shifts(iso)
    reach = max(SHIFT_RANGE, float(np.max(np.abs(seeds))) + SHIFT_MARGIN)
    def many(calls):
        if submit is None:
            return [f(*a) for f, *a in calls]
        return [fut.result() for fut in [submit(f, *a) for f, *a in calls]]

    verticals = VERTICALS if vertical == "auto" else (vertical,)
    noises = NOISE if noise == "auto" else (noise,)
    notes = []
    # Every noise model with every vertical option: the noise model is told apart where the
    # vertical shift is right (misfit from a missing vertical shift reads as noise). Free
    # vertical shifts contain the other two: they start from the better one's maximum (from
    # the seeds, the optimiser may stop at a lower local maximum).
    simple = [(k, v) for k in noises for v in verticals if v != "free"]
    models = {kv: SmoothMaster.of(iso, kv[1], "free", reach, kv[0]) for kv in simple}
    fits = dict(zip(simple, many([(best_fit, models[kv], start_of(models[kv], seeds))
                                  for kv in simple]), strict=True))
    if "free" in verticals:
        calls = []
        for k in noises:
            model = models[(k, "free")] = SmoothMaster.of(iso, "free", "free", reach, k)
            nested = [kv for kv in fits if kv[0] == k]
            if nested:
                near = max(nested, key=lambda kv: fits[kv][1])
                start = _free_layout(model, models[near], models[near].to_params(
                    fits[near][0]))[0]
            else:  # tan δ is free of the vertical shift: the phases place the isotherms
                phase = _seed_shifts(iso, phase_only=True)
                start = start_of(model, phase)
                h = model.n_horizontal
                vertical = np.clip(np.delete(_vertical_seeds(iso, phase), model.reference),
                                   -0.9 * VERTICAL_RANGE, 0.9 * VERTICAL_RANGE)
                start[h:h + vertical.size] = vertical
            calls.append((best_fit, model, start))
        fits.update(zip([(k, "free") for k in noises], many(calls), strict=True))
    # Sampled in the order of their Laplace estimates of ln Z, the likely leader first; one
    # whose best fit stays BOUND_MARGIN below the leader's ln Z is set aside with that bound.
    fitted, bounded_nv = _sample_bounded(models, fits, seed, many)
    chosen_noise, n_evidence = noises[0], {}
    if len(noises) > 1:
        best_of = {k: max((fitted[kv] for kv in fitted if kv[0] == k), key=_z)
                   for k in noises if any(kv[0] == k for kv in fitted)}
        out_of = {k: max(b for kv, b in bounded_nv.items() if kv[0] == k)
                  for k in noises if k not in best_of}
        chosen_noise, n_evidence, n_notes = _weigh(best_of, out_of, "noise")
        notes += n_notes
    posts = {v: fitted[(chosen_noise, v)] for v in verticals if (chosen_noise, v) in fitted}
    v_bounded = {v: bounded_nv[(chosen_noise, v)] for v in verticals
                 if (chosen_noise, v) in bounded_nv}
    chosen_v, v_evidence = verticals[0], {}
    if len(verticals) > 1:
        chosen_v, v_evidence, v_notes = _weigh(posts, v_bounded, "vertical shift")
        notes += v_notes
    laws = (LAWS if law == "auto" and len(iso.temperatures) >= AUTO_LAWS_MIN
            else ("free",) if law == "auto" else (law,))
    law_posts = {"free": posts[chosen_v]} if "free" in laws else {}
    others = [k for k in laws if k != "free"]
    bounded = {}
    if others:
        ceiling = _z(posts[chosen_v]) - BOUND_MARGIN if "free" in laws else -math.inf
        best_shifts = posts[chosen_v].model.log_shifts(posts[chosen_v].map_theta)[0]
        fits = many([(_bounded_or_sampled, SmoothMaster.of(iso, chosen_v, k, reach,
                                                            chosen_noise),
                      best_shifts, seed, ceiling) for k in others])
        for k, f in zip(others, fits, strict=True):
            if isinstance(f, float):
                bounded[k] = f
            else:
                law_posts[k] = f
    chosen_law, l_evidence = laws[0], {}
    if len(laws) > 1:
        chosen_law, l_evidence, l_notes = _weigh(law_posts, bounded, "horizontal shifts")
        notes += l_notes
    if law == "auto":
        # The shift factors are the isotherms' own (free shifts) whatever law the evidence
        # prefers: a law is a description of them, and a law that holds nearly but not
        # exactly would give intervals narrower than the shifts' own.
        post, reported = law_posts["free"], "free"
        if chosen_law != "free":
            notes.append(f"the shift factors are each isotherm's own (free shifts); "
                         f"{_label(chosen_law, 'law')} describes them")
    else:
        post, reported = law_posts[chosen_law], chosen_law
    notes += [f"shifts ({_label(reported, 'law')}): {m}" for m in post.messages]
    weights = {v: e["probability"] for v, e in v_evidence.items() if v in posts
               and e.get("probability") is not None and e["probability"] >= AVERAGE_MIN}
    if reported == "free" and len(weights) > 1:
        # The evidence does not settle the vertical shift: the shifts are averaged over the
        # options it leaves open, each by its probability, in the free vertical shifts'
        # layout (no vertical shift and the density correction are values of it).
        post = _averaged({v: posts[v] for v in weights}, weights, iso, reach, chosen_noise,
                         seed)
        notes.append("the evidence leaves the vertical shift open: the shifts are averaged "
                     "over " + " and ".join(f"{_label(v, 'vertical')} (probability "
                                            f"{weights[v] / sum(weights.values()):.2f})"
                                            for v in sorted(weights, key=lambda v: -weights[v]))
                     + ", carried as free vertical shifts")
        chosen_v = "free"
    return Shifts(post, chosen_v, reported, v_evidence, l_evidence, tuple(notes),
                  chosen_noise, n_evidence)


def _averaged(posts: dict, weights: dict, iso, reach: float, noise: str,
              seed: int) -> ShiftPosterior:
    """The posteriors ``posts`` (``{vertical option: ShiftPosterior}``, free shifts) as one
    mixture in the free vertical shifts' layout, each with draws in proportion to its weight;
    ln Z, the maximum and the certificate those of the heaviest."""
    model = SmoothMaster.of(iso, "free", "free", reach, noise)
    total = sum(weights.values())
    rng = np.random.default_rng(seed)
    n = max(p.draws.shape[0] for p in posts.values())
    counts = rng.multinomial(n, [weights[v] / total for v in posts])
    parts = []
    for p, c in zip(posts.values(), counts, strict=True):
        if c:
            rows = p.draws[rng.choice(p.draws.shape[0], size=c, replace=c > p.draws.shape[0])]
            parts.append(_free_layout(model, p.model, rows))
    draws = np.vstack(parts)[rng.permutation(n)]
    lead = posts[max(posts, key=lambda v: weights[v])]
    theta = _free_layout(model, lead.model, lead.map_theta)[0]
    return ShiftPosterior(model, draws, lead.log_evidence, lead.log_evidence_err, theta,
                          lead.max_log_likelihood, lead.sampler, max(p.k_hat for p in
                                                                     posts.values()),
                          min(p.ess for p in posts.values()),
                          all(p.converged for p in posts.values()),
                          tuple(m for p in posts.values() for m in p.messages),
                          lead.model.shift_information(lead.map_theta))


def _laplace(model: SmoothMaster, fit) -> float:
    """The Laplace estimate of ln Z at a best fit (its point, log-likelihood and Hessian in
    the sampling coordinates): an ordering of the models, never a certified value."""
    u, ll, hess = fit
    cov = _proposal_cov(hess, model.bounds)
    sign, log_det = np.linalg.slogdet(cov)
    return (ll - model.log_prior_volume + 0.5 * u.size * math.log(2 * math.pi)
            + 0.5 * (log_det if sign > 0 else -math.inf))


def _sample_bounded(models: dict, fits: dict, seed: int, many) -> tuple[dict, dict]:
    """The posteriors of ``models`` (``{key: SmoothMaster}``, best fits ``fits``) sampled
    from the highest Laplace estimate down; a model whose best fit's log-likelihood (an upper
    bound of its ln Z) lies :data:`BOUND_MARGIN` below the highest ln Z certified so far is
    set aside: ``({key: ShiftPosterior}, {key: max ln L})``."""
    order = sorted(models, key=lambda kv: -_laplace(models[kv], fits[kv]))
    fitted, bounded = {}, {}
    lead = order[0]
    fitted[lead] = sample_shifts(models[lead], None, seed, fit=fits[lead])
    ceiling = max(_z(p) for p in fitted.values()) - BOUND_MARGIN
    rest = [kv for kv in order[1:] if fits[kv][1] >= ceiling]
    bounded.update({kv: fits[kv][1] for kv in order[1:] if kv not in rest})
    for kv, post in zip(rest, many([(sample_shifts, models[kv], None, seed, fits[kv])
                                    for kv in rest]), strict=True):
        fitted[kv] = post
    return fitted, bounded


def _free_layout(model: SmoothMaster, near: SmoothMaster, theta) -> np.ndarray:
    """Parameter sets ``theta`` (natural units, rows) of a model ``near`` with free shifts in
    the layout of the free-vertical ``model``, which contains it: its shifts, its vertical
    shifts (0, the density correction or free ones), then ρ and σ of each part."""
    theta = np.atleast_2d(np.asarray(theta, float))
    vertical = np.delete(near.log_vertical(theta), model.reference, axis=1)
    return np.column_stack([theta[:, :near.n_horizontal], vertical, theta[:, -4:]])


def _bounded_or_sampled(model: SmoothMaster, seeds, seed: int, ceiling: float):
    """The model's posterior, or its best fit's log-likelihood (a float) where that stays
    below ``ceiling``."""
    fit = best_fit(model, start_of(model, seeds))
    if fit[1] < ceiling:
        return fit[1]
    return sample_shifts(model, start_of(model, seeds), seed, fit=fit)
