"""Run structures on one data set and rank them: the engine behind ``bayesfo compare``.

Each structure runs the three steps of :mod:`.steps` (the optimisation and the noise screen; a
certified posterior per noise model by :func:`~bayesfo.inference.certified_posterior`; the
noise model chosen by evidence, the criteria, the checks), one after the other or as tasks of a
pool (:mod:`.schedule`); each step runs with the same seed, so the numbers do not depend on
where. Structures are ranked by ln Z; posterior model probabilities assume equal prior odds
unless given. The output directory is written by :func:`bayesfo.output.write_outputs`.
"""

from __future__ import annotations

import contextlib
import sys
import warnings

import numpy as np

from ..data import MAX_FREQUENCIES, FrequencyResponse
from ..errors import DataWarning, InputError
from ..inference.bound import BOUND_MARGIN
from ..inference.likelihood import zero_part
from ..inference.posterior import sample_posterior
from ..options import check_prior_names, check_routes, check_sample, check_sampler_settings
from ..parallel import LazyPool, check_workers, executor, runs_here, single_blas_thread
from ..structures import resolve_structures
from .criteria import _model_probabilities
from .results import Comparison, data_problems
from .schedule import run_in_pool
from .steps import RunOptions


def compare(data: FrequencyResponse, structures, *, noise: str = "auto", seed: int = 0,
            priors=None, progress: bool | None = None, evidence: str = "auto",
            evidence_check: bool = False, prior_odds: dict | None = None, holdout=None,
            workers: int = 1, pool=None, sampler: str = "auto", sample: str = "needed",
            **sampler_kwargs) -> Comparison:
    """Fit, sample and score every structure on ``data``.

    Parameters
    ----------
    data : FrequencyResponse
    structures : str or sequence of Structure or str
        Structures, names or comma lists of names (``"voigt,zener"``, ``"max3"``).
    noise : {"auto", "known", "constant", "proportional", "relative_parts"}
        ``auto``: ``known`` when the data carry σ; else every structure weighs ``constant``,
        ``proportional`` and ``relative_parts`` noise (relative errors σ_rel·|Re G| and
        σ_rel·|Im G| of each part, a rheometer's, pyRheo's cost; left out where a part is
        exactly 0) and keeps the one with the largest ln Z
        (:data:`~bayesfo.comparison.steps.NOISE_SCREEN_MARGIN` lets a quick estimate set aside a
        model that trails far behind); each is stated in the result
        (``criteria.noise_models``). Any other value forces that model.
    seed : int
        The same seed gives the same numbers.
    priors : dict, optional
        Prior overrides ``{name: Prior}`` applied to every structure that has the parameter.
    progress : bool, optional
        A progress bar over structures (default: when stderr is a terminal).
    evidence : {"auto", "bridge", "ladder"}
        How ln Z is computed: ``"auto"`` by the route that gave the posterior; ``"bridge"`` by
        bridge sampling from emcee's draws; ``"ladder"`` from a tempered ladder's particles.
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
        (:func:`~bayesfo.parallel.lazy_process_pool`), which then take every step still to
        come. The numbers do not depend on it: every
        step runs with ``seed``.
    pool : concurrent.futures.Executor, optional
        Run the structures in this pool instead (from :func:`process_pool`; ``workers`` is then
        ignored). A :class:`~bayesfo.parallel.LazyPool` (from
        :func:`~bayesfo.parallel.lazy_process_pool`) gets the automatic schedule of
        ``workers=0``.
    sampler : {"auto", "emcee"}
        How each posterior is computed: ``"auto"`` tries importance sampling from the optima,
        then the tempered ladder, then emcee, and reports the first that its certificate
        accepts; ``"emcee"`` starts with emcee (the policy:
        :mod:`bayesfo.inference.certified`). Sampler settings (``max_steps``, ``n_walkers``)
        or ``evidence="ladder"`` send the structures that importance sampling does not certify
        to emcee directly; ``evidence="bridge"`` implies emcee.
    sample : {"needed", "all"}
        ``"needed"``: a structure whose best fit (the global optimiser's maximum
        log-likelihood under every noise model considered) lies more than
        :data:`~bayesfo.inference.bound.BOUND_MARGIN` (10) nats below the leader's certified
        ln Z is not sampled: ln Z ≤ max ln L under any normalised prior, so its posterior
        probability is provably below e^-10. Its result has the best fit, RMSE, AIC, AICc and
        BIC, and ``criteria.bound`` (the bound, P ≤ …, the source of the maximum); no
        posterior, PSIS-LOO, WAIC or figures. Structures whose posterior importance sampling
        promises to certify quickly are sampled anyway. ``"all"``: every structure is sampled.
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
    check_routes(sampler, evidence)
    check_sample(sample)
    check_workers(workers)
    check_prior_names(priors, structures)
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
        if (why := zero_part(data)) is not None:
            raise InputError(why)
    held_out = None
    if holdout is not None and len(holdout):
        data, held_out = data.split(holdout)
    for problem in data_problems(data):
        warnings.warn(problem, DataWarning, stacklevel=2)
    if progress is None:
        progress = sys.stderr.isatty()
    options = RunOptions(noise=noise, priors=priors, seed=seed, evidence=evidence,
                         evidence_check=evidence_check, sampler=sampler,
                         sampler_kwargs=sampler_kwargs, holdout=held_out, sample=sample)
    record = {"sample": sample, "margin": BOUND_MARGIN}
    bar = tqdm(total=len(structures), desc="structures", disable=not progress, leave=False)
    # One path whatever the processes (parallel.executor): the steps of every structure as
    # tasks, each with the same seed wherever it runs, so the numbers do not depend on them.
    with contextlib.ExitStack() as stack:
        if pool is None:
            pool = stack.enter_context(executor(workers, len(structures)))
        if runs_here(pool):
            stack.enter_context(single_blas_thread())
        outcomes = run_in_pool(pool, structures, data, options, bar,
                               here=isinstance(pool, LazyPool), record=record)
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
    record["bounded"] = [r.name for r in results if r.criteria.bound is not None]
    return Comparison(data, tuple(results), seed, holdout=held_out, evidence_bound=record)


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


    known = [n for n, p in inspect.signature(sample_posterior).parameters.items()
             if p.kind is p.KEYWORD_ONLY and n not in ("seed", "progress")]
    for name in options:
        if name not in known:
            raise InputError(f"compare: unknown sampler option {name!r}; the options are "
                             + ", ".join(known))
    check_sampler_settings({"max_steps": options.get("max_steps"),
                            "walkers": options.get("n_walkers")}, "compare")
