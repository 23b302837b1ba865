"""A free parameter of a structure-like model, and what every such model derives from its
parameters: names, count, and whether a parameter set lies in the priors' support."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..priors import Prior


@dataclass(frozen=True)
class Parameter:
    """A free parameter: its name, its role (``coefficient`` or ``exponent``) and its prior."""

    name: str
    role: str
    prior: Prior


def in_prior_support(parameters, theta) -> np.ndarray:
    """True where every column of ``theta`` (one per :class:`Parameter`) lies within the
    support of that parameter's prior; a bool per row, or one bool for a single set."""
    theta2 = np.atleast_2d(np.asarray(theta, float))
    ok = np.ones(theta2.shape[0], dtype=bool)
    for i, p in enumerate(parameters):
        ok &= p.prior.contains(theta2[:, i])
    return ok if np.ndim(theta) == 2 else ok[0]


class Parametrised:
    """What a model with a ``parameters`` tuple of :class:`Parameter` derives from it (cards,
    the master curve's shifted structure, the relaxation spectrum)."""

    @property
    def param_names(self) -> tuple[str, ...]:
        """Names of the free parameters, in the column order of ``theta``."""
        return tuple(p.name for p in self.parameters)

    @property
    def n_params(self) -> int:
        """Number of free parameters (without noise parameters)."""
        return len(self.parameters)

    def in_support(self, theta) -> np.ndarray:
        """True where every free parameter lies within the support of its prior."""
        return in_prior_support(self.parameters, theta)
