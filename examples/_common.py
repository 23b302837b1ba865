"""Helpers shared by the example scripts: command line, running a comparison, printing tables.

Not part of the bayesfo package: the examples import it from their own directory.
"""

from __future__ import annotations

import argparse
import math
import time
import warnings
from pathlib import Path

from bayesfo.comparison import compare
from bayesfo.output import write_outputs

#: Sampler cap of the quick forms: structures that converge do so in 750–2500 steps here;
#: those that do not (multimodal q, vanishing terms) stop at the cap and are flagged.
QUICK_SAMPLER = {"max_steps": 2500}


def make_parser(name: str, doc: str) -> argparse.ArgumentParser:
    """The options every example has: ``--quick``, ``--out DIR``, ``--seed N``."""
    parser = argparse.ArgumentParser(
        description=doc.strip().splitlines()[0],
        epilog=f"Outputs go to examples-output/{name} unless --out is given.",
    )
    parser.add_argument("--quick", action="store_true",
                        help="fewer structures and a sampler cap of "
                             f"{QUICK_SAMPLER['max_steps']} steps (the form run by the tests)")
    parser.add_argument("--out", default=f"examples-output/{name}", help="output directory")
    parser.add_argument("--seed", type=int, default=0, help="seed of the optimiser and sampler")
    parser.add_argument("--no-figures", action="store_true",
                        help="write summary.json, ranking.csv and the NetCDF files only")
    parser.add_argument("--workers", type=int, default=1,
                        help="structures run in this many processes (0: one per CPU); the "
                             "numbers do not depend on it")
    return parser


def run_compare(data, structures, *, seed: int, quick: bool, **kwargs):
    """:func:`bayesfo.comparison.compare` with the quick cap, timed, with warnings collected.

    Sampler and predictive warnings are expected for structures that the data do not support
    (they are flags in the results as well); they are printed once, one line each, after the
    run instead of interleaved with it. Every structure is sampled (``sample="all"``): the
    examples set each fractional structure against its integer baseline by ln Z, and a
    baseline that the evidence bound left out would have only a bound.
    """
    kwargs = {"sample": "all", **kwargs}
    if quick:
        kwargs = {**QUICK_SAMPLER, **kwargs}
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        comp = compare(data, structures, seed=seed, progress=False, **kwargs)
    elapsed = time.perf_counter() - t0
    held = "" if comp.holdout is None else f" ({comp.holdout.n_frequencies} held out)"
    print(f"{data.label}: {comp.data.n_frequencies} frequencies fitted{held}, kind {data.kind}; "
          f"{len(comp.results)} structures in {elapsed:.1f} s")
    _print_warnings(caught)
    return comp


def _print_warnings(caught) -> None:
    seen = []
    for w in caught:
        text = str(w.message).splitlines()[0]
        if text not in seen:
            seen.append(text)
            print(f"  warning: {text} ({w.category.__name__})")


def order_parameter(result):
    """The posterior summary of the fractional order (``q``, or ``beta`` for the Maxwell)."""
    if result.posterior is None:  # left out by the evidence bound
        return None, None
    summary = result.posterior.summary
    return next(((k, summary[k]) for k in ("q", "beta") if k in summary), (None, None))


def _num(x, fmt: str) -> str:
    """'-' for a number that does not apply (R-hat of importance draws)."""
    return "-" if x is None or not math.isfinite(x) else format(x, fmt)


def print_table(comp, title: str, names=None) -> list[dict]:
    """Print the ranking (by ln Z) of ``comp``, or of the structures ``names`` only.

    For a subset the ln Z differences and the posterior model probabilities (equal prior odds)
    are taken within the subset, as if only those structures had been compared.
    """
    rows = [r for r in comp.table() if not r.get("error")
            and (names is None or r["structure"] in names)]
    failed = [r for r in comp.table() if r.get("error")
              and (names is None or r["structure"] in names)]
    with_z = [r for r in rows if r["log_evidence"] is not None]
    best = max((r["log_evidence"] for r in with_z), default=math.nan)
    norm = sum(math.exp(r["log_evidence"] - best) for r in with_z)
    print(f"\n{title}")
    print(f"{'#':>2} {'structure':<17} {'k':>2} {'ln Z':>17} {'dlnZ':>9} {'P':>6} "
          f"{'elpd_loo':>10} {'BIC':>10} {'q 94% HDI':>15} {'R-hat':>6} {'ok':>3}")
    for i, r in enumerate(rows, start=1):
        z = r["log_evidence"]
        zs = "-" if z is None else f"{z:.2f} ± {r['log_evidence_err']:.2f}"
        dz = "-" if z is None else f"{z - best:.2f}"
        p = "-" if z is None else f"{math.exp(z - best) / norm:.3f}"
        _, q = order_parameter(comp[r["structure"]])
        qs = "" if q is None else f"[{q.hdi_low:.3f}, {q.hdi_high:.3f}]"
        print(f"{i:>2} {r['structure']:<17} {r['n_params']:>2} {zs:>17} {dz:>9} {p:>6} "
              f"{r['loo']:>10.2f} {r['bic']:>10.2f} {qs:>15} {_num(r['rhat_max'], '.3f'):>6} "
              f"{'yes' if r['converged'] else 'NO':>3}")
    for r in failed:
        print(f" - {r['structure']:<17} {r['n_params']:>2}  not run: {r['error']}")
    return rows


def print_orders(comp, names=None) -> None:
    """Posterior of the fractional order per structure: mean, sd, 94 % HDI and the flags."""
    print("\nPosterior of the commensurate order (94 % HDI):")
    for name in comp.ranking:
        if names is not None and name not in names:
            continue
        key, q = order_parameter(comp[name])
        if q is None:
            print(f"  {name:<17} (integer order, q = 1 fixed)")
            continue
        flags = [f for f, on in (("multimodal", q.multimodal),
                                 ("poorly determined", q.poorly_determined)) if on]
        width = q.hdi_high - q.hdi_low
        print(f"  {name:<17} {key} = {q.mean:.3f} ± {q.sd:.3f}, HDI [{q.hdi_low:.3f}, "
              f"{q.hdi_high:.3f}] (width {width:.3f}), MAP {q.map:.3f}"
              + (f"  [{', '.join(flags)}]" if flags else ""))


def print_holdout(comp) -> None:
    """In-sample against hold-out figures per structure.

    RMSE as thesis eq. (3.23) is (1/N)·sqrt(Σ|e|²): it scales as 1/sqrt(N), so an RMSE over
    two held-out points cannot be compared with one over the fitted points. The per-point RMS
    sqrt(Σ|e|²/N) can; both are printed.
    """
    if comp.holdout is None:
        return
    n_fit, n_test = comp.data.n_frequencies, comp.holdout.n_frequencies
    print("\nHeld out " + ", ".join(f"{w:.4g}" for w in comp.holdout.omega)
          + f" rad/s; in-sample = the {n_fit} fitted points")
    print(f"  {'structure':<17} {'k':>2} {'lpd held out':>13} {'elpd_loo/pt':>12} "
          f"{'lpd/pt held out':>16} {'RMS in-sample':>14} {'RMS held out':>13} {'ratio':>6}")
    for r in comp.table():
        if r.get("error"):
            continue
        rms_in = r["rmse"] * math.sqrt(n_fit)
        rms_out = r["holdout_rmse"] * math.sqrt(n_test)
        print(f"  {r['structure']:<17} {r['n_params']:>2} {r['holdout_lpd']:>13.2f} "
              f"{r['loo'] / n_fit:>12.3f} {r['holdout_lpd'] / n_test:>16.3f} "
              f"{rms_in:>14.4g} {rms_out:>13.4g} {rms_out / rms_in:>6.2f}")


def save(comp, out_dir, *, figures: bool = True, quick: bool = False) -> Path:
    """Write the outputs with :func:`bayesfo.output.write_outputs` and say where they are.

    The quick forms draw PNG figures only.
    """
    out_dir = Path(out_dir)
    kwargs = {"figures": figures}
    if figures and quick:
        kwargs["formats"] = ("png",)
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        written = write_outputs(comp, out_dir, **kwargs)
    _print_warnings(caught)
    paths = []
    for value in written.values():
        paths += [Path(p) for p in value] if isinstance(value, (list, tuple)) else [Path(value)]
    nc = sum(p.suffix == ".nc" for p in paths)
    figs = sum(p.suffix in (".png", ".pdf", ".svg") for p in paths)
    names = sorted(p.name for p in paths if p.suffix in (".json", ".csv", ".html"))
    print(f"wrote {out_dir}/: " + ", ".join(names) + f", {nc} posteriors as NetCDF"
          + (f", {figs} figure files" if figs else "")
          + f" ({time.perf_counter() - t0:.1f} s)")
    return out_dir


def comment_lines(path) -> list[str]:
    """The ``#`` comment lines at the top of a data file (its provenance and licence)."""
    lines = []
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        if not line.startswith("#"):
            break
        lines.append(line[1:].strip())
    return lines


def same_csv(text: str, other: str, rel: float = 1e-13) -> bool:
    """Whether two CSV texts hold the same lines: comment lines and text cells identical, each
    number within ``rel`` relative. The generators' last bits may differ between CPUs (a complex
    power rounded one unit in the last place apart), which is not a different data set."""
    lines, others = text.splitlines(), other.splitlines()
    if len(lines) != len(others):
        return False
    for line, that in zip(lines, others):
        if line == that:
            continue
        cells, theirs = line.split(","), that.split(",")
        if line.startswith("#") or len(cells) != len(theirs):
            return False
        for x, y in zip(cells, theirs):
            try:
                fx, fy = float(x), float(y)
            except ValueError:
                if x != y:
                    return False
                continue
            if not abs(fx - fy) <= rel * max(abs(fx), abs(fy)):
                return False
    return True


def check_or_write_csv(path: Path, text: str, regenerate: bool, seed: int) -> Path:
    """Write ``text`` to the data file ``path`` (``regenerate``, or when it is missing), or check
    that the bundled file is what the generator produces (:func:`same_csv`)."""
    if regenerate or not path.exists():
        path.write_text(text, encoding="utf-8")
        print(f"wrote {path}")
    elif not same_csv(path.read_text(encoding="utf-8"), text):
        raise SystemExit(f"{path} differs from what the generator produces; "
                         "run with --regenerate to rewrite it")
    else:
        print(f"{path.relative_to(path.parents[2])} is what the generator produces (seed {seed})")
    return path
