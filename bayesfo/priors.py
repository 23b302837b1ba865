"""Prior distributions of single parameters, as objects.

Each prior can be evaluated (:meth:`log_prob`), sampled (:meth:`sample`), mapped from the unit
interval (:meth:`ppf`, the prior transform of nested samplers) and states its support
(:attr:`bounds`), so an MCMC sampler and a nested sampler use the very same prior. All priors are
proper: the evidence depends on them.

Priors are declared in the structure cards (``bayesfo/models/*.toml``) as tables such as
``{ prior = "log-uniform", low = 1e-4, high = 1e4 }`` and apply to parameters on the scaled data
(ω/ω_ref, G/g_ref; see :mod:`bayesfo.structures`).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np
from scipy import special

from .errors import StructureError


@dataclass(frozen=True)
class Prior:
    """Base class. Subclasses define ``bounds``, ``log_prob``, ``ppf`` and ``to_dict``."""

    def sample(self, rng: np.random.Generator, size=None) -> np.ndarray:
        """Draw from the prior with the generator ``rng``."""
        return self.ppf(rng.uniform(size=size))

    def contains(self, x) -> np.ndarray:
        """True where ``x`` lies in the support."""
        lo, hi = self.bounds
        x = np.asarray(x, dtype=float)
        return (x >= lo) & (x <= hi)

    def describe(self) -> str:
        """One line for reports, e.g. ``log-uniform(1e-4, 1e4)``."""
        d = self.to_dict()
        args = ", ".join(f"{v:g}" for k, v in d.items() if k != "prior")
        return f"{d['prior']}({args})"


@dataclass(frozen=True)
class Uniform(Prior):
    """Uniform density on [low, high]."""

    low: float
    high: float

    def __post_init__(self):
        _check_interval(self.low, self.high, "uniform")

    @property
    def bounds(self) -> tuple[float, float]:
        return (self.low, self.high)

    def log_prob(self, x) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        return np.where(self.contains(x), -math.log(self.high - self.low), -np.inf)

    def ppf(self, u) -> np.ndarray:
        return self.low + np.asarray(u, dtype=float) * (self.high - self.low)

    def to_dict(self) -> dict:
        return {"prior": "uniform", "low": self.low, "high": self.high}


@dataclass(frozen=True)
class LogUniform(Prior):
    """Density ∝ 1/x on [low, high], 0 < low: uniform in log x, the scale-invariant prior."""

    low: float
    high: float

    def __post_init__(self):
        _check_interval(self.low, self.high, "log-uniform")
        if self.low <= 0:
            raise StructureError(f"log-uniform prior needs low > 0, got low = {self.low:g}")
        if not math.isfinite(self.high / self.low):
            raise StructureError(
                f"log-uniform prior needs a ratio high/low that is a finite double, got "
                f"low = {self.low:g}, high = {self.high:g}"
            )

    @property
    def bounds(self) -> tuple[float, float]:
        return (self.low, self.high)

    def log_prob(self, x) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        inside = self.contains(x)
        with np.errstate(divide="ignore", invalid="ignore"):
            lp = -np.log(np.where(inside, x, 1.0)) - math.log(math.log(self.high / self.low))
        return np.where(inside, lp, -np.inf)

    def ppf(self, u) -> np.ndarray:
        u = np.asarray(u, dtype=float)
        return self.low * np.exp(u * math.log(self.high / self.low))

    def to_dict(self) -> dict:
        return {"prior": "log-uniform", "low": self.low, "high": self.high}


@dataclass(frozen=True)
class Normal(Prior):
    """Normal density with mean ``mu`` and standard deviation ``sd`` (unbounded)."""

    mu: float
    sd: float

    def __post_init__(self):
        if not (math.isfinite(self.mu) and math.isfinite(self.sd) and self.sd > 0):
            raise StructureError(f"normal prior needs finite mu and sd > 0, got {self.mu}, {self.sd}")

    @property
    def bounds(self) -> tuple[float, float]:
        return (-math.inf, math.inf)

    def log_prob(self, x) -> np.ndarray:
        z = (np.asarray(x, dtype=float) - self.mu) / self.sd
        return -0.5 * z * z - math.log(self.sd) - 0.5 * math.log(2 * math.pi)

    def ppf(self, u) -> np.ndarray:
        return self.mu + self.sd * special.ndtri(np.asarray(u, dtype=float))

    def to_dict(self) -> dict:
        return {"prior": "normal", "mu": self.mu, "sd": self.sd}


def _check_interval(low, high, what):
    if not (math.isfinite(low) and math.isfinite(high) and low < high):
        raise StructureError(f"{what} prior needs finite low < high, got low = {low}, high = {high}")
    if not math.isfinite(high - low) or not high - low > 0:
        raise StructureError(
            f"{what} prior needs a width high - low that is a finite double, got low = {low:g}, "
            f"high = {high:g}"
        )


PRIOR_TYPES = {"uniform": Uniform, "log-uniform": LogUniform, "normal": Normal}


def _short(value, limit: int = 60) -> str:
    """``repr(value)`` shortened for a one-line message."""
    text = repr(value)
    return text if len(text) <= limit else f"{text[:limit]}..."


def prior_from_dict(spec: dict, where: str) -> Prior:
    """Build a prior from a card table such as ``{prior = "uniform", low = 0, high = 1}``.

    Raises
    ------
    StructureError
        Naming ``where`` (card and parameter) for an unknown prior type or bad or missing
        arguments.
    """
    if not isinstance(spec, dict) or "prior" not in spec:
        raise StructureError(f"{where}: expected a table with a 'prior' key, got {_short(spec)}")
    kind = spec["prior"]
    cls = PRIOR_TYPES.get(kind) if isinstance(kind, str) else None
    if cls is None:
        raise StructureError(
            f"{where}: unknown prior {_short(kind)}; known priors are {', '.join(PRIOR_TYPES)}"
        )
    args = {k: v for k, v in spec.items() if k != "prior"}
    needed = [f for f in cls.__dataclass_fields__]
    missing = [f for f in needed if f not in args]
    extra = [k for k in args if k not in needed]
    if missing or extra:
        raise StructureError(
            f"{where}: a {kind} prior takes {', '.join(needed)}"
            + (f"; missing {', '.join(missing)}" if missing else "")
            + (f"; unknown {', '.join(_short(k) for k in extra)}" if extra else "")
        )
    bad = [k for k, v in args.items() if isinstance(v, bool) or not isinstance(v, numbers.Real)]
    if bad:
        raise StructureError(
            f"{where}: prior arguments must be numbers, got {bad[0]} = {_short(args[bad[0]])}"
        )
    values = {k: float(v) for k, v in args.items()}
    try:
        return cls(**values)
    except StructureError as exc:
        raise StructureError(f"{where}: {exc}") from None
