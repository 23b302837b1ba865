"""Multi-start nonlinear least squares of a structure on a frequency response (thesis §3.3).

The complex residual between data and structure is formed on the scaled data (ω/ω_ref,
G/g_ref), real and imaginary parts stacked once, and minimised with scipy's trust-region
reflective least squares from several starts drawn from the prior. Coefficients with
log-uniform priors are optimised in log space, so positivity holds by construction and the
prior bounds become box bounds. Optima outside the support of the posterior (unstable, not
dissipative, or violating a card inequality) are rejected; the best admissible optimum is
returned, and how many starts reached it is reported.

Commensurate structures have an exact passivity check, and their best optima often lie on the
boundary of the passive region (a coefficient that the noise would make slightly negative, a
dissipation that would turn negative decades outside the data). A local optimum that is not
admissible, with a cost below twice the best admissible one so far, is re-solved with penalty
residuals of growing weight (:func:`~bayesfo.structures.passivity.dissipation_shortfall`: the
wrong-signed end coefficients of the dissipation polynomial and its worst value at a critical
point, with a margin of 1e-8 into the passive region), first from its start, which leads to the
boundary point of the start's basin, then from the optimum. The repair gives admissible optima
where the plain fit has none, and keeps boundary modes among the optima (BENCHMARKS.md,
"Measurements behind design choices").
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from scipy import optimize

from ..data import FrequencyResponse
from ..errors import InputError
from ..priors import LogUniform
from ..structures import Scaling, Structure, passivity
from ..structures.response import commensurate_response, dissipation_grid
from .scan import fit_linear, q_grid_scan

#: The penalty weights (times the root of the optimum's cost) of :meth:`_Problem.repair`.
REPAIR_WEIGHTS = (1e1, 1e3, 1e5)
#: Evaluations per penalty weight, and the costs (relative to the best admissible one so far)
#: of the inadmissible optima that are repaired: worse ones are no mode worth keeping.
REPAIR_NFEV = 40
REPAIR_COST_RATIO = 2.0
REPAIR_MAX_FAILED = 3
#: How far inside the passive region the repaired optima lie (relative dissipation).
REPAIR_MARGIN = 1e-8

WEIGHTINGS = ("auto", "sigma", "relative", "parts", "none")


@dataclass(frozen=True, eq=False)
class FitResult:
    """The outcome of :func:`fit_structure`.

    Attributes
    ----------
    structure : str
        Structure name.
    param_names : tuple of str
    theta : ndarray
        Best admissible parameters in physical units (NaN if no start reached an admissible
        optimum; see ``admissible``).
    theta_scaled : ndarray
        The same parameters of the scaled problem.
    rmse : float
        (1/N)·sqrt(Σ|G_k − Ĝ_k|²) in physical units (thesis eq. (3.23)).
    chi2 : float
        Minimised weighted sum of squares (real and imaginary parts).
    weighting : str
        ``"sigma"`` (1/σ_k), ``"relative"`` (1/|G_k|) or ``"none"``.
    admissible : bool
        Whether the returned optimum satisfies every constraint of the structure.
    n_starts, n_admissible, n_at_best : int
        Starts run (fewer than offered when the search stopped early), starts that ended
        admissible, and admissible starts within 1e-6 (relative) of the best cost: a measure of
        how reliably the optimum is found.
    optima : ndarray, shape (k, n_params)
        Distinct admissible local optima (scaled), best first: the modes that seed the sampler.
    scaling : Scaling
        The units of the scaled problem (``theta_scaled``, ``optima``).
    linear : dict of str to ndarray
        The thesis' linear methods 1–5 at their best q (:func:`linear_fits`), in physical units,
        kept so that figures mark them without fitting again; empty unless ``fit_structure``
        ran with ``linear_methods=True`` (as ``compare`` runs it), and for structures not of
        the thesis form.
    """

    structure: str
    param_names: tuple[str, ...]
    theta: np.ndarray
    theta_scaled: np.ndarray
    rmse: float
    chi2: float
    weighting: str
    admissible: bool
    n_starts: int
    n_admissible: int
    n_at_best: int
    optima: np.ndarray = field(repr=False)
    scaling: Scaling = field(default_factory=Scaling, repr=False)
    linear: dict = field(default_factory=dict, repr=False)

    def to_dict(self) -> dict:
        return {
            "structure": self.structure,
            "parameters": dict(zip(self.param_names, map(float, self.theta))),
            "rmse": self.rmse,
            "chi2": self.chi2,
            "weighting": self.weighting,
            "admissible": self.admissible,
            "n_starts": self.n_starts,
            "n_admissible": self.n_admissible,
            "n_at_best": self.n_at_best,
            "linear_methods": {k: dict(zip(self.param_names, map(float, v)))
                               for k, v in self.linear.items()},
        }


def choose_weighting(data: FrequencyResponse, weighting: str = "auto") -> str:
    """Resolve ``"auto"``: 1/σ if the data carry σ, else relative (1/|G|) when |G| spans more
    than a decade, else unweighted."""
    if weighting not in WEIGHTINGS:
        raise InputError(f"argument 'weighting' must be one of {', '.join(WEIGHTINGS)}, got {weighting!r}")
    if weighting == "sigma" and data.sigma is None:
        raise InputError(f"weighting 'sigma' needs sigma in {data.where()}")
    if weighting != "auto":
        return weighting
    if data.sigma is not None:
        return "sigma"
    mag = data.magnitude
    return "relative" if mag.max() > 10 * mag.min() else "none"


class _Problem:
    """Scaled least-squares problem in optimiser coordinates u (log for log-uniform priors)."""

    def __init__(self, structure: Structure, data: FrequencyResponse, weighting: str,
                 scaling: Scaling | None = None):
        self.s = structure
        self.kind = data.kind
        self.scaling = Scaling.from_data(data) if scaling is None else scaling
        self.w = data.omega / self.scaling.omega_ref
        self.g = data.response / self.scaling.g_ref
        if weighting == "sigma":
            wt = self.scaling.g_ref / data.sigma
        elif weighting == "relative":
            wt = 1.0 / np.abs(self.g)
        else:
            wt = np.ones_like(self.w)
        # "parts": each part by itself (1/|Re g|, 1/|Im g|), the cost of relative_parts noise.
        self.wt_re, self.wt_im = ((1.0 / np.abs(self.g.real), 1.0 / np.abs(self.g.imag))
                                  if weighting == "parts" else (wt, wt))
        self.log = np.array([isinstance(p.prior, LogUniform) for p in structure.parameters])
        lo, hi = np.array([p.prior.bounds for p in structure.parameters], dtype=float).T
        self.lo = np.where(self.log, np.log(lo, where=self.log, out=np.ones_like(lo)), lo)
        self.hi = np.where(self.log, np.log(hi, where=self.log, out=np.ones_like(hi)), hi)
        self.grid = dissipation_grid(self.w.min(), self.w.max())

    def theta(self, u):
        return np.where(self.log, np.exp(u), u)

    def residuals_many(self, u):
        """Stacked weighted residuals for many points u, shape (n_sets, 2N)."""
        model = self.s.response(self.theta(u), self.w, self.kind)
        r = model - self.g
        return np.concatenate([r.real * self.wt_re, r.imag * self.wt_im], axis=-1)

    def fun(self, u):
        return _finite(self.residuals_many(u[None, :])[0])

    def jac(self, u, weight=None):
        # Forward differences evaluated as one vectorised batch of n+1 parameter sets.
        h = 1e-7 * np.maximum(1.0, np.abs(u))
        pts = np.vstack([u, u + np.diag(h)])
        r = _finite(self.residuals_many(pts) if weight is None else self.penalised_many(pts, weight))
        return ((r[1:] - r[0]) / h[:, None]).T

    # -------------------------------------------------------------- the passivity boundary
    @property
    def repairable(self) -> bool:
        """Commensurate with an exact passivity constraint: inadmissible optima are re-solved
        onto the boundary of the passive region (:meth:`repair`)."""
        return (self.s.commensurate_order is not None and "passive" in self.s.constraints
                and self.kind != "generic" and passivity.EXACT_COMMENSURATE)

    def shortfall(self, u):
        """The dissipation shortfall (:func:`~bayesfo.structures.passivity.dissipation_shortfall`)
        at points u, shape (n_sets, 3)."""
        den, num, q = self.s.polynomials(self.theta(u))
        return passivity.dissipation_shortfall(den, num, q, margin=REPAIR_MARGIN)

    def penalised_many(self, u, weight):
        return np.concatenate([self.residuals_many(u), weight * self.shortfall(u)], axis=1)

    def repair(self, x, cost, limit=np.inf):
        """Re-solve an optimum that is not passive with penalty residuals of growing weight
        until it is admissible: (x, cost, admissible). Gives up once the data's cost exceeds
        ``limit`` (the penalty only raises it)."""
        if not self.s.in_support(self.theta(x)):
            return x, cost, False
        base = np.sqrt(max(cost, 1e-12))
        for factor in REPAIR_WEIGHTS:
            w = base * factor
            res = optimize.least_squares(
                lambda u, w=w: _finite(self.penalised_many(u[None, :], w)[0]), x,
                jac=lambda u, w=w: self.jac(u, w), bounds=(self.lo, self.hi), method="trf",
                x_scale="jac", xtol=1e-10, ftol=1e-10, gtol=1e-10, max_nfev=REPAIR_NFEV,
            )
            x = res.x
            r = self.fun(x)
            new_cost = float(r @ r)
            if not new_cost <= limit:
                break
            if self.s.admissible(self.theta(x), self.kind, self.grid):
                return x, new_cost, True
        return x, cost, False


def fit_structure(
    structure: Structure,
    data: FrequencyResponse,
    *,
    n_starts: int = 24,
    rng: np.random.Generator | int | None = 0,
    weighting: str = "auto",
    starts=None,
    seed_methods: bool = False,
    linear_methods: bool = False,
    min_starts: int = 12,
    stop_after: int | None = 4,
    scaling: Scaling | None = None,
) -> FitResult:
    """Fit ``structure`` to ``data`` by multi-start bounded least squares.

    Parameters
    ----------
    structure : Structure
    data : FrequencyResponse
    n_starts : int
        Random starts: uniform over the central 90 % of each prior range in optimiser
        coordinates (log for log-uniform priors), except coefficients with uniform priors,
        which start at positive magnitudes 10^U(-1.5, 1.5) on the scaled data.
    rng : numpy.random.Generator or int or None
        Source of the random starts (reproducible for a given seed).
    weighting : {"auto", "sigma", "relative", "parts", "none"}
        Residual weights; see :func:`choose_weighting`.
    starts : array_like, shape (k, n_params), optional
        Extra starts in physical units.
    seed_methods : bool
        Also start from the linear methods 2 and 3 (thesis Table 3.1) on a coarse q grid, for
        structures of the thesis form B(λ)/A(λ) or A(λ)/B(λ) (see :func:`linear_seeds`).
    linear_methods : bool
        Keep the fits of the linear methods 1–5 at their best q in ``FitResult.linear``
        (:func:`linear_fits`, which figures mark; a small cost per structure: BENCHMARKS.md,
        "Measurements behind design choices").
    min_starts, stop_after : int
        Stop once at least ``min_starts`` starts have run and ``stop_after`` of them ended at
        the best admissible cost found so far (``stop_after=None`` runs every start). Given and
        seeded starts alternate with random ones, so an early stop still has both kinds.
    scaling : Scaling, optional
        Units of the scaled problem, in which the prior bounds hold (default
        ``Scaling.from_data(data)``).

    Returns
    -------
    FitResult

    Raises
    ------
    InputError
        If the data have fewer points than the structure has parameters, or an argument is bad.

    References
    ----------
    Thesis §3.3 (Problem 5) and §3.4.2.
    """
    structure.check_data(data)
    if n_starts < 1:
        raise InputError(f"argument 'n_starts' must be at least 1, got {n_starts}")
    rng = np.random.default_rng(rng)
    weighting = choose_weighting(data, weighting)
    prob = _Problem(structure, data, weighting, scaling)
    span = prob.hi - prob.lo
    finite = np.isfinite(span)
    u0 = np.where(finite, prob.lo, 0.0) + np.where(finite, span, 0.0) * (
        0.05 + 0.9 * rng.uniform(size=(n_starts, structure.n_params)))
    for i, p in enumerate(structure.parameters):
        if not finite[i]:  # unbounded (normal) prior: start from prior draws
            u0[:, i] = p.prior.sample(rng, n_starts)
    # Coefficients with a uniform prior: on the scaled data they are of order one, so start
    # them at magnitudes 10^U(-1.5, 1.5), positive (the physical sign of the material models),
    # inside the bounds, rather than spread over the whole, mostly unphysical, prior range.
    coef = np.array([p.role == "coefficient" for p in structure.parameters]) & ~prob.log & finite
    if coef.any():
        mags = 10.0 ** rng.uniform(-1.5, 1.5, size=(n_starts, int(coef.sum())))
        u0[:, coef] = np.clip(mags, prob.lo[coef] + 1e-9 * span[coef], prob.hi[coef] - 1e-9 * span[coef])
    if seed_methods:
        seeds = linear_seeds(structure, data)
        if seeds.size:
            starts = seeds if starts is None else np.vstack([np.atleast_2d(starts), seeds])
    if starts is not None:
        extra = structure.to_scaled(np.atleast_2d(np.asarray(starts, float)), prob.scaling)
        with np.errstate(divide="ignore", invalid="ignore"):
            extra_u = np.where(prob.log, np.log(np.abs(extra)), extra)
        margin = np.where(finite, 1e-9 * span, 0.0)
        extra_u = np.clip(extra_u, prob.lo + margin, prob.hi - margin)
        u0 = _interleave(extra_u[np.all(np.isfinite(extra_u), axis=1)], u0)

    sols, costs, oks = [], [], []
    best_cost, hits = np.inf, 0
    repair, repaired, failures = prob.repairable, [], [0, 0]
    for i, u in enumerate(u0):
        res = optimize.least_squares(
            prob.fun, u, jac=prob.jac, bounds=(prob.lo, prob.hi), method="trf",
            x_scale="jac", xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=400,
        )
        x, cost = res.x, 2 * res.cost
        ok_i = bool(np.isfinite(cost) and structure.admissible(prob.theta(x), data.kind, prob.grid))
        if not ok_i and repair and np.isfinite(cost) and cost < REPAIR_COST_RATIO * best_cost:
            # A good optimum that is not passive: its constrained counterpart lies on the
            # boundary of the passive region. Starts often end at the same optimum: repair once.
            # The penalised problem is solved from the start, which leads to the boundary
            # point of the start's basin, and if that fails from the optimum (which may pull
            # along a ridge of equivalent optima without a passive end). Starts that ended at
            # an optimum already repaired reuse its result; at most REPAIR_MAX_FAILED failed
            # attempts of each kind per fit.
            done = next((r for r in repaired if r.ok and _same(x, r.optimum)), None)
            for origin, start in enumerate((u, x)):  # 0: from the start, 1: from the optimum
                if done is not None or failures[origin] >= REPAIR_MAX_FAILED:
                    continue
                if origin == 1 and any(r.origin == 1 and _same(x, r.optimum) for r in repaired):
                    continue  # this optimum failed before
                attempt = _Repair(x, *prob.repair(start, cost, REPAIR_COST_RATIO * best_cost),
                                  origin)
                repaired.append(attempt)
                if attempt.ok:
                    done = attempt
                else:
                    failures[origin] += 1
            if done is not None:
                x, cost, ok_i = done.x, done.cost, True
        sols.append(x)
        costs.append(cost)
        oks.append(ok_i)
        if ok_i:
            if cost < best_cost * (1 - 1e-6) - 1e-12:
                best_cost, hits = cost, 1
            elif cost <= best_cost * (1 + 1e-6) + 1e-12:
                hits += 1
        if stop_after is not None and i + 1 >= min_starts and hits >= stop_after:
            break
    sols, costs, ok = np.array(sols), np.array(costs), np.array(oks)
    thetas = prob.theta(sols)
    n_adm = int(ok.sum())
    if n_adm:
        idx = np.flatnonzero(ok)[np.argsort(costs[ok])]
    else:
        idx = np.argsort(costs)
    best = idx[0]
    # Scaled residuals are of order one, so 1e-12 is an absolute floor below any noise.
    at_best = int(np.sum(ok & (costs <= costs[best] * (1 + 1e-6) + 1e-12)))
    optima = _distinct(thetas[idx] if n_adm else thetas[:0])
    theta_s = thetas[best]
    theta_p = structure.to_physical(theta_s, prob.scaling)
    model = structure.response(theta_p, data.omega, data.kind)
    rmse = float(np.sqrt(np.sum(np.abs(data.response - model) ** 2)) / data.n_frequencies)
    return FitResult(
        structure=structure.name,
        param_names=structure.param_names,
        theta=theta_p,
        theta_scaled=theta_s,
        rmse=rmse,
        chi2=float(costs[best]),
        weighting=weighting,
        admissible=bool(n_adm),
        n_starts=len(sols),
        n_admissible=n_adm,
        n_at_best=at_best,
        optima=optima,
        scaling=prob.scaling,
        linear=linear_fits(structure, data) if linear_methods else {},
    )


def _finite(r: np.ndarray) -> np.ndarray:
    return np.where(np.isfinite(r), r, 1e10)


class _Repair(NamedTuple):
    """One attempt of :meth:`_Problem.repair`: the optimum it started from, its result (x,
    the data's cost, whether admissible) and where the penalised solve began (0: the start,
    1: the optimum)."""

    optimum: np.ndarray
    x: np.ndarray
    cost: float
    ok: bool
    origin: int


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    """Two optima that are the same point (starts often end at one optimum)."""
    return bool(np.allclose(a, b, rtol=1e-4, atol=1e-8))


def _interleave(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Rows of ``first`` and ``second`` alternately, the rest of the longer one at the end."""
    out = []
    for i in range(max(len(first), len(second))):
        if i < len(first):
            out.append(first[i])
        if i < len(second):
            out.append(second[i])
    return np.array(out).reshape(-1, second.shape[1])


def _distinct(thetas: np.ndarray, rtol: float = 1e-3) -> np.ndarray:
    """Keep the first of parameter vectors that agree within ``rtol`` (relative)."""
    kept: list[np.ndarray] = []
    for t in thetas:
        if not any(np.allclose(t, k, rtol=rtol, atol=1e-8) for k in kept):
            kept.append(t)
    return np.array(kept).reshape(-1, thetas.shape[1] if thetas.ndim == 2 else 0)


SEED_Q_GRID = np.round(np.arange(0.1, 1.01, 0.1), 2)


def thesis_degrees(structure: Structure) -> tuple[int, int] | None:
    """(n, m) if ``structure`` is B(λ)/A(λ) (or A/B when inverted) with A = 1 + a_1 λ + … +
    a_n λ^n and B = b_0 + … + b_m λ^m in the thesis' parameter names, else None."""
    if structure.commensurate_order != "q":
        return None
    names = set(structure.param_names) | set(structure.fixed)
    n = sum(1 for k in range(1, 20) if f"a{k}" in names)
    m = sum(1 for k in range(20) if f"b{k}" in names) - 1
    expected = {f"a{k}" for k in range(1, n + 1)} | {f"b{k}" for k in range(m + 1)} | {"q"}
    if m < 0 or names != expected:
        return None
    rng = np.random.default_rng(0)
    theta = rng.uniform(0.5, 1.5, structure.n_params)
    vals, _ = structure.values(theta)
    a = np.r_[1.0, [vals[f"a{k}"][0] for k in range(1, n + 1)]]
    b = np.array([vals[f"b{k}"][0] for k in range(m + 1)])
    w = np.array([0.3, 1.0, 3.0])
    g = commensurate_response(w, a, b, vals["q"][0])
    g = 1.0 / g if structure.inverted else g
    return (n, m) if np.allclose(structure.transfer(theta, w), g, rtol=1e-10) else None


def linear_seeds(structure: Structure, data: FrequencyResponse, q_values=None,
                 methods=(2, 3)) -> np.ndarray:
    """Parameter vectors (physical units) from the linear methods, as starts for optimisers.

    Returns an empty array for structures that are not of the thesis form (e.g. the
    generalised Maxwell model) or when a method cannot be applied.
    """
    degrees = thesis_degrees(structure)
    if degrees is None:
        return np.empty((0, structure.n_params))
    n, m = degrees
    if "q" in structure.fixed:
        q_values = [float(structure.fixed["q"])]
    q_values = SEED_Q_GRID if q_values is None else q_values
    seeds = []
    for method in methods:
        if n == 0 and method != 1:
            continue
        try:
            fits = fit_linear(data, n, m, method, q_values, inverted=structure.inverted)
        except InputError:
            continue
        for f in fits:
            vals = {f"a{k}": f.a[k] for k in range(1, n + 1)}
            vals.update({f"b{k}": f.b[k] for k in range(m + 1)})
            vals["q"] = f.q
            theta = np.array([vals[name] for name in structure.param_names])
            if np.all(np.isfinite(theta)):
                seeds.append(theta)
    return np.array(seeds).reshape(-1, structure.n_params)


def linear_fits(structure: Structure, data: FrequencyResponse) -> dict[str, np.ndarray]:
    """The thesis' linear methods 1–5 on ``data``, each at its best stable q of the q grid
    (thesis §4.3.2; q fixed for structures that fix it), as parameter vectors of ``structure``
    in physical units: ``{"method 1": theta, ...}``. Methods without a stable fit are left
    out; empty for structures that are not of the thesis form (e.g. the generalised Maxwell).
    """
    degrees = thesis_degrees(structure)
    if degrees is None:
        return {}
    n, m = degrees
    out = {}
    for method in (1, 2, 3, 4, 5):
        if n == 0 and method != 1:
            continue
        try:
            if "q" in structure.fixed:
                fits = fit_linear(data, n, m, method, [float(structure.fixed["q"])],
                                  inverted=structure.inverted)
                best = fits[0] if fits and fits[0].stable else None
            else:
                best = q_grid_scan(data, n, m, method, inverted=structure.inverted).best
        except InputError:
            continue
        if best is None:
            continue
        vals = {f"a{k}": best.a[k] for k in range(1, n + 1)}
        vals.update({f"b{k}": best.b[k] for k in range(m + 1)})
        vals["q"] = best.q
        theta = np.array([vals[name] for name in structure.param_names], dtype=float)
        if np.all(np.isfinite(theta)):
            out[f"method {method}"] = theta
    return out
