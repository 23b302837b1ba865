"""Run structures on one data set and rank them: the engine behind ``bayesfo compare``.

For every structure: the global least-squares optimisation (modes and a maximum-likelihood
start), the emcee posterior, and the criteria that follow from them: maximum log-likelihood,
AIC, AICc, BIC (from the higher of the optimiser's and the sampler's maximum), WAIC and PSIS-LOO
(arviz, pointwise per frequency), RMSE at the posterior mode (thesis eq. (3.23)). Structures are
ranked by PSIS-LOO (expected log predictive density), the Bayesian criterion available without
the evidence.

Outputs (:func:`write_outputs`, each file written atomically): ``summary.json`` (the contract of
DESIGN.md), ``ranking.csv``, and one ``<structure>.nc`` (arviz InferenceData) per structure.
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
            "integer": s.integer, "n_params": s.n_params,
        }
        if self.error is not None:
            out["error"] = self.error
            return out
        post = self.posterior
        out.update(
            parameters={k: v.to_dict() for k, v in post.summary.items()},
            priors=self.criteria["priors"],
            noise=post.noise, noise_reason=post.noise_reason,
            log_evidence=None, log_evidence_err=None, evidence_method=None,
            posterior_probability=None,
        )
        for key in ("max_log_likelihood", "aic", "aicc", "bic", "waic", "waic_se", "loo", "loo_se",
                    "pareto_k_max", "rmse"):
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


@dataclass(frozen=True, eq=False)
class Comparison:
    """Results of :func:`compare`: the data, one :class:`StructureResult` per structure."""

    data: FrequencyResponse
    results: tuple[StructureResult, ...]
    seed: int
    ranked_by: str = "loo"

    @property
    def ranking(self) -> list[str]:
        """Structure names, best first by PSIS-LOO; structures that failed are left out."""
        ok = [r for r in self.results if r.error is None]
        return [r.name for r in sorted(ok, key=lambda r: -r.criteria["loo"])]

    def __getitem__(self, name: str) -> StructureResult:
        for r in self.results:
            if r.name == name:
                return r
        raise KeyError(name)

    def table(self) -> list[dict]:
        """One row per structure, best first (failed structures last), for printing or CSV."""
        order = {n: i for i, n in enumerate(self.ranking)}
        rows = []
        best = self[self.ranking[0]].criteria["loo"] if self.ranking else math.nan
        for r in sorted(self.results, key=lambda r: order.get(r.name, len(order))):
            if r.error is not None:
                rows.append({"rank": None, "structure": r.name, "n_params": r.structure.n_params,
                             "error": r.error})
                continue
            c, p = r.criteria, r.posterior
            q = p.summary.get("q") or p.summary.get("beta")
            rows.append({
                "rank": order[r.name] + 1, "structure": r.name, "n_params": r.structure.n_params,
                "loo": c["loo"], "loo_se": c["loo_se"], "delta_loo": c["loo"] - best,
                "waic": c["waic"], "aic": c["aic"], "aicc": c["aicc"], "bic": c["bic"],
                "max_log_likelihood": c["max_log_likelihood"], "rmse": c["rmse"],
                "q_mean": None if q is None else q.mean, "q_sd": None if q is None else q.sd,
                "pareto_k_max": c["pareto_k_max"], "rhat_max": p.rhat_max, "ess_min": p.ess_min,
                "converged": p.converged, "error": "",
            })
        return rows

    def to_summary(self) -> dict:
        """The ``summary.json`` contract."""
        return {
            "data": {"path": self.data.source, "name": self.data.label,
                     "n_frequencies": self.data.n_frequencies, "kind": self.data.kind,
                     "units": self.data.units, "omega_min": float(self.data.omega.min()),
                     "omega_max": float(self.data.omega.max())},
            "seed": self.seed,
            "ranked_by": self.ranked_by,
            "structures": [r.to_dict() for r in self.results],
            "ranking": self.ranking,
        }


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
        msg = (f"{post.structure}: Pareto k up to {k_max:.2f} at omega = "
               + ", ".join(f"{w:.4g}" for w in bad) + " rad/s; PSIS-LOO is unreliable there")
        warn.append(msg)
        warnings.warn(msg, PredictiveWarning, stacklevel=3)
    model = lik.structure.response(
        post.map_theta[: lik.structure.n_params], lik.data.omega, lik.data.kind
    )
    rmse = float(np.sqrt(np.sum(np.abs(lik.data.response - model) ** 2)) / lik.data.n_frequencies)
    return {
        "max_log_likelihood": max_ll, "aic": aic, "aicc": aicc, "bic": bic,
        "waic": float(waic.elpd_waic), "waic_se": float(waic.se),
        "loo": float(loo.elpd_loo), "loo_se": float(loo.se), "pareto_k_max": k_max,
        "pareto_k": pareto_k.tolist(), "rmse": rmse, "warnings": warn,
        "priors": lik.describe_priors(),
    }


def compare(data: FrequencyResponse, structures, *, noise: str = "auto", seed: int = 0,
            priors=None, progress: bool | None = None, **sampler_kwargs) -> Comparison:
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
    if progress is None:
        progress = sys.stderr.isatty()
    results = []
    for s in tqdm(structures, desc="structures", disable=not progress, leave=False):
        try:
            own = {k: v for k, v in (priors or {}).items() if k in s.param_names or k in ("sigma", "sigma_rel")}
            lik = Likelihood(s, data, noise=noise, priors=own)
            fit = fit_structure(lik.structure, data, rng=seed, seed_methods=True)
            post, _ = run_posterior(lik.structure, data, noise=noise, priors=own, seed=seed,
                                    fit=fit, progress=False, **sampler_kwargs)
            results.append(StructureResult(s, fit, post, _criteria(lik, fit, post)))
        except InputError as exc:
            results.append(StructureResult(s, error=str(exc)))
    if all(r.error is not None for r in results):
        raise InputError("; ".join(f"{r.name}: {r.error}" for r in results))
    return Comparison(data, tuple(results), seed)


RANKING_FIELDS = ("rank", "structure", "n_params", "loo", "loo_se", "delta_loo", "waic", "aic",
                  "aicc", "bic", "max_log_likelihood", "rmse", "q_mean", "q_sd", "pareto_k_max",
                  "rhat_max", "ess_min", "converged", "error")


def ranking_csv(comparison: Comparison) -> str:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=RANKING_FIELDS, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in comparison.table():
        writer.writerow({k: ("" if row.get(k) is None else row.get(k)) for k in RANKING_FIELDS})
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


def write_outputs(comparison: Comparison, out_dir) -> dict[str, Path]:
    """Write ``summary.json``, ``ranking.csv`` and one NetCDF per structure into ``out_dir``.

    The NetCDF files come first and ``summary.json`` last, each through a temporary file and a
    rename, so an interrupted run never leaves a half-written summary.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written = {}
    for r in comparison.results:
        if r.posterior is not None:
            written[r.name] = save_netcdf(r.posterior.idata, out_dir / f"{r.name}.nc")
    written["ranking.csv"] = atomic_write_text(out_dir / "ranking.csv", ranking_csv(comparison))
    text = json.dumps(_finite(comparison.to_summary()), indent=2, default=_json_default,
                      allow_nan=False)
    written["summary.json"] = atomic_write_text(out_dir / "summary.json", text + "\n")
    return written
