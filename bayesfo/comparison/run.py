"""Run structures on one data set and rank them: the engine behind ``bayesfo compare``.

For every structure: the global least-squares optimisation (modes and a maximum-likelihood
start); without σ in the data, the choice between a constant and a proportional noise model by
their evidence; a certified posterior, by importance sampling from the optima where its weights certify
it (:mod:`bayesfo.inference.importance`), else emcee, and where the walkers do not converge the
particles of the tempered ladder if its independent runs agree; the criteria that follow:
maximum log-likelihood, AIC, AICc, BIC (from the higher of the optimiser's and the sampler's
maximum), WAIC and PSIS-LOO (arviz, pointwise per frequency), RMSE at the posterior mode (thesis
eq. (3.23)); the log-evidence ln Z from the route that gave the posterior (optionally checked by
dynesty nested sampling, flagged when the two disagree by more than twice their combined error);
and the posterior predictive adequacy checks (:mod:`bayesfo.inference.adequacy`). Structures are
ranked by ln Z; posterior model probabilities assume equal prior odds unless given.

Structures run one after the other or side by side in worker processes (``workers``), where
the posteriors of a structure's two noise models run side by side too (:mod:`.schedule`), or,
by default in the command line (``workers=0``), in this process where the noise screen
promises a quick certified posterior and in worker processes, started only then, where it
does not; each step runs with the same seed, so the numbers do not depend on where.

Outputs (:func:`~bayesfo.comparison.output.write_outputs`, staged and swapped in as one run by
:mod:`bayesfo.outdir`): one ``<structure>.nc`` (ArviZ DataTree) per structure,
``figures/`` and ``report.html`` (:mod:`bayesfo.plotting`, :mod:`bayesfo.report`),
``ranking.csv`` and ``summary.json`` (the contract of DESIGN.md).
"""

from __future__ import annotations

import sys
import warnings
from dataclasses import replace

import numpy as np

from ..data import MAX_FREQUENCIES, FrequencyResponse
from ..errors import DataWarning, InputError, NoiseWarning
from ..identify.optimize import fit_structure
from ..inference import Likelihood, starting_points
from ..inference.adequacy import check_adequacy
from ..inference.certified import certified_posterior, evidence_check
from ..inference.importance import K_HAT_MAX, screen_noise
from ..inference.likelihood import NOISE_PRIORS
from ..options import EVIDENCE_ROUTES, SAMPLERS, check_sampler_settings
from ..parallel import (
    LazyPool,
    available_cpus,
    lazy_process_pool,
    process_pool,
    single_blas_thread,
)
from ..structures import Structure, resolve_structures
from .criteria import _criteria, _holdout, _model_probabilities, fit_log_likelihood
from .criteria_types import Criteria
from .results import Comparison, StructureResult, data_problems


def compare(data: FrequencyResponse, structures, *, noise: str = "auto", seed: int = 0,
            priors=None, progress: bool | None = None, evidence: str = "auto",
            evidence_check: bool = False, prior_odds: dict | None = None, holdout=None,
            workers: int = 1, pool=None, sampler: str = "auto", **sampler_kwargs) -> Comparison:
    """Fit, sample and score every structure on ``data``.

    Parameters
    ----------
    data : FrequencyResponse
    structures : str or sequence of Structure or str
        Structures, names or comma lists of names (``"voigt,zener"``, ``"max3"``).
    noise : {"auto", "known", "constant", "proportional", "relative_parts"}
        ``auto``: ``known`` when the data carry σ; else every structure runs under
        ``constant`` and ``proportional`` noise and keeps the one with the larger ln Z
        (:data:`SCREEN_MARGIN` lets a quick estimate set aside a model that trails far behind);
        both are stated in the result (``criteria["noise_models"]``). Any other value forces
        that model; ``relative_parts`` (relative errors σ_rel·|Re G| and σ_rel·|Im G| of each
        part, pyRheo's cost) is only used when forced, never by ``auto``.
    seed : int
        The same seed gives the same numbers.
    priors : dict, optional
        Prior overrides ``{name: Prior}`` applied to every structure that has the parameter.
    progress : bool, optional
        A progress bar over structures (default: when stderr is a terminal).
    evidence : {"auto", "bridge", "ladder"}
        How ln Z is computed: bridge sampling from the emcee draws (``"bridge"``), or from the
        particles of a tempered ladder (``"ladder"``, sequential Monte Carlo from the prior,
        seconds per structure); ``"auto"`` takes the certified importance weights where they
        gave the posterior (k̂ < 0.5), the emcee draws where the walkers converged, and the
        ladder otherwise.
    evidence_check : bool
        Also compute ln Z by dynesty nested sampling and flag disagreements with the default
        estimate larger than twice the combined error (slower: seconds to minutes each).
    prior_odds : dict, optional
        Prior model probabilities ``{name: weight}`` (default equal).
    holdout : sequence of float, optional
        Angular frequencies [rad/s] left out of the fit (thesis §4.3.3); the log predictive
        density and the RMSE on them are reported next to the in-sample figures.
    workers : int
        Processes running structures side by side. 0: automatic: this process runs each
        structure's optimisation and noise screen, and the posteriors that the screen's
        importance weights promise to certify quickly; the others (the tempered ladder, emcee)
        run in worker processes, one per CPU, started only when some structure needs them
        (:func:`~bayesfo.parallel.lazy_process_pool`). The numbers do not depend on it: every
        step runs with ``seed``.
    pool : concurrent.futures.Executor, optional
        Run the structures in this pool instead (from :func:`process_pool`; ``workers`` is then
        ignored). A :class:`~bayesfo.parallel.LazyPool` (from
        :func:`~bayesfo.parallel.lazy_process_pool`) gets the automatic schedule of
        ``workers=0``.
    sampler : {"auto", "emcee"}
        How each posterior is computed. ``"auto"``: importance sampling from the optima where
        its weights certify it (Pareto k̂ < 0.7, ESS ≥ 1000; well-posed structures, a fraction
        of a second), else the particles of two independent tempered-ladder runs where they
        agree (R-hat < 1.01, ESS ≥ 400; ridged structures such as the Maxwell, seconds), else
        emcee, and where its walkers do not converge a ladder guided by them (see
        :mod:`bayesfo.inference.importance` and :mod:`bayesfo.inference.smc`). Sampler
        settings (``max_steps``, ``n_walkers``) or ``evidence="ladder"`` send the structures
        that importance sampling does not certify to emcee directly. ``"emcee"``: emcee first.
        ``evidence="bridge"`` implies emcee (bridge sampling uses its draws).
    **sampler_kwargs
        Passed to :func:`~bayesfo.inference.posterior.sample_posterior` (e.g. ``max_steps``).

    Returns
    -------
    Comparison

    Raises
    ------
    InputError
        If no structure can be run on the data (each structure's reason is in the message).
    """
    from tqdm.auto import tqdm

    from .schedule import run_in_pool

    structures = _as_structures(structures)
    _check_sampler_options(sampler_kwargs)
    if not structures:
        raise InputError("no structure to compare")
    if sampler not in SAMPLERS:
        raise InputError(f"sampler must be one of {', '.join(SAMPLERS)}, got {sampler!r}")
    if evidence not in EVIDENCE_ROUTES:
        raise InputError(f"evidence must be one of {', '.join(EVIDENCE_ROUTES)}, "
                         f"got {evidence!r}")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 0:
        raise InputError(f"workers must be a non-negative integer, got {workers!r}")
    if data.n_frequencies > MAX_FREQUENCIES:
        raise InputError(f"{data.where()}: {data.n_frequencies} frequencies, more than the "
                         f"{MAX_FREQUENCIES} the samplers handle in reasonable time; thin to "
                         "10-50 log-spaced points per decade or average neighbours")
    if noise in ("auto", "proportional") and data.sigma is None and np.any(data.response == 0):
        # sigma_rel * |G| would be zero there: the likelihood has no scale at that point.
        raise InputError(f"{data.where()}: the response is exactly 0 at omega = "
                         f"{data.omega[data.response == 0][0]:.4g} rad/s, where relative noise "
                         "has no scale; remove the point or give sigma")
    if noise == "relative_parts":
        # The relative error of a real or imaginary part that is exactly 0 has no scale either.
        from ..inference.likelihood import zero_part
        if (why := zero_part(data)) is not None:
            raise InputError(why)
    test = None
    if holdout is not None and len(holdout):
        data, test = data.split(holdout)
    for problem in data_problems(data):
        warnings.warn(problem, DataWarning, stacklevel=2)
    if progress is None:
        progress = sys.stderr.isatty()
    n_proc = min(workers or available_cpus(), len(structures))
    options = {"noise": noise, "priors": priors, "seed": seed, "evidence_check": evidence_check,
               "evidence": evidence,
               "test": test, "sampler": sampler, "sampler_kwargs": sampler_kwargs}
    bar = tqdm(total=len(structures), desc="structures", disable=not progress, leave=False)
    # Each step gets the same seed whatever the worker count or the process that runs it, so
    # the numbers do not depend on them.
    if isinstance(pool, LazyPool):
        with single_blas_thread():
            outcomes = run_in_pool(pool, structures, data, options, bar, here=True)
    elif pool is not None:
        outcomes = run_in_pool(pool, structures, data, options, bar)
    elif workers == 0:
        with lazy_process_pool(n_proc) as own, single_blas_thread():
            outcomes = run_in_pool(own, structures, data, options, bar, here=True)
    elif n_proc <= 1:
        outcomes = []
        with single_blas_thread():
            for s in structures:
                outcomes.append(_run_structure(s, data, options))
                bar.update()
    else:
        with process_pool(n_proc) as own:
            outcomes = run_in_pool(own, structures, data, options, bar)
    bar.close()
    results = []
    for result, caught in outcomes:
        # Warnings of the run, re-issued here so that they look the same whichever process ran it.
        for category, message in caught:
            warnings.warn(message, category, stacklevel=2)
        results.append(result)
    if all(r.error is not None for r in results):
        raise InputError("; ".join(f"{r.name}: {r.error}" for r in results))
    results = _model_probabilities(results, prior_odds or {})
    return Comparison(data, tuple(results), seed, holdout=test)


def _as_structures(spec) -> list:
    """Structures from objects, names or comma lists of names (shortcuts such as ``max3``)."""
    if isinstance(spec, str):
        return resolve_structures(spec)
    out = []
    for s in spec:
        out.extend(resolve_structures(s) if isinstance(s, str) else [s])
    return out


def _check_sampler_options(options: dict) -> None:
    """A misspelt sampler option fails here, before any work, not inside a worker."""
    import inspect

    from ..inference.posterior import sample_posterior

    known = [n for n, p in inspect.signature(sample_posterior).parameters.items()
             if p.kind is p.KEYWORD_ONLY and n not in ("seed", "progress")]
    for name in options:
        if name not in known:
            raise InputError(f"compare: unknown sampler option {name!r}; the options are "
                             + ", ".join(known))
    check_sampler_settings({"max_steps": options.get("max_steps"),
                            "walkers": options.get("n_walkers")}, "compare")


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
    likelihood resolves to ``known``, saying why) when the data carry σ; else both
    ``constant`` and ``proportional``, between which the evidence chooses. (:func:`compare`
    refuses ``auto`` without σ where the response is exactly 0: relative noise has no scale
    there.)"""
    if noise != "auto" or data.sigma is not None:
        return (noise,)
    return NOISE_CANDIDATES


#: The noise models between which ``noise="auto"`` chooses by evidence, when the data carry no σ.
NOISE_CANDIDATES = ("constant", "proportional")


def _sample(s: Structure, data: FrequencyResponse, noise: str, fit, options: dict) -> dict:
    """Posterior, criteria and evidence of one structure under one noise model."""
    own = {k: v for k, v in (options["priors"] or {}).items()
           if k in s.param_names or k == NOISE_PRIORS.get(noise, ("",))[0]}
    lik = Likelihood(s, data, noise=noise, priors=own)
    modes, starts = starting_points(lik, fit)
    # Without optima (none admissible) there is no importance proposal: emcee from the best fit.
    sampler = options["sampler"] if fit.optima.size else "emcee"
    found = certified_posterior(
        lik, modes, starts=starts, sampler=sampler, evidence=options["evidence"],
        seed=options["seed"], fit_log_likelihood=fit_log_likelihood(lik, fit), remedy=remedy(lik),
        sampler_options=options["sampler_kwargs"])
    post = found.posterior
    criteria = _criteria(lik, fit, post)
    criteria["warnings"].extend(found.notes)
    criteria.update(evidence=found.evidence, evidence_check=None, evidence_agree=None)
    if found.importance is not None:
        criteria["importance"] = found.importance
    return {"lik": lik, "post": post, "criteria": criteria}


def _exponent_intervals(run: dict) -> dict:
    """94 % HDIs of the structure's exponents (q, α, β, ...) under one noise model."""
    lik, post = run["lik"], run["post"]
    return {p.name: (post.summary[p.name].hdi_low, post.summary[p.name].hdi_high)
            for p in lik.structure.parameters if p.role == "exponent"}


#: A noise model whose quick ln Z (:func:`~bayesfo.inference.importance.screen_noise`) trails
#: the other's by this many nats (posterior odds above 150:1) is not sampled in full, provided
#: its own estimate is reliable (Pareto k̂ < 0.7; a heavy-tailed estimate of the leader only
#: understates its lead).
SCREEN_MARGIN = 5.0


def _quick_estimates(s, data, candidates, fit, options) -> dict:
    """The quick ln Z (:func:`~bayesfo.inference.importance.screen_noise`) of each candidate
    noise model in turn, up to the first that has none (None)."""
    quick = {}
    for noise in candidates:
        own = {k: v for k, v in (options["priors"] or {}).items()
               if k in s.param_names or k == NOISE_PRIORS.get(noise, ("",))[0]}
        lik = Likelihood(s, data, noise=noise, priors=own)
        modes = lik.structure.to_scaled(lik.structure.to_physical(fit.optima, fit.scaling),
                                        lik.scaling)
        try:
            quick[noise] = screen_noise(lik, modes, seed=options["seed"])
        except (np.linalg.LinAlgError, FloatingPointError):
            quick[noise] = None
        if quick[noise] is None:
            break
    return quick


def _screen(s, data, candidates, fit, options, quick=None) -> dict | None:
    """The quick ln Z of each candidate noise model, and the leader where it is decisive (see
    :data:`SCREEN_MARGIN`); None when all candidates must be sampled. ``quick``: the estimates
    of :func:`_quick_estimates`, when already made."""
    if len(candidates) < 2 or not fit.optima.size:
        return None
    if quick is None:
        quick = _quick_estimates(s, data, candidates, fit, options)
    if any(quick.get(noise) is None for noise in candidates):
        return None
    quick = {noise: quick[noise] for noise in candidates}
    order = sorted(candidates, key=lambda n: -quick[n]["log_z"])
    leader, other = order[0], order[1]
    if (quick[leader]["log_z"] - quick[other]["log_z"] < SCREEN_MARGIN
            or not quick[other]["k_hat"] < K_HAT_MAX):
        return None
    return {"leader": leader, "quick": quick}


def _choose_noise(name: str, runs: list[dict], screened: dict | None) -> tuple[dict, dict]:
    """The run whose noise model has the larger evidence, and the record of the choice: each
    noise model's ln Z (certified, or the quick estimate of a model left out by the screen),
    its posterior probability (equal prior odds) and the exponents' intervals, and
    ``sensitive`` when an exponent's intervals under the two models do not overlap."""
    entries = []  # (noise, log_z, log_z_err, method, intervals, run or None)
    for r in runs:
        e = r["criteria"]["evidence"]
        entries.append((r["lik"].noise, e.log_z if e is not None else -np.inf,
                        None if e is None else float(e.log_z_err),
                        None if e is None else e.method, _exponent_intervals(r), r))
    if screened is not None:
        for noise, q in screened["quick"].items():
            if noise != screened["leader"]:
                entries.append((noise, q["log_z"], None, q["method"], q["intervals"], None))
    log_z = np.array([e[1] for e in entries])
    sampled = [i for i, e in enumerate(entries) if e[5] is not None]
    best = max(sampled, key=lambda i: log_z[i])
    if np.isfinite(log_z[best]):
        prob = np.exp(log_z - log_z[best])
        prob /= prob.sum()
    else:
        prob = np.full(len(entries), np.nan)
    chosen = entries[best][5]
    record = {"chosen": entries[best][0], "models": {}}
    for (noise, lz, err, method, hdi, _), p in zip(entries, prob, strict=True):
        record["models"][noise] = {
            "log_evidence": float(lz) if np.isfinite(lz) else None, "log_evidence_err": err,
            "evidence_method": method,
            "probability": float(p) if np.isfinite(p) else None,
            "hdi": {k: [float(lo), float(hi)] for k, (lo, hi) in hdi.items()},
        }
    intervals = [e[4] for e in entries]
    apart = []
    for param in intervals[best]:
        spans = [iv[param] for iv in intervals if param in iv]
        if max(lo for lo, _ in spans) > min(hi for _, hi in spans):
            apart.append(param)
    record["sensitive"] = bool(apart)
    record["sensitive_parameters"] = apart
    other = next(i for i in range(len(entries)) if i != best)
    delta = log_z[best] - log_z[other]
    reason = (f"chosen by evidence over {' and '.join(e[0] for e in entries)} noise "
              + (f"(ln Z higher by {delta:.1f}; probability {prob[best]:.3f})"
                 if np.isfinite(delta) else "(the other has no evidence)"))
    chosen["post"] = replace(chosen["post"], noise_reason=reason)
    if apart:
        ours, theirs = intervals[best], intervals[other]
        shown = "; ".join(
            f"{p} {ours[p][0]:.3g}…{ours[p][1]:.3g} under {entries[best][0]} noise, "
            f"{theirs[p][0]:.3g}…{theirs[p][1]:.3g} under {entries[other][0]}"
            for p in apart)
        decided = np.isfinite(prob[best]) and prob[best] >= NOISE_DECISIVE
        msg = (f"{name}: the exponents depend on the noise model: 94 % intervals do not overlap "
               f"({shown}); the evidence favours {entries[best][0]} noise with probability "
               f"{prob[best]:.3f}")
        if not decided:
            msg += (". Give sigma per point, or force a model with --noise, if you know how "
                    "the instrument's error scales")
        chosen["criteria"]["warnings"].append(msg)
        if not decided:
            warnings.warn(msg, NoiseWarning, stacklevel=3)
    return chosen, record


#: The evidence decides the noise model when it gives the chosen one at least this probability;
#: below, non-overlapping exponent intervals raise a NoiseWarning (the conclusion then hangs on
#: a choice the data do not make).
NOISE_DECISIVE = 0.99


def _run_structure(s: Structure, data: FrequencyResponse, options: dict):
    """Optimisation, posterior, criteria and evidence of one structure, in three steps:
    :func:`_fit_and_screen`, :func:`_sample_held` per noise model still in the running, and
    :func:`_conclude` (a pool runs the steps as separate tasks, :mod:`.schedule`). Returns the
    result and the warnings raised on the way."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            fit, screened, noises = _fit_and_screen(s, data, options)
            runs = [_sample_held(s, data, noise, fit, options) for noise in noises]
            result = _conclude(s, data, fit, screened, runs, options)
        except InputError as exc:
            result = StructureResult(s, error=str(exc))
    return result, _kept(s.name, [(w.category, str(w.message)) for w in caught])


def _fit_and_screen(s: Structure, data: FrequencyResponse, options: dict):
    """Step 1: the optimisation and the noise screen (:func:`_screen`). Returns the fit, the
    screen's record (None when it did not decide) and the noise models to sample."""
    candidates, fit = _fit(s, data, options)
    screened = _screen(s, data, candidates, fit, options)
    return fit, screened, [n for n in candidates if screened is None or n == screened["leader"]]


def _fit_and_probe(s: Structure, data: FrequencyResponse, options: dict):
    """Step 1 as :func:`_fit_and_screen`, and whether the rest promises to be quick: the
    screen's raw importance weights of every noise model still to sample have a Pareto k̂ below
    :data:`~bayesfo.inference.importance.K_HAT_MAX`, so that importance sampling will most
    likely certify the posterior (a fraction of a second) and neither the ladder nor emcee will
    run. Returns ((fit, screened, noise models), quick). The numbers and the warnings are those
    of :func:`_fit_and_screen`: the estimates that the screen does not make itself are made
    with their warnings discarded, and they only guide where the next steps run."""
    candidates, fit = _fit(s, data, options)
    quick = (_quick_estimates(s, data, candidates, fit, options)
             if len(candidates) > 1 and fit.optima.size else {})
    screened = _screen(s, data, candidates, fit, options, quick=quick)
    noises = [n for n in candidates if screened is None or n == screened["leader"]]
    if (options["sampler"] != "auto" or options["evidence"] != "auto"
            or options["evidence_check"] or not fit.optima.size):
        return (fit, screened, noises), False
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for noise in noises:
            if noise not in quick:
                try:
                    quick.update(_quick_estimates(s, data, (noise,), fit, options))
                except (InputError, np.linalg.LinAlgError, FloatingPointError):
                    quick[noise] = None
    promise = all(quick.get(n) is not None and quick[n]["k_hat"] < K_HAT_MAX for n in noises)
    return (fit, screened, noises), promise


def _fit(s: Structure, data: FrequencyResponse, options: dict):
    """The noise models to choose from and the global optimisation (the modes)."""
    candidates = _noise_candidates(data, options["noise"])
    structure = Likelihood(s, data, noise=candidates[0], priors={
        k: v for k, v in (options["priors"] or {}).items() if k in s.param_names
    }).structure
    fit = fit_structure(structure, data, rng=options["seed"], seed_methods=True,
                        linear_methods=True)
    return candidates, fit


def _sample_held(s: Structure, data: FrequencyResponse, noise: str, fit, options: dict) -> dict:
    """Step 2: :func:`_sample` under one noise model, its warnings held back in
    ``run["caught"]`` (category, message, file, line): only the chosen model's reach the user
    (:func:`_conclude`; the other's are kept in its record)."""
    with warnings.catch_warnings(record=True) as held:
        warnings.simplefilter("always")
        run = _sample(s, data, noise, fit, options)
    run["caught"] = [(w.category, str(w.message), w.filename, w.lineno) for w in held]
    return run


def _conclude(s: Structure, data: FrequencyResponse, fit, screened, runs: list[dict],
              options: dict) -> StructureResult:
    """Step 3, once the runs of step 2 are in: the noise model chosen by evidence, the chosen
    run's warnings issued, the evidence check, the adequacy checks, the held-out points."""
    seed, test = options["seed"], options["test"]
    if len(_noise_candidates(data, options["noise"])) > 1:
        run, record = _choose_noise(s.name, runs, screened)
    else:
        run, record = runs[0], None
    lik, post, criteria = run["lik"], run["post"], run["criteria"]
    for category, message, filename, lineno in run["caught"]:
        warnings.warn_explicit(message, category, filename, lineno)
    for other in runs:
        if other is not run:
            record["models"][other["lik"].noise]["warnings"] = list(
                dict.fromkeys(message for _, message, _, _ in other["caught"]))
    criteria["noise_models"] = record
    if options["evidence_check"] and criteria["evidence"] is not None:
        check = evidence_check(lik, post, criteria["evidence"], seed)
        criteria["warnings"].extend(check.pop("warnings"))
        criteria.update(check)
    try:
        criteria["adequacy"] = check_adequacy(lik, post, seed=seed)
    except InputError as exc:  # e.g. too few frequencies for the statistics
        criteria["adequacy"] = None
        criteria["warnings"].append(f"{s.name}: no adequacy check: {exc}")
    if test is not None:
        criteria.update(_holdout(lik, post, test))
    return StructureResult(s, fit, post, Criteria.from_dict(criteria))


def _kept(name: str, caught) -> list[tuple]:
    """The warnings (category, message) of a structure's run, each once, said of the structure
    (a library's gets its name in front; deprecations are dropped)."""
    kept = {}
    for category, text in caught:
        text = text if text.startswith(f"{name}:") else f"{name}: {text}"
        if not issubclass(category, (DeprecationWarning, PendingDeprecationWarning)):
            kept.setdefault((category, text))
    return list(kept)
