"""Where to measure next to determine one parameter, or all of a structure's together:
:func:`design_parameter` (see :mod:`bayesfo.planning.choice` for the predictive and the
window)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
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
        ``parameter`` is ``"all"`` where the plan is for every parameter of the structure
        together (``parameter=None``).
    omega : ndarray
        The candidate frequencies [rad/s].
    information : ndarray
        Expected information about the parameter of one measurement at each candidate [nats].
    proposed : tuple of dict
        The chosen points in the order chosen: ``omega``, ``information`` (of the set so far),
        ``gain``, ``seconds``, ``sd_after`` (the parameter's expected posterior sd after the set;
        for ``"all"``, ``{name: sd}``).
    sd_now : float or dict
        The parameter's posterior sd now (for ``"all"``, ``{name: sd}``).
    window : tuple of float
    cost : str
    notes : tuple of str
    """

    structure: str
    parameter: str
    omega: np.ndarray = field(repr=False)
    information: np.ndarray = field(repr=False)
    proposed: tuple
    sd_now: float | dict
    window: tuple[float, float]
    cost: str
    notes: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        return {"structure": self.structure, "parameter": self.parameter,
                "window": list(self.window), "cost": self.cost,
                "sd_now": dict(self.sd_now) if isinstance(self.sd_now, dict) else self.sd_now,
                "proposed": [dict(p) for p in self.proposed],
                "candidates": {"omega": self.omega.tolist(),
                               "information": self.information.tolist()},
                "notes": list(self.notes)}


def design_parameter(result, parameter: str | None, *, structure: str | None = None,
                     window=None, points: int = 3, cost: str = "uniform", seed: int = 0,
                     notes=()) -> ParameterDesign:
    """The frequencies whose measurement would best determine one parameter of one structure
    (e.g. the order α of the leading structure), or all its parameters together.

    The parameter's posterior draws and the structure's predictive of a set of measurements
    (as for :func:`design`, in ln|G| and arg G with the noise) are taken as jointly normal; the
    expected information about the parameter is then −½ ln(1 − cᵀC⁻¹c/σ²), with C the
    predictive covariance of the set, c its covariance with the parameter and σ² the parameter's
    variance, and the parameter's expected posterior variance after the set σ² − cᵀC⁻¹c. For
    all parameters together (``parameter=None``) the information is about the parameter vector,
    −½ ln det(I − Σ⁻¹ Cᵀ_{yθ} C⁻¹ C_{yθ}) with Σ their covariance: it narrows the joint
    posterior most, in units free of each parameter's scale.

    Parameters
    ----------
    result : Comparison
    parameter : str or None
        A parameter of the structure as sampled (``alpha``, ``q``, ``c_beta``, ...); None for
        all of them (not the noise scale).
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
    notes : sequence of str
        Carried into the result (why this plan was made).

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
    if cut is not None:  # a note of the plan, as the model choice's design has it
        notes = (*notes, cut)
    name = structure or (result.ranking[0] if result.ranking else None)
    if name not in result.ranking or result[name].posterior is None:
        raise InputError(f"design: no structure '{name}' with a posterior in the comparison; it "
                         f"has {', '.join(result.ranking)}")
    r = result[name]
    post = r.posterior
    own = list(post.param_names[: r.structure.n_params])
    if parameter is not None and parameter not in own:
        raise InputError(f"design: structure {name} has no parameter '{parameter}'; its "
                         f"parameters are {', '.join(own)}")
    if isinstance(result, MasterCurve):
        raise InputError("design: a master curve is not a comparison of structures; design "
                         "on a comparison (e.g. of the master curve's master_data())")
    names = own if parameter is None else [parameter]
    data = result.data
    omega = np.logspace(math.log10(w_lo), math.log10(w_hi), N_CANDIDATES)
    rng = np.random.default_rng(seed)
    draws, z, noise = _draws_at(r, omega, data.kind, _relative_sigma(data), rng,
                                n_draws=4 * N_DRAWS)
    theta = draws[:, [post.param_names.index(p) for p in names]]
    sd = theta.std(axis=0, ddof=1)
    # Standardised, so that the information is free of each parameter's scale; a parameter
    # the draws do not move (fixed by a constraint) carries none.
    moving = sd > 0
    u = (theta[:, moving] - theta[:, moving].mean(axis=0)) / sd[moving]
    time = seconds(omega)

    def explained(sets):
        """Cᵀ_{yθ} C⁻¹ C_{yθ} of every candidate set (n_sets, k, k), θ standardised."""
        n_sets, m = sets.shape
        zz = z[:, sets, :].reshape(len(theta), n_sets, 2 * m)
        dev = zz - zz.mean(axis=0)
        cov = np.einsum("snd,sne->nde", dev, dev) / (len(theta) - 1)
        idx = np.arange(2 * m)
        cov[:, idx, idx] += noise[sets, :].reshape(n_sets, 2 * m)
        c = np.einsum("snd,sk->ndk", dev, u) / (len(theta) - 1)
        return np.einsum("ndk,ndl->nkl", c, np.linalg.solve(cov, c))

    def info(sets):
        e = explained(sets)
        if e.shape[1] == 0:
            return np.zeros(len(sets))
        corr = np.corrcoef(u, rowvar=False).reshape(e.shape[1], e.shape[1])
        # −½ ln det(I − R⁻¹E), R the correlation of the draws: by the determinant of R − E
        sign, logdet = np.linalg.slogdet(corr[None] - e)
        _, logdet0 = np.linalg.slogdet(corr)
        out = -0.5 * (logdet - logdet0)
        return np.where(sign > 0, np.maximum(out, 0.0), np.inf)

    def sd_after(sets):
        left = np.ones(len(names))
        left[moving] = np.clip(np.diag(np.corrcoef(u, rowvar=False).reshape(
            int(moving.sum()), int(moving.sum()))) - np.diag(explained(sets)[0]), 0.0, None)
        return np.sqrt(left) * sd

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
        after = sd_after(np.array([chosen]))
        proposed.append({"omega": float(omega[j]), "information": best, "gain": best - so_far,
                         "seconds": float(time[j]),
                         "sd_after": (float(after[0]) if parameter is not None
                                      else dict(zip(names, map(float, after), strict=True)))})
        so_far = best
    return ParameterDesign(structure=name, parameter=parameter or "all", omega=omega,
                           information=single, proposed=tuple(proposed),
                           sd_now=(float(sd[0]) if parameter is not None
                                   else dict(zip(names, map(float, sd), strict=True))),
                           window=(w_lo, w_hi), cost=cost, notes=tuple(notes))
