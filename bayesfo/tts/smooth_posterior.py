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
#: Adapted rounds (a mixture of t's fitted to the weighted draws) before emcee takes over.
ROUNDS = 4
#: Widening of an adapted component's covariance, and the weight of the Laplace component
#: kept in every adapted proposal.
WIDEN = 1.5
DEFENSIVE = 0.2
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
    #: What each isotherm's own points tell of its shift, where it was not ``model``'s
    #: (:meth:`SmoothMaster.shift_information`; a posterior averaged over vertical options
    #: takes the heaviest option's).
    information: np.ndarray | None = None

    @property
    def shift_draws(self) -> np.ndarray:
        return self.model.log_shifts(self.draws)

    @property
    def vertical_draws(self) -> np.ndarray | None:
        return None if self.model.vertical == "none" else self.model.log_vertical(self.draws)

    def undetermined(self) -> list[int]:
        """The isotherms whose log10 a_T the data do not fix: a 94 % interval wider than
        :data:`UNDETERMINED` decades, or an isotherm whose own points carry too little
        information on its shift (:meth:`SmoothMaster.shift_information`) for a normal
        interval that narrow. The second catches an isotherm on a featureless stretch whose
        posterior the smoothness prior holds near its neighbours: the data alone would let
        it slide."""
        from ..inference import hdi_columns

        lo, hi = hdi_columns(self.shift_draws, 0.94)
        if self.model.law == "free":
            info = (self.model.shift_information(self.map_theta) if self.information is None
                    else self.information)
            with np.errstate(divide="ignore"):
                own = 2.0 * 1.881 / np.sqrt(info)  # the 94 % normal interval's width
        else:  # a law ties the shifts: each one's own points do not set it
            own = np.zeros(lo.size)
        return [i for i in range(lo.size) if i != self.model.reference
                and not (hi[i] - lo[i] <= UNDETERMINED and own[i] <= UNDETERMINED)]


class _TMixture:
    """A proposal: a mixture of multivariate t's (weights, locations, shapes) with
    :data:`DF` degrees of freedom. One component is the Laplace proposal; adapted ones are
    fitted to weighted draws (k-means clusters, :class:`~bayesfo.inference.GaussianMixture`),
    with the Laplace component kept beside them (a defensive mixture: the weights stay bounded
    where the Laplace proposal covered the posterior)."""

    def __init__(self, weights, locs, shapes, rng):
        from scipy.stats import multivariate_t

        self.weights = np.asarray(weights, float) / float(np.sum(weights))
        self.parts = [multivariate_t(loc=m, shape=c, df=DF, seed=rng)
                      for m, c in zip(locs, shapes, strict=True)]
        self.rng = rng

    def rvs(self, size: int) -> np.ndarray:
        counts = self.rng.multinomial(size, self.weights)
        out = np.vstack([np.atleast_2d(p.rvs(size=c)).reshape(c, -1)
                         for p, c in zip(self.parts, counts, strict=True) if c])
        return out[self.rng.permutation(size)]

    def logpdf(self, x) -> np.ndarray:
        from scipy.special import logsumexp

        terms = np.array([math.log(w) + np.atleast_1d(p.logpdf(x))
                          for w, p in zip(self.weights, self.parts, strict=True) if w > 0])
        return logsumexp(terms, axis=0)

    @classmethod
    def adapted(cls, x, w, laplace: tuple, rng, defensive: float = DEFENSIVE):
        """Fitted to draws ``x`` with normalised weights ``w`` (resampled, then clustered),
        shapes widened by :data:`WIDEN`; the Laplace ``(loc, shape)`` kept with weight
        ``defensive``."""
        from ..inference import GaussianMixture

        pick = x[rng.choice(x.shape[0], size=DRAWS, replace=True, p=w)]
        fallback = cls([1.0 - defensive, defensive], [w @ x, laplace[0]],
                       [4.0 * laplace[1], laplace[1]], rng)
        if np.unique(pick, axis=0).shape[0] < 5 * x.shape[1]:
            return fallback  # too few distinct draws for a covariance: Laplace's, widened
        try:
            fit = GaussianMixture.fit(pick, rng)
        except np.linalg.LinAlgError:
            fit = None
        if fit is None:
            return fallback
        shapes = [_well_conditioned(WIDEN * (c @ c.T)) for c in fit.chols]
        return cls(list((1.0 - defensive) * fit.weights) + [defensive],
                   list(fit.means) + [laplace[0]], shapes + [laplace[1]], rng)


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
    at the likelihood's maximum (Laplace covariance), adapted up to :data:`ROUNDS` times as a
    mixture of t's fitted to the weighted draws (:class:`_TMixture`); emcee where the weights
    never certify, and then one more proposal fitted to emcee's draws for ln Z.

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
    rng = np.random.default_rng(seed)
    u_map, max_ll, hess = best_fit(model, start) if fit is None else fit
    laplace = (u_map, _proposal_cov(hess, model.bounds))
    prop = _TMixture([1.0], [laplace[0]], [laplace[1]], rng)
    best = None
    for _ in range(ROUNDS):
        got = _importance(model, prop)
        if got is None:
            break
        if best is None or _better(got, best):
            best = got
        if got[2] < K_HAT_EVIDENCE and got[3] >= ESS_MIN:
            break
        # Adapt: a mixture of t's fitted to the weighted draws, the Laplace one beside it.
        prop = _TMixture.adapted(got[0], got[1], laplace, rng)
    if best is not None and best[2] < K_HAT_MAX and best[3] >= ESS_MIN:
        return _from_weights(model, best, u_map, max_ll, rng, ())
    messages = ("the importance weights did not certify the posterior (Pareto k "
                f"{'n/a' if best is None else f'{best[2]:.2f}'}); emcee drew it",)
    chain = _emcee(model, u_map, laplace[1], max_ll, seed, messages,
                   None if best is None or best[2] >= K_HAT_EVIDENCE else best[4:6])
    # The emcee draws shape one more proposal: where its weights certify, the posterior
    # and ln Z come from them (emcee alone gives no ln Z).
    x = model.to_u(chain.draws)
    got = _importance(model, _TMixture.adapted(x, np.full(x.shape[0], 1.0 / x.shape[0]),
                                               laplace, rng))
    if got is not None and got[2] < K_HAT_MAX and got[3] >= ESS_MIN:
        return _from_weights(model, got, u_map, max_ll, rng,
                             ("importance weights from a proposal fitted to emcee's draws",))
    return chain


def _better(a, b) -> bool:
    """Whether importance round ``a`` certifies more than ``b``: certified (k̂ < 0.7 with
    ESS ≥ 1000) first, then the lower k̂."""
    ok_a = a[2] < K_HAT_MAX and a[3] >= ESS_MIN
    ok_b = b[2] < K_HAT_MAX and b[3] >= ESS_MIN
    return (ok_a, -a[2]) > (ok_b, -b[2])


def _importance(model: SmoothMaster, prop: _TMixture):
    """One importance round: draws from ``prop`` until the weights' ESS reaches ESS_MIN (at
    most MAX_DRAWS), or their tail (k̂) fails. ``(draws, normalised smoothed weights, k̂,
    ESS, ln Z, its error)`` in the sampling coordinates; None where fewer than a tenth of
    the draws fall in the prior's support."""
    from scipy.special import logsumexp

    from ..inference import psis

    bounds = model.bounds
    log_prior = -model.log_prior_volume
    u = np.empty((0, bounds.shape[0]))
    log_w = np.empty(0)
    while u.shape[0] < MAX_DRAWS:
        more = prop.rvs(DRAWS)
        inside = np.all((more > bounds[:, 0]) & (more < bounds[:, 1]), axis=1)
        ll = np.full(DRAWS, -np.inf)
        ll[inside] = model.log_likelihood(model.to_params(more[inside]))
        u = np.vstack([u, more])
        log_w = np.r_[log_w, ll + log_prior - prop.logpdf(more)]
        finite = np.isfinite(log_w)
        if finite.sum() < 0.1 * u.shape[0]:
            return None
        smoothed, k_hat = psis(log_w[finite])
        w = np.exp(smoothed - logsumexp(smoothed))
        if not np.all(np.isfinite(w)):  # the smoothing failed on extreme weights
            return None
        ess = float(1.0 / np.sum(w ** 2))
        if k_hat >= K_HAT_MAX or ess >= ESS_MIN:
            break
    n = u.shape[0]
    raw = np.where(finite, log_w, -np.inf)
    log_z = float(logsumexp(raw) - math.log(n))
    rel = np.exp(raw - logsumexp(raw))
    log_z_err = float(math.sqrt(max(n * np.sum(rel ** 2) - 1.0, 0.0) / n))
    return u[finite], w, float(k_hat), ess, log_z, log_z_err


def _from_weights(model, got, u_map, max_ll, rng, messages: tuple) -> ShiftPosterior:
    """The posterior of certified importance weights ``got`` (:func:`_importance`); ln Z
    where k̂ < :data:`K_HAT_EVIDENCE`."""
    x, w, k_hat, ess, log_z, log_z_err = got
    pick = rng.choice(x.shape[0], size=DRAWS // 2, replace=True, p=w)
    evidence_ok = k_hat < K_HAT_EVIDENCE
    if not evidence_ok:
        messages += (f"importance weights certify the posterior but not ln Z "
                     f"(Pareto k {k_hat:.2f})",)
    return ShiftPosterior(model, model.to_params(x[pick]),
                          log_z if evidence_ok else math.nan,
                          log_z_err if evidence_ok else math.nan, model.to_params(u_map),
                          max_ll, "importance", k_hat, ess, True, messages)


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
