"""``bayesfo simulate``: the thesis' Monte Carlo studies beside its printed tables."""

from __future__ import annotations

import json

import numpy as np

from ..errors import InputError
from ..options import (
    seed_argument,
)


def add_parser(subparsers):
    """Register ``bayesfo simulate``: the thesis' Monte Carlo studies."""
    p = subparsers.add_parser("simulate", help="thesis Monte Carlo studies beside the printed tables")
    p.add_argument("study", metavar="STUDY", help="table-3.2, table-a.1, table-a.3, table-3.4, table-a.5, table-a.7, figure-3.2")
    p.add_argument("--runs", type=int, default=None, help="noisy realisations (default: as in the thesis)")
    p.add_argument("--seed", type=seed_argument, default=0)
    p.add_argument("--figure", metavar="FILE", help="figure-3.2: write the RMSE surface (.png, .pdf)")
    p.add_argument("--json", action="store_true", help="print JSON")
    return p


def run(args) -> int:
    from ..studies import rmse_surface, run_study

    if args.study == "figure-3.2":
        runs = 1 if args.runs is None else args.runs
        if runs < 1:
            raise InputError(f"--runs must be at least 1, got {runs}")
        surface = rmse_surface(runs=runs, seed=args.seed)
        if args.figure:
            from ..plotting import plot_rmse_surface, save_figure

            mesh = plot_rmse_surface(surface)
            save_figure(mesh.axes.figure, args.figure, named=True)
        if args.json:
            print(json.dumps(surface))
        else:
            z = np.asarray(surface["rmse"])
            for s_, row in zip(surface["sigma"], z):
                k = int(np.argmin(row))
                print(f"sigma = {s_:.4f}: minimum RMSE {row[k]:.4g} at q = {surface['q'][k]:.2f}")
            if args.figure:
                print(f"wrote {args.figure}")
        return 0
    if args.figure:
        raise InputError("--figure applies to figure-3.2 only")
    result = run_study(args.study, runs=args.runs, seed=args.seed)
    if args.json:
        print(json.dumps(result, indent=2))
        return 0
    print(f"{result['study']}: {result['runs']} runs, seed {result['seed']} (thesis values in brackets)")
    for key, row in result["methods"].items():
        th = result["thesis"].get(key, {})
        print(f"method {key}")
        for field in ("mean_a", "var_a", "mean_b", "var_b", "mean_q", "var_q", "rmse_spec",
                      "var_rmse_spec", "rmse_noise", "var_rmse_noise"):
            ours = np.atleast_1d(row[field])
            text = " ".join(f"{v:.4g}" for v in ours)
            if field in th:
                text += "   [" + " ".join(f"{v:.4g}" for v in np.atleast_1d(th[field])) + "]"
            print(f"  {field:<15} {text}")
    return 0
