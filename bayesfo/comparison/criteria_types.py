"""The criteria of one structure as a typed, frozen record (:class:`Criteria`).

:func:`~bayesfo.comparison.run.compare` builds each structure's criteria as a dict while it
runs and turns it into a :class:`Criteria` once, at the end (:meth:`Criteria.from_dict`); a
misspelt key fails there. Its fields are read as attributes (``criteria.loo``,
``criteria.evidence``); it cannot be changed: a new value is a new object
(``dataclasses.replace(criteria, posterior_probability=0.7)``). The mapping interface of earlier
releases (``criteria["loo"]``, ``criteria.get("evidence")``, ``"holdout_lpd" in criteria``)
still works for one release, with a :class:`DeprecationWarning`.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any

#: Fields holding a sequence of numbers or texts: stored as tuples.
_SEQUENCES = ("pareto_k", "loo_pointwise", "holdout_lpd_pointwise", "holdout_omega", "warnings")


@dataclass(frozen=True, eq=False)
class Criteria:
    """Criteria, evidence and checks of one structure on one data set.

    Every field is optional: a structure that could not be run has none (``Criteria()``), and
    some exist only for some runs (``importance`` for an importance-sampled posterior, the
    ``holdout_*`` entries with held-out frequencies, ``posterior_probability`` with an
    evidence). Read the fields as attributes (``criteria.loo``); :meth:`to_dict` gives those
    that are not None. The mapping interface of earlier releases (``criteria[name]``,
    ``get``, ``in``, iteration) is deprecated and warns.

    Attributes
    ----------
    max_log_likelihood : float
        The higher of the optimiser's and the sampler's best log-likelihood.
    aic, aicc, bic : float
        From ``max_log_likelihood`` (AICc is inf when there are too few points).
    waic, waic_se, loo, loo_se : float
        elpd by WAIC and PSIS-LOO with their standard errors (NaN when undefined).
    pareto_k_max : float
        Largest Pareto k̂ of PSIS-LOO.
    pareto_k, loo_pointwise : tuple of float
        Pareto k̂ and the elpd of PSIS-LOO per frequency.
    rmse : float
        RMSE at the posterior mode (thesis eq. (3.23)).
    priors : dict
        ``{parameter: description}`` of the priors used (``Likelihood.describe_priors``).
    warnings : tuple of str
        What went wrong or needs attention, in plain words.
    importance : dict or None
        The certificate of an importance-sampled posterior (Pareto k̂ of its weights, ESS, the
        optima covered, ...).
    evidence, evidence_check : Evidence or None
        ln Z by the route that gave the posterior, and by dynesty nested sampling when asked.
    evidence_agree : bool or None
        Whether the two agree within twice their combined error.
    noise_models : dict or None
        The record of the choice between noise models (``noise="auto"`` without σ).
    adequacy : Adequacy or None
        The posterior predictive checks.
    holdout_lpd, holdout_rmse : float or None
        Log predictive density and RMSE on the held-out frequencies.
    holdout_lpd_pointwise, holdout_omega : tuple of float or None
        The log predictive density per held-out frequency, and those frequencies [rad/s].
    delta_loo_se : float or None
        Standard error of the difference in PSIS-LOO elpd to the structure of the comparison
        with the highest elpd, from the pointwise differences (``arviz.compare``'s ``dse``;
        0 for that structure; None when the elpd is undefined).
    posterior_probability : float or None
        Posterior model probability among the structures compared (from ln Z and the prior
        odds).
    bound : dict or None
        For a structure that was not sampled because its best fit bounds its ln Z
        (:mod:`bayesfo.inference.bound`): ``log_evidence_bound`` (the highest log-likelihood
        over the noise models considered, ln Z ≤ it), ``by_noise`` (``{noise: max ln L}``),
        ``source`` (how those maxima were found), ``leader`` and ``leader_log_evidence`` (the
        certified ln Z it was compared with), ``margin`` (nats), ``reason``, and
        ``posterior_probability_bound`` (P ≤ it). None for a sampled structure.
    """

    max_log_likelihood: float | None = None
    aic: float | None = None
    aicc: float | None = None
    bic: float | None = None
    waic: float | None = None
    waic_se: float | None = None
    loo: float | None = None
    loo_se: float | None = None
    pareto_k_max: float | None = None
    pareto_k: tuple[float, ...] | None = None
    loo_pointwise: tuple[float, ...] | None = None
    rmse: float | None = None
    priors: dict | None = None
    warnings: tuple[str, ...] = ()
    importance: dict | None = None
    evidence: Any = None
    evidence_check: Any = None
    evidence_agree: bool | None = None
    noise_models: dict | None = None
    adequacy: Any = None
    holdout_lpd: float | None = None
    holdout_rmse: float | None = None
    holdout_lpd_pointwise: tuple[float, ...] | None = None
    holdout_omega: tuple[float, ...] | None = None
    posterior_probability: float | None = None
    delta_loo_se: float | None = None
    bound: dict | None = None

    def __post_init__(self):
        for name in _SEQUENCES:
            value = getattr(self, name)
            if value is not None and not isinstance(value, tuple):
                object.__setattr__(self, name, tuple(value))

    @classmethod
    def names(cls) -> tuple[str, ...]:
        """The field names, which are the keys a criteria dict may have."""
        return tuple(f.name for f in dataclasses.fields(cls))

    @classmethod
    def from_dict(cls, values: Mapping) -> Criteria:
        """The criteria from a dict with the field names as keys (as ``compare`` builds it).

        Raises
        ------
        KeyError
            For a key that is not a field (a misspelt key fails here, not in a reader).
        """
        if isinstance(values, Criteria):
            return values
        known = cls.names()
        unknown = [k for k in values if k not in known]
        if unknown:
            raise KeyError(f"unknown criteria key {unknown[0]!r}; the keys are "
                           + ", ".join(known))
        return cls(**dict(values))

    def to_dict(self) -> dict:
        """The fields that are not None, as a plain dict (no copies of their values)."""
        return {n: getattr(self, n) for n in _NAMES if getattr(self, n) is not None}

    # ---- the read side of a mapping, deprecated: attribute access replaces it
    @staticmethod
    def _deprecated(instead: str, stacklevel: int = 3) -> None:
        warnings.warn("reading Criteria as a mapping is deprecated and goes in the next "
                      f"release; use {instead}", DeprecationWarning, stacklevel=stacklevel)

    def _check(self, key) -> None:
        # The warning points at the caller of __getitem__ or get.
        self._deprecated(f"criteria.{key}" if isinstance(key, str) else "its attributes", 4)
        if key not in _NAMES:
            raise KeyError(f"{key!r} is not a criteria key; the keys are " + ", ".join(_NAMES))

    def __getitem__(self, key):
        self._check(key)
        return getattr(self, key)

    def get(self, key, default=None):
        """Deprecated: the attribute ``key`` (``default`` when it is None)."""
        self._check(key)
        value = getattr(self, key)
        return default if value is None else value

    def __contains__(self, key) -> bool:
        self._deprecated(f"criteria.{key} is not None")
        return key in _NAMES and getattr(self, key) is not None

    def keys(self) -> list[str]:
        """Deprecated: ``to_dict().keys()``."""
        self._deprecated("criteria.to_dict()")
        return list(self.to_dict())

    def __iter__(self) -> Iterator[str]:
        self._deprecated("criteria.to_dict()")
        return iter(self.to_dict())

    def __len__(self) -> int:
        self._deprecated("criteria.to_dict()")
        return len(self.to_dict())

    def items(self) -> list[tuple[str, Any]]:
        """Deprecated: ``to_dict().items()``."""
        self._deprecated("criteria.to_dict()")
        return list(self.to_dict().items())

    def values(self) -> list:
        """Deprecated: ``to_dict().values()``."""
        self._deprecated("criteria.to_dict()")
        return list(self.to_dict().values())

    def __repr__(self) -> str:
        shown = []
        for name in ("loo", "bic", "rmse", "posterior_probability"):
            value = getattr(self, name)
            if isinstance(value, float):
                shown.append(f"{name}={value:.6g}")
        ev = self.evidence
        if ev is not None:
            shown.insert(0, f"log_z={ev.log_z:.6g} ± {ev.log_z_err:.2g} ({ev.method})")
        if self.warnings:
            shown.append(f"{len(self.warnings)} warning(s)")
        return f"Criteria({', '.join(shown)})"


_NAMES = Criteria.names()
