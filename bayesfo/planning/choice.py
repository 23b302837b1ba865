"""Where to measure next: the frequencies whose measurement would best settle the model choice.

From a finished comparison, each candidate frequency ω in a window is scored by the expected
information about the model index M that one more complex measurement y there would bring: the
mutual information

    I(M; y) = Σ_m p_m E_{y ~ p(y | m)} [ln p(y | m) − ln p(y)],   p(y) = Σ_m p_m p(y | m),

under each structure's posterior predictive p(y | m) (its posterior draws of the parameters and
of the noise) and the current posterior model probabilities p_m. I is in nats, at most the
entropy of the p_m (the information still missing about M), and zero where the structures
predict the same. Several distinct points are chosen greedily: each next point is the one
that adds the most to the information of the set chosen so far (the joint y of the set), or
the most per second of measuring time with ``cost="low-frequency"`` (a sweep point at ω takes
about :data:`SETTLE_S` plus :data:`PERIODS` periods 2π/ω).

Each structure's predictive of a set of measurements is taken as a normal distribution in the
coordinates (ln|G|, arg G) of each point, with the mean and covariance of its posterior draws'
responses plus the noise variance of its noise model (its σ for constant noise, σ_rel for
proportional noise, σ_rel of each part for relative parts; with σ given per point, the data's
median relative σ). The posterior spread of a structure is often far wider than the noise
outside the measured window, so that a mixture over a few hundred draws would be a poor density
(its Monte Carlo estimate of I is biased, even below zero); the normal form gives exact
densities, and I is then a plain Monte Carlo mean over simulated y, with the same standard
normals for every candidate so that the candidates differ by what they measure. The normal form
does not represent a predictive with several separate branches (two modes of a posterior):
there the numbers are a rough guide.

The model probabilities are those of the structures' ln Z with equal prior odds, over the
structures considered.

For the two leading structures the result states what the proposed points would do to their
log Bayes factor: its expected change if either is true, and the probability (under the current
model probabilities) that after them it is decisive, |ln B| > ln 100.

:func:`~bayesfo.planning.parameter.design_parameter` answers the same for one parameter of one
structure (e.g. the order α of the leading structure): the expected information about it, and
its expected posterior sd after the proposed points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.special import logsumexp

from ..errors import InputError
from ..inference.likelihood import NOISE_PRIORS, noise_variance
from ..tts.result import MasterCurve

__all__ = ["COSTS", "Design", "design", "seconds"]

#: Draws of each structure's posterior used (half simulate y, half give its density).
N_DRAWS = 160
#: Simulated measurements y per structure.
N_Y = 200
#: Candidate frequencies on a log grid over the window.
N_CANDIDATES = 61
#: Structures below this posterior probability carry no information about the choice (they
#: cannot win) and are left out, with at most :data:`MAX_STRUCTURES` kept.
MIN_PROBABILITY = 1e-4
MAX_STRUCTURES = 4
#: Measuring time of a sweep point at ω: SETTLE_S + PERIODS · 2π/ω seconds.
SETTLE_S = 10.0
PERIODS = 3.0
#: A further point is proposed only where it adds at least this much information [nats], and
#: this share of the entropy still missing: below, it would cost measuring time for nothing.
NEGLIGIBLE = 1e-3
NEGLIGIBLE_SHARE = 0.01
#: Proposed frequencies lie at least this share of the width of the single-point information's
#: peak apart (its full width at half maximum, in decades), and at least one candidate step,
#: at most :data:`MAX_SPACING` decades: two points closer than that measure nearly the same
#: thing (0.063 and 0.074 rad/s were proposed together, 0.07 decades apart).
SPACING_SHARE = 0.5
MAX_SPACING = 0.5
#: |ln B| beyond which the evidence is decisive (Jeffreys: B > 100).
DECISIVE = math.log(100.0)
COSTS = ("uniform", "low-frequency")


@dataclass(frozen=True)
class Design:
    """The proposed measurements (:func:`design`).

    Attributes
    ----------
    omega : ndarray
        The candidate frequencies [rad/s].
    information : ndarray
        Expected information of one measurement at each candidate [nats].
    proposed : tuple of dict
        The chosen points in the order chosen: ``omega``, ``information`` (of the set so far,
        nats), ``gain`` (what this point added), ``seconds`` (its measuring time). Fewer than
        asked where no further point adds measurable information (a note says so).
    structures : tuple of str
        The structures considered (probability ≥ :data:`MIN_PROBABILITY`), best first.
    probabilities : tuple of float
        Their posterior probabilities, renormalised over them.
    entropy : float
        The entropy of those probabilities [nats]: the most any measurement can tell.
    leading : tuple of str
        The two leading structures.
    log_bayes_factor : float
        Their current ln B (first over second).
    expected_change : dict
        ``{structure: E[Δ ln B]}`` if that structure is true, for the proposed set.
    p_decisive : float
        Probability that ln B of the two is decisive after the proposed points.
    alternatives : dict
        The expected information of as many points placed by rules of thumb: ``log-uniform``
        over the window, ``decade below`` (log-uniform over the decade below the data, as far
        as the window reaches), ``decade above``.
    window : tuple of float
    cost : str
    notes : tuple of str
    asked : int
        The number of points asked for (the rules of thumb place as many).
    spacing : float
        The least distance between proposed frequencies [decades] (:func:`min_spacing`).
    """

    omega: np.ndarray = field(repr=False)
    information: np.ndarray = field(repr=False)
    proposed: tuple
    structures: tuple[str, ...]
    probabilities: tuple[float, ...]
    entropy: float
    leading: tuple[str, ...]
    log_bayes_factor: float
    expected_change: dict
    p_decisive: float
    alternatives: dict
    window: tuple[float, float]
    cost: str
    notes: tuple[str, ...] = ()
    asked: int = 0
    spacing: float = math.nan

    def to_dict(self) -> dict:
        """The design as JSON (``bayesfo design --json``)."""
        return {"window": list(self.window), "cost": self.cost, "points_asked": self.asked,
                "structures": dict(zip(self.structures, self.probabilities, strict=True)),
                "entropy": self.entropy,
                "proposed": [dict(p) for p in self.proposed],
                "leading": list(self.leading), "log_bayes_factor": self.log_bayes_factor,
                "expected_change": dict(self.expected_change),
                "p_decisive": self.p_decisive, "alternatives": dict(self.alternatives),
                "candidates": {"omega": self.omega.tolist(),
                               "information": self.information.tolist()},
                "min_spacing_decades": self.spacing, "notes": list(self.notes)}


def seconds(omega) -> np.ndarray:
    """Measuring time of a sweep point at ``omega`` [s] (see the module)."""
    return SETTLE_S + PERIODS * 2.0 * np.pi / np.asarray(omega, dtype=float)


def _noise_var(result, draws, g, rel_sigma) -> np.ndarray:
    """Variance of a measurement's ln|G| and arg G [rad] (last axis) for model responses ``g``
    (draws × frequencies) under the structure's noise model
    (:func:`~bayesfo.inference.likelihood.noise_variance`): each draw's sampled noise scale
    (its last parameter, physical units), or the data's relative σ under known noise."""
    noise = result.posterior.noise
    sigma = draws[:, -1][:, None] if noise in NOISE_PRIORS else rel_sigma
    return noise_variance(noise, g, sigma)


@dataclass
class _Predictive:
    """Each structure's posterior predictive of measurements at the candidates, in the
    coordinates (ln|G|, arg G): the draws' responses ``z`` (structures, draws, candidates, 2)
    and the noise variances ``noise`` (structures, candidates, 2; the mean over draws). The
    predictive of a set of candidates is taken as a normal distribution with the draws' mean and
    covariance plus the noise (parameter uncertainty and noise; replicates at one frequency share
    the first and not the second)."""

    z: np.ndarray
    noise: np.ndarray

    def _normals(self, sets):
        """Means (M, n_sets, 2k) and inverse Cholesky factors and log-determinants of the
        covariances (M, n_sets, 2k, 2k), (M, n_sets) of the candidate ``sets`` (n_sets, k)."""
        m, n_draws = self.z.shape[:2]
        n_sets, k = sets.shape
        zz = self.z[:, :, sets, :].reshape(m, n_draws, n_sets, 2 * k)
        mu = zz.mean(axis=1)
        dev = zz - mu[:, None]
        cov = np.einsum("msnd,msne->mnde", dev, dev) / (n_draws - 1)
        idx = np.arange(2 * k)
        cov[..., idx, idx] += self.noise[:, sets, :].reshape(m, n_sets, 2 * k)
        chol = np.linalg.cholesky(cov)
        inv = np.linalg.inv(chol)
        logdet = 2.0 * np.log(np.diagonal(chol, axis1=-2, axis2=-1)).sum(axis=-1)
        return mu, chol, inv, logdet

    def simulate(self, sets, n: int, rng):
        """``n`` measurements of each set from each structure's predictive, and their log
        densities under every structure: (M_true, n, n_sets, 2k), (M_true, M, n, n_sets)."""
        mu, chol, inv, logdet = self._normals(sets)
        m, n_sets, d = mu.shape
        # The same standard normals for every set (common random numbers): the sets'
        # estimates differ by what the sets do, not by the Monte Carlo draws.
        e = np.broadcast_to(rng.standard_normal((m, n, 1, d)), (m, n, n_sets, d))
        y = mu[:, None] + np.einsum("mnde,mNne->mNnd", chol, e)
        diff = y[:, None] - mu[None, :, None]  # (M_true, M, n, n_sets, d)
        x = np.einsum("knde,tkNne->tkNnd", inv, diff)
        log_p = (-0.5 * np.einsum("...d,...d->...", x, x) - 0.5 * logdet[None, :, None, :]
                 - 0.5 * d * math.log(2.0 * math.pi))
        return y, log_p

    def information(self, sets, log_prior, rng, n: int = None):
        """I(M; y_set) [nats] of each candidate set (n_sets,), and the log densities."""
        _, log_p = self.simulate(sets, n or N_Y, rng)
        m = log_p.shape[0]
        own = log_p[np.arange(m), np.arange(m)]  # (M, n, n_sets)
        mix = logsumexp(log_p + log_prior[None, :, None, None], axis=1)  # (M, n, n_sets)
        info = np.einsum("m,mn->n", np.exp(log_prior), (own - mix).mean(axis=1))
        return np.maximum(info, 0.0), log_p


def _relative_sigma(data) -> float:
    """The data's median relative σ (NaN without σ): the noise of a new point under known σ."""
    if data.sigma is None:
        return math.nan
    return float(np.median(data.sigma / np.abs(data.response)))


def _draws_at(r, omega, kind, rel_sigma, rng, n_draws: int = N_DRAWS):
    """Up to ``n_draws`` posterior draws of one structure whose response at ``omega`` is finite,
    their responses in (ln|G|, arg G) (draws, frequencies, 2), and the mean noise variance of a
    measurement there (frequencies, 2)."""
    post = r.posterior
    pick = rng.choice(post.samples.shape[0], size=min(n_draws, post.samples.shape[0]),
                      replace=False)
    draws = post.samples[pick]
    with np.errstate(all="ignore"):
        g = r.structure.response(draws[:, : r.structure.n_params], omega, kind)
    ok = np.all(np.isfinite(g) & (g != 0), axis=1)
    draws, g = draws[ok], g[ok]
    if len(draws) < 20:
        raise InputError("design: too few posterior draws with a finite response in the window")
    z = np.stack([np.log(np.abs(g)), np.angle(g)], axis=-1)
    return draws, z, _noise_var(r, draws, g, rel_sigma).mean(axis=0)


def _predictive(results, omega, kind, rel_sigma, rng) -> _Predictive:
    """The posterior predictive of each structure at ``omega`` (see :class:`_Predictive`)."""
    zs, noise = [], []
    for r in results:
        _, z, v = _draws_at(r, omega, kind, rel_sigma, rng)
        zs.append(z)
        noise.append(v)
    n = min(len(z) for z in zs)
    return _Predictive(np.stack([z[:n] for z in zs]), np.stack(noise))


def _checked(data, window, points, cost) -> tuple[float, float]:
    """The window (default: the data's, a decade wider on each side), after checking it,
    ``points`` and ``cost``."""
    if cost not in COSTS:
        raise InputError(f"argument 'cost' must be one of {', '.join(COSTS)}, got {cost!r}",
                         option="cost")
    if isinstance(points, bool) or not isinstance(points, (int, np.integer)) \
            or not 1 <= points <= 20:
        raise InputError(f"argument 'points' must be an integer from 1 to 20, got {points!r}",
                         option="points")
    if window is None:
        window = (float(data.omega.min()) / 10.0, float(data.omega.max()) * 10.0)
    try:
        w_lo, w_hi = (float(w) for w in window)
    except (TypeError, ValueError):
        raise InputError(f"argument 'window' must be two frequencies (low, high) in rad/s, "
                         f"got {window!r}", option="window") from None
    if not (0 < w_lo < w_hi and math.isfinite(w_hi)):
        raise InputError(f"argument 'window' must have 0 < low < high, got ({w_lo:g}, {w_hi:g})",
                         option="window")
    return w_lo, w_hi


#: How far beyond the measured frequencies [decades] a proposed frequency may lie: the
#: structures' predictions further out are extrapolations that the data do not constrain (a
#: window of 1e-6 to 1e6 rad/s proposed 1e6, four decades beyond the data, with an "expected
#: change" of ln B of -128350).
MAX_REACH_DECADES = 3.0


def capped_window(data, w_lo: float, w_hi: float) -> tuple[float, float, str | None]:
    """The window cut to :data:`MAX_REACH_DECADES` beyond the data's frequencies, and a note
    saying so where it was (else None)."""
    reach = 10.0 ** MAX_REACH_DECADES * (1 + 1e-9)  # a window just at the reach is kept
    lo = max(w_lo, float(data.omega.min()) / reach)
    hi = min(w_hi, float(data.omega.max()) * reach)
    if lo >= hi:
        raise InputError(f"argument 'window' ({w_lo:.4g}, {w_hi:.4g}) lies wholly more than "
                         f"{MAX_REACH_DECADES:g} decades beyond the measured frequencies "
                         f"({float(data.omega.min()):.4g}-{float(data.omega.max()):.4g} "
                         "rad/s), where the data constrain no prediction; give a window that "
                         "reaches nearer", option="window")
    if (lo, hi) == (w_lo, w_hi):
        return w_lo, w_hi, None
    return lo, hi, (f"the window {w_lo:.4g}-{w_hi:.4g} rad/s is cut to {lo:.4g}-{hi:.4g} rad/s, "
                    f"{MAX_REACH_DECADES:g} decades beyond the measured frequencies at most: "
                    "further out the structures' predictions are extrapolations the data do "
                    "not constrain")


def _named_notes(ranked, names) -> list[str]:
    """What the user should know of the structures ``--structures`` names: the best ranked
    structure left out, and named structures that fail the posterior predictive checks (telling
    apart two that miss the data may settle nothing)."""
    notes = []
    if ranked and ranked[0].name not in names:
        notes.append(f"the best ranked structure, {ranked[0].name}, is not among those named; "
                     "their probabilities are relative to each other only")
    missing = [r.name for r in ranked if r.name in names and r.criteria.adequacy is not None
               and not r.criteria.adequacy.adequate]
    if missing:
        notes.append(f"{', '.join(missing)} {'fails' if len(missing) == 1 else 'fail'} the "
                     "posterior predictive checks: points that tell them apart may not tell "
                     "which describes the material")
    return notes


def min_spacing(log_omega: np.ndarray, information: np.ndarray) -> float:
    """The least distance [decades] between proposed frequencies: :data:`SPACING_SHARE` of the
    full width at half maximum of the single-point information about its peak, at least one
    step of the candidates' grid and at most :data:`MAX_SPACING`."""
    step = float(log_omega[1] - log_omega[0]) if log_omega.size > 1 else 0.0
    j = int(np.argmax(information))
    half = information[j] / 2.0
    if not half > 0:
        return step
    above = information >= half
    lo = j
    while lo > 0 and above[lo - 1]:
        lo -= 1
    hi = j
    while hi < above.size - 1 and above[hi + 1]:
        hi += 1
    width = float(log_omega[hi] - log_omega[lo]) + step
    return float(min(max(SPACING_SHARE * width, step), MAX_SPACING))


def all_inadequate(result, structures=None) -> list[str]:
    """The names of the structures considered (those named, else every one with a posterior,
    best first) where every one of them fails the posterior predictive checks, else ``[]``:
    then points that tell them apart would choose among descriptions that all miss the data,
    and ``bayesfo design`` plans for the best one's parameters instead."""
    # Structures left out by the evidence bound have no posterior to plan with.
    ranked = [result[n] for n in result.ranking if result[n].posterior is not None]
    if structures is not None:
        names = [structures] if isinstance(structures, str) else list(structures)
        ranked = [r for r in ranked if r.name in names]
    checked = [getattr(r.criteria, "adequacy", None) for r in ranked]
    if not ranked or any(a is None or a.adequate for a in checked):
        return []
    return [r.name for r in ranked]


def _inadequate_note(results) -> list[str]:
    """Where every structure considered fails the posterior predictive checks: points that
    tell them apart choose among descriptions that all miss the data."""
    checked = [r.criteria.adequacy for r in results
               if getattr(r.criteria, "adequacy", None) is not None]
    if len(checked) < len(results) or any(a.adequate for a in checked):
        return []
    return [f"every structure considered ({', '.join(r.name for r in results)}) fails the "
            "posterior predictive checks: the proposed points tell apart descriptions that all "
            "miss the data; a structure that describes them is wanted first, or measure where "
            f"the best one's parameters are least determined (--parameter NAME on "
            f"{results[0].name})"]


def design(result, *, window=None, points: int = 3, structures=None, cost: str = "uniform",
           seed: int = 0) -> Design:
    """The frequencies to measure next to tell the structures of ``result`` apart.

    Parameters
    ----------
    result : Comparison
        From :func:`bayesfo.compare` or :func:`bayesfo.load`.
    window : (float, float), optional
        The instrument's frequency window [rad/s] (default: the data's, a decade wider on each
        side).
    points : int
        How many frequencies to propose (1-20).
    structures : sequence of str, optional
        The structures to tell apart (default: every one with a posterior probability of at
        least :data:`MIN_PROBABILITY`, at most :data:`MAX_STRUCTURES`).
    cost : {"uniform", "low-frequency"}
        ``low-frequency`` chooses by information per second of measuring time.
    seed : int

    Returns
    -------
    Design

    Raises
    ------
    InputError
        Fewer than two structures to tell apart, a window that is not two positive increasing
        frequencies, an unknown cost or structure.
    """
    if isinstance(result, MasterCurve):
        raise InputError("design: a master curve is not a comparison of structures; design "
                         "on a comparison (e.g. of the master curve's master_data())")
    data = result.data
    lo_d, hi_d = float(data.omega.min()), float(data.omega.max())
    w_lo, w_hi = _checked(data, window, points, cost)
    w_lo, w_hi, cut = capped_window(data, w_lo, w_hi)
    # Structures left out by the evidence bound have no posterior to plan with.
    ranked = [result[n] for n in result.ranking if result[n].posterior is not None]
    notes = [] if cut is None else [cut]
    if structures is not None:
        names = [structures] if isinstance(structures, str) else list(structures)
        known = {r.name for r in ranked}
        for n in names:
            if n not in known:
                raise InputError(f"design: no structure '{n}' with a posterior in the "
                                 f"comparison; it has {', '.join(sorted(known))}")
        notes += _named_notes(ranked, names)
        ranked = [r for r in ranked if r.name in names]
    # Probabilities from ln Z over the structures considered, equal prior odds.
    log_z = np.array([-np.inf if r.log_z is None else r.log_z for r in ranked])
    with np.errstate(invalid="ignore"):
        probs = np.exp(log_z - log_z.max()) if np.isfinite(log_z).any() else np.zeros(len(ranked))
    probs = probs / probs.sum() if probs.sum() > 0 else probs
    keep = [i for i in range(len(ranked)) if probs[i] >= MIN_PROBABILITY][:MAX_STRUCTURES]
    if len(keep) < 2:
        leader = ranked[0].name if ranked else "none"
        among = " among those --structures names" if structures is not None else ""
        raise InputError(
            "design needs two or more structures that could still win; "
            + (f"{leader} has posterior probability {probs[0]:.4f}{among} and the others "
               f"below {MIN_PROBABILITY:g}: the choice is settled by these data (--parameter "
               f"NAME instead proposes the frequencies that best determine a parameter of "
               f"{leader})"
               if len(ranked) > 1 else "the comparison has one structure with a posterior"))
    if len(keep) < sum(probs >= MIN_PROBABILITY):
        notes.append(f"the {MAX_STRUCTURES} most probable structures are considered")
    results = [ranked[i] for i in keep]
    notes += _inadequate_note(results)
    p = probs[keep] / probs[keep].sum()
    log_prior = np.log(p)
    entropy = float(-np.sum(p * np.log(p)))
    omega = np.logspace(math.log10(w_lo), math.log10(w_hi), N_CANDIDATES)
    rel = _relative_sigma(data)
    rng = np.random.default_rng(seed)
    # Rules of thumb, inside the window: as many points log-uniform over it, or over the
    # decade below (above) the data where the window reaches there.
    extra = {"log-uniform": np.logspace(math.log10(w_lo), math.log10(w_hi), points + 2)[1:-1]}
    below = (max(w_lo, lo_d / 10.0), min(lo_d, w_hi))
    above = (max(hi_d, w_lo), min(hi_d * 10.0, w_hi))
    if below[1] > below[0] * 1.01:
        extra["decade below"] = np.logspace(*np.log10(below), points + 1)[:-1]
    if above[1] > above[0] * 1.01:
        extra["decade above"] = np.logspace(*np.log10(above), points + 1)[1:]
    grid = np.concatenate([omega, *extra.values()])
    pred = _predictive(results, grid, data.kind, rel, rng)
    c = np.arange(omega.size)
    single, _ = pred.information(c[:, None], log_prior, rng)
    time = seconds(omega)
    log_w = np.log10(omega)
    spacing = min_spacing(log_w, single)
    chosen, proposed, info_so_far = [], [], 0.0
    for _ in range(points):
        # The first point's information is the candidates' own (the same estimate, so that the
        # proposal and the curve drawn of the candidates agree); later ones that of the set.
        info = single if not chosen else pred.information(
            np.array([chosen + [j] for j in c]), log_prior, rng)[0]
        gains = info - info_so_far
        # Distinct frequencies, as a sweep measures them, and apart by the spacing.
        for k in chosen:
            gains[np.abs(log_w - log_w[k]) < spacing - 1e-9] = -np.inf
        gains[chosen] = -np.inf
        if chosen and not np.isfinite(gains).any():
            notes.append(f"after {len(chosen)} point(s) no frequency of the window lies "
                         f"{spacing:.2f} decades or more from those proposed (the width of "
                         "the information's peak)")
            break
        if chosen and gains.max() < max(NEGLIGIBLE, NEGLIGIBLE_SHARE * entropy):
            notes.append(f"after {len(chosen)} point(s) no further frequency of the window "
                         "adds measurable information: the rest of the choice lies beyond the "
                         "window's reach")
            break
        score = gains / time if cost == "low-frequency" else gains
        j = int(np.argmax(score))
        # A point cannot remove information: a negative gain is Monte Carlo noise about none.
        total = max(float(info[j]), info_so_far)
        proposed.append({"omega": float(omega[j]), "information": total,
                         "gain": total - info_so_far, "seconds": float(time[j])})
        chosen.append(j)
        info_so_far = total
    offset = omega.size
    alternatives = {}
    for name, w in extra.items():
        cols = np.arange(offset, offset + w.size)[None, :]
        offset += w.size
        alternatives[name] = float(pred.information(cols, log_prior, rng)[0][0])
    # The two leading structures' ln B after the proposed points.
    z = [math.nan if r.log_z is None else r.log_z for r in results[:2]]
    ln_b = z[0] - z[1]
    _, log_p = pred.information(np.array([chosen]), log_prior, rng, n=4 * N_Y)
    delta = log_p[:, 0, :, 0] - log_p[:, 1, :, 0]  # (M_true, n): ln p(y|first) − ln p(y|second)
    expected = {results[m].name: float(delta[m].mean()) for m in (0, 1)}
    base = ln_b if math.isfinite(ln_b) else 0.0
    p_decisive = float(np.sum(p * (np.abs(base + delta) > DECISIVE).mean(axis=1)))
    if not math.isfinite(ln_b):
        notes.append("the leading structures have no ln Z: the change of ln B is stated "
                     "without its present value")
    return Design(omega=omega, information=single, proposed=tuple(proposed),
                  structures=tuple(r.name for r in results), probabilities=tuple(map(float, p)),
                  entropy=entropy, leading=(results[0].name, results[1].name),
                  log_bayes_factor=float(ln_b), expected_change=expected,
                  p_decisive=p_decisive, alternatives=alternatives, window=(w_lo, w_hi),
                  cost=cost, notes=tuple(notes), asked=int(points), spacing=spacing)
