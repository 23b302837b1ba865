"""What a comparison produced: one :class:`StructureResult` per structure and the
:class:`Comparison` that ranks them (tables, summary.json contract, baselines, families)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..data import FrequencyResponse
from ..errors import StructureError
from ..identify.optimize import FitResult
from ..inference import PosteriorResult
from ..inference.results import HDI_PROB, draws_digest
from ..predictions import predict
from ..predictions.draws import Draws, comparison_draws
from ..structures import Structure
from .criteria_types import Criteria
from .notebook import comparison_html
from .parameters import (  # noqa: F401  (re-exported: the names results offered before)
    NOISE_UNITS,
    limit_reasons,
    parameter_units,
    physical_forms,
    physical_text,
    prior_limited,
    shown_hdi,
    summarise_draws,
    with_determination,
)
from .table import (  # noqa: F401  (re-exported)
    ORDER_SYMBOLS,
    RANKING_FIELDS,
    number,
    order_parameter,
    order_parameters,
    ranking_lines,
    ranking_rows,
)


@dataclass(frozen=True, eq=False)
class StructureResult:
    """Everything computed for one structure on one data set.

    ``error`` holds the reason when the structure could not be run (the other fields are None,
    the criteria empty). ``criteria`` is a :class:`~bayesfo.comparison.criteria_types.Criteria`;
    a dict given instead is turned into one (:meth:`Criteria.from_dict`, which refuses unknown
    keys).
    """

    structure: Structure
    fit: FitResult | None = None
    posterior: PosteriorResult | None = None
    criteria: Criteria = field(default_factory=Criteria)
    error: str | None = None
    #: The kind and unit of the data the structure was run on (set by :class:`Comparison`);
    #: they give the parameters their units.
    data_kind: str | None = None
    data_units: str = ""
    #: The letter of the data's measured quantity (:attr:`FrequencyResponse.symbol`, set by
    #: :class:`Comparison`): figures name the moduli by it (E_e for tensile data); names only.
    data_symbol: str = "G"

    def __post_init__(self):
        if not isinstance(self.criteria, Criteria):
            object.__setattr__(self, "criteria", Criteria.from_dict(self.criteria or {}))

    @property
    def name(self) -> str:
        return self.structure.name

    @property
    def units(self) -> dict[str, str]:
        """``{parameter: unit}`` of the sampled parameters (:func:`parameter_units`); empty
        when the data's kind is not known."""
        if self.data_kind is None:
            return {}
        names = self.posterior.param_names if self.posterior is not None \
            else self.structure.param_names
        try:
            return parameter_units(self.structure, names, self.data_kind, self.data_units)
        except StructureError:
            return {}

    @cached_property
    def physical(self) -> dict | None:
        """The posterior's parameters in both forms with units (:func:`physical_forms`), or
        None without a posterior, without the data's kind, or when the structure's units
        cannot be derived."""
        post = self.posterior
        if post is None or self.data_kind is None:
            return None
        names = self.structure.param_names
        idx = {n: post.param_names.index(n) for n in names}
        draws = {n: post.samples[:, i] for n, i in idx.items()}
        at_map = {n: np.asarray(post.map_theta[i], dtype=float) for n, i in idx.items()}
        poor = {n: s.poorly_determined for n, s in post.summary.items()}
        try:
            return physical_forms(self.structure, draws, at_map, self.data_kind, self.data_units,
                                  poorly_determined=poor,
                                  limited=prior_limited(self.structure, post.summary))
        except StructureError:
            return None

    @cached_property
    def sampled_parameters(self) -> dict:
        """``{name: summary}`` of the parameters as sampled (the card's coefficients and the
        noise): ``ParameterSummary.to_dict()``, the unit where the data's kind is known, and
        ``not_determined``/``not_determined_reason``
        (:func:`~bayesfo.comparison.parameters.not_determined`, judged on the draws); empty
        without a posterior. Computed once, as :attr:`physical` is (the summary, the verdict
        and the report all read it)."""
        post = self.posterior
        if post is None:
            return {}
        units = self.units
        block = {k: v.to_dict() | ({"unit": units[k]} if k in units else {})
                 for k, v in post.summary.items()}
        draws = {k: post.samples[:, post.param_names.index(k)] for k in block
                 if k in post.param_names}
        return with_determination(
            block, draws=draws, limited=limit_reasons(prior_limited(self.structure, post.summary)))

    @property
    def natural_parameters(self) -> dict:
        """``{name: summary}`` in the form natural to the data: the physical parameters for
        modulus data (:attr:`physical`), else the parameters as sampled
        (:attr:`sampled_parameters`)."""
        phys = self.physical
        if phys is not None and phys["natural_form"] == "physical":
            return phys["physical"]
        return self.sampled_parameters

    @property
    def sampled(self) -> bool:
        """Whether the structure has a posterior: False for one the evidence bound left out
        (``criteria.bound``; :mod:`bayesfo.inference.bound`) and for one that failed."""
        return self.error is None and self.posterior is not None

    @property
    def log_z_bound(self) -> float | None:
        """For a structure left out by the evidence bound, the upper bound of its ln Z (its
        maximum log-likelihood); None otherwise."""
        b = self.criteria.bound
        return None if b is None else float(b["log_evidence_bound"])

    @property
    def log_z(self) -> float | None:
        """ln Z, the log-evidence (None without one: a failed structure, or none computed)."""
        ev = self.criteria.evidence
        return None if ev is None else float(ev.log_z)

    @property
    def log_z_err(self) -> float | None:
        """The Monte Carlo error of :attr:`log_z`."""
        ev = self.criteria.evidence
        return None if ev is None else float(ev.log_z_err)

    @property
    def probability(self) -> float | None:
        """The posterior probability of the structure among those compared (from ln Z and the
        prior odds), or None."""
        return self.criteria.posterior_probability

    @property
    def adequacy(self):
        """The posterior predictive checks (:class:`~bayesfo.inference.adequacy.Adequacy`), or
        None when they could not be run."""
        return self.criteria.adequacy

    @property
    def fits(self) -> str | None:
        """``"yes"`` (adequate), ``"partly"`` (adequate, but the fitted noise swamps points that
        the posterior mode misses by more than 2° or 3.5 %: ``misfit_masked``), ``"small"`` (a
        systematic misfit within 2° and 3.5 %), ``"no"``, or None without a check."""
        a = self.adequacy
        if a is None:
            return None
        if a.adequate:
            return "partly" if a.misfit_masked else "yes"
        return "small" if a.misfit_small else "no"

    def __repr__(self) -> str:
        if self.error is not None:
            return f"<StructureResult {self.name}: failed: {self.error}>"
        parts = []
        ev = self.criteria.evidence
        if ev is not None:
            parts.append(f"ln Z = {number(ev.log_z, '.2f')} ± {number(ev.log_z_err, '.2f')}")
        prob = self.criteria.posterior_probability
        if prob is not None:
            parts.append(f"P = {prob:.3f}")
        bound = self.criteria.bound
        if bound is not None:
            parts.append(f"ln Z ≤ {number(bound['log_evidence_bound'], '.2f')}")
            if bound.get("posterior_probability_bound") is not None:
                parts.append(f"P ≤ {bound['posterior_probability_bound']:.2g}")
            parts.append(bound["reason"])
        post = self.posterior
        if post is not None:
            parts.append(("certified" if post.converged else "NOT certified")
                         + f" ({getattr(post, 'sampler', 'emcee')})")
        if self.fits is not None:
            parts.append(f"fits: {self.fits}")
        return f"<StructureResult {self.name}: {', '.join(parts)}>"

    def summary(self) -> str:
        """A few lines on this structure: its evidence, certificate and adequacy, then each
        parameter (the physical form where the structure has one) with its unit, posterior
        median and 94 % HDI. ``print(result["zener"].summary())``."""
        s = self.structure
        head = f"{s.name}: {s.formula}"
        if self.error is not None:
            return f"{head}\n  failed: {self.error}"
        post = self.posterior
        lines = [head]
        ev = self.criteria.evidence
        prob = self.criteria.posterior_probability
        bound = self.criteria.bound
        if bound is not None:
            upper = bound.get("posterior_probability_bound")
            lines.append(f"  ln Z ≤ {number(bound['log_evidence_bound'], '.2f')}"
                         + ("" if upper is None else f", P ≤ {upper:.2g}")
                         + f" ({bound['reason']}); BIC = {number(self.criteria.bic, '.2f')}, "
                         f"RMSE of the best fit {number(self.criteria.rmse, '.4g')}")
            for w in self.criteria.warnings:
                lines.append(f"  ! {w}")
            return "\n".join(lines)
        lines.append(
            "  ln Z = " + ("-" if ev is None else
                           f"{number(ev.log_z, '.2f')} ± {number(ev.log_z_err, '.2f')} ({ev.method})")
            + ("" if prob is None else f", P = {prob:.3f}")
            + f", elpd_loo = {number(self.criteria.loo, '.2f')}"
            + f", BIC = {number(self.criteria.bic, '.2f')}")
        if post is not None:
            lines.append(
                f"  posterior: {getattr(post, 'sampler', 'emcee')}, "
                + ("certified" if post.converged else "NOT certified")
                + f" (R-hat {number(post.rhat_max, '.3f')}, ESS {number(post.ess_min, '.0f')}); "
                f"noise {post.noise}; fits: {self.fits or '-'}")
        phys = self.physical
        if phys is not None:
            block = dict(phys["physical"])
            units = self.units
            noise = {n: summarise_draws(post.samples[:, post.param_names.index(n)],
                                        post.map_theta[post.param_names.index(n)],
                                        units.get(n, ""))
                     for n in post.param_names if n not in s.param_names}
            block.update(with_determination(
                noise, {n: post.summary[n].poorly_determined for n in noise},
                draws={n: post.samples[:, post.param_names.index(n)] for n in noise}))
        else:
            block = self.sampled_parameters
        if block:
            width = max(len(n) for n in block)
            lines.append(f"  {'parameter':<{width}}  {'median':>11}  {HDI_PROB:.0%} HDI "
                         "(on a log scale for quantities with a unit)")
            for n, v in block.items():
                unit = f" {v['unit']}" if v.get("unit") else ""
                flags = ([f"not determined: {v['not_determined_reason']}"]
                         if v.get("not_determined") else []) + (
                    ["poorly determined: the HDI covers more than half of the prior range"]
                    if v.get("poorly_determined") else [])
                flag = f"  ({'; '.join(flags)})" if flags else ""
                lo, hi = shown_hdi(v)
                lines.append(f"  {n:<{width}}  {number(v.get('median'), '11.4g')}  "
                             f"[{number(lo, '.4g')}, {number(hi, '.4g')}]{unit}{flag}")
        for w in self.criteria.warnings:
            lines.append(f"  ! {w}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        s = self.structure
        out = {
            "name": s.name, "family": s.family, "formula": s.formula, "inverted": s.inverted,
            "integer": s.integer, "parent": _parent(s), "n_params": s.n_params,
        }
        if self.error is not None:
            out["error"] = self.error
            return out
        if self.posterior is None:
            return out | self._bounded_dict()
        out["sampled"] = True
        post = self.posterior
        ev = self.criteria.evidence
        check = self.criteria.evidence_check
        phys = self.physical
        out.update(
            # Each parameter as sampled (the card's coefficients and the noise), with its unit
            # when the data's kind is known and whether the data determine it.
            parameters=self.sampled_parameters,
            # Both forms with units (:func:`physical_forms`): which one is natural to the
            # data's kind, the physical parameters and the form that is not natural.
            natural_form=None if phys is None else phys["natural_form"],
            picture=None if phys is None else phys["picture"],
            parameters_physical=None if phys is None else phys["physical"],
            parameters_other_form=None if phys is None else phys["other"],
            priors=self.criteria.priors,
            noise=post.noise, noise_reason=post.noise_reason,
            # Under noise="auto" without σ: each candidate noise model's ln Z, probability and
            # exponent HDIs; ``noise_sensitive`` when those HDIs do not overlap.
            noise_models=self.criteria.noise_models,
            noise_sensitive=(None if self.criteria.noise_models is None
                             else self.criteria.noise_models["sensitive"]),
            log_evidence=None if ev is None else ev.log_z,
            log_evidence_err=None if ev is None else ev.log_z_err,
            evidence_method=None if ev is None else ev.method,
            log_prior_support=None if ev is None else ev.log_support,
            # the nested ln Z, and the one it was checked against: under the chosen noise
            # model alone (log_evidence is marginalised over the noise models where there were
            # several)
            evidence_check=None if check is None else check.to_dict() | {
                "compared_with": None if ev is None else float(ev.conditional.log_z)},
            evidence_agree=self.criteria.evidence_agree,
            posterior_probability=self.criteria.posterior_probability,
            delta_loo_se=self.criteria.delta_loo_se,
        )
        for key in ("max_log_likelihood", "aic", "aicc", "bic", "waic", "waic_se", "loo", "loo_se",
                    "pareto_k_max", "rmse"):
            out[key] = getattr(self.criteria, key)
        for key in ("holdout_lpd", "holdout_rmse", "holdout_lpd_pointwise", "holdout_omega"):
            value = getattr(self.criteria, key)
            if value is not None:
                out[key] = list(value) if isinstance(value, tuple) else value
        out.update(
            rhat_max=post.rhat_max, ess_min=post.ess_min, ess_bulk_min=post.ess_bulk_min,
            ess_tail_min=post.ess_tail_min, converged=post.converged, tau_max=float(np.max(post.tau)),
            n_steps=post.n_steps, n_draws=int(post.samples.shape[0]), messages=list(post.messages),
            sampler=getattr(post, "sampler", "emcee"),
            # Ties the structure's NetCDF to this summary (load refuses another run's draws).
            draws_sha256=draws_digest(post.samples),
            # The certificate of an importance-sampled posterior: Pareto k of its weights, their
            # ESS and the optima the proposal covered.
            importance=None if self.criteria.importance is None else {
                k: v for k, v in self.criteria.importance.items() if k != "seconds"},
            adequacy=None if self.adequacy is None else self.adequacy.to_dict(),
            warnings=list(self.criteria.warnings),
            optimum=self._optimum(),
        )
        return out


    def _bounded_dict(self) -> dict:
        """The ``summary.json`` record of a structure the evidence bound left out: the keys of
        a sampled one that need no posterior, those that do as null, and the bound."""
        c, bound = self.criteria, self.criteria.bound or {}
        out = {"sampled": False, "parameters": {}, "priors": c.priors,
               "log_evidence": None, "log_evidence_err": None, "evidence_method": None,
               "log_evidence_bound": bound.get("log_evidence_bound"),
               "posterior_probability": None,
               "posterior_probability_bound": bound.get("posterior_probability_bound"),
               "bound_reason": bound.get("reason"), "bound": dict(bound),
               "best_fit_source": bound.get("source"), "noise": bound.get("noise"),
               "delta_loo_se": None}
        for key in ("max_log_likelihood", "aic", "aicc", "bic", "waic", "waic_se", "loo",
                    "loo_se", "pareto_k_max", "rmse"):
            out[key] = getattr(c, key)
        out.update(rhat_max=None, ess_min=None, converged=None, sampler="not sampled",
                   # The posterior predictive checks with the best fit for the posterior.
                   adequacy=None if self.adequacy is None else self.adequacy.to_dict(),
                   adequacy_of="best fit", warnings=list(c.warnings), optimum=self._optimum())
        return out

    def _optimum(self) -> dict | None:
        """The global optimisation's best point, as ``summary.json["structures"][i]["optimum"]``."""
        if self.fit is None:
            return None
        return {"parameters": dict(zip(self.fit.param_names, map(float, self.fit.theta))),
                "rmse": self.fit.rmse, "starts": self.fit.n_starts,
                "starts_at_optimum": self.fit.n_at_best, "admissible": self.fit.admissible,
                # The thesis' linear methods 1–5 at their best q, as the corner plot marks them.
                "linear_methods": {k: dict(zip(self.fit.param_names, map(float, v)))
                                   for k, v in self.fit.linear.items()}}


def _parent(structure) -> str | None:
    """The fractional structure an integer baseline comes from (``zener-int`` → ``zener``)."""
    return structure.name[: -len("-int")] if structure.integer else None


#: A Kramers–Kronig inconsistency whose best causal description misses the data by more than
#: this (rms, relative) is warned as a problem of the data: no linear viscoelastic structure can
#: fit them better. Smaller ones (real isotherms fail the test by 0.3-4 %) are stated in the
#: verdict and ``summary.json["data"]["kramers_kronig"]`` only.
KK_WARN_RMS = 0.05


def data_problems(data: FrequencyResponse) -> list[str]:
    """What is wrong with ``data`` for every structure: points with the loss of the wrong sign
    for a passive material (an instrument artefact or noise that no passive structure fits), and
    parts far from Kramers–Kronig consistent (misfit over :data:`KK_WARN_RMS`)."""
    out = []
    bad = data.omega[data.dissipation_violations()]
    if bad.size:
        letter = getattr(data, "response_symbol", "J" if data.kind == "compliance" else "G")
        loss = f"Im {letter} > 0" if data.kind == "compliance" else f"Im {letter} < 0"
        shown = ", ".join(f"{w:.4g}" for w in bad[:6]) + (f" and {bad.size - 6} more"
                                                           if bad.size > 6 else "")
        out.append(f"{data.label}: {bad.size} of {data.n_frequencies} points have negative loss "
                   f"({loss}), impossible for a passive {data.kind}, at omega = {shown} rad/s; "
                   "no passive structure can fit them")
    kk = data.kramers_kronig() if data.kind in ("modulus", "compliance") else None
    if kk is not None and not kk.consistent and kk.misfit_rms > KK_WARN_RMS:
        out.append(f"{data.label}: {kk.describe()}")
    return out


@dataclass(frozen=True, eq=False)
class Comparison:
    """Results of :func:`compare`: the data, one :class:`StructureResult` per structure.

    ``evidence_bound`` records the evidence bound's decisions (:mod:`bayesfo.inference.bound`):
    ``sample`` (``"needed"`` or ``"all"``), ``margin`` (nats), ``leader`` and
    ``leader_log_evidence`` (the certified ln Z, less twice its error, that the bounds were
    compared with), ``bounded`` (the structures left out), ``optimiser_shortfall`` (by how
    much the sampled structures' draws exceeded the optimiser's maximum, 0 where never) and
    ``rechecked`` (structures sampled after all because of it). None for results made
    before it existed."""

    data: FrequencyResponse
    results: tuple[StructureResult, ...]
    seed: int
    ranked_by: str = "log_evidence"
    holdout: FrequencyResponse | None = None
    evidence_bound: dict | None = None

    def __post_init__(self):
        # Each result learns the kind and unit of the data, which give its parameters units,
        # and the data's symbol, which names them.
        symbol = getattr(self.data, "symbol", "G")
        results = tuple(
            dataclasses.replace(r, data_kind=self.data.kind, data_units=self.data.units or "",
                                data_symbol=symbol)
            if isinstance(r, StructureResult) and (r.data_kind, r.data_units, r.data_symbol)
            != (self.data.kind, self.data.units or "", symbol) else r
            for r in self.results)
        object.__setattr__(self, "results", results)

    @property
    def data_warnings(self) -> list[str]:
        """Problems of the data that no structure can mend, in plain words (also warned by
        :func:`compare` and stated in ``summary.json["data"]["warnings"]``)."""
        return data_problems(self.data)

    @property
    def ranking(self) -> list[str]:
        """Structure names, best first by ln Z (those without an evidence after them: the
        ones the evidence bound left out by their bound, then the others by PSIS-LOO);
        structures that failed are left out."""
        ok = [r for r in self.results if r.error is None]

        def key(r):
            ev = r.criteria.evidence
            bound = r.log_z_bound
            value = (ev.log_z if ev is not None else bound if bound is not None
                     else r.criteria.loo)
            value = math.nan if value is None else value
            return (ev is None, bound is None, not math.isfinite(value),
                    -value if math.isfinite(value) else 0)

        return [r.name for r in sorted(ok, key=key)]

    @property
    def noise_note(self) -> str | None:
        """How the noise model enters ln Z, in words, where some structure's ln Z is
        marginalised over noise models (``noise="auto"`` without σ); None otherwise."""
        records = [r.criteria.noise_models for r in self.results
                   if r.error is None and r.criteria.noise_models
                   and "marginal" in r.criteria.noise_models]
        if not records:
            return None
        models = list(dict.fromkeys(n for rec in records for n in rec["marginal"]["prior"]))
        listed = models[0] if len(models) == 1 else ", ".join(models[:-1]) + " and " + models[-1]
        return (f"ln Z treats the noise model as a nuisance (the mean of the evidences under "
                f"{listed} noise, equal prior weights), so every structure is ranked on one "
                "footing; each posterior is under its most probable noise model")

    def draws(self, structure: str | None = None, average: str | None = None, *,
              seed: int = 0, temperature: float | None = None) -> Draws:
        """The posterior draws that predictions, Prony series and long-time moduli evaluate:
        :data:`~bayesfo.predictions.draws.MAX_DRAWS` of ``structure`` (default the best
        ranked), or of the ``average`` (``"bma"`` or ``"stacking"``) of the ranked structures.

        Raises
        ------
        InputError
            An unknown structure or average, both given, a structure without a posterior, or
            a ``temperature`` (a comparison's draws are at the data's own).
        """
        return comparison_draws(self, structure, average, seed=seed, temperature=temperature)

    def predict(self, quantity: str, x, *, structure: str | None = None,
                average: str | None = None, seed: int = 0):
        """A material function with its credible band: :func:`bayesfo.predict` of this
        comparison (G′, G″, tan δ, J′, J″, |η*| at ω; G(t), J(t); spectra H(τ), L(τ))."""
        return predict(self, quantity, x, structure=structure, average=average, seed=seed)

    def __getitem__(self, name: str) -> StructureResult:
        for r in self.results:
            if r.name == name:
                return r
        raise KeyError(name)

    def __repr__(self) -> str:
        ranking = self.ranking
        best = ""
        if ranking:
            prob = self[ranking[0]].probability
            best = f"; best {ranking[0]}" + ("" if prob is None else f" (P = {prob:.3f})")
        failed = sum(r.error is not None for r in self.results)
        return (f"<Comparison of {len(self.results)} structure(s) on '{self.data.label}' "
                f"({self.data.n_frequencies} frequencies, {self.data.kind}){best}"
                + (f"; {failed} failed" if failed else "") + ">")

    def _repr_html_(self) -> str:
        return comparison_html(self)

    def summary(self) -> str:
        """The ranking as ``bayesfo compare`` prints it
        (:func:`~bayesfo.comparison.table.ranking_lines`): per structure ln Z ± error (L: from
        a tempered ladder), Δln Z, the posterior probability P, elpd by PSIS-LOO, BIC, the
        fractional orders' means, R-hat, whether the posterior is certified (ok) and whether
        the structure fits the data (posterior predictive checks); the structures that failed
        with their reason.
        ``print(result.summary())``; per structure, :meth:`StructureResult.summary`."""
        d = self.data
        held = "" if self.holdout is None else f", {self.holdout.n_frequencies} held out"
        lines = [f"{d.label}: {d.n_frequencies} frequencies{held} "
                 f"({d.omega.min():.4g} to {d.omega.max():.4g} rad/s), {d.kind}; seed "
                 f"{self.seed}; ranked by ln Z", *ranking_lines(self.table())]
        if self.noise_note:
            lines.append(self.noise_note)
        for w in self.data_warnings:
            lines.append(f"! {w}")
        return "\n".join(lines)

    def table(self) -> list[dict]:
        """One row per structure, best first (failed structures last), for printing or CSV
        (:func:`ranking_rows` of the structures' ``summary.json`` records)."""
        return ranking_rows([r.to_dict() for r in self.results], self.ranking)

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
                     "units": self.data.units, "symbol": self.data.symbol,
                     "omega_min": float(self.data.omega.min()),
                     "omega_max": float(self.data.omega.max()),
                     "warnings": self.data_warnings, "notes": list(self.data.notes),
                     "dissipation_violations_omega":
                         self.data.omega[self.data.dissipation_violations()].tolist(),
                     "kramers_kronig": None if (kk := self.data.kramers_kronig()) is None
                     else kk.to_dict()},
            "seed": self.seed,
            "ranked_by": self.ranked_by,
            "structures": [r.to_dict() for r in self.results],
            "ranking": self.ranking,
            "families": self.families(),
            "baselines": self.baselines(),
        }
        if self.holdout is not None:
            summary["data"]["holdout_omega"] = self.holdout.omega.tolist()
        if self.evidence_bound is not None:
            summary["evidence_bound"] = self.evidence_bound
        return summary

    def baselines(self) -> list[dict]:
        """Each integer baseline next to its fractional parent (both run on these data).

        Returns one dict per pair: ``parent``, ``baseline``, ``delta_log_evidence`` (ln Z of the
        parent minus the baseline's; > 0 favours the fractional order) with
        ``delta_log_evidence_relation`` (``"="``; ``">="`` where the baseline was left out by
        the evidence bound and its bound stands in for its ln Z, ``"<="`` where the parent
        was), ``bayes_factor`` (parent over baseline, under the same relation), the parent's posterior order ``order`` (``q``, or ``beta`` for the
        Maxwell) with ``order_mean``, ``order_hdi`` (94 %) and ``order_hdi_includes_1``: whether
        q = 1, the baseline, is inside the parent's HDI; and ``orders``, the same for every
        order the baseline fixes at 1 (``name``, ``symbol``, ``mean``, ``hdi``,
        ``hdi_includes_1``).
        """
        done = {r.name: r for r in self.results if r.error is None}
        out = []
        for r in self.results:
            parent = _parent(r.structure)
            if parent is None or r.name not in done or parent not in done:
                continue
            p = done[parent]
            ev_p, ev_b = p.criteria.evidence, r.criteria.evidence
            # Where one of the two was left out by the evidence bound, its bound stands in
            # for its ln Z, and the difference is a bound too (``delta_log_evidence_relation``).
            relation, d, err = "=", None, None
            if ev_p is not None and ev_b is not None:
                d, err = ev_p.log_z - ev_b.log_z, math.hypot(ev_p.log_z_err, ev_b.log_z_err)
            elif ev_p is not None and r.log_z_bound is not None:
                relation, d, err = ">=", ev_p.log_z - r.log_z_bound, ev_p.log_z_err
            elif p.log_z_bound is not None and ev_b is not None:
                relation, d, err = "<=", p.log_z_bound - ev_b.log_z, ev_b.log_z_err
            # Every order the baseline fixes at 1 (the Maxwell's α and β), the first as before.
            summary = {} if p.posterior is None else p.posterior.summary
            fixed = [k for k in order_parameters(summary) if k in r.structure.fixed]
            order = next((k for k in ("q", "beta") if k in fixed), fixed[0] if fixed else None)
            row = {"parent": parent, "baseline": r.name, "delta_log_evidence": d,
                   "delta_log_evidence_err": err,
                   "delta_log_evidence_relation": None if d is None else relation,
                   "bayes_factor": None if d is None else math.exp(min(d, 700.0)),
                   "order": order, "orders": []}
            for k in fixed:
                o = p.posterior.summary[k]
                row["orders"].append({"name": k, "symbol": ORDER_SYMBOLS[k], "mean": o.mean,
                                      "hdi": [o.hdi_low, o.hdi_high],
                                      "hdi_includes_1": bool(o.hdi_low <= 1.0 <= o.hdi_high)})
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
            if r.error is None and r.criteria.evidence is not None:
                groups.setdefault(r.structure.family, []).append(r)
        out = []
        for family, members in groups.items():
            if len(members) < 2:
                continue
            z = np.array([m.log_z for m in members])
            err = np.array([m.log_z_err for m in members])
            top = z.max()
            w = np.exp(z - top)
            log_z = float(top + np.log(w.mean()))
            out.append({
                "family": family, "members": [m.name for m in members], "log_evidence": log_z,
                "log_evidence_err": float(np.sqrt(np.sum((w / w.sum() * err) ** 2))),
                "posterior_probability": float(sum(m.probability or 0.0
                                                   for m in members)),
            })
        return sorted(out, key=lambda f: -f["log_evidence"])
