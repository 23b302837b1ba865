"""Run structures on one data set and rank them: the engine behind ``bayesfo compare``.

For every structure: the global least-squares optimisation (modes and a maximum-likelihood
start), the emcee posterior, and the criteria that follow from them: maximum log-likelihood,
AIC, AICc, BIC (from the higher of the optimiser's and the sampler's maximum), WAIC and PSIS-LOO
(arviz, pointwise per frequency), RMSE at the posterior mode (thesis eq. (3.23)), and the
log-evidence ln Z by bridge sampling from the posterior draws, or from the particles of a
tempered ladder where the posterior did not converge (optionally checked by dynesty nested
sampling, with a flag when the two disagree by more than twice their combined error).
Structures are ranked by ln Z; posterior model probabilities assume equal prior odds unless
given.

Structures run one after the other or side by side in worker processes (``workers``); each runs
with the same seed, so the numbers do not depend on how many.

Outputs (:func:`write_outputs`, each file written atomically): one ``<structure>.nc`` (arviz
InferenceData) per structure, ``figures/`` and ``report.html`` (:mod:`bayesfo.plotting`,
:mod:`bayesfo.report`), ``ranking.csv`` and ``summary.json`` (the contract of DESIGN.md), last.
"""

from __future__ import annotations

import csv
import io
import json
import math
import sys
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ._io import atomic_write_text
from .data import FrequencyResponse
from .errors import InputError
from .identify.optimize import FitResult, fit_structure
from .inference import Likelihood, PosteriorResult, run_posterior, save_netcdf
from .inference._arviz import arviz
from .inference.evidence import bridge_evidence, ladder_evidence, nested_evidence
from .outdir import final_path, staged_run
from .parallel import WORKER_ENV, available_cpus, process_pool, worker_environment  # noqa: F401
from .structures import Structure

PARETO_K_WARN = 0.7


class PredictiveWarning(UserWarning):
    """PSIS-LOO is unreliable for some frequency (Pareto k above 0.7)."""


@dataclass(frozen=True, eq=False)
class StructureResult:
    """Everything computed for one structure on one data set.

    ``error`` holds the reason when the structure could not be run (the other fields are None).
    """

    structure: Structure
    fit: FitResult | None = None
    posterior: PosteriorResult | None = None
    criteria: dict = field(default_factory=dict)
    error: str | None = None

    @property
    def name(self) -> str:
        return self.structure.name

    def to_dict(self) -> dict:
        s = self.structure
        out = {
            "name": s.name, "family": s.family, "formula": s.formula, "inverted": s.inverted,
            "integer": s.integer, "parent": _parent(s), "n_params": s.n_params,
        }
        if self.error is not None:
            out["error"] = self.error
            return out
        post = self.posterior
        ev = self.criteria.get("evidence")
        check = self.criteria.get("evidence_check")
        out.update(
            parameters={k: v.to_dict() for k, v in post.summary.items()},
            priors=self.criteria["priors"],
            noise=post.noise, noise_reason=post.noise_reason,
            log_evidence=None if ev is None else ev.log_z,
            log_evidence_err=None if ev is None else ev.log_z_err,
            evidence_method=None if ev is None else ev.method,
            log_prior_support=None if ev is None else ev.log_support,
            evidence_check=None if check is None else check.to_dict(),
            evidence_agree=self.criteria.get("evidence_agree"),
            posterior_probability=self.criteria.get("posterior_probability"),
        )
        for key in ("max_log_likelihood", "aic", "aicc", "bic", "waic", "waic_se", "loo", "loo_se",
                    "pareto_k_max", "rmse"):
            out[key] = self.criteria[key]
        for key in ("holdout_lpd", "holdout_rmse", "holdout_lpd_pointwise", "holdout_omega"):
            if key in self.criteria:
                out[key] = self.criteria[key]
        out.update(
            rhat_max=post.rhat_max, ess_min=post.ess_min, ess_bulk_min=post.ess_bulk_min,
            ess_tail_min=post.ess_tail_min, converged=post.converged, tau_max=float(np.max(post.tau)),
            n_steps=post.n_steps, n_draws=int(post.samples.shape[0]), messages=list(post.messages),
            warnings=self.criteria["warnings"],
            optimum={"parameters": dict(zip(self.fit.param_names, map(float, self.fit.theta))),
                     "rmse": self.fit.rmse, "starts": self.fit.n_starts,
                     "starts_at_optimum": self.fit.n_at_best, "admissible": self.fit.admissible},
        )
        return out


def _parent(structure) -> str | None:
    """The fractional structure an integer baseline comes from (``zener-int`` → ``zener``)."""
    return structure.name[: -len("-int")] if structure.integer else None


@dataclass(frozen=True, eq=False)
class Comparison:
    """Results of :func:`compare`: the data, one :class:`StructureResult` per structure."""

    data: FrequencyResponse
    results: tuple[StructureResult, ...]
    seed: int
    ranked_by: str = "log_evidence"
    holdout: FrequencyResponse | None = None

    @property
    def ranking(self) -> list[str]:
        """Structure names, best first by ln Z (those without an evidence after them, by
        PSIS-LOO); structures that failed are left out."""
        ok = [r for r in self.results if r.error is None]

        def key(r):
            ev = r.criteria.get("evidence")
            value = ev.log_z if ev is not None else r.criteria["loo"]
            return (ev is None, not math.isfinite(value), -value if math.isfinite(value) else 0)

        return [r.name for r in sorted(ok, key=key)]

    def __getitem__(self, name: str) -> StructureResult:
        for r in self.results:
            if r.name == name:
                return r
        raise KeyError(name)

    def table(self) -> list[dict]:
        """One row per structure, best first (failed structures last), for printing or CSV."""
        order = {n: i for i, n in enumerate(self.ranking)}
        rows = []
        ok = [r for r in self.results if r.error is None]
        best_loo = max((r.criteria["loo"] for r in ok if math.isfinite(r.criteria["loo"])),
                       default=math.nan)
        evs = [r.criteria["evidence"].log_z for r in ok if r.criteria.get("evidence") is not None]
        best_z = max(evs, default=math.nan)
        ranks = {}
        for crit, sign in (("loo", -1), ("waic", -1), ("aic", 1), ("aicc", 1), ("bic", 1)):
            # An undefined criterion (NaN, with its reason among the warnings) ranks last.
            ordered = sorted(ok, key=lambda r, c=crit, g=sign: (
                not math.isfinite(r.criteria[c]),
                g * r.criteria[c] if math.isfinite(r.criteria[c]) else 0))
            ranks[crit] = {r.name: i + 1 for i, r in enumerate(ordered)}
        for r in sorted(self.results, key=lambda r: order.get(r.name, len(order))):
            if r.error is not None:
                rows.append({"rank": None, "structure": r.name, "n_params": r.structure.n_params,
                             "error": r.error})
                continue
            c, p = r.criteria, r.posterior
            q = p.summary.get("q") or p.summary.get("beta")
            ev = c.get("evidence")
            log_z = None if ev is None else ev.log_z
            rows.append({
                "rank": order[r.name] + 1, "structure": r.name, "n_params": r.structure.n_params,
                "parent": _parent(r.structure), "log_evidence": log_z, "log_evidence_err": None if ev is None else ev.log_z_err,
                "evidence_method": None if ev is None else ev.method,
                "delta_log_evidence": None if ev is None else log_z - best_z,
                "bayes_factor": None if ev is None else math.exp(log_z - best_z),
                "posterior_probability": c.get("posterior_probability"),
                "evidence_agree": c.get("evidence_agree"),
                **{f"rank_{k}": v[r.name] for k, v in ranks.items()},
                "loo": c["loo"], "loo_se": c["loo_se"], "delta_loo": c["loo"] - best_loo,
                "waic": c["waic"], "aic": c["aic"], "aicc": c["aicc"], "bic": c["bic"],
                "max_log_likelihood": c["max_log_likelihood"], "rmse": c["rmse"],
                "holdout_lpd": c.get("holdout_lpd"), "holdout_rmse": c.get("holdout_rmse"),
                "q_mean": None if q is None else q.mean, "q_sd": None if q is None else q.sd,
                "pareto_k_max": c["pareto_k_max"], "rhat_max": p.rhat_max, "ess_min": p.ess_min,
                "converged": p.converged, "error": "",
            })
        return rows

    def to_dataframe(self):
        """The ranking table as a ``pandas.DataFrame`` with a ``data`` column naming the data
        set, so tables of several comparisons combine with ``pandas.concat``.

        Examples
        --------
        >>> tables = [compare(d, structures).to_dataframe() for d in datasets]  # doctest: +SKIP
        >>> combined = pandas.concat(tables, ignore_index=True)  # doctest: +SKIP
        """
        import pandas as pd

        rows = [{"data": self.data.label, **row} for row in self.table()]
        return pd.DataFrame(rows, columns=["data", *RANKING_FIELDS])

    def to_summary(self) -> dict:
        """The ``summary.json`` contract."""
        summary = {
            "data": {"path": self.data.source, "name": self.data.label,
                     "n_frequencies": self.data.n_frequencies, "kind": self.data.kind,
                     "units": self.data.units, "omega_min": float(self.data.omega.min()),
                     "omega_max": float(self.data.omega.max())},
            "seed": self.seed,
            "ranked_by": self.ranked_by,
            "structures": [r.to_dict() for r in self.results],
            "ranking": self.ranking,
            "families": self.families(),
            "baselines": self.baselines(),
        }
        if self.holdout is not None:
            summary["data"]["holdout_omega"] = self.holdout.omega.tolist()
        return summary

    def baselines(self) -> list[dict]:
        """Each integer baseline next to its fractional parent (both run on these data).

        Returns one dict per pair: ``parent``, ``baseline``, ``delta_log_evidence`` (ln Z of the
        parent minus the baseline's; > 0 favours the fractional order), ``bayes_factor`` (parent
        over baseline), the parent's posterior order ``order`` (``q``, or ``beta`` for the
        Maxwell) with ``order_mean``, ``order_hdi`` (94 %) and ``order_hdi_includes_1``: whether
        q = 1, the baseline, is inside the parent's HDI.
        """
        done = {r.name: r for r in self.results if r.error is None}
        out = []
        for r in self.results:
            parent = _parent(r.structure)
            if parent is None or r.name not in done or parent not in done:
                continue
            p = done[parent]
            ev_p, ev_b = p.criteria.get("evidence"), r.criteria.get("evidence")
            d = None if ev_p is None or ev_b is None else ev_p.log_z - ev_b.log_z
            order = next((k for k in ("q", "beta") if k in p.posterior.summary), None)
            row = {"parent": parent, "baseline": r.name, "delta_log_evidence": d,
                   "delta_log_evidence_err": None if d is None
                   else math.hypot(ev_p.log_z_err, ev_b.log_z_err),
                   "bayes_factor": None if d is None else math.exp(min(d, 700.0)),
                   "order": order}
            if order is not None:
                o = p.posterior.summary[order]
                row.update(order_mean=o.mean, order_hdi=[o.hdi_low, o.hdi_high],
                           order_hdi_includes_1=bool(o.hdi_low <= 1.0 <= o.hdi_high))
            out.append(row)
        return out

    def families(self) -> list[dict]:
        """Evidence of each family with several members (e.g. the max-order family), with equal
        prior weight on its members: ln Z_family = ln mean_i Z_i."""
        groups: dict[str, list] = {}
        for r in self.results:
            if r.error is None and r.criteria.get("evidence") is not None:
                groups.setdefault(r.structure.family, []).append(r)
        out = []
        for family, members in groups.items():
            if len(members) < 2:
                continue
            z = np.array([m.criteria["evidence"].log_z for m in members])
            err = np.array([m.criteria["evidence"].log_z_err for m in members])
            top = z.max()
            w = np.exp(z - top)
            log_z = float(top + np.log(w.mean()))
            out.append({
                "family": family, "members": [m.name for m in members], "log_evidence": log_z,
                "log_evidence_err": float(np.sqrt(np.sum((w / w.sum() * err) ** 2))),
                "posterior_probability": float(sum(m.criteria.get("posterior_probability") or 0.0
                                                   for m in members)),
            })
        return sorted(out, key=lambda f: -f["log_evidence"])


def _frequencies(omega, shown: int = 6) -> str:
    """``omega = 1, 2, 3 rad/s``, or the first few and how many more, for a warning line."""
    text = ", ".join(f"{w:.4g}" for w in omega[:shown])
    if len(omega) > shown:
        text += f" and {len(omega) - shown} more"
    return f"omega = {text} rad/s"


def _criteria(lik: Likelihood, fit: FitResult, post: PosteriorResult) -> dict:
    az = arviz()
    n_real = 2 * lik.data.n_frequencies
    k = lik.ndim
    # Maximum log-likelihood: the sampler's best draw or the optimiser's optimum (with the
    # maximum-likelihood noise for that optimum), whichever is higher.
    theta_fit = np.atleast_2d(fit.theta_scaled)
    if lik.noise_param:
        theta_fit = np.column_stack([theta_fit, lik.noise_estimate(theta_fit)])
    ll_fit = float(lik(theta_fit)[0]) if fit.admissible and lik.in_support(theta_fit)[0] else -np.inf
    max_ll = max(post.max_log_likelihood, ll_fit)
    aic = 2 * k - 2 * max_ll
    aicc = aic + (2 * k * (k + 1) / (n_real - k - 1) if n_real - k - 1 > 0 else math.inf)
    bic = k * math.log(n_real) - 2 * max_ll
    warn = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        waic = az.waic(post.idata, pointwise=True)
        loo = az.loo(post.idata, pointwise=True)
    for w in caught:
        if "posterior variance of the log predictive" in str(w.message):
            warn.append(f"{post.structure}: WAIC is unreliable (large pointwise variances)")
    pareto_k = np.asarray(loo.pareto_k)
    k_max = float(np.max(pareto_k))
    if k_max > PARETO_K_WARN:
        bad = lik.data.omega[pareto_k > PARETO_K_WARN]
        msg = (f"{post.structure}: Pareto k up to {k_max:.2f} at {_frequencies(bad)}; "
               "PSIS-LOO is unreliable there")
        warn.append(msg)
        warnings.warn(msg, PredictiveWarning, stacklevel=3)
    elpd = {"waic": (float(waic.elpd_waic), float(waic.se)),
            "loo": (float(loo.elpd_loo), float(loo.se))}
    for name, (value, se) in elpd.items():
        if not (math.isfinite(value) and math.isfinite(se)):
            # Pointwise log-likelihoods that differ by more than ~700 nats between draws
            # overflow the importance ratios: the criterion is undefined, not a number.
            pointwise = post.idata.log_likelihood["G"].values.reshape(-1, lik.data.n_frequencies)
            spread = float(np.ptp(pointwise, axis=0).max())
            msg = (f"{post.structure}: {name.upper()} cannot be computed: the pointwise "
                   f"log-likelihood varies by up to {spread:.3g} nats between posterior draws "
                   "(the structure misfits these data far beyond its noise scale)")
            warn.append(msg)
            warnings.warn(msg, PredictiveWarning, stacklevel=3)
            elpd[name] = (math.nan, math.nan)  # null in summary.json, empty in ranking.csv
    model = lik.structure.response(
        post.map_theta[: lik.structure.n_params], lik.data.omega, lik.data.kind
    )
    rmse = float(np.sqrt(np.sum(np.abs(lik.data.response - model) ** 2)) / lik.data.n_frequencies)
    return {
        "max_log_likelihood": max_ll, "aic": aic, "aicc": aicc, "bic": bic,
        "waic": elpd["waic"][0], "waic_se": elpd["waic"][1],
        "loo": elpd["loo"][0], "loo_se": elpd["loo"][1], "pareto_k_max": k_max,
        "pareto_k": pareto_k.tolist(), "loo_pointwise": np.asarray(loo.loo_i).tolist(),
        "rmse": rmse, "warnings": warn,
        "priors": lik.describe_priors(),
    }


def compare(data: FrequencyResponse, structures, *, noise: str = "auto", seed: int = 0,
            priors=None, progress: bool | None = None, evidence: str = "auto",
            evidence_check: bool = False, prior_odds: dict | None = None, holdout=None,
            workers: int = 1, pool=None, **sampler_kwargs) -> Comparison:
    """Fit, sample and score every structure on ``data``.

    Parameters
    ----------
    data : FrequencyResponse
    structures : sequence of Structure
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
        seconds per structure); ``"auto"`` takes the draws where the posterior converged and
        the ladder where it did not.
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

    structures = list(structures)
    if not structures:
        raise InputError("no structure to compare")
    if evidence not in ("auto", "bridge", "ladder"):
        raise InputError(f"evidence must be 'auto', 'bridge' or 'ladder', got {evidence!r}")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 0:
        raise InputError(f"workers must be a non-negative integer, got {workers!r}")
    test = None
    if holdout is not None and len(holdout):
        data, test = data.split(holdout)
    if progress is None:
        progress = sys.stderr.isatty()
    n_proc = min(workers or available_cpus(), len(structures))
    options = {"noise": noise, "priors": priors, "seed": seed, "evidence_check": evidence_check,
               "evidence": evidence,
               "test": test, "sampler_kwargs": sampler_kwargs}
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


def _run_in_pool(pool, structures, data, options, bar) -> list:
    # Larger structures first (they take longest); results keep the order given.
    order = sorted(range(len(structures)), key=lambda i: -structures[i].n_params)
    futures = {i: pool.submit(_run_structure, structures[i], data, options) for i in order}
    for f in futures.values():
        f.add_done_callback(lambda _: bar.update())
    return [futures[i].result() for i in range(len(structures))]


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
            post, _ = run_posterior(lik.structure, data, noise=noise, priors=own, seed=seed,
                                    fit=fit, progress=False, **options["sampler_kwargs"])
            criteria = _criteria(lik, fit, post)
            if test is not None:
                criteria.update(_holdout(lik, post, test))
            extra = _evidence(lik, post, seed, options["evidence_check"], options["evidence"],
                              best_log_likelihood=criteria["max_log_likelihood"])
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


def _holdout(lik, post, test: FrequencyResponse) -> dict:
    """Log pointwise predictive density and RMSE on held-out frequencies."""
    from scipy.special import logsumexp

    # Same structure, noise model, priors and units as the fit: the draws apply unchanged.
    held = Likelihood(lik.structure, test, noise=lik.noise, priors=lik.priors,
                      scaling=lik.scaling, require_points=False)
    draws = post.samples_scaled
    pointwise = held.pointwise(draws)
    lpd = logsumexp(pointwise, axis=0) - np.log(draws.shape[0])
    model = lik.structure.response(post.map_theta[: lik.structure.n_params], test.omega, test.kind)
    rmse = float(np.sqrt(np.sum(np.abs(test.response - model) ** 2)) / test.n_frequencies)
    return {"holdout_lpd": float(lpd.sum()), "holdout_lpd_pointwise": lpd.tolist(),
            "holdout_rmse": rmse, "holdout_omega": test.omega.tolist()}


class EvidenceWarning(UserWarning):
    """The two evidence estimates disagree, or the evidence could not be computed."""


#: A tempered-ladder run whose best particle ends this far (nats) below the best fit found by the
#: optimiser and the sampler has missed part of the posterior (1 000 particles of a posterior
#: reach within a few nats of its maximum).
LADDER_SHORTFALL = 5.0


def _evidence(lik, post, seed, check: bool, route: str = "auto", *,
              best_log_likelihood: float | None = None) -> dict:
    out = {"evidence": None, "evidence_check": None, "evidence_agree": None, "warnings": []}
    # Bridge sampling from the emcee draws needs draws that represent the posterior; where the
    # walkers did not converge (ridges, several modes), a tempered ladder reaches the posterior
    # from the prior instead (ladder_evidence), proposing from the draws as well so that it
    # keeps the narrow modes the walkers found.
    ladder = route == "ladder" or (route == "auto" and not post.converged)
    try:
        if ladder:
            try:
                out["evidence"] = ladder_evidence(lik, seed=seed, guide=post)
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
        out["warnings"].append(f"{post.structure}: posterior not converged, so its evidence is unreliable")
    if check:
        # Uniform draws from bounding ellipsoids where emcee found one compact mode; slice
        # sampling where it did not converge (ridges, several modes), on which uniform draws
        # stall (see nested_evidence).
        how = {} if post.converged else {"sample": "rslice", "slices": max(25, 5 * lik.ndim)}
        nested = nested_evidence(lik, seed=seed, **how)
        out["evidence_check"] = nested
        combined = math.hypot(out["evidence"].log_z_err, nested.log_z_err)
        agree = abs(out["evidence"].log_z - nested.log_z) <= 2 * combined
        out["evidence_agree"] = bool(agree)
        if not agree:
            method = out["evidence"].method
            out["warnings"].append(f"{post.structure}: {method} and nested ln Z disagree")
            warnings.warn(
                f"{post.structure}: {method} ln Z = {out['evidence'].log_z:.2f} ± "
                f"{out['evidence'].log_z_err:.2f} and nested ln Z = {nested.log_z:.2f} ± "
                f"{nested.log_z_err:.2f} disagree", EvidenceWarning, stacklevel=3)
    return out


def _model_probabilities(results, prior_odds: dict) -> None:
    """Posterior model probabilities from ln Z and the prior odds, in place."""
    with_z = [r for r in results if r.error is None and r.criteria.get("evidence") is not None]
    unknown = set(prior_odds) - {r.name for r in results}
    if unknown:
        raise InputError(f"prior odds given for unknown structure '{sorted(unknown)[0]}'")
    if not with_z:
        return
    log_w = np.array([r.criteria["evidence"].log_z + math.log(prior_odds.get(r.name, 1.0))
                      for r in with_z])
    p = np.exp(log_w - log_w.max())
    p /= p.sum()
    for r, prob in zip(with_z, p, strict=True):
        r.criteria["posterior_probability"] = float(prob)


RANKING_FIELDS = ("rank", "structure", "parent", "n_params", "log_evidence", "log_evidence_err",
                  "evidence_method", "delta_log_evidence", "bayes_factor", "posterior_probability", "evidence_agree",
                  "loo", "loo_se", "delta_loo", "rank_loo", "waic", "rank_waic", "aic", "rank_aic",
                  "aicc", "rank_aicc", "bic", "rank_bic", "max_log_likelihood", "rmse",
                  "holdout_lpd", "holdout_rmse", "q_mean",
                  "q_sd", "pareto_k_max", "rhat_max", "ess_min", "converged", "error")


def ranking_csv(comparison: Comparison) -> str:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=RANKING_FIELDS, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in comparison.table():
        # No literal nan or inf: an undefined number is an empty cell, as null in summary.json.
        writer.writerow({k: ("" if v is None else v)
                         for k, v in _finite({k: row.get(k) for k in RANKING_FIELDS}).items()})
    return buf.getvalue()


def _json_default(obj):
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def _finite(obj):
    """JSON has no NaN or infinity: such numbers become null."""
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    if isinstance(obj, (float, np.floating)) and not math.isfinite(obj):
        return None
    return obj


def write_outputs(comparison: Comparison, out_dir, *, figures: bool = True,
                  formats=("png", "pdf"), pool=None) -> dict[str, Path]:
    """Write everything a comparison produced into ``out_dir``.

    One NetCDF per structure, the figures (``formats``; see
    :func:`bayesfo.plotting.write_figures`), ``report.html`` (self-contained, figures embedded),
    ``ranking.csv`` and ``summary.json``. Everything is written into a staging directory inside
    ``out_dir`` and swapped in at the end (:mod:`bayesfo.outdir`), so ``out_dir`` always holds the
    complete output of one run: an interrupted run leaves the earlier output as it was, and the
    outputs of an earlier run that this one does not write (a structure left out) are removed.
    Files of the user's own in ``out_dir`` are never touched.

    Parameters
    ----------
    comparison : Comparison
    out_dir : path
        Created if missing.
    figures : bool
        Draw the figures and the report (matplotlib; a few seconds per structure).
    formats : sequence of str
        Figure file formats.
    pool : concurrent.futures.Executor, optional
        Draw the figures in these worker processes (from :func:`process_pool`).

    Returns
    -------
    dict
        ``{name: path}`` of the files written (figures: ``{name: [paths]}``).
    """
    out_dir = Path(out_dir)
    written = {}
    with staged_run(out_dir) as stage:
        for r in comparison.results:
            if r.posterior is not None:
                written[r.name] = save_netcdf(r.posterior.idata, stage / f"{r.name}.nc")
        if figures:
            from .plotting import write_figures
            from .report import write_report

            drawn = write_figures(comparison, stage / "figures", formats=formats,
                                  seed=comparison.seed, pool=pool)
            written.update(drawn)
            written["report.html"] = write_report(comparison, stage, drawn)
        written["ranking.csv"] = atomic_write_text(stage / "ranking.csv", ranking_csv(comparison))
        text = json.dumps(_finite(comparison.to_summary()), indent=2, default=_json_default,
                          allow_nan=False)
        written["summary.json"] = atomic_write_text(stage / "summary.json", text + "\n")
    return {name: [final_path(p, stage, out_dir) for p in paths] if isinstance(paths, list)
            else final_path(paths, stage, out_dir) for name, paths in written.items()}
