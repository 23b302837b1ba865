"""The thesis' simulation studies (§3.4, appendix A.1), then the posterior on the same set-up.

Part 1 runs methods 1-5 on G_spec = 1/(1 + s^0.5) (Tables 3.2/3.3, A.1/A.2, A.3/A.4), the global
optimisation of Table A.7, and writes the RMSE surface of Figure 3.2, each beside the printed
values.

Part 2 asks what the thesis could only suspect from Table A.7 (the global optimum of n = m = 2
scatters, with a mean q of 0.50 but coefficient variances of ~500): how well do one data set's
numbers determine q, structure by structure? One noisy realisation of the thesis' set-up (25
log-spaced ω in [0.6, 300] rad/s, noise = FFT of a real N(0, 0.001²) vector, so complex noise of
sd 0.005) is compared with ``voigt`` and the max-order members ``max-n1m0``, ``max-n1m1``,
``max-n2m2`` (Table A.7's orders) and ``max-n3m3``; σ is unknown to the analysis (one constant σ,
sampled). The 94 % HDI of q is printed per structure, with a text histogram of its draws and
the share near q = 1/2, 1/4 and 1/6: a member of degree n in λ = s^q reproduces G_spec exactly
at q = 1/(2k) for every k ≤ n (1/(1 + s^0.5) = 1/(1 + λ^k) with λ = s^(1/(2k))), and between
those aliases it approximates s^0.5 by a rational function of s^q well enough for the noise, so
from n = 2 on the posterior of q spreads over a wide range instead of the n = 1 structures'
±0.005 (and the sampler, started in every optimiser mode, mixes slowly between them: such
members are flagged as not converged within the step cap).

(The thesis' noise pairs frequency k with 25 − k as complex conjugates, FFT of a real vector;
the likelihood treats the 25 points as independent, which is what the thesis' RMSE does too.)

Usage: python examples/thesis_simulation.py [--quick] [--runs N] [--global-runs N] [--out DIR]
[--seed N] [--skip-studies] [--skip-posterior]
(the thesis used 10 000 and 100 runs; ``--quick`` uses 500 and 5, and two structures in part 2).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from _common import make_parser, print_orders, print_table, run_compare, save

from bayesfo import FrequencyResponse
from bayesfo.structures import resolve_structures
from bayesfo.studies import OMEGA, g_spec, rmse_surface, run_study, thesis_noise

HERE = Path(__file__).resolve().parent
NAME = "thesis_simulation"
FIELDS = ("mean_a", "var_a", "mean_b", "var_b", "mean_q", "rmse_spec", "rmse_noise")
POSTERIOR_FULL = "voigt,max-n1m0,max-n1m1,max-n2m2,max-n3m3"
POSTERIOR_QUICK = "voigt,max-n2m2"
#: Exact aliases of G_spec in a commensurate member: q = 1/(2k), k = 1, 2, 3.
ALIASES = (0.5, 0.25, 1 / 6)


def show(result):
    print(f"\n{result['study']} ({result['runs']} runs, seed {result['seed']}); thesis in brackets")
    for key, row in result["methods"].items():
        th = result["thesis"].get(key, {})
        cells = []
        for f in FIELDS:
            ours = " ".join(f"{v:.4g}" for v in np.atleast_1d(row[f]))
            printed = " ".join(f"{v:.4g}" for v in np.atleast_1d(th[f])) if f in th else "-"
            cells.append(f"{f}={ours} [{printed}]")
        print(f"  {key}: " + "; ".join(cells))


def studies(args, runs: int, global_runs: int, out: Path) -> None:
    for study in ("table-3.2", "table-a.1", "table-a.3"):
        show(run_study(study, runs=runs, seed=args.seed))
    show(run_study("table-a.7", runs=global_runs, seed=args.seed))
    import matplotlib

    matplotlib.use("Agg")
    from bayesfo.plotting import plot_rmse_surface, save_figure

    mesh = plot_rmse_surface(rmse_surface(seed=args.seed))
    path = out / "figure-3.2.png"
    save_figure(mesh.axes.figure, path)
    print(f"\nwrote {path}")


def gspec_data(seed: int) -> FrequencyResponse:
    """One noisy realisation of the thesis' set-up (§3.4): G_spec plus the FFT noise."""
    noisy = g_spec() + thesis_noise(np.random.default_rng(seed), 1)[0]
    return FrequencyResponse(OMEGA, noisy, kind="generic",
                             name=f"G_spec = 1/(1 + s^0.5), thesis noise, seed {seed}")


def alias_shares(q_draws) -> dict[str, float]:
    """Share of q draws within ±0.03 of each alias 1/(2k), and elsewhere."""
    q_draws = np.asarray(q_draws, dtype=float)
    out, used = {}, np.zeros(q_draws.size, dtype=bool)
    for a in ALIASES:
        near = np.abs(q_draws - a) < 0.03
        out[f"{a:.3g}"] = float(near.mean())
        used |= near
    out["other"] = float((~used).mean())
    return out


def histogram(values, bins: int = 20) -> str:
    """A one-line text histogram of values in [0, 1] (one character per bin, ' ' = empty)."""
    counts, _ = np.histogram(values, bins=bins, range=(0.0, 1.0))
    levels = " .:-=+*#%@"
    top = counts.max() or 1
    return "|" + "".join(levels[int(np.ceil(c / top * (len(levels) - 1)))] for c in counts) + "|"


def posterior(args, out: Path):
    data = gspec_data(args.seed)
    names = POSTERIOR_QUICK if args.quick else POSTERIOR_FULL
    print("\n== Posterior on the thesis' simulation set-up (truth: n = 1, m = 0, q = 0.5)")
    comp = run_compare(data, resolve_structures(names), seed=args.seed, quick=args.quick,
                       workers=args.workers, noise="constant")
    print_table(comp, "Ranking by ln Z")
    print_orders(comp)
    print("\nShare of the posterior draws of q near the exact aliases q = 1/(2k):")
    for name in comp.ranking:
        post = comp[name].posterior
        if "q" not in post.param_names:
            continue
        q = post.samples[:, post.param_names.index("q")]
        shares = alias_shares(q)
        print(f"  {name:<10} " + ", ".join(f"q≈{k}: {v:.2f}" if k != "other" else f"other: {v:.2f}"
                                           for k, v in shares.items()))
        print(f"  {'':<10} histogram over [0, 1] in 0.05 bins: {histogram(q)}")
    save(comp, out / "posterior_gspec", figures=not args.no_figures, quick=args.quick)
    return comp


def main(argv=None):
    parser = make_parser(NAME, __doc__)
    parser.add_argument("--runs", type=int, default=10_000)
    parser.add_argument("--global-runs", type=int, default=100)
    parser.add_argument("--skip-studies", action="store_true", help="only part 2")
    parser.add_argument("--skip-posterior", action="store_true", help="only part 1")
    args = parser.parse_args(argv)
    runs, global_runs = (500, 5) if args.quick else (args.runs, args.global_runs)
    out = Path(args.out)
    if not args.skip_studies:
        studies(args, runs, global_runs, out)
    if not args.skip_posterior:
        posterior(args, out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
