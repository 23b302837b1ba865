"""Deterministic identification: the seeds of the posterior sampler.

``linear``: methods 1–5 of thesis Table 3.1, vectorised over data sets and orders q;
``scan``: q-grid scan and max-order loop (§4.3.2, §4.3.4); ``optimize``: multi-start bounded
least squares of the complex residual on scaled data for every structure (§3.3, Problem 5).
:func:`identify` is the one-call entry point behind ``bayesfo identify``.
"""

from __future__ import annotations

import math
import numbers

from ..errors import InputError
from ..structures import Structure, fix_parameters
from .optimize import FitResult, fit_structure, linear_seeds, thesis_degrees
from .scan import LinearFit, QScan, fit_linear, max_order_scan, q_grid_scan

__all__ = [
    "FitResult", "LinearFit", "QScan", "check_q", "fit_linear", "fit_structure", "identify",
    "linear_seeds", "max_order_scan", "q_grid_scan", "thesis_degrees",
]


def check_q(q, structure: Structure) -> float:
    """``q`` as a float, checked to be finite and within the support of the prior of q of
    ``structure`` (structures without a free q are left to :func:`identify`).

    Raises
    ------
    InputError
        Naming ``q``, the prior and the range to choose from.
    """
    if isinstance(q, bool) or not isinstance(q, numbers.Real) or not math.isfinite(q):
        raise InputError(f"argument 'q' must be a finite number, got {q!r}")
    q = float(q)
    prior = structure.priors.get("q")
    if prior is not None:
        lo, hi = prior.bounds
        if not lo <= q <= hi:
            raise InputError(
                f"argument 'q' = {q:g} is outside the prior {prior.describe()} of q in "
                f"structure '{structure.name}': give a q from {lo:g} to {hi:g}"
            )
    return q


def identify(data, structure: Structure, *, method="opt", q: float | None = None,
             seed: int | None = 0) -> dict:
    """Fit one structure with a linear method (1–5) or the global optimisation ("opt").

    Returns
    -------
    dict
        The ``identify --json`` contract: ``structure``, ``method``, ``q``, ``a`` = [1, a_1, …],
        ``b`` = [b_0, …] (physical units; None for structures not of the thesis form),
        ``rmse`` (eq. (3.23)), ``stable``, plus ``parameters`` by name, ``inverted`` and, for a
        q-grid scan, ``rejected_unstable_q``.
    """
    structure.check_data(data)
    method = str(method)
    if q is not None:
        q = check_q(q, structure)
    degrees = thesis_degrees(structure)
    out = {"structure": structure.name, "method": method, "inverted": structure.inverted}
    if method in ("1", "2", "3", "4", "5"):
        if degrees is None:
            raise InputError(
                f"method {method} applies to commensurate structures B(λ)/A(λ); "
                f"use --method opt for '{structure.name}'"
            )
        n, m = degrees
        if "q" in structure.fixed:
            if q is not None and q != structure.fixed["q"]:
                raise InputError(f"structure '{structure.name}' has q fixed to {structure.fixed['q']:g}")
            q = structure.fixed["q"]
        if q is not None:
            fit = fit_linear(data, n, m, int(method), q, inverted=structure.inverted)[0]
            rejected = []
        else:
            scan = q_grid_scan(data, n, m, int(method), inverted=structure.inverted)
            if scan.best is None:
                raise InputError(
                    f"method {method} gives an unstable '{structure.name}' for every q of the grid"
                )
            fit, rejected = scan.best, scan.rejected_unstable.tolist()
        params = {f"a{k}": float(fit.a[k]) for k in range(1, n + 1)}
        params |= {f"b{k}": float(fit.b[k]) for k in range(m + 1)}
        params["q"] = fit.q
        out.update(q=fit.q, a=fit.a.tolist(), b=fit.b.tolist(), rmse=fit.rmse, stable=fit.stable,
                   parameters={k: params[k] for k in structure.param_names + ("q",) if k in params})
        if rejected:
            out["rejected_unstable_q"] = rejected
        return out
    if method != "opt":
        raise InputError(f"method must be 1, 2, 3, 4, 5 or opt, got {method!r}")
    target = structure
    if q is not None:
        if "q" not in structure.param_names:
            raise InputError(f"structure '{structure.name}' has no free q to fix")
        target = fix_parameters(structure, {"q": q})
    fit = fit_structure(target, data, rng=seed, seed_methods=True)
    if not fit.admissible:
        raise InputError(
            f"no start reached a stable, dissipative optimum of '{structure.name}' on {data.where()}"
        )
    params = dict(zip(fit.param_names, map(float, fit.theta)))
    params |= {k: float(v) for k, v in target.fixed.items()}
    qv = params.get("q")
    a = b = None
    if degrees is not None:
        n, m = degrees
        a = [1.0] + [params[f"a{k}"] for k in range(1, n + 1)]
        b = [params[f"b{k}"] for k in range(m + 1)]
    stable = bool(target.stable(fit.theta, data.kind))
    out.update(q=qv, a=a, b=b, rmse=fit.rmse, stable=stable, parameters=params,
               starts=fit.n_starts, starts_at_optimum=fit.n_at_best)
    return out
