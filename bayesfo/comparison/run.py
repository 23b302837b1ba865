"""Run structures on one data set and rank them: the engine behind ``bayesfo compare``.

For every structure: the global least-squares optimisation (modes and a maximum-likelihood
start); a certified posterior, by importance sampling from the optima where its weights certify
it (:mod:`bayesfo.inference.importance`), else emcee, and where the walkers do not converge the
particles of the tempered ladder if its independent runs agree; the criteria that follow:
maximum log-likelihood, AIC, AICc, BIC (from the higher of the optimiser's and the sampler's
maximum), WAIC and PSIS-LOO (arviz, pointwise per frequency), RMSE at the posterior mode (thesis
eq. (3.23)); the log-evidence ln Z from the route that gave the posterior (optionally checked by
dynesty nested sampling, flagged when the two disagree by more than twice their combined error);
and the posterior predictive adequacy checks (:mod:`bayesfo.inference.adequacy`). Structures are
ranked by ln Z; posterior model probabilities assume equal prior odds unless given.

Structures run one after the other or side by side in worker processes (``workers``); each runs
with the same seed, so the numbers do not depend on how many.

Outputs (:func:`~bayesfo.comparison.output.write_outputs`, staged and swapped in as one run by
:mod:`bayesfo.outdir`): one ``<structure>.nc`` (arviz InferenceData) per structure,
``figures/`` and ``report.html`` (:mod:`bayesfo.plotting`, :mod:`bayesfo.report`),
``ranking.csv`` and ``summary.json`` (the contract of DESIGN.md).
"""

from __future__ import annotations

import sys
import warnings

import numpy as np

from ..data import MAX_FREQUENCIES, FrequencyResponse
from ..errors import CertifiedWarning, ConvergenceWarning, DataWarning, InputError
from ..identify.optimize import fit_structure
from ..inference import Likelihood, run_posterior
from ..inference.adequacy import check_adequacy
from ..inference.importance import importance_posterior
from ..inference.posterior import posterior_from_particles
from ..options import EVIDENCE_ROUTES, SAMPLERS
from ..parallel import available_cpus, process_pool
from ..structures import Structure, resolve_structures
from .criteria import _criteria, _evidence, _holdout, _model_probabilities
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
    noise : {"auto", "known", "constant", "proportional"}
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
    sampler : {"auto", "emcee"}
        How each posterior is computed. ``"auto"``: importance sampling from the optima where
        its weights certify it (Pareto k̂ < 0.7, ESS ≥ 1000; well-posed structures, a fraction
        of a second), else emcee, and where the walkers do not converge the tempered ladder's
        particles (see :mod:`bayesfo.inference.importance`). ``"emcee"``: emcee first.
        ``evidence="bridge"`` implies emcee (bridge sampling uses its draws).
    evidence_check : bool
        Also compute ln Z by dynesty nested sampling and flag disagreements with the default
        estimate larger than twice the combined error (slower: seconds to minutes each).
    prior_odds : dict, optional
        Prior model probabilities ``{name: weight}`` (default equal).
    holdout : sequence of float, optional
        Angular frequencies [rad/s] left out of the fit (thesis §4.3.3); the log predictive
        density and the RMSE on them are reported next to the in-sample figures.
    workers : int
        Processes running structures side by side (0: one per CPU). The numbers do not depend
        on it: every structure runs with ``seed``.
    pool : concurrent.futures.Executor, optional
        Run the structures in this pool instead (from :func:`process_pool`; ``workers`` is then
        ignored).
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
    if pool is None and n_proc <= 1:
        outcomes = []
        for s in structures:
            outcomes.append(_run_structure(s, data, options))
            bar.update()
    elif pool is not None:
        outcomes = _run_in_pool(pool, structures, data, options, bar)
    else:
        # Each structure gets the same seed whatever the worker count, so the numbers do not
        # depend on it.
        with process_pool(n_proc) as own:
            outcomes = _run_in_pool(own, structures, data, options, bar)
    bar.close()
    results = []
    for result, caught in outcomes:
        # Warnings of the run, re-issued here so that they look the same whichever process ran it.
        for category, message in caught:
            warnings.warn(message, category, stacklevel=2)
        results.append(result)
    if all(r.error is not None for r in results):
        raise InputError("; ".join(f"{r.name}: {r.error}" for r in results))
    _model_probabilities(results, prior_odds or {})
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


def _run_in_pool(pool, structures, data, options, bar) -> list:
    # Larger structures first (they take longest); results keep the order given.
    order = sorted(range(len(structures)), key=lambda i: -structures[i].n_params)
    futures = {i: pool.submit(_run_structure, structures[i], data, options) for i in order}
    for f in futures.values():
        f.add_done_callback(lambda _: bar.update())
    return [futures[i].result() for i in range(len(structures))]


def _certified_by_ladder(lik, fit, post, criteria, runs, seed):
    """Where the emcee walkers did not converge, the final particles of the independent
    tempered-ladder runs (which gave ln Z) are the posterior, if the runs agree: summaries,
    HDIs, figures, LOO and WAIC then come from them. Returns (posterior, criteria)."""
    ladder = posterior_from_particles(lik, runs, seed=seed)
    if not ladder.converged:
        note = (f"{lik.structure.name}: the tempered-ladder runs do not certify the posterior "
                f"either ({'; '.join(m.split(': ', 1)[1] for m in ladder.messages)}); the "
                "emcee draws are reported, flagged")
        warnings.warn(note, ConvergenceWarning, stacklevel=3)
        criteria["warnings"].append(note)
        return post, criteria
    note = (f"{lik.structure.name}: the posterior reported is that of {ladder.n_walkers} "
            f"independent tempered-ladder runs of {ladder.samples.shape[0] // ladder.n_walkers} "
            f"particles, which agree (R-hat {ladder.rhat_max:.3f}, ESS {ladder.ess_min:.0f}); "
            "the emcee walkers did not converge")
    criteria = _criteria(lik, fit, ladder)
    criteria["warnings"].append(note)
    warnings.warn(note, CertifiedWarning, stacklevel=3)
    return ladder, criteria


def _run_structure(s: Structure, data: FrequencyResponse, options: dict):
    """Optimisation, posterior, criteria and evidence of one structure (runs in a worker process
    when ``compare`` has several). Returns the result and the warnings raised on the way."""
    seed, test = options["seed"], options["test"]
    noise = options["noise"]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            own = {k: v for k, v in (options["priors"] or {}).items()
                   if k in s.param_names or k in ("sigma", "sigma_rel")}
            lik = Likelihood(s, data, noise=noise, priors=own)
            fit = fit_structure(lik.structure, data, rng=seed, seed_methods=True)
            post = ev = None
            # Bridge sampling is defined on emcee's draws: a forced bridge route takes emcee.
            if (options["sampler"] == "auto" and options["evidence"] != "bridge"
                    and fit.optima.size):
                modes = lik.structure.to_scaled(
                    lik.structure.to_physical(fit.optima, fit.scaling), lik.scaling)
                try:
                    post, ev, info = importance_posterior(lik, modes, seed=seed)
                except (np.linalg.LinAlgError, FloatingPointError):  # to the samplers
                    post = ev = None
            if post is None:
                post, _ = run_posterior(lik.structure, data, noise=noise, priors=own, seed=seed,
                                        fit=fit, progress=False, **options["sampler_kwargs"])
            criteria = _criteria(lik, fit, post)
            if post.sampler == "importance":
                criteria["importance"] = info
            extra = _evidence(lik, post, seed, options["evidence_check"], options["evidence"],
                              best_log_likelihood=criteria["max_log_likelihood"], importance=ev)
            runs = extra.pop("ladder_runs")
            if runs is not None and not post.converged:
                post, criteria = _certified_by_ladder(lik, fit, post, criteria, runs, seed)
            try:
                criteria["adequacy"] = check_adequacy(lik, post, seed=seed)
            except InputError as exc:  # e.g. too few frequencies for the statistics
                criteria["adequacy"] = None
                criteria["warnings"].append(f"{s.name}: no adequacy check: {exc}")
            if test is not None:
                criteria.update(_holdout(lik, post, test))
            criteria["warnings"].extend(extra.pop("warnings"))
            criteria.update(extra)
            result = StructureResult(s, fit, post, criteria)
        except InputError as exc:
            result = StructureResult(s, error=str(exc))
    seen = set()
    kept = []
    for w in caught:
        text = str(w.message)
        if not text.startswith(f"{s.name}:"):  # a library's warning: say which structure
            text = f"{s.name}: {text}"
        key = (w.category, text)
        if key not in seen and not issubclass(w.category, (DeprecationWarning, PendingDeprecationWarning)):
            seen.add(key)
            kept.append(key)
    return result, kept


