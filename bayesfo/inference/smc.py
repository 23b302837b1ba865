"""Log-evidence by sequential Monte Carlo over a tempered ladder (stepping-stone sampling).

A population of particles drawn from the prior (restricted to its support) is carried through
the tempered posteriors π_β ∝ prior · L^β, β = 0 → 1. Each rung reweights the particles by
L^(β' − β), resamples them and moves them with Metropolis steps that leave π_β' invariant. The
rungs are chosen so that the reweighting keeps 80 % of the effective sample size (Jasra et al.
2011; Zhou, Johansen and Aston 2016). The product of the rungs' mean weights is the
stepping-stone estimate of ln Z (Del Moral, Doucet and Jasra 2006; Xie et al. 2011), kept in
``LadderRun.log_z``; it depends on every rung being in equilibrium and scatters between runs
far more than bridge sampling from the final particles, so
:func:`bayesfo.inference.evidence.ladder_evidence` takes ln Z by bridge sampling instead
(BENCHMARKS.md, "Measurements behind design choices").

The moves are differential-evolution proposals (ter Braak 2006) drawn from the population at
the start of the rung: u' = u + γ (u_a − u_b) for two other particles a, b. The difference of
two particles is a symmetric random-walk step whose scale follows the tempered posterior, and
γ = 1 (one move in ten) carries a particle from one mode to another, which is how the ladder
keeps every mode of a multimodal posterior (the q ↔ q/2 aliases of the max-order members) with
its proper weight: the modes are all present in the prior, and each rung only reweights them.

A mode with almost no prior mass (a narrow peak of high likelihood beside a broad region of
lower likelihood: L^β keeps it narrow at every β) is found by no prior draw and would be lost,
and ln Z with it. Given draws from elsewhere that cover the posterior's modes (``guide``: the
emcee walkers, converged or not, or the draws of the importance proposal built at the optima),
each rung also takes independence Metropolis–Hastings steps proposing from a normal mixture
fitted to the particles and one fitted to those draws, reweighted to the rung's tempered
posterior (see :class:`_Guide`); the steps are exact for the tempered posterior whatever the
guide, so it can only help the particles find modes, not bias their weights.

The error of ``ladder_evidence`` combines the bridge-sampling errors of independent runs with
their spread (the single-run variance estimators of sequential Monte Carlo degenerate once the
genealogy of the particles collapses).

References
----------
P. Del Moral, A. Doucet and A. Jasra (2006), J. R. Stat. Soc. B 68; W. Xie, P. O. Lewis, Y. Fan,
L. Kuo and M.-H. Chen (2011), Syst. Biol. 60; C. J. F. ter Braak (2006), Stat. Comput. 16;
Y. Zhou, A. M. Johansen and J. A. D. Aston (2016), J. Comput. Graph. Stat. 25; A. Jasra,
D. A. Stephens, A. Doucet and T. Tsagaris (2011), Scand. J. Stat. 38.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import logsumexp

from .. import parallel  # its Helper and SpareCPU by attribute: tests stand in for them
from ..errors import InputError
from ._mixture import _GaussianMixture
from .likelihood import Likelihood
from .transform import Transform, _log_parts_fn

#: A rung whose moves leave fewer distinct particles than this many per dimension (of the
#: 1000) ends the run with an error: the population has collapsed (see :func:`ladder_run`).
MIN_DISTINCT_PER_DIM = 10

#: Draws of the mixture fitted to the guide added to the guide's own before they are reweighted
#: to each rung (:class:`_Guide`): their density is known exactly, and they give the reweighted
#: set enough distinct points in a narrow mode where the guide has few.
GUIDE_EXTRA = 4000

#: The share of an independence step's proposal given to the slabs of the configurations where
#: an element vanishes (:mod:`~bayesfo.inference._configurations`), where there are any.
SLAB_SHARE = 0.2


@dataclass(frozen=True)
class LadderRun:
    """One sequential Monte Carlo run: its stepping-stone ln Z, the rungs β, the final particles
    (in the sampling coordinates u), their log-likelihoods and the acceptance rate per rung."""

    log_z: float
    betas: np.ndarray
    particles: np.ndarray
    log_likelihood: np.ndarray
    acceptance: np.ndarray
    n_likelihood: int
    #: ln Z and its error by bridge sampling from the final particles, where
    #: :func:`~bayesfo.inference.evidence.ladder_runs` computed them (the run's share of the
    #: evidence; runs of a later call that adds runs are combined with them).
    bridge: tuple[float, float] | None = None


class _Target:
    """Log prior (in the sampling coordinates u) and log-likelihood of a batch of particles,
    counting the likelihood evaluations."""

    def __init__(self, lik: Likelihood):
        self.lik = lik
        self.tr = Transform(lik)
        self._parts = _log_parts_fn(lik, self.tr)
        self._box_parts = _log_parts_fn(lik, self.tr, constraints=False)

    def __call__(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self._parts(u)

    def unchecked(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """As a call, but without the structure's constraints (stability, dissipation,
        inequalities): only the prior box. :func:`_accept` checks them where a move would
        be accepted."""
        return self._box_parts(u)

    def holds(self, u: np.ndarray) -> np.ndarray:
        """The structure's constraints at points of the prior box."""
        k = self.lik.structure.n_params
        return self.lik.structure.constraints_hold(self.tr.to_theta(u)[:, :k],
                                                   self.lik.data.kind, self.lik.grid)


def _accept(prop, u, log_prior, log_lik, beta: float, log_uniform, log_q_prop=0.0,
            log_q_cur=0.0):
    """Metropolis–Hastings acceptance (in place) of ``prop`` for prior · L^β, with the proposal
    densities ``log_q_prop`` at the proposals and ``log_q_cur`` at the current points (both 0
    for a symmetric proposal); returns the accepted rows.

    The constraints are part of the prior (its indicator): a proposal outside them has ratio 0.
    They are checked only where the rest of the ratio would accept, which gives the same
    decisions from the same uniforms as checking them first, without the constraint checks of
    every rejected proposal (most of them at the acceptance rates of the later rungs): the
    stability test, and the dissipation check (exact for commensurate structures, on a dense
    grid for the others).

    A generator (as every step of a run, see :func:`_drive`): it yields its evaluations,
    ``("unchecked", points)`` and ``("holds", points)``, and returns the accepted rows.
    """
    lp_new, ll_new = yield "unchecked", prop
    with np.errstate(invalid="ignore"):
        log_ratio = ((lp_new + beta * ll_new - log_q_prop)
                     - (log_prior + beta * log_lik - log_q_cur))
    ok = log_uniform < np.where(np.isfinite(log_ratio), log_ratio, -np.inf)
    rows = np.flatnonzero(ok)
    if rows.size:
        ok[rows] = yield "holds", prop[rows]
    u[ok], log_prior[ok], log_lik[ok] = prop[ok], lp_new[ok], ll_new[ok]
    return ok


def _prior_particles(target: _Target, n: int, rng: np.random.Generator,
                     max_draws: int = 5_000_000) -> np.ndarray:
    """``n`` prior draws in the support (by rejection), in the sampling coordinates.

    Each batch is sized by the admissible fraction seen so far (the support check costs several
    times a likelihood evaluation per draw, so drawing far more than needed is not free). The
    search gives up once even a generous upper bound of that fraction (:func:`_upper_count`)
    leaves fewer than ``n`` admissible draws within ``max_draws``: drawing on would, all but
    surely, end with the same error, later."""
    lik = target.lik
    batch = 2 * n
    kept, drawn, found = [], 0, 0
    while found < n:
        if drawn >= max_draws or found + _upper_count(found, drawn, max_draws - drawn) < n:
            raise InputError(
                f"structure '{lik.structure.name}': only {found} of {drawn} prior draws are "
                f"stable and dissipative, too few to start the tempered ladder (it needs {n} "
                f"within {max_draws} draws)")
        theta = np.column_stack([p.sample(rng, batch) for p in lik.prior_list])
        drawn += batch
        theta = theta[lik.in_support(theta)]
        kept.append(target.tr.to_u(theta))
        found += len(theta)
        fraction = max(found, 1) / drawn
        batch = int(min(max(1.5 * (n - found) / fraction, n), 20 * n, 200_000))
    return np.concatenate(kept)[:n]


#: Standard deviations by which :func:`_upper_count` overstates the admissible fraction seen
#: (the search gives up only where the fraction is far below what ``n`` draws would need).
UPPER_SD = 5.0


def _upper_count(found: int, drawn: int, more: int) -> float:
    """A generous upper bound of the admissible draws among ``more`` further prior draws,
    after ``found`` of ``drawn``: the rate's bound (found + z²/2 + z √(found + z²/4)) / drawn,
    the upper end of Wilson's score interval (z = :data:`UPPER_SD`) made larger still by
    leaving out its factors below one, times ``more``; infinite before the first draw."""
    if drawn <= 0:
        return math.inf
    z = UPPER_SD
    return (found + z * z / 2 + z * math.sqrt(found + z * z / 4)) / drawn * more


def unique_rows(x: np.ndarray) -> np.ndarray:
    """The distinct rows of ``x`` (finite values) in lexicographic order: ``np.unique(x,
    axis=0)``, by a lexicographic sort of the columns instead of a sort of the rows as
    records, which is faster on the ladder's particles and guide draws (BENCHMARKS.md,
    "The ladder's distinct rows")."""
    x = np.asarray(x)
    if len(x) < 2:
        return x.copy()
    s = x[np.lexsort(x.T[::-1])]
    keep = np.empty(len(s), dtype=bool)
    keep[0] = True
    np.any(s[1:] != s[:-1], axis=1, out=keep[1:])
    return s[keep]


def _systematic(log_w: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    w = np.exp(log_w - logsumexp(log_w))
    n = w.size
    positions = (rng.random() + np.arange(n)) / n
    return np.minimum(np.searchsorted(np.cumsum(w), positions), n - 1)


def _next_beta(beta: float, log_lik: np.ndarray, ess_fraction: float) -> float:
    """The largest β' ≤ 1 whose weights L^(β' − β) keep ``ess_fraction`` of the sample size.

    The bisection evaluates the ESS 60 times per rung; with the weights shifted by their
    maximum it is (Σw)²/Σw² directly (scipy's ``logsumexp``, twice per evaluation, cost a
    noticeable share of a tempered-ladder run in its argument checks: BENCHMARKS.md,
    "Measurements behind design choices")."""
    finite = log_lik[np.isfinite(log_lik)]
    n = log_lik.size
    if not finite.size:
        return 1.0

    def ess(b):
        lw = (b - beta) * finite
        w = np.exp(lw - lw.max())
        return float(np.sum(w)) ** 2 / float(np.dot(w, w)) / n

    if ess(1.0) >= ess_fraction:
        return 1.0
    lo, hi = beta, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if ess(mid) >= ess_fraction:
            lo = mid
        else:
            hi = mid
    return max(lo, beta + 1e-12)


def ladder_run(lik: Likelihood, rng: np.random.Generator, *, n_particles: int = 1000,
               ess_fraction: float = 0.8, accepted_moves: float = 5.0, max_moves: int = 100,
               jump_fraction: float = 0.1, max_rungs: int = 2000, guide=None,
               guided_moves: int = 2, own_moves: int = 3, final_moves: int = 30,
               slabs=()) -> LadderRun:
    """One sequential Monte Carlo run from the prior to the posterior of ``lik``.

    At each rung the particles take Metropolis steps until each has made ``accepted_moves``
    accepted moves on average (at most ``max_moves`` steps). Where fewer than one step in
    twenty is accepted (the late rungs of the Maxwell and the max-order members) the cap sets
    the cost; elsewhere the target does. The default of 5 accepted moves takes fewer likelihood
    evaluations than 10 and leaves ln Z where it was (BENCHMARKS.md, "Measurements behind
    design choices").

    ``guide`` (draws in the sampling coordinates, e.g. emcee's) adds ``guided_moves``
    independence Metropolis–Hastings steps per rung, proposing from an equal mixture of a
    normal mixture fitted to the particles and one fitted to the guide reweighted to the
    rung's tempered posterior (:class:`_Guide`). They leave each tempered posterior invariant,
    whatever the guide, and let particles reach a narrow mode of high likelihood that none of
    them found by chance at small β (a mode with little prior mass is otherwise lost, and ln Z
    with it); the guide's mixture at β = 1 also takes part in the ``final_moves``. Without a
    guide, ``own_moves`` such steps propose from the mixture fitted to the particles alone,
    and ``final_moves`` more are taken at β = 1: they
    move particles between distant regions of the posterior, which the differential-evolution
    steps connect only through a narrow neck. These moves, with ``ess_fraction=0.8``, let the
    two runs of :func:`ladder_runs` agree on a posterior of two arms that meet in such a neck
    (BENCHMARKS.md, "Measurements behind design choices").

    ``slabs`` (the slabs and ways of :func:`~bayesfo.inference._configurations.configurations`:
    regions where an element vanishes, which no optimum seeds) join the proposal of every
    independence step with :data:`SLAB_SHARE` of its weight, at every rung: the differential-
    evolution moves cannot reach a region that no particle occupies, and the particles' own
    mixture has no component there, so a region lost at one rung is otherwise not regained,
    and both runs can agree on a posterior without it (see
    :mod:`~bayesfo.inference._configurations`). The steps stay exact: the slabs' densities are
    part of the proposal's.
    """
    return ladder_runs_together(lik, [rng], n_particles=n_particles, ess_fraction=ess_fraction,
                                accepted_moves=accepted_moves, max_moves=max_moves,
                                jump_fraction=jump_fraction, max_rungs=max_rungs,
                                guides=[guide], guided_moves=guided_moves, own_moves=own_moves,
                                final_moves=final_moves, slabs=slabs)[0]


def ladder_runs_together(lik: Likelihood, rngs, *, guides=None, **kwargs) -> list[LadderRun]:
    """Independent runs of :func:`ladder_run`, one per generator of ``rngs`` (with the guide
    of the same index in ``guides``), advanced in lock-step: the evaluations that the runs
    need at the same time are made in one batch.

    Each run draws from its own generator and decides alone (its rungs, its moves), so its
    result is that of :func:`ladder_run` with the same generator; only the batching differs.
    Why: a run takes thousands of Metropolis steps, each one or two evaluation calls of hundreds
    of points, and each call has a fixed cost (the likelihood's and the constraint checks') that
    runs in one call pay once, so runs in lock-step take less time than one after the other
    (BENCHMARKS.md, "Measurements behind design choices").
    """
    guides = [None] * len(rngs) if guides is None else list(guides)
    if len(guides) != len(rngs):
        raise ValueError("guides must have one entry per generator of rngs")
    target = _Target(lik)
    return _drive(target, [_ladder_steps(lik, target, rng, guide=guide, **kwargs)
                           for rng, guide in zip(rngs, guides, strict=True)])


def _drive(target: _Target, runs: list) -> list:
    """Advance generators that yield evaluation requests ``(kind, points)`` (``kind`` one of
    ``"call"``, ``"unchecked"``, ``"holds"``: the methods of :class:`_Target`) until each
    returns; the requests of the same kind pending at once are evaluated in one call. Returns
    the generators' return values.

    In a pool's worker, once a CPU has been idle of late (:class:`~bayesfo.parallel.SpareCPU`:
    the other workers have run out of work), half of the runs still going move to a process
    forked from this one (:class:`~bayesfo.parallel.Helper`), which finishes them and sends
    their results back; a run's result does not depend on the runs it is advanced with, so the
    numbers are the same. Where the helper fails, the runs go on here from where it took them.
    """
    out = [None] * len(runs)
    pending = {}

    def advance(i, value):
        try:
            pending[i] = runs[i].send(value)
        except StopIteration as stop:
            out[i] = stop.value
            pending.pop(i, None)

    def step():
        kinds = {}
        for i, (kind, _) in pending.items():
            kinds.setdefault(kind, []).append(i)
        for kind, members in kinds.items():
            points = [pending[i][1] for i in members]
            fn = target if kind == "call" else getattr(target, kind)
            values = fn(points[0] if len(points) == 1 else np.concatenate(points))
            cuts = np.cumsum([len(x) for x in points])[:-1]
            if isinstance(values, tuple):
                parts = list(zip(*(np.split(v, cuts) for v in values), strict=True))
            else:
                parts = np.split(values, cuts)
            for i, part in zip(members, parts, strict=True):
                advance(i, part)

    def finish(moved):  # in the helper: the moved runs alone
        for i in [i for i in pending if i not in moved]:
            del pending[i]
        while pending:
            step()
        return {i: out[i] for i in moved}

    for i in range(len(runs)):
        advance(i, None)
    spare = parallel.SpareCPU() if len(runs) > 1 else None
    helper = kept = None
    try:
        while pending:
            if helper is None and len(pending) > 1 and spare is not None and spare.now():
                moved = tuple(sorted(pending)[len(pending) // 2:])
                helper = parallel.Helper(lambda: finish(moved))
                kept = {i: pending.pop(i) for i in moved}  # their requests, for a failure
            step()
        if helper is not None:
            done, helper = helper.result(), None
            if done is None:  # the helper failed: the moved runs go on here
                pending.update(kept)
                while pending:
                    step()
            else:
                for i, value in done.items():
                    out[i] = value
    finally:
        if helper is not None:  # a run here raised: the helper's work is not wanted
            helper.stop()
    return out


def _ladder_steps(lik: Likelihood, target: _Target, rng: np.random.Generator, *,
                  n_particles: int = 1000, ess_fraction: float = 0.8,
                  accepted_moves: float = 5.0, max_moves: int = 100,
                  jump_fraction: float = 0.1, max_rungs: int = 2000, guide=None,
                  guided_moves: int = 2, own_moves: int = 3, final_moves: int = 30,
                  slabs=()):
    """The body of :func:`ladder_run`, as a generator of evaluation requests (:func:`_drive`)
    that returns the run."""
    calls = 0

    def evaluate(kind, x):
        nonlocal calls
        values = yield kind, x
        if kind != "holds":
            calls += int(np.count_nonzero(np.isfinite(values[0])))
        return values

    def count(gen):
        # The requests of a step (moves), counted as they pass.
        value = None
        while True:
            try:
                kind, x = gen.send(value)
            except StopIteration as stop:
                return stop.value
            value = yield from evaluate(kind, x)

    u = _prior_particles(target, n_particles, rng)
    log_prior, log_lik = yield from evaluate("call", u)
    n, d = u.shape
    guide_at = None
    if guide is not None:
        guide = np.asarray(guide, dtype=float)
        guide = guide[np.all(np.isfinite(guide), axis=1)]
        if len(guide) >= 10 * d:
            guide_at = _Guide(guide, rng)
            guide_at.evaluated(*(yield from evaluate("call", guide_at.draws)))
    gamma = 2.38 / math.sqrt(2 * d)
    beta, log_z = 0.0, 0.0
    betas, acceptance = [0.0], []
    for _ in range(max_rungs):
        if beta >= 1.0:
            break
        new_beta = _next_beta(beta, log_lik, ess_fraction)
        log_w = (new_beta - beta) * log_lik
        log_z += float(logsumexp(log_w) - math.log(n))
        idx = _systematic(log_w, rng)
        u, log_prior, log_lik = u[idx], log_prior[idx], log_lik[idx]
        beta = new_beta
        betas.append(beta)
        if guide_at is None:
            yield from count(_guided_moves(None, u, log_prior, log_lik, beta, rng, own_moves,
                                           slabs))
        else:
            yield from count(_guided_moves(guide_at.mixture(beta, rng), u, log_prior, log_lik,
                                           beta, rng, guided_moves, slabs))
        snapshot = u.copy()
        accepted = np.zeros(n)
        steps = 0
        while steps < max_moves and accepted.mean() < accepted_moves:
            a = rng.integers(n, size=n)
            b = (a + rng.integers(1, n, size=n)) % n
            g = np.where(rng.random(n) < jump_fraction, 1.0, gamma)
            # u + g (snapshot[a] − snapshot[b]), in place (the same numbers, in less time than
            # the expression: BENCHMARKS.md, "Measurements behind design choices").
            prop = np.take(snapshot, a, axis=0)
            prop -= np.take(snapshot, b, axis=0)
            prop *= g[:, None]
            prop += u
            accepted += yield from count(_accept(prop, u, log_prior, log_lik, beta,
                                                 np.log(rng.random(n))))
            steps += 1
        acceptance.append(accepted.mean() / max(steps, 1))
        distinct = len(unique_rows(u))
        if distinct < min(MIN_DISTINCT_PER_DIM * d, n):
            # Even the smallest rung put all the weight on a few particles, and the moves
            # cannot spread copies of one point (their differences are 0): the likelihood is
            # so peaked, relative to the prior, that no prior draw comes near its mass (e.g. a
            # structure that cannot describe the data, log L of order -1e13). ln Z would be
            # meaningless; the callers take emcee's draws (bridge sampling) instead.
            raise InputError(
                f"structure '{lik.structure.name}': the tempered ladder collapsed to {distinct} "
                f"distinct particle(s) at β = {beta:.3g} (the likelihood is too peaked for the "
                "particles drawn from the prior to follow)")
    else:
        raise InputError(f"structure '{lik.structure.name}': the tempered ladder did not reach "
                         f"the posterior in {max_rungs} rungs")
    # At the posterior, the independence moves redistribute the particles between the regions
    # of a posterior made of several (the Maxwell's two arms, where either springpot vanishes):
    # the ladder sets the regions' shares only up to the noise of its resampling. The guide's
    # mixture at β = 1 takes part: a narrow mode that holds few particles gets no component of
    # the particles' own mixture.
    yield from count(_guided_moves(None if guide_at is None else guide_at.mixture(1.0, rng), u,
                                   log_prior, log_lik, 1.0, rng, final_moves, slabs))
    return LadderRun(log_z=log_z, betas=np.array(betas), particles=u, log_likelihood=log_lik,
                     acceptance=np.array(acceptance), n_likelihood=calls)


class _Guide:
    """Draws that cover the posterior's modes (``guide`` of :func:`ladder_run`), turned into a
    proposal for each rung: a normal mixture fitted to the draws resampled with weights
    prior · L^β / g, where g is the mixture fitted to the draws themselves (their density,
    approximately).

    Why the reweighting: the draws of the importance proposal (multivariate t components at the
    optima, with tails wide enough for its weights) are far broader than a narrow mode of the
    posterior, and a mixture fitted to them as they are proposes into that mode too rarely to
    be accepted there: guided by the draws as they are, runs miss the narrow modes, and ln Z
    with them; reweighted, they find every mode with its share. Each run of
    :func:`~bayesfo.inference.evidence.ladder_runs` has half the draws, with which a narrow mode
    can get too small a share unless :data:`GUIDE_EXTRA` draws of g, whose density is exact, are
    added before the reweighting (BENCHMARKS.md, "Measurements behind design choices"). Where
    the reweighted draws are too few distinct points for a mixture (at small β, where the
    weights follow 1/g), the mixture of the draws as they are is used.
    """

    def __init__(self, draws: np.ndarray, rng: np.random.Generator):
        self.fitted = _GaussianMixture.fit(draws, rng)
        self.draws = np.concatenate([draws, self.fitted.sample(GUIDE_EXTRA, rng)])

    def evaluated(self, log_prior: np.ndarray, log_lik: np.ndarray) -> _Guide:
        """Keep the draws in the support, with their prior and likelihood (at ``draws``)."""
        draws = self.draws
        ok = np.isfinite(log_prior) & np.isfinite(log_lik)
        self.draws = draws[ok]
        self.log_base = log_prior[ok] - self.fitted.log_pdf(self.draws)
        self.log_lik = log_lik[ok]
        return self

    def mixture(self, beta: float, rng: np.random.Generator) -> _GaussianMixture:
        """The proposal at the tempered posterior prior · L^β."""
        d = self.draws.shape[1]
        if len(self.draws) < 10 * d:
            return self.fitted
        idx = _systematic(self.log_base + beta * self.log_lik, rng)
        x = unique_rows(self.draws[idx])
        if len(x) < 10 * d:
            return self.fitted
        return _GaussianMixture.fit(x, rng) or self.fitted


def _guided_moves(guide_mix: _GaussianMixture | None, u, log_prior, log_lik, beta: float,
                  rng: np.random.Generator, steps: int, slabs=()):
    """Independence Metropolis–Hastings steps (in place) targeting prior · L^β, proposing from
    ½ (mixture fitted to the particles) + ½ (``guide_mix``), or from the particles' mixture
    alone without a guide; ``slabs`` (configurations where an element vanishes) take
    :data:`SLAB_SHARE` of the proposal's weight, in equal parts, from the others."""
    if steps <= 0:
        return
    n, d = u.shape
    unique = unique_rows(u)
    own = _GaussianMixture.fit(unique, rng) if len(unique) >= 10 * d else None
    if own is None:
        return
    parts = [own] if guide_mix is None else [own, guide_mix]
    if slabs:
        weights = ([(1.0 - SLAB_SHARE) / len(parts)] * len(parts)
                   + [SLAB_SHARE / len(slabs)] * len(slabs))
        parts += list(slabs)
        log_weights = np.log(weights)

    def log_q(x):
        if len(parts) == 1:
            return own.log_pdf(x)
        if not slabs:  # the two halves, as before there were slabs (the same numbers)
            return np.logaddexp(own.log_pdf(x), guide_mix.log_pdf(x)) - math.log(2.0)
        return logsumexp([lw + p.log_pdf(x) for lw, p in zip(log_weights, parts, strict=True)],
                         axis=0)

    log_q_u = log_q(u)  # kept up to date as moves are accepted, not evaluated again
    for _ in range(steps):
        if len(parts) == 1:
            prop = own.sample(n, rng)
        elif not slabs:
            from_guide = rng.random(n) < 0.5
            prop = np.where(from_guide[:, None], guide_mix.sample(n, rng), own.sample(n, rng))
        else:
            which = rng.choice(len(parts), size=n, p=weights)
            prop = np.empty_like(u)
            for i, part in enumerate(parts):
                rows = np.flatnonzero(which == i)
                if rows.size:
                    prop[rows] = part.sample(rows.size, rng)
        log_q_prop = log_q(prop)
        ok = yield from _accept(prop, u, log_prior, log_lik, beta, np.log(rng.random(n)),
                                log_q_prop, log_q_u)
        log_q_u[ok] = log_q_prop[ok]
