"""The evidence bound: work that cannot change the answer is not done.

Under any normalised prior π, ln Z = ln ∫ L π ≤ ln max L. A model (a structure, a shift law)
whose highest log-likelihood lies more than :data:`BOUND_MARGIN` nats below the certified ln Z
of the leading model therefore has posterior probability below e^-BOUND_MARGIN against it
(equal prior odds), whatever its posterior: it need not be sampled. :func:`bounded` is that
rule, used by :func:`bayesfo.compare` (structures) and ``bayesfo mastercurve`` (shift laws, and
the master structures); :func:`model_probabilities` turns ln Z (and prior odds) into posterior
model probabilities, and :func:`probability_bound` gives the upper bound of the probability of
a model that has only a bound.

The bound is only as good as the maximum it is given: the maximum a global optimiser found,
which may miss the true one. :func:`bayesfo.compare` therefore records where each bound comes
from and re-checks the bounded structures when a sampled structure's draws reach a higher
log-likelihood than the optimiser found for it.
"""

from __future__ import annotations

import math

import numpy as np

#: A model whose maximum log-likelihood lies more than this many nats below the leader's
#: certified ln Z is not sampled: its posterior probability is below e^-10 (4.5e-5) against
#: the leader, however its posterior looks.
BOUND_MARGIN = 10.0

#: What the ranking says of a structure left out by the bound.
BOUND_REASON = "not sampled: its best fit bounds ln Z"


def bounded(best_log_likelihood, leader_log_z, margin: float = BOUND_MARGIN) -> bool:
    """Whether a model whose highest log-likelihood is ``best_log_likelihood`` is ruled out
    by a leader whose certified ln Z is ``leader_log_z``: ``best < leader - margin``.

    Parameters
    ----------
    best_log_likelihood : float
        The model's highest log-likelihood found (an upper bound of its ln Z under any
        normalised prior); -inf (no admissible point) is ruled out by any finite leader.
    leader_log_z : float or None
        The leader's certified ln Z; None or not finite rules nothing out.
    margin : float
        Nats (non-negative).

    Returns
    -------
    bool

    Examples
    --------
    >>> bounded(-120.0, -100.0), bounded(-105.0, -100.0)
    (True, False)
    """
    if not margin >= 0:
        raise ValueError(f"argument 'margin' must be a non-negative number, got {margin!r}")
    if leader_log_z is None or not math.isfinite(leader_log_z):
        return False
    if best_log_likelihood is None or math.isnan(best_log_likelihood):
        return False
    return bool(best_log_likelihood < leader_log_z - margin)


def model_probabilities(log_z, log_prior=None) -> np.ndarray:
    """Posterior model probabilities from ln Z (and log prior weights, default equal): the
    softmax of ``log_z + log_prior``; a model with ln Z = -inf gets 0, and all are NaN when
    none is finite.

    Examples
    --------
    >>> model_probabilities([0.0, 0.0]).tolist()
    [0.5, 0.5]
    """
    log_w = np.asarray(log_z, dtype=float)
    if log_prior is not None:
        log_w = log_w + np.asarray(log_prior, dtype=float)
    finite = np.isfinite(log_w)
    if not finite.any():
        return np.full(log_w.shape, np.nan)
    top = np.max(log_w[finite])
    with np.errstate(under="ignore"):
        w = np.where(finite, np.exp(np.where(finite, log_w, top) - top), 0.0)
    return w / w.sum()


def probability_bound(bound: float, log_z_others, log_prior: float = 0.0,
                      log_prior_others=None) -> float:
    """The upper bound of the posterior probability of a model with ln Z ≤ ``bound`` among
    models whose ln Z are ``log_z_others`` (the probability grows with the model's own ln Z,
    so it is largest at the bound): e^(bound + log_prior) / (that + Σ e^(ln Z_j + log prior_j)).

    Examples
    --------
    >>> round(probability_bound(-110.0, [-100.0]), 8)
    4.54e-05
    """
    others = np.asarray(log_z_others, dtype=float)
    if log_prior_others is not None:
        others = others + np.asarray(log_prior_others, dtype=float)
    mine = bound + log_prior
    terms = np.append(others[np.isfinite(others)], mine)
    if not np.isfinite(mine):
        return 0.0
    top = np.max(terms)
    return float(np.exp(mine - top) / np.sum(np.exp(terms - top)))
