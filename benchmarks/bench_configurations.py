"""A posterior region that no optimum seeds: the spring of a fractional Zener that vanishes.

The data set is number 44 of the fractional_zener_sl calibration with seed 16
(``bench_calibration_routes.py --card fractional_zener_sl --seed 16``; 25 frequencies
0.6-300 rad/s, 5 % complex noise, σ known), whose truth has G_e near zero. The posterior has a
region where G_e vanishes (ln G_e from its prior bound up to where the spring matters, with a
springpot of small order and a large viscosity) beside the optimum's. Printed:

- the exact share of the posterior below G_e = 0.0646 (scaled; the lowest value of the route's
  draws before the configurations were searched) and in bins of ln G_e, by importance sampling
  from 1 000 000 draws of a proposal that covers both regions: a normal mixture fitted to the
  route's draws of the four seeds at twice their scale, and the slabs and ways of
  :func:`bayesfo.inference._configurations.configurations` at four times their scale (exact
  densities), and a tenth from the prior (defensive importance sampling), with the Pareto k̂
  of the weights (below 0.7: the estimate converges) and their ESS, and ln Z' (the log
  evidence on the support, the prior normalised on its box);
- for seeds 44-47 of ``certified_posterior`` with the configurations searched (the default) and
  without (``--without`` adds that run): the route, its seconds, the share below 0.0646 and the
  bins, and ln Z.

Usage: python benchmarks/bench_configurations.py [--without]
"""

from __future__ import annotations

import argparse
import math
import platform
import sys
import time
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.special import logsumexp

sys.path.insert(0, str(Path(__file__).parents[1] / "tests" / "integration"))
import test_configurations as setup  # noqa: E402  (the data set)

from bayesfo.inference import certified, certified_posterior  # noqa: E402
from bayesfo.inference._arviz import psis  # noqa: E402
from bayesfo.inference._configurations import _Slab, configurations  # noqa: E402
from bayesfo.inference._mixture import _GaussianMixture  # noqa: E402
from bayesfo.inference.transform import Transform, _log_prob_fn  # noqa: E402

#: Scale of the slabs and ways in the proposal of the exact computation.
SCALE = 4.0
EDGES = [-math.inf, -7.0, -5.7, -4.0, math.log(setup.LOWEST), math.inf]


def _bins(u0: np.ndarray, w=None) -> list[float]:
    w = np.full(u0.size, 1.0 / u0.size) if w is None else w
    return [round(float(w[(u0 >= a) & (u0 < b)].sum()), 3) for a, b in zip(EDGES[:-1], EDGES[1:])]


class _Box:
    """The uniform distribution on the prior box (the prior in the sampling coordinates)."""

    def __init__(self, lo, hi):
        self.lo, self.hi = lo, hi

    def sample(self, n, rng):
        return rng.uniform(self.lo, self.hi, size=(n, self.lo.size))

    def log_pdf(self, x):
        inside = np.all((x >= self.lo) & (x <= self.hi), axis=1)
        return np.where(inside, -float(np.sum(np.log(self.hi - self.lo))), -np.inf)


def _exact(lik, draws_u, slabs, n=1_000_000, seed=5):
    rng = np.random.default_rng(seed)
    tr = Transform(lik)
    log_prob = _log_prob_fn(lik, tr)
    mix = _GaussianMixture.fit(draws_u, rng)
    wide = _GaussianMixture(mix.weights, mix.means, mix.chols * 2.0)
    # The slabs and ways at SCALE times their scale: tails heavier than the posterior's.
    parts = [wide] + [replace(p, chol=SCALE * p.chol) if isinstance(p, _Slab) else
                      _GaussianMixture(p.weights, p.means, SCALE * p.chols) for p in slabs]
    # A tenth from the prior (uniform on the box in these coordinates): the weights are then
    # bounded by ten times the likelihood (defensive importance sampling, Hesterberg 1995).
    parts.append(_Box(tr.lo_u, tr.hi_u))
    weights = np.array([0.5] + [0.4 / len(slabs)] * len(slabs) + [0.1])
    which = rng.choice(len(parts), size=n, p=weights)
    x = np.empty((n, draws_u.shape[1]))
    for i, p in enumerate(parts):
        rows = np.flatnonzero(which == i)
        x[rows] = p.sample(rows.size, rng)
    log_q = logsumexp([math.log(wt) + p.log_pdf(x) for wt, p in zip(weights, parts)], axis=0)
    lp = np.concatenate([log_prob(x[i:i + 100_000]) for i in range(0, n, 100_000)])
    ok = np.isfinite(lp)
    smoothed, k_hat = psis(lp[ok] - log_q[ok])
    w = np.exp(smoothed - logsumexp(smoothed))
    u0 = x[ok, 0]
    log_z = float(logsumexp(lp[ok] - log_q[ok]) - math.log(n))
    return (float(w[u0 < math.log(setup.LOWEST)].sum()), _bins(u0, w), float(k_hat),
            float(1 / np.sum(w**2)), log_z)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--without", action="store_true")
    args = ap.parse_args()
    print(f"{platform.processor() or platform.machine()}, {platform.python_version()}")
    lik, modes, starts = setup.set_44()
    tr = Transform(lik)
    variants = [("with the configurations", None)]
    if args.without:
        variants.append(("without", lambda *a, **k: []))
    route_draws = None
    for label, patch in variants:
        saved = certified.configurations
        if patch is not None:
            certified.configurations = patch
        try:
            for seed in range(44, 48):
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    t = time.perf_counter()
                    cp = certified_posterior(lik, modes, starts=starts, seed=seed)
                    seconds = time.perf_counter() - t
                u = tr.to_u(cp.posterior.samples_scaled)
                if patch is None:  # the draws of the route with the search, every seed
                    route_draws = u if route_draws is None else np.vstack([route_draws, u])
                print(f"{label}, seed {seed}: {cp.posterior.sampler} "
                      f"{'certified' if cp.posterior.converged else 'NOT certified'}, "
                      f"{seconds:.1f} s, share below {setup.LOWEST}: "
                      f"{np.mean(u[:, 0] < math.log(setup.LOWEST)):.3f}, bins {_bins(u[:, 0])}, "
                      f"ln Z {cp.evidence.log_z:.3f} ± {cp.evidence.log_z_err:.3f}")
        finally:
            certified.configurations = saved
    slabs = configurations(lik, modes, route_draws[:0])
    if not slabs:
        raise SystemExit("no configuration found: the exact computation needs its slabs")
    share, bins, k_hat, ess, log_z = _exact(lik, route_draws, slabs)
    print(f"exact (importance sampling, 1 000 000 draws, k̂ {k_hat:.2f}, ESS {ess:.0f}): share "
          f"below {setup.LOWEST}: {share:.3f}, bins {bins}; ln Z' (on the support) {log_z:.3f}")
    bins = ", ".join(f"[{a:.2f}, {b:.2f})" for a, b in zip(EDGES[:-1], EDGES[1:]))
    print(f"bins of ln G_e: {bins}")


if __name__ == "__main__":
    main()
