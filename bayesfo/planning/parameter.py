"""Where to measure next to determine one parameter: :func:`design_parameter` (see
:mod:`bayesfo.planning.choice` for the predictive and the window)."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..errors import DataWarning, InputError
from ..tts.result import MasterCurve
from .choice import (
    N_CANDIDATES,
    N_DRAWS,
    _checked,
    _draws_at,
    _relative_sigma,
    capped_window,
    seconds,
)

__all__ = ["ParameterDesign", "design_parameter"]


@dataclass(frozen=True)
class ParameterDesign:
    """The proposed measurements for one parameter (:func:`design_parameter`).

    Attributes
    ----------
    structure, parameter : str
    omega : ndarray
        The candidate frequencies [rad/s].
    information : ndarray
        Expected information about the parameter of one measurement at each candidate [nats].
    proposed : tuple of dict
        The chosen points in the order chosen: ``omega``, ``information`` (of the set so far),
        ``gain``, ``seconds``, ``sd_after`` (the parameter's expected posterior sd after the set).
    sd_now : float
        The parameter's posterior sd now.
    window : tuple of float
    cost : str
    """

    structure: str
    parameter: str
    omega: np.ndarray = field(repr=False)
    information: np.ndarray = field(repr=False)
    proposed: tuple
    sd_now: float
    window: tuple[float, float]
    cost: str

    def to_dict(self) -> dict:
        return {"structure": self.structure, "parameter": self.parameter,
                "window": list(self.window), "cost": self.cost, "sd_now": self.sd_now,
                "proposed": [dict(p) for p in self.proposed],
                "candidates": {"omega": self.omega.tolist(),
                               "information": self.information.tolist()}}


def design_parameter(result, parameter: str, *, structure: str | None = None, window=None,
                     points: int = 3, cost: str = "uniform", seed: int = 0) -> ParameterDesign:
    """The frequencies whose measurement would best determine one parameter of one structure
    (e.g. the order α of the leading structure).

    The parameter's posterior draws and the structure's predictive of a set of measurements
    (as for :func:`design`, in ln|G| and arg G with the noise) are taken as jointly normal; the
    expected information about the parameter is then −½ ln(1 − cᵀC⁻¹c/σ²), with C the
    predictive covariance of the set, c its covariance with the parameter and σ² the parameter's
    variance, and the parameter's expected posterior variance after the set σ² − cᵀC⁻¹c.

    Parameters
    ----------
    result : Comparison
    parameter : str
        A parameter of the structure as sampled (``alpha``, ``q``, ``c_beta``, ...).
    structure : str, optional
        Default: the best ranked.
    window : (float, float), optional
        As for :func:`design`.
    points : int
        As for :func:`design`.
    cost : {"uniform", "low-frequency"}
        As for :func:`design`.
    seed : int
        Seed of the choice of draws.

    Returns
    -------
    ParameterDesign

    Raises
    ------
    InputError
        An unknown structure or parameter, or a bad window, count or cost.
    """
    w_lo, w_hi = _checked(result.data, window, points, cost)
    w_lo, w_hi, cut = capped_window(result.data, w_lo, w_hi)
    if cut is not None:
        warnings.warn(cut, DataWarning, stacklevel=2)
    name = structure or (result.ranking[0] if result.ranking else None)
    if name not in result.ranking:
        raise InputError(f"design: no structure '{name}' with a posterior in the comparison; it "
                         f"has {', '.join(result.ranking)}")
    r = result[name]
    post = r.posterior
    if parameter not in post.param_names[: r.structure.n_params]:
        raise InputError(f"design: structure {name} has no parameter '{parameter}'; its "
                         f"parameters are {', '.join(post.param_names[: r.structure.n_params])}")
    if isinstance(result, MasterCurve):
        raise InputError("design: a master curve is not a comparison of structures; design "
                         "on a comparison (e.g. of the master curve's master_data())")
    data = result.data
    omega = np.logspace(math.log10(w_lo), math.log10(w_hi), N_CANDIDATES)
    rng = np.random.default_rng(seed)
    draws, z, noise = _draws_at(r, omega, data.kind, _relative_sigma(data), rng,
                                n_draws=4 * N_DRAWS)
    theta = draws[:, post.param_names.index(parameter)]
    var = float(np.var(theta, ddof=1))
    time = seconds(omega)

    def explained(sets):
        """cᵀC⁻¹c of every candidate set (n_sets, k)."""
        n_sets, m = sets.shape
        zz = z[:, sets, :].reshape(len(theta), n_sets, 2 * m)
        dev = zz - zz.mean(axis=0)
        cov = np.einsum("snd,sne->nde", dev, dev) / (len(theta) - 1)
        idx = np.arange(2 * m)
        cov[:, idx, idx] += noise[sets, :].reshape(n_sets, 2 * m)
        c = np.einsum("snd,s->nd", dev, theta - theta.mean()) / (len(theta) - 1)
        return np.einsum("nd,nd->n", c, np.linalg.solve(cov, c[..., None])[..., 0])

    def info(sets):
        frac = np.clip(explained(sets) / var, 0.0, 1.0 - 1e-12) if var > 0 else 0.0
        return -0.5 * np.log1p(-frac)

    cand = np.arange(omega.size)
    single = info(cand[:, None])
    chosen, proposed, so_far = [], [], 0.0
    for _ in range(points):
        sets = np.array([chosen + [j] for j in cand])
        total = info(sets)
        gains = total - so_far
        score = gains / time if cost == "low-frequency" else gains
        score[chosen] = -np.inf
        j = int(np.argmax(score))
        best = max(float(total[j]), so_far)
        chosen.append(j)
        sd_after = math.sqrt(max(var - float(explained(np.array([chosen]))[0]), 0.0))
        proposed.append({"omega": float(omega[j]), "information": best, "gain": best - so_far,
                         "seconds": float(time[j]), "sd_after": sd_after})
        so_far = best
    return ParameterDesign(structure=name, parameter=parameter, omega=omega, information=single,
                           proposed=tuple(proposed), sd_now=math.sqrt(var),
                           window=(w_lo, w_hi), cost=cost)
