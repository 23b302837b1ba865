"""The certified-posterior policy: which route gives a likelihood's posterior and its ln Z.

:func:`certified_posterior` is the one entry point; ``compare`` calls it for every structure
and noise model, and any new likelihood with the :class:`~bayesfo.inference.Likelihood`
interface gets its posterior the same way.

The routes, in order, with ``sampler="auto"``:

1. importance sampling from a proposal centred on the optima
   (:func:`~bayesfo.inference.importance.importance_posterior`): certified when the Pareto k̂
   of the weights is below 0.7, their ESS at least 1000, and every fractional order
   determined (its 94 % interval within a quarter of its prior range: an undetermined order
   allows configurations, springpots exchanged or vanishing, that a proposal built at the
   optima can miss), and no ridge found along which the posterior holds mass that the
   proposal does not reach (the ridge probe); ln Z from the same weights where k̂ < 0.5
   (where it is 0.5 or more, from a later round, adapted to the weighted draws or a normal
   mixture fitted to them, if its k̂ is below 0.5, else from a tempered ladder, whose
   particles replace the importance draws where :data:`LADDER_MISSED` more of them lie outside
   the draws' range than draws of one posterior would and its runs agree: the draws missed
   part of the posterior); where the weights give ln Z (and ``evidence="auto"``, without
   sampler settings), the configurations where an element vanishes
   (:mod:`~bayesfo.inference._configurations`: a coefficient at its lower prior bound, the
   others maximised), which no optimum seeds, are searched, and the posterior mass they hold
   beyond the draws' range must be at most :data:`CONFIGURATIONS_MISSED`;
2. where the weights do not certify it (ridges, several regions), or no optimum is admissible
   (no proposal: the posterior lies against a constraint; the runs must then reach the
   optimiser's best fit moved into the support within :data:`LADDER_SHORTFALL`), two
   independent runs of the tempered ladder guided by the proposal's draws where there is one
   (and proposing in the configurations where an element vanishes that the search found, as
   every ladder of this module does): their final particles are the posterior when the runs
   agree (R-hat < 1.01, ESS ≥ 400), and their ln Z the evidence; where they do not, two more
   runs (unless one of the first ended more than :data:`LADDER_SHORTFALL` below the best fit,
   which more runs cannot mend), and the four where the new pair agrees and all four agree;
3. else emcee from the optima (and any other starts given); ln Z by bridge sampling from its
   draws where the walkers converged, else by a tempered ladder guided by them, whose
   particles replace the walkers' draws when its runs agree. A posterior that no route
   certifies is returned flagged (``posterior.converged`` False), with the reason.

``sampler="emcee"`` starts at 3. Sampler settings (``max_steps``, ``n_walkers``) or
``evidence="ladder"`` skip route 2; ``evidence="bridge"`` implies emcee (bridge sampling
needs its draws); ``evidence="ladder"`` takes ln Z from a ladder whatever gave the posterior.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import CertifiedWarning, ConvergenceWarning, EvidenceWarning, InputError
from ..options import EVIDENCE_ROUTES, SAMPLERS, check_routes  # noqa: F401  (the routes, named here too)
from ._configurations import configurations, missed_share, vanished
from ._ridge import PROBE_MAX_DIM
from .evidence import Evidence, bridge_evidence, ladder_runs, nested_evidence
from .importance import importance_posterior
from .likelihood import Likelihood
from .posterior import sample_posterior, support_seeds
from .results import PosteriorResult, ladder_agreement, posterior_from_particles
from .transform import Transform

#: A tempered-ladder run whose best particle ends this far (nats) below the best fit found by
#: the optimiser and the sampler has missed part of the posterior (1 000 particles of a
#: posterior reach within a few nats of its maximum).
LADDER_SHORTFALL = 5.0


@dataclass(frozen=True)
class CertifiedPosterior:
    """What :func:`certified_posterior` found.

    Attributes
    ----------
    posterior : PosteriorResult
        Certified unless ``posterior.converged`` is False (``posterior.messages`` say why).
    evidence : Evidence or None
        ln Z by the route that gave the posterior (or the one asked for); None where none
        could be computed (a warning says why).
    evidence_check : Evidence or None
        ln Z by dynesty nested sampling, when asked for (``check=True``).
    evidence_agree : bool or None
        Whether the two ln Z agree within twice their combined error (with the check).
    notes : tuple of str
        How the posterior was reached where the first route did not give it, and what the
        evidence's checks found, in words for the user.
    importance : dict or None
        The importance route's certificate (k̂, ESS, proposal modes, seconds) where it gave the
        posterior.
    best_log_likelihood : float
        The highest log-likelihood seen: the optimiser's (as given) or any posterior draw's.
    """

    posterior: PosteriorResult
    evidence: Evidence | None
    evidence_check: Evidence | None = None
    evidence_agree: bool | None = None
    notes: tuple[str, ...] = ()
    importance: dict | None = None
    best_log_likelihood: float = -math.inf


def certified_posterior(lik: Likelihood, modes, *, starts=None, sampler: str = "auto",
                        evidence: str = "auto", seed: int = 0, check: bool = False,
                        fit_log_likelihood: float = -math.inf, remedy: str = "",
                        sampler_options: dict | None = None) -> CertifiedPosterior:
    """The certified posterior of ``lik`` and its ln Z, by the routes of this module.

    Parameters
    ----------
    lik : Likelihood
        Or any object with its interface (``pointwise``, ``in_support``, priors, scaling).
    modes : ndarray, shape (n_modes, ndim_structure)
        The optima found (scaled coordinates of ``lik``, without the noise parameter): the
        centres of the importance proposal and starts of emcee. Empty where none is
        admissible: the tempered ladder then starts from the prior (route 2), and emcee, if it
        runs, from ``starts``.
    starts : ndarray, optional
        More starting points for emcee (e.g. linear estimates, an inadmissible best fit);
        ``modes`` are always used.
    sampler : {"auto", "emcee"}
    evidence : {"auto", "bridge", "ladder"}
    seed : int
        Every random step is seeded from it: the same seed gives the same numbers.
    check : bool
        Also compute ln Z by dynesty nested sampling, and say whether the two agree.
    fit_log_likelihood : float
        The optimiser's best log-likelihood: a ladder that ends far below it is flagged.
    remedy : str
        What to try when no route certifies the posterior (appended to that note).
    sampler_options : dict, optional
        Settings of emcee (``max_steps``, ``n_walkers``, ...; see
        :func:`~bayesfo.inference.posterior.sample_posterior`).

    Returns
    -------
    CertifiedPosterior
    """
    check_routes(sampler, evidence)
    sampler_options = dict(sampler_options or {})
    modes = np.atleast_2d(np.asarray(modes, dtype=float))
    name = lik.structure.name
    post = ev = tried = info = more = slabs = None
    notes = []
    # Bridge sampling is defined on emcee's draws: a forced bridge route takes emcee.
    if sampler == "auto" and evidence != "bridge":
        if modes.size:
            try:
                post, ev, info = importance_posterior(lik, modes, seed=seed)
            except (np.linalg.LinAlgError, FloatingPointError):  # to the samplers
                post, ev, info = None, None, {}
            if post is not None and ev is not None and evidence == "auto" \
                    and not sampler_options:
                post, ev, slabs = _configurations_checked(lik, modes, post, ev, info, seed)
        if post is None and evidence == "auto" and not sampler_options:
            # Without optima (none admissible: the posterior lies against a constraint) there
            # is no importance proposal, and the ladder starts from the prior unguided.
            guide = (info or {}).get("proposal_draws")
            if slabs is None:
                slabs = configurations(lik, modes, guide)
            # The log-likelihood the runs must reach (within LADDER_SHORTFALL): the best start
            # moved into the support where no optimum is admissible; else the best fit's.
            reach = (_seeds_log_likelihood(lik, starts, seed) if not modes.size
                     else fit_log_likelihood)
            post, ev, tried, more = _ladder_first(lik, seed, guide, slabs, reach)
            if post is not None and not modes.size \
                    and (tried := _shortfall(reach, ev, "the best fit moved into the "
                                             "posterior's support")) is not None:
                post = ev = more = None
            if post is not None and not modes.size:
                notes.append(f"{name}: no optimum found lies in the posterior's support "
                             "(each is unstable, not dissipative or breaks an inequality of the "
                             "structure); the tempered ladder, started from the prior, gave "
                             "the posterior")
    # The warnings of emcee's draws are held until it is known whether they are the posterior
    # reported: a ladder that certifies it instead replaces them.
    with warnings.catch_warnings(record=True) as held:
        warnings.simplefilter("always")
        if post is None:
            x0 = modes if starts is None or not np.size(starts) else np.vstack([modes, starts])
            post = sample_posterior(lik, x0, seed=seed, progress=False,
                                    **{"give_up": True, **sampler_options})
        if post.sampler == "ladder" and info and (info.get("undetermined") or info.get("ridge")
                                                  or info.get("vanishing")):
            notes.append(f"{name}: {info['reason']}; the tempered ladder, started from the "
                         "prior, gave the posterior")
        if more and post.sampler == "ladder":
            notes.append(more)
        if post.sampler == "emcee" and tried:
            notes.append(f"{name}: the tempered-ladder runs tried first did not certify the "
                         f"posterior ({tried}); emcee ran instead")
        best = max(post.max_log_likelihood, fit_log_likelihood)
        of_draws = len(held)
        if slabs is None and (evidence == "ladder" or (evidence == "auto" and ev is None and (
                not post.converged or post.sampler == "importance"))):
            # A ladder runs for ln Z: it proposes in the configurations too.
            slabs = configurations(lik, modes, Transform(lik).to_u(post.samples_scaled))
        found = _evidence(lik, post, seed, evidence, best_log_likelihood=best, importance=ev,
                          slabs=slabs or ())
        runs = found.pop("ladder_runs")
        if slabs and (post.sampler == "ladder" or runs is not None) \
                and not (info or {}).get("vanishing"):
            notes.append(f"{name}: where {' or '.join(vanished(lik, slabs))} vanishes, the "
                         "posterior holds a region that no optimum seeds; the tempered ladder "
                         "proposes there as well")
        replaced = False
        if runs is not None and not post.converged:
            post, note, replaced = _certified_by_ladder(lik, post, runs, seed, remedy)
            notes.append(note)
            warnings.warn(note, CertifiedWarning if replaced else ConvergenceWarning,
                          stacklevel=2)
        elif runs is not None and post.sampler == "importance":
            post, note = _checked_by_ladder(lik, post, runs, seed, info)
            if note is not None:
                notes.append(note)
    # Replaced, emcee's draws and their warnings are set aside; everything after them stands.
    for w in held[of_draws if replaced else 0:]:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    notes += found["warnings"]
    checked = {}
    if check and found["evidence"] is not None:
        checked = evidence_check(lik, post, found["evidence"], seed)
        notes += checked.pop("warnings")
    return CertifiedPosterior(
        posterior=post, evidence=found["evidence"],
        evidence_check=checked.get("evidence_check"),
        evidence_agree=checked.get("evidence_agree"), notes=tuple(notes),
        importance=info if post.sampler == "importance" else None,
        best_log_likelihood=max(best, post.max_log_likelihood))


#: The share of the posterior that configurations where an element vanishes may hold beyond
#: the importance draws' reach (:func:`~._configurations.missed_share`) for the weights to
#: certify it: the ridge probe's threshold, for the same reason.
CONFIGURATIONS_MISSED = 0.03


def _configurations_checked(lik, modes, post, ev, info: dict, seed: int):
    """The fourth part of the importance route's certificate, where its weights gave the
    posterior and ln Z (no ladder runs to check them): the configurations where an element
    vanishes (:mod:`~._configurations`), which no optimum seeds, and the posterior mass they
    hold beyond the draws' range. Records ``configurations`` in ``info`` (the coefficients
    whose vanishing was found, the share missed); where it exceeds :data:`CONFIGURATIONS_MISSED`
    the importance posterior is not certified (``vanishing`` and ``reason`` in ``info``, its
    draws the ladder's guide). Returns (posterior or None, evidence or None, slabs)."""
    draws_u = Transform(lik).to_u(post.samples_scaled)
    slabs = configurations(lik, modes, draws_u)
    names = vanished(lik, slabs)
    missed = 0.0
    if slabs:
        with np.errstate(all="ignore"):
            missed = missed_share(lik, slabs, draws_u, ev.log_z + ev.log_support, seed)
    info["configurations"] = {"vanishing": names, "missed": missed}
    if lik.ndim > PROBE_MAX_DIM:
        info["configurations"]["skipped"] = f"{lik.ndim} parameters, more than {PROBE_MAX_DIM}"
    if not missed > CONFIGURATIONS_MISSED:
        return post, ev, slabs
    info["vanishing"] = names
    info["reason"] = (f"where {' or '.join(names)} vanishes, the "
                      f"posterior holds about {100 * missed:.0f} % of its mass beyond the "
                      "importance draws' reach")
    info["proposal_draws"] = draws_u
    return None, None, slabs


def _ladder_first(lik, seed: int, guide=None, slabs=(), reach: float = -math.inf):
    """Where importance sampling does not certify the posterior (ridges, several regions) or
    has no proposal (no admissible optimum), the tempered ladder's two independent runs: their
    final particles are the posterior when the runs agree (R-hat < 1.01, ESS ≥ 400; see
    :func:`~bayesfo.inference.results.posterior_from_particles`), and their ln Z the evidence.

    Where the two do not agree, two more runs are made: the four are the posterior when the two
    new runs agree with each other and all four agree, by the same tests (a second, independent
    pair that passes on its own, and the first pair's particles consistent with it). The R-hat
    of two runs whose particles share ancestors scatters enough on a broad posterior that two
    runs of the same posterior can fail the test by chance, and emcee, the next route, costs
    many times as much on the posteriors that reach it (undetermined orders; BENCHMARKS.md,
    "The demo's Maxwell: a second pair of ladder runs").

    Returns (posterior, evidence, None, note), or (None, None, reason, None) when the runs
    disagree or the ladder fails: emcee then runs, and a ladder guided by its walkers. ``note``
    says so where the posterior took four runs.

    ``guide``: the importance proposal's draws (sampling coordinates), which cover every optimum
    found; the ladder's independence moves propose from them too, so that a narrow mode with
    little prior mass that the optimiser found is not lost (see
    :func:`~bayesfo.inference.smc.ladder_run`); ``slabs``: the configurations where an element
    vanishes (:mod:`~bayesfo.inference._configurations`), where the ladder proposes too;
    ``reach``: the log-likelihood that the runs must reach within :data:`LADDER_SHORTFALL`
    (the best fit's, or the best start's moved into the support): where the first two runs
    disagree and one ended further below, they missed the region around it, which more runs
    cannot mend (a run that falls short keeps the four short), so none are made."""
    def why(post):
        return "; ".join(m.split(": ", 1)[-1] for m in post.messages)

    try:
        ev, runs = ladder_runs(lik, seed=seed, guide=guide, slabs=slabs)
        first = ladder_agreement(lik, runs, seed=seed)
        if first.converged:
            return posterior_from_particles(lik, runs, seed=seed, agreement=first), ev, None, None
        if (short := _shortfall(reach, ev, "the best fit")) is not None:
            return None, None, f"{why(first)}; {short}", None
        ev, runs = ladder_runs(lik, seed=seed, guide=guide, earlier=runs, slabs=slabs)
        second = ladder_agreement(lik, runs[len(runs) // 2:], seed=seed)
        if not second.converged:
            return None, None, f"{why(first)}; two more runs: {why(second)}", None
        four = ladder_agreement(lik, runs, seed=seed)
        if not four.converged:
            return None, None, f"{why(first)}; all four runs: {why(four)}", None
        post = posterior_from_particles(lik, runs, seed=seed, agreement=four)
    except (InputError, np.linalg.LinAlgError, FloatingPointError) as exc:  # to emcee
        return None, None, str(exc), None
    note = (f"{lik.structure.name}: the first two tempered-ladder runs did not certify the "
            f"posterior ({why(first)}); two more runs agree with each other (R-hat "
            f"{second.rhat_max:.3f}) and with them (R-hat {post.rhat_max:.3f} over the four, "
            f"ESS {post.ess_min:.0f}), and the four give the posterior")
    return post, ev, None, note


def _seeds_log_likelihood(lik, starts, seed: int) -> float:
    """The log-likelihood of the best of ``starts`` (the optimiser's best fit among them)
    moved into the support; −inf where there are none, or none could be moved there."""
    if starts is None or not np.size(starts):
        return -math.inf
    try:
        _, ll = support_seeds(lik, starts, np.random.default_rng(seed))
    except InputError:  # no start in the support, nor any prior draw: nothing to compare
        return -math.inf
    return float(ll[0])


def _shortfall(reach: float, ev: Evidence, what: str) -> str | None:
    """Why the tempered-ladder runs of ``ev`` are set aside: the run that reached least high
    ended more than :data:`LADDER_SHORTFALL` below ``reach`` (the log-likelihood of ``what``),
    missing the region around it; None where they reached it (or ``reach`` is −inf). Where
    no optimum is admissible, emcee, started from the best fit moved into the support,
    explores that region instead."""
    gap = reach - ev.reached_log_likelihood
    if not gap > LADDER_SHORTFALL:
        return None
    return f"a run ended {gap:.1f} nats below {what}, missing the region around it"


#: Share of the particles of the tempered ladder run for ln Z beside an importance posterior
#: (its weights too heavy-tailed for ln Z) that may lie outside the range of the importance
#: draws on some parameter, beyond the share expected of draws from the same posterior
#: (:func:`_expected_outside`), before the ladder's particles replace them. Ladders beside
#: importance draws of the same posterior left about 1 % outside; importance posteriors that
#: missed a configuration of the springpots left far more (BENCHMARKS.md, "The ladder run for
#: ln Z checks the importance draws").
LADDER_MISSED = 0.03


def _expected_outside(n_params: int, ess: float) -> float:
    """The share of draws from a posterior expected outside the range of ``ess`` independent
    draws from it on some of ``n_params`` parameters: at most 2/(ess + 1) per parameter (the
    chance that a new draw is the smallest or the largest), summed; about 1 % for four
    parameters and 1 000 draws, several % for the dozens of a master curve."""
    return min(1.0, 2.0 * n_params / (max(ess, 1.0) + 1.0))


def _outside(draws: np.ndarray, others: np.ndarray) -> float:
    """Share of ``others`` outside the range of ``draws`` on some parameter (rows are draws)."""
    lo, hi = draws.min(axis=0), draws.max(axis=0)
    return float(np.mean(np.any((others < lo) | (others > hi), axis=1)))


def _checked_by_ladder(lik, post, runs, seed, info: dict):
    """The last part of the importance route's certificate, where its weights gave the posterior
    but not ln Z and a tempered ladder (started from the prior) ran for it: where the ladder's
    particles lie outside the range of the importance draws in :data:`LADDER_MISSED` more of
    cases than draws of one posterior would (:func:`_expected_outside`), the draws missed part
    of the posterior (a configuration no probe from the optima reaches), and the ladder's
    particles are the posterior if its runs agree. Records ``ladder_outside`` in ``info``;
    returns (posterior, note or None)."""
    name = lik.structure.name
    agreement = ladder_agreement(lik, runs, seed=seed)
    particles = Transform(lik).to_theta(
        agreement.chain_u.reshape(-1, agreement.chain_u.shape[-1]))
    outside = _outside(post.samples_scaled, particles)
    info["ladder_outside"] = outside
    if outside <= LADDER_MISSED + _expected_outside(lik.ndim, post.ess_min):
        return post, None
    ladder = posterior_from_particles(lik, runs, seed=seed, agreement=agreement)
    share = f"{100 * outside:.0f} % of the particles of the tempered-ladder runs that gave ln Z"
    if not ladder.converged:
        note = (f"{name}: {share} lie outside the range of the importance draws, but the runs "
                "do not agree with each other; the importance draws are reported, and may "
                "miss part of the posterior")
        warnings.warn(note, ConvergenceWarning, stacklevel=3)
        return post, note
    note = (f"{name}: {share} lie outside the range of the importance draws, which missed "
            f"part of the posterior; the runs agree (R-hat {ladder.rhat_max:.3f}, ESS "
            f"{ladder.ess_min:.0f}), and their particles are the posterior reported")
    return ladder, note


def _certified_by_ladder(lik, post, runs, seed, remedy: str):
    """Where the emcee walkers did not converge, the final particles of the independent
    tempered-ladder runs (which gave ln Z) are the posterior, if the runs agree. Returns
    (posterior, note, whether the ladder certified it)."""
    name = lik.structure.name
    ladder = posterior_from_particles(lik, runs, seed=seed)
    if not ladder.converged:
        note = (f"{name}: the tempered-ladder runs do not certify the posterior "
                f"either ({'; '.join(m.split(': ', 1)[1] for m in ladder.messages)}); the "
                "emcee draws are reported, flagged." + (f" {remedy}" if remedy else ""))
        return post, note, False
    why = "; ".join(m.split(": ", 1)[-1] for m in post.messages)
    note = (f"{name}: the posterior reported is that of {ladder.n_walkers} "
            f"independent tempered-ladder runs of {ladder.samples.shape[0] // ladder.n_walkers} "
            f"particles, which agree (R-hat {ladder.rhat_max:.3f}, ESS {ladder.ess_min:.0f}); "
            "the emcee walkers did not converge" + (f" ({why})" if why else ""))
    return ladder, note, True


def _evidence(lik, post: PosteriorResult, seed: int, route: str = "auto", *,
              best_log_likelihood: float | None = None, importance=None, slabs=()) -> dict:
    """ln Z of ``post`` by ``route``: ``{"evidence", "ladder_runs", "warnings"}``; a ladder
    proposes in the configurations ``slabs`` too."""
    out = {"evidence": None, "warnings": [], "ladder_runs": None}
    # Bridge sampling from the emcee draws needs draws that represent the posterior; where the
    # walkers did not converge (ridges, several modes), a tempered ladder reaches the posterior
    # from the prior instead, proposing from the draws as well so that it keeps the narrow modes
    # the walkers found. Importance draws are a resample (duplicates): without the weights' own
    # ln Z (k̂ ≥ 0.5) they go to the ladder, not to bridge sampling.
    ladder = route == "ladder" or (route == "auto" and (
        not post.converged or getattr(post, "sampler", "emcee") == "importance"))
    try:
        if importance is not None and route == "auto":
            out["evidence"] = importance  # the certified weights that gave the posterior
        elif ladder:
            try:
                out["evidence"], out["ladder_runs"] = ladder_runs(lik, seed=seed, guide=post,
                                                                  slabs=slabs)
            except InputError as exc:
                if route == "ladder":
                    raise
                warnings.warn(f"{post.structure}: tempered ladder failed ({exc}); ln Z from the "
                              "emcee draws instead", EvidenceWarning, stacklevel=3)
                out["evidence"] = bridge_evidence(lik, post, seed=seed)
        else:
            out["evidence"] = bridge_evidence(lik, post, seed=seed)
    except InputError as exc:
        warnings.warn(f"{post.structure}: no evidence: {exc}", EvidenceWarning, stacklevel=3)
        return out
    ev = out["evidence"]
    if (ev.reached_log_likelihood is not None and best_log_likelihood is not None
            and ev.reached_log_likelihood < best_log_likelihood - LADDER_SHORTFALL):
        message = (f"{post.structure}: a tempered-ladder run ended "
                   f"{best_log_likelihood - ev.reached_log_likelihood:.1f} nats below the best "
                   "fit, so its ln Z may be too low")
        out["warnings"].append(message)
        warnings.warn(message, EvidenceWarning, stacklevel=3)
    if not post.converged and ev.method == "bridge":
        out["warnings"].append(f"{post.structure}: posterior not converged, so its evidence is "
                               "unreliable")
    return out


def evidence_check(lik, post, evidence, seed: int) -> dict:
    """ln Z by dynesty nested sampling beside ``evidence``, and whether they agree within twice
    their combined error: ``{"evidence_check", "evidence_agree", "warnings"}``. Nested
    sampling runs under the likelihood's one noise model: where ``evidence`` is marginalised
    over noise models, it is compared with the estimate under that model
    (:attr:`Evidence.conditional`)."""
    out = {"warnings": []}
    evidence = evidence.conditional
    # Uniform draws from bounding ellipsoids where the posterior is one compact mode; slice
    # sampling where the walkers did not converge (ridges, several modes), on which uniform
    # draws stall (see nested_evidence).
    how = {} if post.converged else {"sample": "rslice", "slices": max(25, 5 * lik.ndim)}
    nested = nested_evidence(lik, seed=seed, **how)
    out["evidence_check"] = nested
    combined = math.hypot(evidence.log_z_err, nested.log_z_err)
    agree = abs(evidence.log_z - nested.log_z) <= 2 * combined
    out["evidence_agree"] = bool(agree)
    if not agree:
        out["warnings"].append(f"{post.structure}: {evidence.method} and nested ln Z disagree")
        warnings.warn(
            f"{post.structure}: {evidence.method} ln Z = {evidence.log_z:.2f} ± "
            f"{evidence.log_z_err:.2f} and nested ln Z = {nested.log_z:.2f} ± "
            f"{nested.log_z_err:.2f} disagree", EvidenceWarning, stacklevel=3)
    return out
