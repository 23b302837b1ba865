"""The steps of one structure's run on one data set, run as tasks by :mod:`.schedule`.

(1) :func:`fit_and_screen`: the global optimisation (the modes) and, without σ in the data,
the quick noise screen (:func:`screen`) of the constant, proportional and relative-parts noise
models, which may set aside those that trail far behind, or defer some until the leader's ln Z
is known (:class:`Deferred`);
:func:`fit_and_probe` does the same and says whether the rest promises to be quick.
(2) :func:`sample_held`: one certified posterior per noise model still in the running
(:func:`~bayesfo.inference.certified.certified_posterior`), its warnings held back; a deferred
noise model is sampled only where :func:`settle` cannot set it aside.
(3) :func:`conclude`: the noise model chosen by evidence (:func:`choose_noise`), the evidence
check, the adequacy checks, the held-out points, and the :class:`StructureResult`.
:mod:`.schedule` runs them as tasks of an executor (this process or worker processes).
Every step takes the comparison's :class:`RunOptions` and uses its seed, so the numbers do not
depend on where a step runs.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from typing import Any, NamedTuple

import numpy as np

from ..data import FrequencyResponse
from ..errors import InputError, NoiseWarning
from ..identify.optimize import fit_structure
from ..inference import Likelihood, PosteriorResult, starting_points
from ..inference.adequacy import check_adequacy
from ..inference.bound import BOUND_MARGIN, BOUND_REASON
from ..inference.certified import certified_posterior, evidence_check
from ..inference.evidence import other_noise_evidence
from ..inference.importance import K_HAT_MAX, screen_noise
from ..inference.likelihood import NOISE_PRIORS, zero_part
from ..structures import Structure
from .criteria import _criteria, _holdout, fit_log_likelihood
from .criteria_types import Criteria
from .results import StructureResult


@dataclass(frozen=True)
class RunOptions:
    """What every step of a comparison needs besides the structure and the data (built once by
    :func:`~bayesfo.comparison.run.compare` from its arguments).

    Attributes
    ----------
    noise : str
        The noise model asked for (``"auto"`` chooses by evidence).
    priors : dict or None
        Prior overrides ``{name: Prior}``.
    seed : int
        The seed of every step.
    evidence : str
        The ln Z route (``"auto"``, ``"bridge"``, ``"ladder"``).
    evidence_check : bool
        Whether dynesty checks ln Z.
    sampler : str
        The posterior route (``"auto"``, ``"emcee"``).
    sampler_kwargs : dict
        Settings passed to emcee (``max_steps``, ``n_walkers``).
    holdout : FrequencyResponse or None
        The held-out frequencies.
    sample : str
        ``"needed"``: a structure whose best fit bounds its ln Z far below the leader's is
        not sampled (:mod:`bayesfo.inference.bound`); ``"all"``: every structure is.
    """

    noise: str = "auto"
    priors: dict | None = None
    seed: int = 0
    evidence: str = "auto"
    evidence_check: bool = False
    sampler: str = "auto"
    sampler_kwargs: dict = field(default_factory=dict)
    holdout: FrequencyResponse | None = None
    sample: str = "needed"

    def priors_of(self, s: Structure, noise: str | None = None) -> dict:
        """The overrides that apply to ``s`` (and to the noise parameter of ``noise``)."""
        noise_param = NOISE_PRIORS.get(noise, ("",))[0] if noise else None
        return {k: v for k, v in (self.priors or {}).items()
                if k in s.param_names or k == noise_param}


@dataclass
class NoiseRun:
    """One structure's posterior under one noise model (step 2), before the choice of noise
    model: the likelihood, the certified posterior, the criteria being built (a dict of
    :class:`Criteria` fields), and the warnings held back as (category, message, file, line)."""

    lik: Any
    post: Any
    criteria: dict
    caught: list = field(default_factory=list)
    aside: dict = field(default_factory=dict)


class Deferred(NamedTuple):
    """A noise model whose posterior waits for the leader's certified ln Z (:func:`settle`):
    ``best``, the highest log-likelihood under it (with the maximum-likelihood noise scale)
    found by polishing the structure's optima under its weighting, at an admissible point
    (−inf where none is)."""

    noise: str
    best: float


class Screen(NamedTuple):
    """The noise screen's decision: the leading noise model and every candidate's quick
    estimate (:func:`~bayesfo.inference.importance.screen_noise`), as records of
    ``{"log_z", "method", "intervals"}``. The leader is sampled, and with it the models of
    ``also``; a candidate in neither nor in ``deferred`` is set aside by its quick estimate.
    The models of ``deferred`` (:class:`Deferred`) are not set aside yet: the leader is sampled
    first, and :func:`settle` decides."""

    leader: str
    quick: dict
    deferred: tuple = ()
    also: tuple = ()


class _Entry(NamedTuple):
    """A noise model in the choice: its ln Z, error and method, its exponents' intervals, and
    its run (None for a model the screen set aside)."""

    noise: str
    log_z: float
    log_z_err: float | None
    method: str | None
    intervals: dict
    run: NoiseRun | None


def remedy(lik) -> str:
    """What to try when a posterior is not certified: the options that address it."""
    walkers = max(32, 4 * lik.ndim)
    walkers += -walkers % 4
    exponents = [p.name for p in lik.structure.parameters if p.role == "exponent"]
    prior = (f", or a narrower prior where you know the physics (e.g. --prior "
             f"{exponents[0]}=uniform:0.2:1)" if exponents else "")
    return (f"Try a longer run (--max-steps 40000; API: max_steps=40000), more walkers "
            f"(--walkers {2 * walkers}; API: n_walkers={2 * walkers}){prior}")


def _noise_candidates(data: FrequencyResponse, noise: str) -> tuple[str, ...]:
    """The noise models a structure is run with: the one asked for; ``auto`` (which the
    likelihood resolves to ``known``, saying why) when the data carry σ; else those of
    :data:`NOISE_CANDIDATES`, among which the evidence chooses, less ``relative_parts`` where a
    real or imaginary part is exactly 0 (:func:`~bayesfo.inference.likelihood.zero_part`: the
    relative error of that part has no scale). (:func:`compare` refuses ``auto`` without σ
    where the response is exactly 0: relative noise has no scale there.)"""
    if noise != "auto" or data.sigma is not None:
        return (noise,)
    if zero_part(data) is not None:
        return tuple(n for n in NOISE_CANDIDATES if n != "relative_parts")
    return NOISE_CANDIDATES


#: The noise models among which ``noise="auto"`` chooses by evidence, when the data carry no σ:
#: one σ for every point, σ proportional to |G|, and a relative error of each part (G' and G''
#: each with its own relative error, the usual error model of a rheometer or DMA).
NOISE_CANDIDATES = ("constant", "proportional", "relative_parts")


def sample(s: Structure, data: FrequencyResponse, noise: str, fit,
           options: RunOptions) -> NoiseRun:
    """Posterior, criteria and evidence of one structure under one noise model."""
    lik = Likelihood(s, data, noise=noise, priors=options.priors_of(s, noise))
    modes, starts = starting_points(lik, fit)
    found = certified_posterior(
        lik, modes, starts=starts, sampler=options.sampler, evidence=options.evidence,
        seed=options.seed, fit_log_likelihood=fit_log_likelihood(lik, fit), remedy=remedy(lik),
        sampler_options=options.sampler_kwargs)
    post = found.posterior
    criteria = _criteria(lik, fit, post)
    criteria["warnings"].extend(found.notes)
    criteria.update(evidence=found.evidence, evidence_check=None, evidence_agree=None)
    if found.importance is not None:
        criteria["importance"] = found.importance
    return NoiseRun(lik, post, criteria)


def _exponent_intervals(run: NoiseRun) -> dict:
    """94 % HDIs of the structure's exponents (q, α, β, ...) under one noise model."""
    lik, post = run.lik, run.post
    return {p.name: (post.summary[p.name].hdi_low, post.summary[p.name].hdi_high)
            for p in lik.structure.parameters if p.role == "exponent"}


#: A noise model whose quick ln Z (:func:`~bayesfo.inference.importance.screen_noise`) trails
#: the leader's by this many nats (posterior odds above 150:1) is not sampled in full, provided
#: its own estimate is reliable (Pareto k̂ < 0.7; a heavy-tailed estimate of the leader only
#: understates its lead). Not a bound: an estimate of ln Z against an estimate, within one
#: structure; the one bound margin of the package, on max ln L against a certified ln Z, is
#: :data:`bayesfo.inference.bound.BOUND_MARGIN`.
NOISE_SCREEN_MARGIN = 5.0


def _quick_estimates(s, data, candidates, fit, options: RunOptions) -> dict:
    """The quick ln Z (:func:`~bayesfo.inference.importance.screen_noise`) of each candidate
    noise model in turn, up to the first that has none (None)."""
    quick = {}
    for noise in candidates:
        lik = Likelihood(s, data, noise=noise, priors=options.priors_of(s, noise))
        modes = lik.structure.to_scaled(lik.structure.to_physical(fit.optima, fit.scaling),
                                        lik.scaling)
        try:
            quick[noise] = screen_noise(lik, modes, seed=options.seed)
        except (np.linalg.LinAlgError, FloatingPointError):
            quick[noise] = None
        if quick[noise] is None:
            break
    return quick


def screen(s, data, candidates, fit, options: RunOptions, quick=None) -> Screen | None:
    """The quick ln Z of each candidate noise model; those that trail the leader decisively
    (see :data:`NOISE_SCREEN_MARGIN`) are set aside. Of the rest, where every quick estimate promises
    a quick posterior, all are sampled at once; where not, the one whose likelihood reaches
    highest is sampled first and the others wait (:func:`_deferral`). None when all candidates
    must be sampled at once. ``quick``: the estimates of :func:`_quick_estimates`, when already
    made."""
    if len(candidates) < 2:
        return None
    if quick is None:
        quick = _quick_estimates(s, data, candidates, fit, options) if fit.optima.size else {}
    aside = []
    if all(quick.get(noise) is not None for noise in candidates):
        order = sorted(candidates, key=lambda n: -quick[n]["log_z"])
        top = quick[order[0]]["log_z"]
        aside = [n for n in order[1:] if top - quick[n]["log_z"] >= NOISE_SCREEN_MARGIN
                 and quick[n]["k_hat"] < K_HAT_MAX]
    known = {n: q for n, q in quick.items() if q is not None}
    left = [n for n in candidates if n not in aside]
    if all(_quick_promise(quick.get(noise)) for noise in left):
        if not aside:
            return None  # every posterior promises to be quick: sampled at once
        leader, *also = sorted(left, key=lambda n: -quick[n]["log_z"])
        return Screen(leader, known, also=tuple(also))
    if len(left) == 1:
        return Screen(left[0], known)
    return _deferral(s, data, left, fit, options, known)


def _quick_promise(estimate) -> bool:
    """Whether a quick estimate promises that importance sampling will certify the posterior:
    its Pareto k̂ below :data:`~bayesfo.inference.importance.K_HAT_MAX` and no order left
    undetermined."""
    return (estimate is not None and estimate["k_hat"] < K_HAT_MAX
            and not estimate.get("undetermined"))


#: Where each noise model's maximum likelihood is sought: the residual weights of
#: :func:`~bayesfo.identify.optimize.fit_structure` under which its likelihood is a sum of
#: squares (σ the same at every point, or proportional to |G|).
NOISE_WEIGHTING = {"constant": "none", "proportional": "relative", "relative_parts": "parts"}


def _best_log_likelihood(s, data, noise, fit, options: RunOptions, *,
                         search: bool = False) -> tuple[float, float]:
    """The highest log-likelihood of ``s`` under ``noise`` (with the maximum-likelihood noise
    scale) that a least-squares fit under its weighting (:data:`NOISE_WEIGHTING`) started from
    the structure's optima finds: polished from them alone, or, with ``search``, by the global
    optimisation of :func:`_fit` (random and linear-method starts besides). Returns (the value
    at its best optimum, admissible or not; the value at its best admissible optimum, −inf where
    none is)."""
    lik = Likelihood(s, data, noise=noise, priors=options.priors_of(s, noise))
    known = fit.optima if fit.optima.size else np.atleast_2d(fit.theta_scaled)
    starts = lik.structure.to_physical(known, fit.scaling)
    found = (fit_structure(lik.structure, data, rng=options.seed, starts=starts,
                           weighting=NOISE_WEIGHTING[noise], seed_methods=True) if search else
             fit_structure(lik.structure, data, rng=options.seed, starts=starts, n_starts=1,
                           weighting=NOISE_WEIGHTING[noise], stop_after=None))
    best = found.optima if found.optima.size else np.atleast_2d(found.theta_scaled)
    theta = lik.structure.to_scaled(lik.structure.to_physical(best, found.scaling), lik.scaling)
    value = float(np.max(lik(np.column_stack([theta, lik.noise_estimate(theta)]))))
    return value, (value if found.optima.size else -np.inf)


def _deferral(s, data, candidates, fit, options: RunOptions, quick) -> Screen:
    """Where the screen does not decide and a posterior promises to be slow (a tempered ladder
    or emcee), the noise model whose likelihood reaches highest (polished optima,
    :func:`_best_log_likelihood`) is sampled first, and the others wait for its ln Z
    (:func:`settle`, :func:`_set_aside`)."""
    best = {n: _best_log_likelihood(s, data, n, fit, options) for n in candidates}
    leader, *others = sorted(candidates, key=lambda n: -best[n][0])
    return Screen(leader, {n: q for n, q in quick.items() if q is not None},
                  tuple(Deferred(n, best[n][1]) for n in others))


#: How the record of a noise model set aside by its maximum likelihood names its ln Z.
BOUND_METHOD = "upper bound (maximum likelihood)"


def _set_aside(s, data, deferred, fit, options: RunOptions, run: NoiseRun) -> dict:
    """For each deferred noise model (a tuple of :class:`Deferred`), the record that sets it
    aside after the leader's posterior ``run`` (:func:`_set_aside_one`), or None where it must
    be sampled: ``{noise: record or None}``."""
    return {d.noise: _set_aside_one(s, data, d, fit, options, run) for d in deferred or ()}


def _set_aside_one(s, data, deferred: Deferred, fit, options: RunOptions,
                   run: NoiseRun) -> dict | None:
    """The record (``{"log_z", "method", "intervals"}``) with which the deferred noise model
    is set aside after the leader's certified posterior ``run``, or None where it must be
    sampled. Set aside where it trails the leader's ln Z by :data:`NOISE_SCREEN_MARGIN`, by

    1. its ln Z estimated from the leader's posterior
       (:func:`~bayesfo.inference.evidence.other_noise_evidence`), where the Pareto k̂ of that
       estimate is below :data:`~bayesfo.inference.importance.K_HAT_MAX` (the rule of the
       quick screen), else
    2. its maximum log-likelihood, an upper bound of its ln Z (ln ∫ L π ≤ ln max L): the
       polished one of :func:`_deferral`, and where that trails (or none was admissible), the
       higher of it and a global fit's (:func:`_best_log_likelihood`). The lead and the
       probability of the leader are then lower bounds."""
    evidence = run.criteria["evidence"]
    if deferred is None or evidence is None or not run.post.converged:
        return None
    other = Likelihood(s, data, noise=deferred.noise,
                       priors=options.priors_of(s, deferred.noise))
    estimate = other_noise_evidence(other, run.lik, run.post, evidence.log_z)
    if estimate is not None and estimate["k_hat"] < K_HAT_MAX:
        return estimate if evidence.log_z - estimate["log_z"] >= NOISE_SCREEN_MARGIN else None
    if evidence.log_z - deferred.best < NOISE_SCREEN_MARGIN:
        return None
    bound = max(deferred.best, _best_log_likelihood(s, data, deferred.noise, fit, options,
                                                    search=True)[1])
    if not (np.isfinite(bound) and evidence.log_z - bound >= NOISE_SCREEN_MARGIN):
        return None  # (−inf: no admissible point found, no bound)
    return {"log_z": bound, "method": BOUND_METHOD, "intervals": {}}


def settle(screened: Screen, run: NoiseRun) -> tuple[Screen, list[str]]:
    """After the leader's posterior (``run``), the deferred noise models of ``screened``: those
    set aside with the record that :func:`sample_held` found for them (``run.aside``; see
    :func:`_set_aside`) join the screen's records, in a :class:`Screen` without ``deferred``;
    returned with the list of the others, which are sampled too."""
    records = {d.noise: run.aside.get(d.noise) for d in screened.deferred}
    rest = [n for n, r in records.items() if r is None]
    found = {n: r for n, r in records.items() if r is not None}
    return Screen(screened.leader, {**screened.quick, **found}, also=screened.also), rest


def choose_noise(name: str, runs: list[NoiseRun],
                 screened: Screen | None) -> tuple[NoiseRun, dict]:
    """The run whose noise model has the largest evidence, and the record of the choice: each
    noise model's ln Z (certified, or the estimate of a model the screen set aside),
    its posterior probability (equal prior odds) and the exponents' intervals, and
    ``sensitive`` when an exponent's intervals under the two models do not overlap.

    The chosen run's evidence becomes the structure's evidence with the noise model as a
    nuisance (:func:`_marginal_evidence`; ``record["marginal"]``), so that structures run
    under different noise models are ranked on one footing; its posterior stays the one under
    the chosen noise model (``evidence.given_noise`` holds that model's own ln Z)."""
    entries = []
    for r in runs:
        e = r.criteria["evidence"]
        entries.append(_Entry(r.lik.noise, e.log_z if e is not None else -np.inf,
                              None if e is None else float(e.log_z_err),
                              None if e is None else e.method, _exponent_intervals(r), r))
    sampled_noise = {r.lik.noise for r in runs}
    if screened is not None:
        for noise, q in screened.quick.items():
            if noise not in sampled_noise:
                entries.append(_Entry(noise, q["log_z"], None, q["method"], q["intervals"],
                                      None))
    # Against an upper bound, the lead and the probability are lower bounds.
    least = "at least " if any(e.method == BOUND_METHOD for e in entries) else ""
    log_z = np.array([e.log_z for e in entries])
    sampled = [i for i, e in enumerate(entries) if e.run is not None]
    best = max(sampled, key=lambda i: log_z[i])
    if np.isfinite(log_z[best]):
        prob = np.exp(log_z - log_z[best])
        prob /= prob.sum()
    else:
        prob = np.full(len(entries), np.nan)
    chosen = entries[best].run
    record = {"chosen": entries[best].noise, "models": {}}
    marginal = _marginal_evidence(chosen.criteria["evidence"], log_z,
                                  [e.log_z_err for e in entries])
    if marginal is not None:
        chosen.criteria["evidence"] = marginal
        record["marginal"] = {
            "log_evidence": float(marginal.log_z), "log_evidence_err": float(marginal.log_z_err),
            "prior": {e.noise: 1.0 / len(entries) for e in entries}}
    for (noise, lz, err, method, hdi, _), p in zip(entries, prob, strict=True):
        record["models"][noise] = {
            "log_evidence": float(lz) if np.isfinite(lz) else None, "log_evidence_err": err,
            "evidence_method": method,
            "probability": float(p) if np.isfinite(p) else None,
            "hdi": {k: [float(lo), float(hi)] for k, (lo, hi) in hdi.items()},
        }
    intervals = [e.intervals for e in entries]
    # The models the evidence has not excluded (probability of at least 1 − NOISE_DECISIVE):
    # exponents that part only under a model it has excluded are decided by it.
    plausible = [i for i in range(len(entries))
                 if i == best or not np.isfinite(prob[i]) or prob[i] >= 1.0 - NOISE_DECISIVE]

    def parted(among):
        out = []
        for param in intervals[best]:
            spans = [intervals[i][param] for i in among if param in intervals[i]]
            if max(lo for lo, _ in spans) > min(hi for _, hi in spans):
                out.append(param)
        return out

    apart = parted(range(len(entries)))
    contested = parted(plausible)
    # Unknown (None) where a model set aside by its maximum likelihood has no intervals.
    unknown = any(param not in iv for iv in intervals for param in intervals[best])
    record["sensitive"] = True if apart else (None if unknown else False)
    record["sensitive_parameters"] = apart
    record["contested_parameters"] = contested
    # The runner-up: the lead is stated against it.
    other = max((i for i in range(len(entries)) if i != best), key=lambda i: log_z[i])
    with np.errstate(invalid="ignore"):  # neither has an evidence: -inf - -inf
        delta = log_z[best] - log_z[other]
    names = [e.noise for e in entries]
    listed = names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]
    reason = (f"chosen by evidence over {listed} noise "
              + (f"(ln Z higher by {least}{delta:.1f}; probability {least}"
                 f"{prob[best]:.3f})" if np.isfinite(delta) else "(the other has no evidence)")
              if np.isfinite(log_z[best]) else
              f"neither {' nor '.join(e.noise for e in entries)} noise has an evidence to "
              "choose by; the first is kept")
    chosen.post = replace(chosen.post, noise_reason=reason)
    if apart:
        decided = not contested
        among = plausible if contested else range(len(entries))
        shown = "; ".join(
            f"{p} " + ", ".join(
                f"{intervals[i][p][0]:.3g}…{intervals[i][p][1]:.3g} under {entries[i].noise}"
                + (" noise" if k == 0 else "")
                for k, i in enumerate([best, *(j for j in among if j != best)])
                if p in intervals[i])
            for p in (contested or apart))
        msg = (f"{name}: the exponents depend on the noise model: 94 % intervals do not overlap "
               f"({shown}); " + (f"the evidence favours {entries[best].noise} noise with "
                                 f"probability {least}{prob[best]:.3f}" if np.isfinite(prob[best])
                                 else "neither noise model has an evidence to choose by"))
        if not decided:
            msg += (". Give sigma per point, or force a model with --noise, if you know how "
                    "the instrument's error scales")
        chosen.criteria["warnings"].append(msg)
        if not decided:
            warnings.warn(msg, NoiseWarning, stacklevel=3)
    return chosen, record


def _marginal_evidence(given, log_z, errors):
    """The evidence of the structure with the noise model as a nuisance: the mean of the noise
    models' evidences (equal prior weights, the same as the probabilities of the choice), with
    the error of that mean from theirs (a model the screen set aside adds its quick estimate,
    without an error: it holds under 1 % of the sum). ``given`` (the chosen model's
    :class:`~bayesfo.inference.evidence.Evidence`) is kept in the result as ``given_noise``;
    None where it is None or not finite."""
    if given is None or not np.isfinite(given.log_z):
        return None
    log_z = np.asarray(log_z, dtype=float)
    top = np.max(log_z)
    w = np.exp(log_z - top)
    total = float(top + np.log(w.mean()))
    share = w / w.sum()
    err = float(np.sqrt(sum((p * (e or 0.0)) ** 2 for p, e in zip(share, errors, strict=True))))
    return replace(given, log_z=total, log_z_err=err, given_noise=given)


#: The evidence decides the noise model when it gives the chosen one at least this probability;
#: below, non-overlapping exponent intervals raise a NoiseWarning (the conclusion then hangs on
#: a choice the data do not make).
NOISE_DECISIVE = 0.99


def fit_and_screen(s: Structure, data: FrequencyResponse, options: RunOptions):
    """Step 1: the optimisation and the noise screen (:func:`screen`). Returns the fit, the
    screen's record (None when it did not decide) and the noise models to sample."""
    candidates, fit = _fit(s, data, options)
    screened = screen(s, data, candidates, fit, options)
    return fit, screened, _to_sample(candidates, screened)


def _to_sample(candidates, screened: Screen | None) -> list[str]:
    """The noise models to sample now: the leader and those sampled with it where the screen
    has one, else all."""
    return list(candidates) if screened is None else [screened.leader, *screened.also]


def fit_and_probe(s: Structure, data: FrequencyResponse, options: RunOptions, fitted=None):
    """Step 1 as :func:`fit_and_screen`, and whether the rest promises to be quick: the
    screen's raw importance weights of every noise model still to sample have a Pareto k̂ below
    :data:`~bayesfo.inference.importance.K_HAT_MAX` and leave no order undetermined, so that
    importance sampling will most likely certify the posterior (a fraction of a second) and
    neither the ladder nor emcee will run. Returns ((fit, screened, noise models), quick).
    The numbers and the warnings are those of :func:`fit_and_screen`: the estimates that the
    screen does not make itself are made with their warnings discarded, and they only guide
    where the next steps run. ``fitted``: the optimisation already made elsewhere, as
    :meth:`~bayesfo.comparison.early.EarlyFits.take` gives it (its warnings are issued
    here)."""
    if fitted is None:
        candidates, fit = _fit(s, data, options)
    else:
        candidates, fit, caught = fitted
        for category, message in caught:
            warnings.warn(message, category, stacklevel=2)
    quick = (_quick_estimates(s, data, candidates, fit, options)
             if len(candidates) > 1 and fit.optima.size else {})
    screened = screen(s, data, candidates, fit, options, quick=quick)
    noises = _to_sample(candidates, screened)
    if (options.sampler != "auto" or options.evidence != "auto"
            or options.evidence_check or not fit.optima.size):
        return (fit, screened, noises), False
    # The promise covers the deferred noise models too: they may be sampled where the leader is.
    promised = noises + ([d.noise for d in screened.deferred] if screened else [])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for noise in promised:
            if noise not in quick:
                try:
                    quick.update(_quick_estimates(s, data, (noise,), fit, options))
                except (InputError, np.linalg.LinAlgError, FloatingPointError):
                    quick[noise] = None
    promise = all(_quick_promise(quick.get(n)) for n in promised)
    return (fit, screened, noises), promise


def _fit(s: Structure, data: FrequencyResponse, options: RunOptions):
    """The noise models to choose from and the global optimisation (the modes)."""
    candidates = _noise_candidates(data, options.noise)
    structure = Likelihood(s, data, noise=candidates[0], priors=options.priors_of(s)).structure
    fit = fit_structure(structure, data, rng=options.seed, seed_methods=True,
                        linear_methods=True)
    return candidates, fit


def sample_held(s: Structure, data: FrequencyResponse, noise: str, fit,
                options: RunOptions, deferred: tuple = ()) -> NoiseRun:
    """Step 2: :func:`sample` under one noise model, its warnings held back in
    ``run.caught`` (category, message, file, line): only the chosen model's reach the user
    (:func:`conclude`; the other's are kept in its record).

    With ``deferred`` (the noise models waiting for this one's ln Z, :func:`_deferral`),
    ``run.aside`` holds the record that sets each aside, where this posterior allows
    (:func:`_set_aside`; for :func:`settle`)."""
    with warnings.catch_warnings(record=True) as held:
        warnings.simplefilter("always")
        run = sample(s, data, noise, fit, options)
        run.aside = _set_aside(s, data, deferred, fit, options, run)
    run.caught = [(w.category, str(w.message), w.filename, w.lineno) for w in held]
    return run


def conclude(s: Structure, data: FrequencyResponse, fit, screened: Screen | None,
             runs: list[NoiseRun], options: RunOptions) -> StructureResult:
    """Step 3, once the runs of step 2 are in: the noise model chosen by evidence, the chosen
    run's warnings issued, the evidence check, the adequacy checks, the held-out points."""
    seed, held_out = options.seed, options.holdout
    if len(_noise_candidates(data, options.noise)) > 1:
        run, record = choose_noise(s.name, runs, screened)
    else:
        run, record = runs[0], None
    lik, post, criteria = run.lik, run.post, run.criteria
    for category, message, filename, lineno in run.caught:
        warnings.warn_explicit(message, category, filename, lineno)
    for other in runs:
        if other is not run:
            record["models"][other.lik.noise]["warnings"] = list(
                dict.fromkeys(message for _, message, _, _ in other.caught))
    criteria["noise_models"] = record
    if options.evidence_check and criteria["evidence"] is not None:
        check = evidence_check(lik, post, criteria["evidence"], seed)
        criteria["warnings"].extend(check.pop("warnings"))
        criteria.update(check)
    try:
        criteria["adequacy"] = check_adequacy(lik, post, seed=seed)
    except InputError as exc:  # e.g. too few frequencies for the statistics
        criteria["adequacy"] = None
        criteria["warnings"].append(f"{s.name}: no adequacy check: {exc}")
    if held_out is not None:
        criteria.update(_holdout(lik, post, held_out))
    return StructureResult(s, fit, post, Criteria.from_dict(criteria))


def kept(name: str, caught) -> list[tuple]:
    """The warnings (category, message) of a structure's run, each once, said of the structure
    (a library's gets its name in front; deprecations are dropped)."""
    kept = {}
    for category, text in caught:
        text = text if text.startswith(f"{name}:") else f"{name}: {text}"
        if not issubclass(category, (DeprecationWarning, PendingDeprecationWarning)):
            kept.setdefault((category, text))
    return list(kept)


#: How a structure's maximum log-likelihood under each noise model is found for the evidence
#: bound (recorded as the bound's ``source``).
BOUND_SOURCES = {
    False: "least squares polished from the global optimisation's optima under each noise "
           "model's weighting",
    True: "global multi-start optimisation (random, linear-method and optima starts) under "
          "each noise model's weighting",
}


def _noise_weighting(lik) -> str:
    """The residual weights under which ``lik``'s likelihood is a sum of squares."""
    return NOISE_WEIGHTING.get(lik.noise, "sigma")


def best_fit(s: Structure, data: FrequencyResponse, noise: str, fit, options: RunOptions, *,
             search: bool = False) -> float:
    """The highest log-likelihood of ``s`` under ``noise`` (with the maximum-likelihood noise
    scale where it is sampled) that least squares under the noise model's weighting finds,
    started from the global optimisation ``fit`` (``search``: with random and linear-method
    starts besides, a global optimisation of its own): an upper bound of the structure's ln Z
    under that noise model, as good as the optimiser (:mod:`bayesfo.inference.bound`). The
    optimum need not be admissible: the maximum over a larger set only loosens the bound.
    -inf where no point has a finite likelihood."""
    return _best_point(s, data, noise, fit, options, search=search)[0]


def _best_point(s, data, noise, fit, options: RunOptions, *, search: bool = False):
    """(value, point on the scaled problem with its noise scale, likelihood) of
    :func:`best_fit`; the point is None where no point has a finite likelihood."""
    lik = Likelihood(s, data, noise=noise, priors=options.priors_of(s, noise))
    known = fit.optima if fit.optima.size else np.atleast_2d(fit.theta_scaled)
    starts = lik.structure.to_physical(known, fit.scaling)
    weighting = _noise_weighting(lik)
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        found = (fit_structure(lik.structure, data, rng=options.seed, starts=starts,
                               weighting=weighting, seed_methods=True) if search else
                 fit_structure(lik.structure, data, rng=options.seed, starts=starts, n_starts=1,
                               weighting=weighting, stop_after=None))
        points = [(found.optima if found.optima.size else np.atleast_2d(found.theta_scaled),
                   found.scaling), (known, fit.scaling)]
        thetas = []
        for theta, scaling in points:
            theta = lik.structure.to_scaled(lik.structure.to_physical(theta, scaling), lik.scaling)
            if lik.noise_param:
                theta = np.column_stack([theta, lik.noise_estimate(theta)])
            thetas.append(theta)
        thetas = np.vstack(thetas)
        values = np.asarray(lik(thetas), dtype=float)
    values = np.where(np.isfinite(values), values, -np.inf)
    if not np.isfinite(values).any():
        return -np.inf, None, lik
    best = int(np.argmax(values))
    return float(values[best]), thetas[best], lik


def best_fit_adequacy(s: Structure, data: FrequencyResponse, noise: str, fit,
                      options: RunOptions):
    """The posterior predictive checks (:func:`~bayesfo.inference.adequacy.check_adequacy`)
    with the best fit under ``noise`` (and its maximum-likelihood noise scale) standing in
    for the posterior: whether the best the structure can do describes the data. None where
    no point has a finite likelihood or the checks cannot be made."""
    _, theta, lik = _best_point(s, data, noise, fit, options)
    if theta is None:
        return None
    physical = lik.to_physical(theta[None, :])
    stand_in = PosteriorResult(
        structure=s.name, param_names=tuple(lik.param_names), noise=lik.noise,
        noise_reason="", samples=physical, samples_scaled=theta[None, :],
        log_likelihood=np.asarray(lik(theta[None, :]), dtype=float), summary={},
        map_theta=physical[0], max_log_likelihood=float(lik(theta[None, :])[0]),
        tau=np.zeros(lik.ndim), n_steps=0, burn=0, thin=1, n_walkers=1, acceptance=np.nan,
        rhat_max=np.nan, ess_bulk_min=np.nan, ess_tail_min=np.nan, converged=False,
        sampler="best fit")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return check_adequacy(lik, stand_in, seed=options.seed)
    except (InputError, ValueError, ArithmeticError):
        return None


def best_fits(s: Structure, data: FrequencyResponse, fit, options: RunOptions, *,
              search: bool = False) -> dict[str, float]:
    """``{noise: highest log-likelihood}`` of ``s`` under every noise model the comparison
    considers for it (:func:`best_fit`; the noise models by the names the posteriors give
    them, ``known`` for ``auto`` on data with σ): the largest of them bounds the structure's
    ln Z, which is the mean of the evidences under those noise models."""
    out = {}
    for noise in _noise_candidates(data, options.noise):
        name = Likelihood(s, data, noise=noise, priors=options.priors_of(s, noise)).noise
        out[name] = best_fit(s, data, noise, fit, options, search=search)
    return out


def bounded_result(s: Structure, data: FrequencyResponse, fit, best: dict[str, float],
                   leader: str, leader_log_z: float, options: RunOptions, *,
                   search: bool = True, margin: float | None = None) -> StructureResult:
    """The result of a structure left out by the evidence bound: its best fit (the optimum,
    RMSE), the maximum log-likelihood (the largest of ``best``, by noise model) with AIC, AICc
    and BIC from it, and ``criteria.bound``; no posterior, so no PSIS-LOO, WAIC or figures."""
    noise = max(best, key=best.get)
    lik = Likelihood(s, data, noise=noise, priors=options.priors_of(s, noise))
    max_ll = float(best[noise])
    k, n_real = lik.ndim, 2 * data.n_frequencies
    aic = 2 * k - 2 * max_ll
    aicc = aic + (2 * k * (k + 1) / (n_real - k - 1) if n_real - k - 1 > 0 else np.inf)
    bic = k * np.log(n_real) - 2 * max_ll
    margin = BOUND_MARGIN if margin is None else margin
    shortfall = leader_log_z - max_ll
    note = (f"{s.name}: {BOUND_REASON} (max ln L {max_ll:.2f} under {noise} noise, "
            f"{shortfall:.1f} nats below the ln Z of {leader}, more than the margin of "
            f"{margin:g}); run with --sample all (API: sample='all') for its posterior, "
            "PSIS-LOO, WAIC and figures")
    bound = {"log_evidence_bound": max_ll, "by_noise": {n: float(v) for n, v in best.items()},
             "noise": noise, "source": BOUND_SOURCES[search], "leader": leader,
             "leader_log_evidence": float(leader_log_z), "margin": float(margin),
             "below_leader": float(shortfall), "reason": BOUND_REASON}
    criteria = {"max_log_likelihood": max_ll, "aic": aic, "aicc": float(aicc), "bic": float(bic),
                "rmse": float(fit.rmse), "priors": lik.describe_priors(), "warnings": [note],
                "bound": bound,
                # Whether the best fit describes the data (the checks with it for the posterior).
                "adequacy": best_fit_adequacy(s, data, noise, fit, options)}
    return StructureResult(s, fit, None, Criteria.from_dict(criteria))
