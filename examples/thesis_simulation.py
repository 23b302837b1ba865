"""The thesis' simulation studies (§3.4, appendix A.1), run beside the printed tables.

Runs methods 1-5 on G_spec = 1/(1 + s^0.5) (Tables 3.2/3.3, A.1/A.2, A.3/A.4), the global
optimisation of Table A.7, and writes the RMSE surface of Figure 3.2.

Usage: python examples/thesis_simulation.py [--runs N] [--global-runs N] [--out DIR]
(the thesis used 10 000 and 100 runs; ``--quick`` uses 500 and 5).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from bayesfo.studies import rmse_surface, run_study

FIELDS = ("mean_a", "var_a", "mean_b", "var_b", "mean_q", "rmse_spec", "rmse_noise")


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


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10_000)
    parser.add_argument("--global-runs", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="thesis-simulation")
    parser.add_argument("--quick", action="store_true", help="500 and 5 runs")
    args = parser.parse_args(argv)
    runs, global_runs = (500, 5) if args.quick else (args.runs, args.global_runs)
    for study in ("table-3.2", "table-a.1", "table-a.3"):
        show(run_study(study, runs=runs, seed=args.seed))
    show(run_study("table-a.7", runs=global_runs, seed=args.seed))
    import matplotlib

    matplotlib.use("Agg")
    from bayesfo.plotting import plot_rmse_surface, save_figure

    mesh = plot_rmse_surface(rmse_surface(seed=args.seed))
    path = Path(args.out) / "figure-3.2.png"
    save_figure(mesh.axes.figure, path)
    print(f"\nwrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
