"""Simulation-based calibration of one card by the default route, split by the route each
posterior took and by parameter.

The same data sets as ``tests/integration/test_calibration.py::coverage(name, n, seed,
route="default")`` (truths from the card's priors on the fixed scaling, 25 frequencies
0.6–300 rad/s, 1 % or 5 % complex noise with σ known), the posterior as ``compare`` computes it;
for each data set the rank of the truth among the posterior draws, per parameter. Printed: the
central 50 % and 90 % coverage per route and per parameter, over all data sets, and the
histogram of the ranks (ten bins; flat when the posteriors are calibrated). The same per noise
level. Where the posteriors are exact, a split by anything the data determine (the route, the
noise level) is calibrated as the whole is; the σ the data sets give, level · |G(θ_true)|,
carries the truth's |G| beyond the noisy response, so the route is a function of the data in
that wider sense only.

With ``--reference``, each data set's posterior is also computed by an independent route: two
tempered-ladder runs of 3 000 particles started from the prior without a guide (they cannot
inherit what the optima miss), the truth's rank under it printed beside the route's, and the
coverage of both over the same data sets: where the two agree, the route computes the
posterior the model defines, and a coverage off nominal is the model's (or chance), not the
route's. ``--first`` skips the first data sets (their draws are made all the same, so the data
sets are those of a full run), to split a long run over processes; ``--noise-level`` keeps only
the data sets of one noise level.

With ``--tails``, the truth's rank is also computed by importance sampling from a
heavy-tailed proposal fitted to the route's draws: a normal mixture (k ≤ 4 by BIC) whose
components become Student-t distributions (the importance route's, 5 degrees of freedom) at
twice their scale, 2 million draws. Its Pareto k̂ says whether the proposal's tails cover the
posterior's (below 0.7 the estimates converge); there, a rank that agrees with the route's says that the route's
draws represent the posterior out to its tails (a mode the route misses altogether is
``--reference``'s to find). The same draws weigh two posteriors: the tool's (σ as the data give
it) and the generative model's, whose σ is the noise level times |G(θ)| of each θ. The data
sets give σ = level · |G(θ_true)|, which depends on the truth: only under the second are the
truth's ranks uniform by construction (the first treats σ as known numbers), so the two
coverages tell the setup's effect from the tool's.

With ``--conditional``, each parameter's posterior given the others at their true values is
computed by quadrature on a grid of 200 001 points over its whole prior range (in the sampling
coordinates), and the truth's rank under it: an exact calibration of the likelihood, the prior
and the generator along each axis, which no sampler enters (the route is not run). With
``--pairs``, the same for each pair of parameters given the others: a 400 × 400 grid on a box
grown from the pair's conditional mode until the log density on each face that is not a prior
bound is 30 nats below the mode (the mode polished from the truth and from the best point of a
coarse grid over the whole prior box). ``--routes-from JSON`` (the ``--json`` of a run of the
route on the same data sets) splits these checks by the route each data set took: a subset that
the data choose is calibrated too when the posteriors are exact.

With ``--density``, beside the route's ranks: the truth's rank in posterior density (the share
of the route's draws whose log posterior density in the sampling coordinates exceeds the
truth's; uniform where the posterior is right, whatever the shape of a ridge), and where a
Nelder-Mead ascent of the log posterior from the truth ends: its squared Mahalanobis distance
(under the draws' covariance) to the nearest draw and its height against the highest draw. An
ascent that ends far from every draw, not far below the top, has found a configuration the
route's draws do not visit (``--reference`` then says how much mass it holds).

Usage: python benchmarks/bench_calibration_routes.py [--card fractional_zener_sl] [--n 300]
[--seed 14] [--first 0] [--noise-level 0.01] [--reference] [--tails] [--density]
[--conditional | --pairs] [--routes-from earlier.json] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parents[1] / "tests" / "integration"))
import test_calibration as calibration  # noqa: E402  (the study's data sets and route)

from bayesfo.data import FrequencyResponse  # noqa: E402
from bayesfo.inference import Likelihood  # noqa: E402
from bayesfo.inference.evidence import ladder_runs  # noqa: E402
from bayesfo.inference.results import posterior_from_particles  # noqa: E402
from bayesfo.structures import get_structure  # noqa: E402


def _coverage(ranks: np.ndarray, level: float) -> np.ndarray:
    half = level / 2
    return np.mean((ranks > 0.5 - half) & (ranks < 0.5 + half), axis=0)


TAIL_DRAWS = 2_000_000
TAIL_SCALE = 2.0
TAIL_BLOCK = 200_000


def _tails(lik, post, theta, level, seed) -> dict:
    """The truth's rank under importance sampling from a heavy-tailed mixture fitted to the
    route's draws (see the module's docstring), under the tool's posterior and the generative
    model's; the Pareto k̂ and ESS of the tool's weights."""
    from scipy.special import logsumexp

    from bayesfo.inference._arviz import psis
    from bayesfo.inference._mixture import _GaussianMixture
    from bayesfo.inference.importance import _mvt
    from bayesfo.inference.transform import Transform, _log_prob_fn

    rng = np.random.default_rng(seed)
    tr = Transform(lik)
    log_prob = _log_prob_fn(lik, tr)
    u = tr.to_u(lik.to_scaled(post.samples))
    mix = _GaussianMixture.fit(u, rng)
    if mix is None:  # no mixture fitted: one component at the draws' mean and covariance
        means, covs, weights = u.mean(0)[None, :], [np.cov(u.T)], np.ones(1)
    else:
        means, weights = np.asarray(mix.means), np.asarray(mix.weights)
        covs = [c @ c.T for c in mix.chols]
    factors = []
    for cov in covs:
        eig, vec = np.linalg.eigh(TAIL_SCALE**2 * cov)
        factors.append((1.0 / eig, vec))
    # The proposal's Student-t mixture (importance._mvt), drawn in blocks to bound memory.
    blocks = [_mvt(factors, means, np.log(weights), TAIL_BLOCK, rng)
              for _ in range(TAIL_DRAWS // TAIL_BLOCK)]
    x = np.vstack([b[0] for b in blocks])
    log_q = np.concatenate([blocks[0][1](b[0]) for b in blocks])
    tool = np.full(TAIL_DRAWS, -np.inf)
    generative = np.full(TAIL_DRAWS, -np.inf)
    physical = np.full(x.shape, np.nan)
    for i in range(0, TAIL_DRAWS, TAIL_BLOCK):
        block = slice(i, i + TAIL_BLOCK)
        lp = log_prob(x[block])
        tool[block] = lp
        ok = np.flatnonzero(np.isfinite(lp))
        if not ok.size:
            continue
        th = tr.to_theta(x[block][ok])
        model = lik.model(th)
        var = (level * np.abs(model)) ** 2
        own = np.sum(-np.log(np.pi * var) - np.abs(lik.g_scaled - model) ** 2 / var, axis=1)
        generative[i + ok] = lp[ok] - lik(th) + own
        physical[i + ok] = lik.to_physical(th)
    kept = np.isfinite(tool)
    out = {}
    for name, lp in (("tails", tool), ("generative", generative)):
        smoothed, k_hat = psis(lp[kept] - log_q[kept])
        w = np.exp(smoothed - logsumexp(smoothed))
        out[name] = [float(np.sum(w[physical[kept, j] < theta[j]])) for j in range(theta.size)]
        if name == "tails":
            out["k_hat"], out["ess"] = float(k_hat), float(1.0 / np.sum(w**2))
    return out


CONDITIONAL_POINTS = 200_001


def _negative(log_density):
    """−log density of one point, for a minimiser (a large finite number outside the support)."""

    def neg(x):
        value = log_density(x[None, :])[0]
        return -value if np.isfinite(value) else 1e300

    return neg


def _exact_setup(lik, theta):
    """What the sampler-free checks share: the sampling coordinates, the log posterior density
    in them, and the truth there."""
    from bayesfo.inference.transform import Transform, _log_prob_fn

    tr = Transform(lik)
    return tr, _log_prob_fn(lik, tr), tr.to_u(lik.to_scaled(theta[None, :]))[0]


def _conditional(lik, theta) -> list[float]:
    """The truth's rank under each parameter's posterior given the others at their true values
    (quadrature over the parameter's prior range in the sampling coordinates)."""
    from scipy.special import logsumexp

    tr, log_prob, ut = _exact_setup(lik, theta)
    out = []
    for j in range(ut.size):
        grid = np.linspace(tr.lo_u[j], tr.hi_u[j], CONDITIONAL_POINTS)
        u = np.repeat(ut[None, :], grid.size, axis=0)
        u[:, j] = grid
        lp = log_prob(u)
        w = np.exp(lp - logsumexp(lp))
        out.append(float(w[grid < ut[j]].sum()))
    return out


#: An ascent from the truth that ends farther than this (squared Mahalanobis distance under the
#: draws' covariance) from every draw is listed.
DENSITY_FAR = 25.0


def _density(lik, post, theta) -> dict:
    """The truth's rank in posterior density among the route's draws, and where an ascent of
    the log posterior from the truth ends relative to the draws (see ``--density``)."""
    from scipy.optimize import minimize

    tr, log_prob, ut = _exact_setup(lik, theta)
    u = tr.to_u(post.samples_scaled)
    lp = log_prob(u)
    at_truth = float(log_prob(ut[None, :])[0])

    end = minimize(_negative(log_prob), ut, method="Nelder-Mead",
                   options={"maxiter": 4000, "xatol": 1e-6, "fatol": 1e-8})
    inv = np.linalg.inv(np.cov(u.T))
    d2 = np.einsum("ij,jk,ik->i", u - end.x, inv, u - end.x)
    return {"density_rank": float(np.mean(lp > at_truth)),
            "ascent_d2": float(d2.min()), "ascent_below_top": float(lp.max() + end.fun)}


PAIR_POINTS = 400
PAIR_DROP = 30.0


def _pairs(lik, theta) -> list[float]:
    """The truth's ranks under each pair of parameters' posterior given the other parameters at
    their true values (a grid of PAIR_POINTS² in the sampling coordinates, on a box grown from
    the pair's conditional mode until the log density on every face that is not a prior bound
    lies PAIR_DROP nats below the mode). Returns the ranks pair by pair, (j, k) in order."""
    import itertools

    from scipy.optimize import minimize
    from scipy.special import logsumexp

    tr, log_prob, ut = _exact_setup(lik, theta)
    out = []
    for a, b in itertools.combinations(range(ut.size), 2):
        box_lo = np.array([tr.lo_u[a], tr.lo_u[b]])
        box_hi = np.array([tr.hi_u[a], tr.hi_u[b]])

        def lp2(x, a=a, b=b):
            u = np.repeat(ut[None, :], len(x), axis=0)
            u[:, a], u[:, b] = x[:, 0], x[:, 1]
            return np.concatenate([log_prob(u[i:i + 40_000]) for i in range(0, len(u), 40_000)])

        # The conditional mode: from the truth and from the best point of a coarse grid over
        # the whole prior box (a second mode is found there), polished.
        ga, gb = (np.linspace(box_lo[i], box_hi[i], 300) for i in (0, 1))
        coarse = np.column_stack([np.repeat(ga, gb.size), np.tile(gb, ga.size)])
        values = lp2(coarse)
        neg = _negative(lp2)
        best = None
        for x0 in (ut[[a, b]], coarse[int(np.argmax(values))]):
            res = minimize(neg, x0, method="Nelder-Mead",
                           options={"xatol": 1e-10, "fatol": 1e-10, "maxfev": 3000})
            if best is None or res.fun < best.fun:
                best = res
        mode, top = best.x, max(-best.fun, float(values.max()))
        lo, hi = np.maximum(box_lo, mode - 1e-3), np.minimum(box_hi, mode + 1e-3)
        for _ in range(60):
            grew = False
            for dim in (0, 1):
                for upper in (False, True):
                    if (hi[dim] >= box_hi[dim]) if upper else (lo[dim] <= box_lo[dim]):
                        continue
                    face = np.empty((PAIR_POINTS, 2))
                    face[:, 1 - dim] = np.linspace(lo[1 - dim], hi[1 - dim], PAIR_POINTS)
                    face[:, dim] = hi[dim] if upper else lo[dim]
                    if np.max(lp2(face)) > top - PAIR_DROP:
                        width = hi[dim] - lo[dim]
                        if upper:
                            hi[dim] = min(box_hi[dim], hi[dim] + width)
                        else:
                            lo[dim] = max(box_lo[dim], lo[dim] - width)
                        grew = True
            if not grew:
                break
        xa, xb = (np.linspace(lo[i], hi[i], PAIR_POINTS) for i in (0, 1))
        grid = np.column_stack([np.repeat(xa, xb.size), np.tile(xb, xa.size)])
        mass = lp2(grid).reshape(xa.size, xb.size)
        mass = np.exp(mass - logsumexp(mass))
        for x, axis, value in ((xa, 1, ut[a]), (xb, 0, ut[b])):
            cell = mass.sum(axis=axis)
            out.append(0.0 if value <= x[0] else 1.0 if value >= x[-1]
                       else float(np.interp(value, x, np.cumsum(cell) - 0.5 * cell)))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--card", default="fractional_zener_sl")
    ap.add_argument("--n", type=int, default=300)
    ap.add_argument("--seed", type=int, default=14)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--noise-level", type=float, default=None)
    ap.add_argument("--reference", action="store_true")
    ap.add_argument("--tails", action="store_true")
    ap.add_argument("--density", action="store_true")
    ap.add_argument("--conditional", action="store_true")
    ap.add_argument("--pairs", action="store_true")
    ap.add_argument("--routes-from", default=None)
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    exact = args.conditional or args.pairs
    if exact and (args.reference or args.tails or args.density):
        ap.error("--conditional and --pairs do not run the route: they go without --reference, "
                 "--tails and --density")
    if args.conditional and args.pairs:
        ap.error("--conditional and --pairs are separate runs: choose one")
    if args.routes_from and not exact:
        ap.error("--routes-from splits --conditional or --pairs by the routes of an earlier run")
    routes_from = ({r["set"]: r["route"] for r in json.loads(Path(args.routes_from).read_text())
                    ["rows"]} if args.routes_from else {})
    rng = np.random.default_rng(args.seed)
    s = get_structure(args.card)
    table = calibration.PRIORS_RIDGED.get(args.card, calibration.PRIORS)
    priors = {k: v for k, v in table.items() if k in s.param_names}
    w = calibration.W
    template = FrequencyResponse(w, np.ones(w.size), np.ones(w.size), kind="compliance")
    rows = []
    t0 = time.perf_counter()
    for k in range(args.n):  # the draws in the order of calibration.coverage
        theta = calibration.draw_truth(
            Likelihood(s, template, priors=priors, scaling=calibration.SCALING), rng)
        g = s.response(theta, w, "compliance")
        level = rng.choice([0.01, 0.05])
        sd = level * np.abs(g)
        noisy = g + sd / np.sqrt(2) * (rng.normal(size=w.size) + 1j * rng.normal(size=w.size))
        data = FrequencyResponse(w, noisy, sd, kind="compliance")
        if k < args.first or args.noise_level not in (None, float(level)):
            continue
        if exact:
            lik = Likelihood(s, data, priors=priors, scaling=calibration.SCALING)
            rows.append({"set": k, "noise": float(level),
                         "route": routes_from.get(k, "pairs" if args.pairs else "conditional"),
                         "ranks": (_pairs if args.pairs else _conditional)(lik, theta)})
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            post, route = calibration.default_route(s, data, priors, seed=k)
            row = {"set": k, "route": route, "noise": float(level),
                   "certified": bool(post.converged),
                   "ranks": np.mean(post.samples < theta, axis=0).tolist()}
            if args.reference:
                lik = Likelihood(s, data, priors=priors, scaling=calibration.SCALING)
                _, runs = ladder_runs(lik, seed=10_000 + k, n_particles=3000, guide=None)
                ref = posterior_from_particles(lik, runs, seed=k)
                row["reference_ranks"] = np.mean(ref.samples[:, :theta.size] < theta,
                                                 axis=0).tolist()
                row["reference_certified"] = bool(ref.converged)
            if args.density:
                lik = Likelihood(s, data, priors=priors, scaling=calibration.SCALING)
                row.update(_density(lik, post, theta))
            if args.tails:
                lik = Likelihood(s, data, priors=priors, scaling=calibration.SCALING)
                t = _tails(lik, post, theta, float(level), seed=k)
                row["tails_ranks"], row["generative_ranks"] = t["tails"], t["generative"]
                row["tails_k_hat"], row["tails_ess"] = t["k_hat"], t["ess"]
        rows.append(row)
    names = list(s.param_names)
    if args.pairs:
        names = [f"{names[c]} (with {names[a + b - c]})" for a in range(len(names))
                 for b in range(a + 1, len(names)) for c in (a, b)]
    print(f"{args.card}: data sets {args.first}-{args.n - 1} (seed {args.seed}), "
          f"{time.perf_counter() - t0:.0f} s")
    groups = {route: [r for r in rows if r["route"] == route]
              for route in sorted({r["route"] for r in rows})}
    groups.update({f"noise {100 * level:.0f} %": [r for r in rows if r["noise"] == level]
                   for level in sorted({r["noise"] for r in rows})})
    groups["all"] = rows
    keys = (["ranks"] + (["reference_ranks"] if args.reference else [])
            + (["tails_ranks", "generative_ranks"] if args.tails else []))
    for group, members in groups.items():
        for key in keys:
            ranks = np.array([r[key] for r in members])
            c50, c90 = _coverage(ranks, 0.5), _coverage(ranks, 0.9)
            extreme = np.mean((ranks < 0.02) | (ranks > 0.98), axis=0)
            cells = ", ".join(f"{n} {a:.2f}/{b:.2f} (extreme {e:.3f})"
                              for n, a, b, e in zip(names, c50, c90, extreme, strict=True))
            by = {"ranks": ("conditional quadrature" if args.conditional else "pair grids"
                            if args.pairs else "route"),
                  "reference_ranks": "reference",
                  "tails_ranks": "heavy-tailed importance",
                  "generative_ranks": "generative model"}[key]
            print(f"  {group} ({len(members)}), {by}: 50 %/90 % coverage: {cells}")
    for key in keys[1:]:
        diff = np.abs(np.array([r["ranks"] for r in rows]) - np.array([r[key] for r in rows]))
        print(f"  |rank by the route - rank by {key.split('_')[0]}|: mean "
              + ", ".join(f"{n} {d:.3f}" for n, d in zip(names, diff.mean(0), strict=True))
              + "; largest " + ", ".join(f"{n} {d:.3f}" for n, d in zip(names, diff.max(0),
                                                                         strict=True)))
    if args.density:
        for group, members in groups.items():
            ranks = np.array([r["density_rank"] for r in members])
            print(f"  {group} ({len(members)}), rank in posterior density at most 0.5 / 0.9: "
                  f"{np.mean(ranks <= 0.5):.3f} / {np.mean(ranks <= 0.9):.3f}")
        far = [r for r in rows if r["ascent_d2"] > DENSITY_FAR]
        print("  ascents from the truth that end far from every draw (set, route, squared "
              "distance, nats below the highest draw): "
              + ("; ".join(f"{r['set']} {r['route']} {r['ascent_d2']:.0f} "
                           f"{r['ascent_below_top']:.2f}" for r in far) or "none"))
    if args.tails:
        k_hat = np.array([r["tails_k_hat"] for r in rows])
        ess = np.array([r["tails_ess"] for r in rows])
        print(f"  heavy-tailed importance: k̂ median {np.median(k_hat):.2f}, largest "
              f"{k_hat.max():.2f} ({np.sum(k_hat >= 0.7)} of {k_hat.size} at 0.7 or more); "
              f"ESS median {np.median(ess):.0f}, smallest {ess.min():.0f}")
    ranks = np.array([r["ranks"] for r in rows])
    for j, n in enumerate(names):
        print(f"  ranks of {n}: {np.histogram(ranks[:, j], bins=10, range=(0, 1))[0].tolist()}")
    if args.json:
        Path(args.json).write_text(json.dumps({"card": args.card, "params": names,
                                               "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
