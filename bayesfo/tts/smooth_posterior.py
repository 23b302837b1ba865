"""The posterior of the model-free master's parameters (:class:`~bayesfo.tts.smooth.SmoothMaster`):
its maximum (L-BFGS in units of the curvature, then Newton steps), importance sampling from a
multivariate t there, certified by Pareto k̂ and ESS as :mod:`bayesfo.inference.importance`
certifies its weights, and emcee where the weights never certify."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .laws import arrhenius, wlf
from .model import KELVIN
from .smooth import SmoothMaster

#: Importance draws per round, and the certificate of the weights (the thresholds of
#: :mod:`bayesfo.inference.importance`: k̂ < 0.7 for the posterior, < 0.5 for ln Z).
DRAWS = 4000
K_HAT_MAX = 0.7
K_HAT_EVIDENCE = 0.5
ESS_MIN = 1000
#: Steps of the emcee fallback (walkers: twice the parameters, plus two).
EMCEE_STEPS = 1500
#: Most draws of one proposal.
MAX_DRAWS = 16000
#: Degrees of freedom of the multivariate-t proposal (tails heavier than the Laplace normal).
DF = 5
#: Adapted rounds (proposal moments from the weighted draws) before emcee takes over.
ROUNDS = 3
#: A shift whose 94 % interval is wider than this [decades] is not determined by the data:
#: an isotherm over a featureless plateau, whose shift slides along it.
UNDETERMINED = 1.0


@dataclass(frozen=True)
class ShiftPosterior:
    """The posterior of a :class:`SmoothMaster`'s parameters.

    Attributes
    ----------
    model : SmoothMaster
    draws : ndarray, shape (n_draws, n_params)
        Equally weighted posterior draws, natural units.
    log_evidence, log_evidence_err : float
        ln Z of the model (the data's logs) and its Monte Carlo error (NaN where no route
        gave one).
    map_theta : ndarray
        The maximum of the likelihood found (natural units).
    max_log_likelihood : float
    sampler : str
        ``"importance"`` (weights certified: Pareto k̂ < 0.7, ESS ≥ 1000) or ``"emcee"``.
    k_hat, ess : float
        Of the last importance round (k̂ NaN after emcee); ESS of the draws.
    converged : bool
        The draws are certified.
    messages : tuple of str
    """

    model: SmoothMaster
    draws: np.ndarray
    log_evidence: float
    log_evidence_err: float
    map_theta: np.ndarray
    max_log_likelihood: float
    sampler: str
    k_hat: float
    ess: float
    converged: bool
    messages: tuple[str, ...] = ()

    @property
    def shift_draws(self) -> np.ndarray:
        return self.model.log_shifts(self.draws)

    @property
    def vertical_draws(self) -> np.ndarray | None:
        return None if self.model.vertical == "none" else self.model.log_vertical(self.draws)

    def undetermined(self) -> list[int]:
        """The isotherms whose log10 a_T the data do not fix (94 % interval wider than
        :data:`UNDETERMINED` decades)."""
        from ..inference import hdi_columns

        lo, hi = hdi_columns(self.shift_draws, 0.94)
        return [i for i in range(lo.size) if i != self.model.reference
                and not (hi[i] - lo[i] <= UNDETERMINED)]


def start_of(model: SmoothMaster, log_shifts) -> np.ndarray:
    """A start (natural units, inside the prior) from seed shifts of every isotherm: the
    free shifts, or the law fitted to them; vertical shifts 0; smoothness 0.05, noise 0.05."""
    from scipy.optimize import least_squares

    temps = np.asarray(model.temperatures, float)
    t_ref = temps[model.reference]
    b = np.array([p.bounds for _, p in model.parameters], float)
    seeds = np.asarray(log_shifts, float)
    if model.law == "wlf":
        c2 = min(max(51.6, b[1, 0] + 10.0), b[1, 1])
        sol = least_squares(lambda q: wlf(temps, t_ref, q[0], q[1]) - seeds, [10.0, c2],
                            bounds=(b[:2, 0] + 1e-9, b[:2, 1] - 1e-9))
        horizontal = list(sol.x)
    elif model.law == "arrhenius":
        basis = arrhenius(temps, t_ref, 1.0)
        horizontal = [float(basis @ seeds / (basis @ basis))]
    else:
        # Ordered as the prior asks: each colder isotherm at least 0.01 decade above its
        # warmer neighbour (an overlay of featureless isotherms may give any order).
        ordered = seeds.copy()
        for i in range(model.reference - 1, -1, -1):
            ordered[i] = max(ordered[i], ordered[i + 1] + 0.01)
        for i in range(model.reference + 1, ordered.size):
            ordered[i] = min(ordered[i], ordered[i - 1] - 0.01)
        horizontal = list(np.delete(ordered, model.reference))
    # Free vertical shifts start at the density correction, which they contain.
    density = np.log10((temps[model.reference] + KELVIN) / (temps + KELVIN))
    vertical = list(np.delete(density, model.reference)) if model.vertical == "free" else []
    theta = np.array(horizontal + vertical + [0.05, 0.05, 0.05, 0.05])
    span = b[:, 1] - b[:, 0]
    return np.clip(theta, b[:, 0] + 1e-6 * span, b[:, 1] - 1e-6 * span)


def _optimum(model: SmoothMaster, u0: np.ndarray, free=None, hess=None) -> np.ndarray:
    """The maximum of the log-likelihood in the sampling coordinates (L-BFGS-B within the
    prior box, with the closed-form gradient), over the parameters ``free`` (a mask; default
    all), the others held at ``u0``. Each parameter is measured in units of its curvature at
    ``u0`` (shifts are fixed to thousandths of a decade, the hyperparameters to a tenth of
    their log): L-BFGS then takes tens of steps where it took thousands."""
    from scipy.optimize import minimize

    free = np.ones(u0.size, bool) if free is None else free
    scale = np.ones(u0.size)
    if int(free.sum()) > 4:
        curvature = -np.diag(_hessian(model, u0) if hess is None else hess)
        ok = np.isfinite(curvature) & (curvature > 0)
        scale[ok] = 1.0 / np.sqrt(curvature[ok])
    scale = scale[free]

    def f_and_g(z):
        u = u0.copy()
        u[free] = z * scale
        value, grad = model.gradient(model.to_params(u))
        if not math.isfinite(value):
            return 1e300, np.zeros(z.size)
        return -value, -grad[free] * scale

    sol = minimize(f_and_g, u0[free] / scale, jac=True, method="L-BFGS-B",
                   bounds=model.bounds[free] / scale[:, None],
                   options={"maxiter": 2000, "ftol": 1e-10, "gtol": 1e-3})
    out = u0.copy()
    out[free] = sol.x * scale
    return out


def _newton(model: SmoothMaster, u: np.ndarray, steps: int = 4):
    """Newton steps from ``u`` (Hessian by differences of the gradient, halved steps until
    the likelihood rises, the prior box kept): where horizontal and vertical shifts trade off
    against each other, L-BFGS stops short of the maximum. Returns the point, its
    log-likelihood and the Hessian there."""
    bounds = model.bounds
    value = float(model.log_likelihood(model.to_params(u))[0])
    hess = _hessian(model, u)
    for _ in range(steps):
        _, grad = model.gradient(model.to_params(u))
        w, v = np.linalg.eigh(-hess)
        if w.min() <= 0:
            break
        step = v @ ((v.T @ grad) / w)
        for _half in range(12):
            trial = np.clip(u + step, bounds[:, 0], bounds[:, 1])
            new = float(model.log_likelihood(model.to_params(trial))[0])
            if new > value:
                break
            step = step / 2
        else:
            break
        gain = new - value
        u, value = trial, new
        if gain < 1e-3:  # the Hessian barely moved: the one in hand serves the proposal
            break
        hess = _hessian(model, u)
    return u, value, hess


def _hessian(model: SmoothMaster, u: np.ndarray, h: float = 1e-4) -> np.ndarray:
    """The Hessian of the log-likelihood at ``u`` (sampling coordinates) by central
    differences of the closed-form gradient."""
    def grad(x):
        value, g = model.gradient(model.to_params(x))
        return g if math.isfinite(value) else np.full(x.size, np.nan)

    d = u.size
    out = np.zeros((d, d))
    for i in range(d):
        e = np.zeros(d)
        e[i] = h
        out[i] = (grad(u + e) - grad(u - e)) / (2 * h)
    out = 0.5 * (out + out.T)
    return np.where(np.isfinite(out), out, 0.0)


def _proposal_cov(hess: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """The Laplace covariance −H⁻¹ made positive definite (directions the likelihood leaves
    flat get a variance of the prior box's width squared / 12)."""
    w, v = np.linalg.eigh(-0.5 * (hess + hess.T))
    widths = np.diff(bounds, axis=1).ravel()
    floor = 12.0 / float(np.max(widths)) ** 2
    w = np.maximum(w, floor)
    return _well_conditioned((v / w) @ v.T)


def _well_conditioned(cov: np.ndarray) -> np.ndarray:
    """``cov`` symmetric, its eigenvalues at least 1e-8 of the largest (a proposal's shape
    that the multivariate t accepts)."""
    w, v = np.linalg.eigh(0.5 * (cov + cov.T))
    w = np.maximum(w, 1e-8 * max(float(w.max()), 1e-300))
    out = (v * w) @ v.T
    return 0.5 * (out + out.T)


def best_fit(model: SmoothMaster, start: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
    """The maximum of the likelihood from ``start`` (natural units): its point in the sampling
    coordinates, its log-likelihood (an upper bound of ln Z under the normalised prior) and
    the Hessian there."""
    u0 = model.to_u(start)
    hyper = np.zeros(u0.size, bool)
    hyper[-4:] = True  # smoothness and noise first, the shifts held at the start
    u1 = _optimum(model, u0, hyper)
    return _newton(model, _optimum(model, u1))


def sample_shifts(model: SmoothMaster, start: np.ndarray, seed: int = 0,
                  fit: tuple | None = None) -> ShiftPosterior:
    """The posterior of the model's parameters by importance sampling from a multivariate t
    at the likelihood's maximum (Laplace covariance), adapted to the weighted draws up to
    :data:`ROUNDS` times; emcee where the weights never certify.

    Parameters
    ----------
    model : SmoothMaster
    start : ndarray
        A start for the optimisation (natural units; :func:`start_of`).
    seed : int
    fit : tuple, optional
        :func:`best_fit` of the model, where it was already found.

    Returns
    -------
    ShiftPosterior
    """
    from scipy.special import logsumexp
    from scipy.stats import multivariate_t

    from ..inference import psis

    rng = np.random.default_rng(seed)
    bounds = model.bounds
    u_map, max_ll, hess = best_fit(model, start) if fit is None else fit
    mean, cov = u_map, _proposal_cov(hess, bounds)
    log_prior = -model.log_prior_volume
    messages = []
    best = None
    for _ in range(ROUNDS):
        prop = multivariate_t(loc=mean, shape=cov, df=DF, seed=rng)
        u = np.empty((0, mean.size))
        log_w = np.empty(0)
        # Draws from one proposal until the weights' ESS reaches ESS_MIN (at most
        # MAX_DRAWS), where their tail (k̂) certifies them.
        while u.shape[0] < MAX_DRAWS:
            more = np.atleast_2d(prop.rvs(size=DRAWS))
            inside = np.all((more > bounds[:, 0]) & (more < bounds[:, 1]), axis=1)
            ll = np.full(DRAWS, -np.inf)
            ll[inside] = model.log_likelihood(model.to_params(more[inside]))
            u = np.vstack([u, more])
            log_w = np.r_[log_w, ll + log_prior - prop.logpdf(more)]
            finite = np.isfinite(log_w)
            if finite.sum() < 0.1 * u.shape[0]:
                break
            smoothed, k_hat = psis(log_w[finite])
            w = np.exp(smoothed - logsumexp(smoothed))
            ess = float(1.0 / np.sum(w ** 2))
            if k_hat >= K_HAT_MAX or ess >= ESS_MIN:
                break
        if finite.sum() < 0.1 * u.shape[0]:
            break
        n = u.shape[0]
        raw = np.where(finite, log_w, -np.inf)
        log_z = float(logsumexp(raw) - math.log(n))
        rel = np.exp(raw - logsumexp(raw))
        log_z_err = float(math.sqrt(max(n * np.sum(rel ** 2) - 1.0, 0.0) / n))
        best = (u[finite], w, k_hat, ess, log_z, log_z_err)
        if k_hat < K_HAT_MAX and ess >= ESS_MIN:
            break
        # Adapt: the proposal's moments from the weighted draws, widened a little.
        x = u[finite]
        mean = w @ x
        cov = _well_conditioned(1.2 * np.cov(x, rowvar=False, aweights=w))
    if best is not None and best[2] < K_HAT_MAX and best[3] >= ESS_MIN:
        x, w, k_hat, ess, log_z, log_z_err = best
        pick = rng.choice(x.shape[0], size=DRAWS // 2, replace=True, p=w)
        draws = model.to_params(x[pick])
        evidence_ok = k_hat < K_HAT_EVIDENCE
        return ShiftPosterior(model, draws, log_z if evidence_ok else math.nan,
                              log_z_err if evidence_ok else math.nan, model.to_params(u_map),
                              max_ll, "importance", k_hat, ess, True,
                              () if evidence_ok else (
                                  f"importance weights certify the posterior but not ln Z "
                                  f"(Pareto k {k_hat:.2f})",))
    messages.append("the importance weights did not certify the posterior (Pareto k "
                    f"{'n/a' if best is None else f'{best[2]:.2f}'}); emcee drew it")
    return _emcee(model, u_map, cov, max_ll, seed, tuple(messages),
                  None if best is None or best[2] >= K_HAT_EVIDENCE else best[4:6])


def _emcee(model: SmoothMaster, u_map, cov, max_ll: float, seed: int, messages: tuple,
           evidence) -> ShiftPosterior:
    """The posterior by emcee (vectorised), walkers started around the maximum."""
    import emcee

    from ..inference import ess_min, rhat_max

    rng = np.random.default_rng(seed)
    bounds = model.bounds
    d = u_map.size
    n_walkers = 2 * d + 2

    def log_prob(u):
        u = np.atleast_2d(u)
        inside = np.all((u > bounds[:, 0]) & (u < bounds[:, 1]), axis=1)
        out = np.full(u.shape[0], -np.inf)
        if inside.any():
            out[inside] = model.log_likelihood(model.to_params(u[inside]))
        return out

    span = bounds[:, 1] - bounds[:, 0]
    p0 = rng.multivariate_normal(u_map, 0.1 * cov, size=n_walkers)
    p0 = np.clip(p0, bounds[:, 0] + 1e-6 * span, bounds[:, 1] - 1e-6 * span)
    p0 += 1e-8 * span * rng.standard_normal(p0.shape)  # no two walkers alike
    sampler = emcee.EnsembleSampler(n_walkers, d, log_prob, vectorize=True,
                                    moves=[(emcee.moves.DEMove(), 0.8),
                                           (emcee.moves.StretchMove(), 0.2)])
    sampler.random_state = np.random.RandomState(int(rng.integers(2**31))).get_state()
    steps = EMCEE_STEPS
    sampler.run_mcmc(p0, steps, progress=False)
    chain = sampler.get_chain(discard=steps // 2, thin=5)  # (steps, walkers, d)
    chains = np.swapaxes(chain, 0, 1)
    rhat = rhat_max(chains)
    ess = ess_min(chains)
    ok = rhat < 1.01 and ess >= 400
    msgs = messages + (() if ok else (f"emcee did not converge (R-hat {rhat:.3f}, ESS "
                                      f"{ess:.0f})",))
    log_z, log_z_err = evidence if evidence is not None else (math.nan, math.nan)
    return ShiftPosterior(model, model.to_params(chain.reshape(-1, d)), log_z, log_z_err,
                          model.to_params(u_map), max_ll, "emcee", math.nan, ess, ok, msgs)
