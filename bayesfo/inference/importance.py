"""Posterior and evidence by importance sampling from the optima: the fast, certified route for
well-posed structures.

The global optimisation already found the modes. Each is polished to the maximum of the log
posterior under the noise model at hand (L-BFGS-B; the optimiser's least squares weight the
residuals by the data's magnitude). Around each (in the sampling coordinates u, log for
log-uniform priors), the curvature of the log posterior gives a Laplace approximation;
a mixture of multivariate Student-t distributions (5 degrees of freedom, scale 1.5 × the
Laplace covariance, each mode weighted by its Laplace mass) is the proposal. Where most of its
draws leave the support (optima on bounds of the prior box, such as a Maxwell order at 0 with a
coefficient at its smallest value: each such coordinate spills half of its component over the
bound), the mixture is built again in unbounded coordinates z, the logit of each coordinate
within its prior range (:class:`~bayesfo.inference.transform._Unbounded`), where no draw
leaves the box; the weights are then the posterior density in z (the density in u times the
Jacobian |du/dz|) over the proposal's, so that their mean is still the evidence. The proposal
stays in u wherever it keeps its draws: a coordinate that leans on a bound along a ridge is
covered better there, by a component cut at the bound, than in z, where the curvature at the
mode does not reach along the ridge (BENCHMARKS.md, "the importance proposal in unbounded
coordinates"). An optimum on the edge
of the support inside the box (a coefficient at 0 where its element vanishes, two orders that
meet) has no difference stencil around it: the curvature is taken a few (smaller) steps
inside (:func:`~._peaks._inward`), and the component spills part of its draws over the edge,
where their weight is zero. One vectorised call of the likelihood on 20 000 proposal draws
gives the importance weights, and from them

* the evidence, ln Z' = ln mean(w), with the standard error of that mean (the prior normalised
  on its support as elsewhere: ln Z = ln Z' − ln P(S)), where k̂ < 0.5;
* the posterior, as draws resampled from the Pareto-smoothed weights.

The certificate is the weights themselves (Vehtari et al. 2024, Pareto smoothed importance
sampling): the Pareto shape k̂ of their upper tail below 0.7 says that the proposal's tails
cover the posterior's and the estimates converge at the usual rate, and their effective sample
size says how many independent draws they are worth. Where the first round's weights do not
certify, a second round adds to the proposal a Student-t matched to their weighted mean and
covariance (one step of population Monte Carlo), which reaches skewed and bounded directions.
The same second round follows a first that certifies the posterior but whose weights are too
heavy-tailed for ln Z (0.5 ≤ k̂ < 0.7, typical of a structure that misfits): where its k̂ is
below 0.5 it gives ln Z (and the posterior), and the tempered ladder is not run for ln Z alone.
Where either still fails (a ridge, a boundary,
a mode the optimiser did not find, an unidentified parameter), the result is None and the
structure goes to the samplers (emcee, then the tempered ladder).

What the weights cannot see: a mode of the posterior that no optimum seeds and that the
proposal's tails never reach; k̂ and the ESS are computed from the proposal's own draws, so they
certify a posterior that lacks it. Such modes arise where the data leave a parameter undetermined:
an element invisible in the window (its coefficient free down to its prior bound, its order free
over its whole range) or two springpots of nearly equal order, where the roles of the elements
can be exchanged (the "c_α dominant" and "c_β dominant" configurations of a two-springpot model
under β ≤ α). A simulation-based calibration found them in two-springpot posteriors certified
by the weights alone, missing a large part of a reference posterior's mass (BENCHMARKS.md).
The certificate therefore has a second part: where the weighted draws leave a fractional order
undetermined (its central 94 % interval spans more than :data:`UNDETERMINED` of its prior
range), the proposal built at the optima is not trusted to cover the configurations this allows,
and the structure goes to the tempered ladder, whose independent runs start from the prior
(and whose agreement certifies them).

Its third part looks for ridges: a coefficient free up to its prior bound, with the other
parameters following it along a curved crest (both elements of a Voigt growing together on a
misfitting isotherm), holds posterior mass that a proposal built at the optima never visits,
though the log posterior there stays within a few nats of the peak. The ridge probe
(:func:`_ridge_probe`) follows the profile of the log posterior outwards along each coordinate
from each mode and estimates the mass the draws do not represent; where it exceeds
:data:`PROBE_MISSED`, the tempered ladder takes over. ``info["probe"]`` of a certified
posterior says what was checked (profile points, the share found).
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.special import logsumexp

from ..errors import InputError
from ._arviz import psis
from ._mixture import _GaussianMixture
from ._peaks import DF, _laplace, _mixture_log_pdf, _polished
from ._ridge import PROBE_MAX_DIM, PROBE_MISSED, _ridge_probe
from .evidence import Evidence, log_support_fraction
from .likelihood import Likelihood
from .results import exponent_intervals, result_from_draws
from .transform import Transform, _log_prob_fn, _Unbounded

#: Certificate of the importance weights: Pareto k̂ below this (Vehtari et al.'s threshold of
#: reliable estimates) and at least this many effective draws.
K_HAT_MAX = 0.7
ESS_MIN_IMPORTANCE = 1000
#: ln Z from the raw weights needs their variance finite: k̂ below 0.5.
K_HAT_EVIDENCE = 0.5

#: Largest share of its prior range that a fractional order's 94 % interval under the weights
#: may span for the route to be certified (see the module's docstring). Orders only: an
#: undetermined coefficient alone (a dashpot or spring invisible in the window) leaves no other
#: configuration to miss, and on real data it is common (misfitting structures, whose noise is
#: large); the alternative configurations of springpot models all move an order. On simulated
#: springpot data, every posterior that missed a mode had an order spanning more than this,
#: and few that missed nothing did (BENCHMARKS.md, "Measurements behind design choices").
UNDETERMINED = 0.25

NEWTON = 4
# Rounds of importance sampling: the Laplace mixture, then one adapted to the weighted draws
# of the first (see _adapted). A second round certifies posteriors that the first alone does
# not; further rounds of the same kind did not certify what two left uncertified, so they are
# not run (BENCHMARKS.md, "Measurements behind design choices"). A third round, a normal
# mixture fitted to certified draws (_fitted), is run for ln Z; a fourth, widened along a
# ridge (_with_ridge), where the ridge probe finds one.
#: The third round (:func:`_fitted`): draws resampled from the certified weights to fit the
#: mixture to (k ≤ 4 components by BIC), and the scale of its Student-t components relative
#: to the fitted covariances (broad: on misfitting structures of real isotherms, 1.6 gave
#: k̂ < 0.5 where 1.0 and 1.3 often did not; BENCHMARKS.md, "ln Z where the first round's
#: weights are heavy-tailed").
FIT_DRAWS = 4000
FIT_SCALE = 1.6
SCALE = 1.5     # proposal scale relative to the Laplace covariance


def _with_ridge(out, probe: dict, n_proposals: int, rng: np.random.Generator):
    """A round whose proposal adds to a round's the normals of the ridge probe (Student-t of the
    same scale), so that its draws reach the ridge: the round's proposal keeps 1 − s of the
    weight, the ridge's components s (the share the probe found, between 0.1 and 0.5),
    divided as the masses the probe estimated. None where too few draws are in the support."""
    _, _, _, n_modes, prop = out
    comps = probe["components"]
    share = min(0.5, max(0.1, probe["missed"]))
    masses = np.array([c[2] for c in comps])
    lw_old = prop["log_weights"] - logsumexp(prop["log_weights"]) + math.log1p(-share)
    lw_new = masses - logsumexp(masses) + math.log(share)
    proposal = {**prop, "factors": list(prop["factors"]) + [c[1] for c in comps],
                "means": np.vstack([prop["means"], [c[0] for c in comps]]),
                "log_weights": np.concatenate([lw_old, lw_new]),
                "base": prop.get("base", prop)}
    return _draw(proposal, n_modes, n_proposals, rng)


def _mvt(factors, means, log_weights, n: int, rng: np.random.Generator):
    """Draws from a mixture of multivariate t (``DF``) and the log density of any points.

    Each component is given by its mean and a factor A with covariance A Aᵀ: ``(w, v)`` of the
    eigendecomposition, A = v·diag(1/sqrt(w)) (no Cholesky: the Laplace covariances of
    structures with a sharp and a flat direction have condition numbers near 1e20)."""
    k, d = means.shape
    p = np.exp(log_weights - logsumexp(log_weights))
    which = rng.choice(k, size=n, p=p)
    z = rng.standard_normal((n, d))
    g = rng.chisquare(DF, size=n) / DF
    a = np.array([v / np.sqrt(w) for w, v in factors])
    x = means[which] + np.einsum("nij,nj->ni", a[which], z) / np.sqrt(g)[:, None]
    return x, _mixture_log_pdf(factors, means, log_weights)


#: Proposal draws handed on as the guide of the tempered ladder where the weights do not certify
#: the posterior.
GUIDE_DRAWS = 2000


def importance_posterior(lik: Likelihood, modes_scaled, *, seed: int = 0,
                         n_proposals: int = 20_000, n_draws: int = 2000, chains: int = 4,
                         predictive: bool = True):
    """The posterior and ln Z of ``lik`` by importance sampling from its modes, if certified.

    Parameters
    ----------
    lik : Likelihood
    modes_scaled : array_like, shape (k, n_structure_params)
        Optima of the structure's parameters on the scaled problem (``FitResult.optima``).
    seed : int
        Seed of the proposal draws, the resampling and the posterior predictive.
    n_proposals : int
        Proposal draws (one vectorised likelihood call).
    n_draws, chains : int
        Posterior draws resampled from the weights, stored as ``chains`` chains.
    predictive : bool
        Store the posterior predictive and the model response in the DataTree.

    Returns
    -------
    (PosteriorResult, Evidence or None, dict) or (None, None, dict)
        The dict states the certificate (``k_hat``, ``ess`` of the weights, ``n_modes``,
        ``rounds`` run and ``k_hat_rounds``, the k̂ of each, ``widest`` order, ``probe``: the
        ridge probe's profile ``points`` and the share of the posterior it found ``missed``,
        with the ``ridge`` coordinate and the share ``covered`` where a round widened along it
        gives the posterior, or why it was ``skipped`` (more than :data:`PROBE_MAX_DIM`
        parameters), ``seconds``) or, when the route does not apply, ``reason`` (with
        ``undetermined`` or ``ridge`` where those parts of the certificate failed, and, where
        the weights were computed but do not certify,
        ``proposal_draws``: up to :data:`GUIDE_DRAWS` draws of the proposal in the sampling
        coordinates, a guide for the tempered ladder). A first round that does not certify
        ln Z (k̂ ≥ 0.5 or too few effective draws) is followed by the adapted round (unless it
        certifies the posterior with an order undetermined: the ladder takes over), and where
        no round certifies ln Z but one certifies the posterior, by a round fitted to its draws
        (:func:`_fitted`); the certified round with the smallest k̂ gives the posterior, and ln Z
        where its k̂ < 0.5 (see :data:`K_HAT_EVIDENCE`; else the evidence is None). The
        posterior's ESS is that of the resampled draws, 1/(1/ESS_weights + 1/n_draws).
    """
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    tr = Transform(lik)
    out = _weights(lik, tr, modes_scaled, n_proposals, rng)
    if isinstance(out, dict):
        return None, None, out
    rounds = [_assessed(out)]
    # An order the first round's certified weights leave undetermined sends the posterior to
    # the tempered ladder whatever later rounds give, which only lighten the tails of weights
    # that already certify it: they are not run.
    (x1, _, finite1, _, _), _, _, w1, _ = rounds[0]
    undetermined = _certifies(rounds[0]) and not _orders_determined(lik, tr, x1[finite1], w1, {})
    if not undetermined:
        if not _certifies(rounds[0], evidence=True):
            # Not certified, or certified with weights too heavy-tailed for ln Z (0.5 ≤ k̂ <
            # 0.7, typical of a structure that misfits): a round adapted to the weighted draws.
            adapted = _adapted(out, n_proposals, rng)
            if adapted is not None:
                rounds.append(_assessed(adapted))
        certified = [r for r in rounds if _certifies(r)]
        if certified and not any(_certifies(r, evidence=True) for r in certified):
            # The posterior is certified, its ln Z not: a round whose proposal is a normal
            # mixture fitted to the certified draws usually has lighter tails; where its k̂ is
            # below 0.5 it gives ln Z, which would otherwise take a tempered ladder.
            fitted = _fitted(min(certified, key=lambda r: r[2]), n_proposals, rng)
            if fitted is not None:
                rounds.append(_assessed(fitted))
    certified = [r for r in rounds if _certifies(r)]
    # The certified round with the lightest tail (the smallest k̂) gives the posterior and,
    # where k̂ < 0.5, ln Z; with none certified, the last round says why.
    best = min(certified, key=lambda r: r[2]) if certified else rounds[-1]
    out, smoothed, k_hat, w, ess = best
    x, log_w, finite, n_modes, _ = out
    k_hats = [float(r[2]) for r in rounds]
    info = {"k_hat": k_hat, "ess": ess, "n_modes": n_modes, "n_proposals": n_proposals,
            "rounds": len(rounds), "k_hat_rounds": k_hats}
    certified = k_hat < K_HAT_MAX and ess >= ESS_MIN_IMPORTANCE
    if not certified:
        info["reason"] = (f"importance weights not certified (Pareto k {k_hat:.2f}, ESS "
                          f"{ess:.0f})")
    elif not _orders_determined(lik, tr, x[finite], w, info):
        certified = False
    elif lik.ndim > PROBE_MAX_DIM:
        info["probe"] = {"points": 0, "missed": None,
                         "skipped": f"{lik.ndim} parameters, more than {PROBE_MAX_DIM}"}
    else:
        probe = _ridge_probe(out)
        info["probe"] = {"points": probe["points"], "missed": probe["missed"]}
        if probe["missed"] > PROBE_MISSED:
            # A round whose proposal reaches along the ridge: it gives the posterior where
            # its weights certify it and its own probe finds nothing more.
            ridge = lik.param_names[probe["coordinate"]]
            info["probe"]["ridge"] = ridge
            widened = _with_ridge(out, probe, n_proposals, rng)
            again = None
            if widened is not None:
                assessed = _assessed(widened)
                k_hats.append(assessed[2])
                if _certifies(assessed):
                    again = _ridge_probe(widened)
            if again is not None and again["missed"] <= PROBE_MISSED:
                out, smoothed, k_hat, w, ess = assessed
                x, log_w, finite, n_modes, _ = out
                info.update(k_hat=k_hat, ess=ess, rounds=len(k_hats))
                info["probe"].update(points=probe["points"] + again["points"],
                                     missed=again["missed"], covered=probe["missed"])
                # A ridge along an order is the undetermined case: checked again.
                certified = _orders_determined(lik, tr, x[finite], w, info)
            else:
                certified = False
                info["rounds"] = len(k_hats)
                info["ridge"] = ridge
                info["reason"] = (f"a ridge of the posterior along {ridge} holds about "
                                  f"{100 * probe['missed']:.0f} % of its mass where the "
                                  "proposal at the optima does not reach")
    if not certified:
        # The proposal's draws cover every optimum: they guide the samplers that take over
        # (an array, so only on this path: a certified run's info goes into summary.json).
        xs = x[finite]
        info["proposal_draws"] = xs[rng.permutation(len(xs))[:GUIDE_DRAWS]]
        return None, None, info
    # Evidence: the mean of the raw weights over every proposal draw (zero outside the
    # support), with the standard error of a mean. That error needs weights of finite
    # variance, k̂ < 0.5; between 0.5 and 0.7 the smoothed weights still give the posterior,
    # but ln Z is left to the tempered ladder.
    lw_all = np.where(finite, log_w, -np.inf)
    log_z_support = float(logsumexp(lw_all) - math.log(n_proposals))
    rel = np.exp(lw_all - log_z_support)
    rel_err = float(np.std(rel) / math.sqrt(n_proposals))
    try:
        log_s, log_s_err = log_support_fraction(lik, rng)
    except InputError:
        return None, None, {"reason": "no prior draw in the support"}
    # Posterior draws: systematic resampling of the smoothed weights, in random order.
    positions = (rng.random() + np.arange(n_draws)) / n_draws
    idx = np.minimum(np.searchsorted(np.cumsum(w), positions), w.size - 1)
    draws_u = x[finite][idx][rng.permutation(n_draws)]
    per_chain = n_draws // chains
    chain_u = draws_u[: per_chain * chains].reshape(chains, per_chain, -1)
    # The reported draws are a resample: their effective size is that of the weights and of
    # the resampling together.
    ess_draws = 1.0 / (1.0 / ess + 1.0 / (per_chain * chains))
    post = result_from_draws(lik, chain_u, sampler="importance", rhat=math.nan,
                             ess_bulk=ess_draws, ess_tail=ess_draws, messages=(),
                             converged=True, seed=seed, predictive=predictive)
    info["seconds"] = time.perf_counter() - t0
    evidence = None
    if k_hat < K_HAT_EVIDENCE:
        evidence = Evidence(log_z=log_z_support - log_s,
                            log_z_err=math.sqrt(min(rel_err, 1.0) ** 2 + log_s_err**2),
                            method="importance", log_support=log_s,
                            n_likelihood=int(n_proposals), seconds=info["seconds"])
    return post, evidence, info


def _assessed(out):
    """A round of importance sampling with its Pareto-smoothed log weights, k̂, normalised
    smoothed weights and their ESS: ``(out, smoothed, k_hat, w, ess)``."""
    _, log_w, finite, _, _ = out
    smoothed, k_hat = psis(log_w[finite])
    w = np.exp(smoothed - logsumexp(smoothed))
    return out, smoothed, float(k_hat), w, float(1.0 / np.sum(w**2))


def _certifies(assessed, *, evidence: bool = False) -> bool:
    """Whether a round's weights certify the posterior (k̂ < 0.7, ESS ≥ 1000), and with
    ``evidence`` its ln Z too (k̂ < 0.5)."""
    _, _, k_hat, _, ess = assessed
    limit = K_HAT_EVIDENCE if evidence else K_HAT_MAX
    return k_hat < limit and ess >= ESS_MIN_IMPORTANCE


def _orders_determined(lik: Likelihood, tr, x: np.ndarray, w: np.ndarray, info: dict) -> bool:
    """The second part of the certificate: whether every fractional order's 94 % interval under
    the weights spans at most :data:`UNDETERMINED` of its prior range; records ``widest`` in
    ``info``, and ``undetermined`` and the ``reason`` where it does not."""
    name, share = _widest(lik, tr, x, w)
    info["widest"] = {"parameter": name, "share_of_prior": share}
    if share <= UNDETERMINED:
        return True
    info["undetermined"] = name
    info["reason"] = (f"the order {name} is undetermined (its 94 % interval spans "
                      f"{100 * share:.0f} % of its prior range), so the proposal at the "
                      "optima may miss configurations the data allow")
    return False


def _widest(lik: Likelihood, tr, x: np.ndarray, w: np.ndarray) -> tuple[str, float]:
    """The fractional order whose central 94 % interval under the weights ``w`` of draws ``x``
    (sampling coordinates) spans the largest share of its prior range, and that share ("" and 0
    for a structure without a free order; priors without a finite range are left out)."""
    span = tr.hi_u - tr.lo_u
    best, share = "", 0.0
    for j, p in enumerate(lik.structure.parameters):
        name = p.name
        if p.role != "exponent" or not (np.isfinite(span[j]) and span[j] > 0):
            continue
        order = np.argsort(x[:, j])
        cdf = np.cumsum(w[order])
        lo, hi = (x[order[min(np.searchsorted(cdf, q), cdf.size - 1)], j] for q in (0.03, 0.97))
        if (hi - lo) / span[j] > share:
            best, share = name, float((hi - lo) / span[j])
    return best, share


def _weights(lik: Likelihood, tr, modes_scaled, n_proposals: int, rng: np.random.Generator):
    """Proposal draws ``x`` (u coordinates) from the Student-t mixture at the Laplace
    approximations of the modes, their log importance weights, which are finite, and the number
    of distinct modes; or a dict with the ``reason`` the route does not apply.

    The mixture is built in u; where most of its draws leave the support (an optimum on a bound
    of the box, such as an order at 0, spills half of its component over it), it is built again
    in the unbounded coordinates of :class:`~.transform._Unbounded`, from new draws, with the
    weights in those coordinates (see :func:`_proposal`)."""
    log_prob = _log_prob_fn(lik, tr)
    modes = np.atleast_2d(np.asarray(modes_scaled, dtype=float))
    if modes.size == 0:
        return {"reason": "no optimum"}
    if lik.noise_param:
        modes = np.column_stack([modes, lik.noise_estimate(modes)])
    u_modes = [u0 for u0 in tr.to_u(modes)
               if np.all(np.isfinite(u0)) and np.isfinite(log_prob(u0[None, :])[0])]
    if not u_modes:
        return {"reason": "no optimum lies in the support"}
    polished = {}  # the optima polished in u, shared by the two proposals
    out = _proposal(log_prob, tr, u_modes, polished, n_proposals, rng, unbounded=False)
    if isinstance(out, dict) and out["reason"] == LEAVE:
        out = _proposal(log_prob, tr, u_modes, polished, n_proposals, rng, unbounded=True)
    return out


#: Why the route gives up where the proposal's draws fall mostly outside the support.
LEAVE = "most proposal draws leave the support"


def _proposal(log_prob, tr, u_modes, polished: dict, n_proposals: int,
              rng: np.random.Generator, *, unbounded: bool):
    """:func:`_weights` with the proposal built in u, or in the coordinates z of
    :class:`~.transform._Unbounded` (``unbounded``), where the target is the posterior density
    in z: the weights are target over proposal density in the coordinates of the draws, so that
    their mean is the evidence in either. ``polished``: the optima polished in u, by index,
    filled as they are computed."""
    d = len(u_modes[0])
    if unbounded:
        zc = _Unbounded(tr.lo_u, tr.hi_u)
        log_target, to_u = zc.target(log_prob), zc.to_u
        free = np.full(d, -np.inf), np.full(d, np.inf)
    else:
        log_target, to_u = log_prob, _identity
    peaks = []
    for i, u0 in enumerate(u_modes):
        if i not in polished:
            polished[i] = _polished(log_prob, u0, tr.lo_u, tr.hi_u)
        if unbounded:
            z0 = zc.start(log_target, polished[i])
            peak = _laplace(log_target, z0, *free, newton_steps=NEWTON, broad=zc.broad(z0),
                            polish=False)
        else:
            peak = _laplace(log_prob, polished[i], tr.lo_u, tr.hi_u, newton_steps=NEWTON,
                            polish=False)
        if peak is None:
            return {"reason": "no curvature at an optimum (the support ends or the Hessian is "
                              "singular there)"}
        if not any(np.allclose(peak[1], p[1], rtol=1e-6, atol=1e-8) for p in peaks):
            peaks.append(peak)
    means = np.array([p[1] for p in peaks])
    factors = [(w / SCALE**2, v) for _, _, (w, v) in peaks]
    # Each mode weighted by its Laplace mass: height × sqrt(det covariance).
    log_weights = np.array([p[0] - 0.5 * np.sum(np.log(p[2][0])) for p in peaks])
    box = free if unbounded else (tr.lo_u, tr.hi_u)
    proposal = {"factors": factors, "means": means, "log_weights": log_weights,
                "log_target": log_target, "to_u": to_u, "lo": box[0], "hi": box[1]}
    out = _draw(proposal, len(peaks), n_proposals, rng)
    return {"reason": LEAVE} if out is None else out


def _identity(u):
    return u


def _draw(proposal: dict, n_modes: int, n_proposals: int, rng: np.random.Generator):
    """A round of importance sampling: draws of the mixture ``proposal`` and their log
    importance weights, ``(draws in u, log weights, finite, n_modes, the proposal with its draws
    in its own coordinates, u or z, as "z")``; None where fewer than a tenth are in the
    support."""
    z, log_q = _mvt(proposal["factors"], proposal["means"], proposal["log_weights"],
                    n_proposals, rng)
    lp = proposal["log_target"](z)
    log_w = np.where(np.isfinite(lp), lp - log_q(z), -np.inf)
    finite = np.isfinite(log_w)
    if finite.sum() < 0.1 * n_proposals:
        return None
    return proposal["to_u"](z), log_w, finite, n_modes, {**proposal, "z": z}


def _fitted(assessed, n_proposals: int, rng: np.random.Generator):
    """A round for ln Z where a certified round's weights are too heavy-tailed for it
    (0.5 ≤ k̂ < 0.7): half the first proposal (its coverage of every optimum), half a normal
    mixture (:class:`~._mixture._GaussianMixture`, k ≤ 4 by BIC) fitted to :data:`FIT_DRAWS`
    draws resampled from the certified weights, each of its components a Student-t of scale
    :data:`FIT_SCALE` times the component's covariance, in the coordinates of the certified
    round's proposal. The mixture follows a skewed or curved posterior that one Laplace
    approximation or one matched component does not. None where the fit fails."""
    out, _, _, w, _ = assessed
    _, _, finite, n_modes, prop = out
    zs = prop["z"][finite]
    picked = zs[rng.choice(len(zs), size=FIT_DRAWS, p=w)]
    try:
        mix = _GaussianMixture.fit(picked, rng)
    except np.linalg.LinAlgError:
        return None
    if mix is None:
        return None
    factors = []
    for chol in mix.chols:
        eig, vec = np.linalg.eigh(FIT_SCALE**2 * (chol @ chol.T))
        if not np.all(np.isfinite(eig)) or eig.min() <= 0:
            return None
        factors.append((1.0 / eig, vec))
    base = prop.get("base", prop)
    lw0 = base["log_weights"] - logsumexp(base["log_weights"])
    proposal = {**prop, "factors": list(base["factors"]) + factors,
                "means": np.vstack([base["means"], mix.means]),
                "log_weights": np.concatenate([lw0 + math.log(0.5),
                                               np.log(mix.weights) + math.log(0.5)]),
                "base": base}
    return _draw(proposal, n_modes, n_proposals, rng)


def _adapted(first, n_proposals: int, rng: np.random.Generator):
    """A second round of importance sampling whose proposal adds, with half the weight, a
    Student-t matched to the mean and covariance of the first round's weighted draws, in the
    coordinates of its proposal (one step of population Monte Carlo). The half of the first
    proposal keeps its coverage of every mode; the matched component reaches the skewed or
    bounded directions the Laplace approximations miss, such as a parameter leaning on its prior
    bound (BENCHMARKS.md, "Measurements behind design choices"). None where the first round's
    draws are too few to estimate a covariance."""
    _, log_w, finite, n_modes, prop = first
    zs = prop["z"][finite]
    smoothed, _ = psis(log_w[finite])
    w = np.exp(smoothed - logsumexp(smoothed))
    d = zs.shape[1]
    if 1.0 / np.sum(w**2) < 10 * d:
        return None
    mean = w @ zs
    centred = zs - mean
    cov = (centred * w[:, None]).T @ centred
    eig, vec = np.linalg.eigh(cov)
    if not np.all(np.isfinite(eig)) or eig.min() <= 0:
        return None
    base = prop.get("base", prop)
    lw0 = base["log_weights"] - logsumexp(base["log_weights"])
    proposal = {**prop, "factors": list(base["factors"]) + [(1.0 / eig, vec)],
                "means": np.vstack([base["means"], mean]),
                "log_weights": np.append(lw0 + math.log(0.5), math.log(0.5)), "base": base}
    return _draw(proposal, n_modes, n_proposals, rng)


def _log_support(lik, rng):
    return log_support_fraction(lik, rng, n=5000, max_draws=5000)


def screen_noise(lik: Likelihood, modes_scaled, *, seed: int = 0, n_proposals: int = 5000,
                 interval: float = 0.94) -> dict | None:
    """A quick, uncertified ln Z of ``lik`` and central intervals of its exponents, from the
    raw importance weights of the same proposal, whatever their Pareto k̂; None where the
    route does not apply.

    Used to choose between noise models when one is far ahead (see
    :func:`bayesfo.comparison.run.compare`): a structure's two noise models share its ridges and
    modes, so the proposal's shortfall largely cancels in the difference of their ln Z, and a
    gap of many nats decides without a certified posterior of the loser. ``k_hat`` is returned
    so that the caller can see how rough the estimate is. Where the first proposal's k̂ is
    :data:`K_HAT_MAX` or more, the estimate is that of a second round adapted to its weighted
    draws (:func:`_adapted`, as in :func:`importance_posterior`), if its k̂ is lower.
    ``undetermined`` names the order that the same weights leave undetermined (see
    :data:`UNDETERMINED`; "" if none), for which the importance route will not certify the
    posterior whatever k̂.
    """
    rng = np.random.default_rng(seed)
    tr = Transform(lik)
    out = _weights(lik, tr, modes_scaled, n_proposals, rng)
    if isinstance(out, dict):
        return None
    x, log_w, finite, _, _ = out
    smoothed, k_hat = psis(log_w[finite])
    if not k_hat < K_HAT_MAX:
        adapted = _adapted(out, n_proposals, rng)
        if adapted is not None:
            smoothed2, k_hat2 = psis(adapted[1][adapted[2]])
            if k_hat2 < k_hat:
                (x, log_w, finite, _, _), smoothed, k_hat = adapted, smoothed2, k_hat2
    try:
        log_s, _ = _log_support(lik, rng)
    except InputError:
        return None
    log_z = float(logsumexp(np.where(finite, log_w, -np.inf)) - math.log(n_proposals)) - log_s
    w = np.exp(smoothed - logsumexp(smoothed))
    intervals = exponent_intervals(lik, tr.to_theta(x[finite]), w, interval)
    name, share = _widest(lik, tr, x[finite], w)
    return {"log_z": log_z, "k_hat": float(k_hat), "intervals": intervals,
            "undetermined": name if share > UNDETERMINED else "",
            "method": "importance (uncertified)"}

