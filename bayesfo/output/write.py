"""The output directory of a comparison (one NetCDF per structure, figures, report.html,
ranking.csv and summary.json: :func:`write_outputs`) and of a master curve (summary.json,
master.csv, the joint posterior's NetCDF, figures and report.html: :func:`write_mastercurve`),
each swapped in as one run (:mod:`bayesfo.outdir`)."""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import sys
from pathlib import Path

import numpy as np

from .._io import atomic_write_text
from ..comparison.results import Comparison
from ..comparison.stored import netcdf_for
from ..comparison.table import RANKING_FIELDS
from ..inference import preload_arviz, save_netcdf
from ..options import STRUCTURE_FIGURES
from ..outdir import final_path, staged_run
from ..tts.result import MasterCurve
from ..tts.stored import netcdf_of, summary_fields


def ranking_csv(comparison: Comparison) -> str:
    """The text of ``ranking.csv``: a row per structure, the columns of
    :data:`~bayesfo.comparison.RANKING_FIELDS` (an undefined number is an empty cell).

    Parameters
    ----------
    comparison : Comparison

    Returns
    -------
    str
    """
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=RANKING_FIELDS, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in comparison.table():
        # No literal nan or inf: an undefined number is an empty cell, as null in summary.json.
        writer.writerow({k: ("" if v is None else v)
                         for k, v in _finite({k: row.get(k) for k in RANKING_FIELDS}).items()})
    return buf.getvalue()


def _json_default(obj):
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def _finite(obj):
    """JSON has no NaN or infinity: such numbers become null."""
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    if isinstance(obj, (float, np.floating)) and not math.isfinite(obj):
        return None
    return obj


@contextlib.contextmanager
def _without_distributed():
    """Inside the block, dask's ``distributed`` cannot be imported unless it already was.

    xarray's ``to_netcdf`` asks dask which scheduler is active, and dask imports ``distributed``
    (when installed) to look for a ``Client``, an import that costs every command that writes
    NetCDF noticeable time. A ``Client`` cannot exist in a process that never
    imported the package, so the answer is the same without it: the import fails at once
    (``sys.modules`` entries ``None``) and xarray takes the scheduler for a local one. A process
    that has imported it (a batch on a Dask cluster) is left alone.
    """
    names = ("distributed", "dask.distributed")
    if any(n in sys.modules for n in names):
        yield
        return
    for n in names:
        sys.modules[n] = None
    try:
        yield
    finally:
        for n in names:
            if n in sys.modules and sys.modules[n] is None:
                del sys.modules[n]
        # dask caches the failed import (a configured string scheduler asks for it): a Client
        # the user creates later would then be ignored. Forget it, so dask asks again.
        base = sys.modules.get("dask.base")
        if base is not None and getattr(base, "_DISTRIBUTED_AVAILABLE", None) is False:
            base._DISTRIBUTED_AVAILABLE = None


def _write_netcdf(comparison: Comparison, stage: Path) -> dict[str, Path]:
    """One NetCDF per structure with a posterior, into ``stage``."""
    written = {}
    with _without_distributed():
        for r in comparison.results:
            if r.posterior is not None:
                written[r.name] = save_netcdf(netcdf_for(comparison, r), stage / f"{r.name}.nc")
    return written


def preload(formats=()) -> None:
    """Import now, not on first use, the compiled libraries that a comparison and its outputs
    use (with those that draw figures in ``formats``): before a command forks its workers, or
    in a worker before its objects are frozen out of the garbage collector."""
    import emcee  # noqa: F401
    import netCDF4  # noqa: F401
    import scipy.optimize  # noqa: F401
    import scipy.special  # noqa: F401
    import scipy.stats  # noqa: F401


    preload_arviz()
    if formats:
        from ..plotting.output import preload as preload_plotting

        preload_plotting(formats)


def write_outputs(comparison: Comparison, out_dir, *, figures: bool = True,
                  formats=("png",), pool=None, figure_processes: int = 1,
                  structure_figures: int | str | None = STRUCTURE_FIGURES) -> dict[str, Path]:
    """Write everything a comparison produced into ``out_dir``.

    One NetCDF per structure (an ArviZ DataTree with the attributes that :func:`load` needs,
    see :mod:`bayesfo.comparison.stored`), the figures (``formats``; see
    :func:`bayesfo.plotting.write_figures`), ``report.html`` (self-contained, figures embedded),
    ``ranking.csv`` and ``summary.json``. Everything is written into a staging directory inside
    ``out_dir`` and swapped in at the end (:mod:`bayesfo.outdir`), so ``out_dir`` always holds the
    complete output of one run: an interrupted run leaves the earlier output as it was, and the
    outputs of an earlier run that this one does not write (a structure left out) are removed.
    Other files in ``out_dir`` are left alone, except files of the very names this run writes
    (replaced); a directory of such a name that no run recorded (a ``figures/`` of your own)
    raises :class:`~bayesfo.errors.OutputError` instead of being replaced.

    Parameters
    ----------
    comparison : Comparison
    out_dir : path
        Created if missing.
    figures : bool
        Draw the figures and the report (matplotlib; a few seconds per structure).
    formats : sequence of str
        Figure file formats (default PNG, which the report embeds; add ``"pdf"`` for
        vector figures).
    pool : concurrent.futures.Executor, optional
        Draw the figures in these worker processes (from :func:`process_pool`; a
        :class:`~bayesfo.parallel.LazyPool` whose processes were not started is not started
        for them: the figures are then drawn in this process).
    figure_processes : int
        Without a pool (or with a lazy pool not started): 2 draws the figures in this process
        and in one forked from it, which starts drawing while this one writes the NetCDF files
        (:func:`bayesfo.plotting.output.draw_forked`); 1 draws them here.
    structure_figures : "leading", int or None
        Which structures get corner (and trace) figures: the leading ones (the default; see
        :func:`bayesfo.plotting.output.leading`), the best that many by the ranking, or every
        one (None).

    Returns
    -------
    dict
        ``{name: path}`` of the files written (figures: ``{name: [paths]}``).
    """
    out_dir = Path(out_dir)
    written = {}
    with staged_run(out_dir) as stage:
        if figures:
            from ..plotting import write_figures
            from .report import write_report

            # The NetCDF files are written while a forked process already draws.
            drawn = write_figures(comparison, stage / "figures", formats=formats,
                                  seed=comparison.seed, pool=pool, processes=figure_processes,
                                  structure_figures=structure_figures,
                                  meanwhile=lambda: written.update(_write_netcdf(comparison,
                                                                                 stage)))
            written.update(drawn)
            written["report.html"] = write_report(comparison, stage, drawn)
        else:
            written.update(_write_netcdf(comparison, stage))
        written["ranking.csv"] = atomic_write_text(stage / "ranking.csv", ranking_csv(comparison))
        text = json.dumps(_finite(comparison.to_summary()), indent=2, default=_json_default,
                          allow_nan=False)
        written["summary.json"] = atomic_write_text(stage / "summary.json", text + "\n")
    return {name: [final_path(p, stage, out_dir) for p in paths] if isinstance(paths, list)
            else final_path(paths, stage, out_dir) for name, paths in written.items()}



#: The figures of a master curve's output directory (``figures/NAME.png``), in the order drawn.
MASTERCURVE_FIGURES = ("mastercurve", "residuals", "van_gurp_palmen")


def mastercurve_summary(mc: MasterCurve) -> dict:
    """The content of a master curve's ``summary.json``: the data, the master curve's fields
    and what :func:`bayesfo.load` needs to restore it; a number that is not finite (a
    posterior's undefined diagnostic) is None, as in a comparison's."""
    return _finite({"data": mc.data.to_dict(), **mc.to_dict(), **summary_fields(mc)})


def _master_csv_comments(mc: MasterCurve) -> list[str]:
    """The comment lines of ``master.csv``: what the reduced data are, the reference
    temperature (read back by ``compare``) and the shift law."""
    law = mc.shift_law()
    return [f"master curve at {mc.reference_temperature:g} °C of {len(mc.temperatures)} "
            f"isotherms ({min(mc.temperatures):g} to {max(mc.temperatures):g} °C), shifted "
            f"by the posterior mean log10 a_T"
            + ("" if mc.vertical == "none" else f" and log10 b_T ({mc.vertical})")
            + f" of bayesfo mastercurve ({mc.structure})",
            f"temperature: {mc.reference_temperature:g} °C",
            f"shift law: {law['name']} "
            + ", ".join(f"{k} = {v['mean']:.6g} {v['unit']}".rstrip()
                        for k, v in law["parameters"].items())]


def write_mastercurve(mc: MasterCurve, out_dir, *, figures: bool = True) -> dict[str, Path]:
    """Write what ``bayesfo mastercurve`` writes of a master curve into ``out_dir``.

    ``summary.json`` (:func:`mastercurve_summary`), ``master.csv`` (the reduced data, which
    :func:`bayesfo.read` and ``compare`` read), ``<structure>.nc`` (the joint posterior, which
    :func:`bayesfo.load` restores; :mod:`bayesfo.tts.stored`) and, with ``figures``,
    ``figures/mastercurve.png``, ``figures/residuals.png``, ``figures/van_gurp_palmen.png``
    and ``report.html``. Staged and swapped in as one run, as :func:`write_outputs` does.

    Parameters
    ----------
    mc : MasterCurve
        From :func:`bayesfo.mastercurve` or :func:`bayesfo.load`.
    out_dir : path
        Created if missing.
    figures : bool
        Draw the figures and the report (matplotlib).

    Returns
    -------
    dict
        ``{name: path}`` of the files written (figures: ``{"figures": [paths]}``).

    Raises
    ------
    OutputError
        If the outputs cannot be written; the earlier outputs stay.

    Examples
    --------
    >>> import bayesfo as bf
    >>> mc = bf.mastercurve(isotherms, "zener")  # doctest: +SKIP
    >>> bf.write_mastercurve(mc, "out")["summary.json"]  # doctest: +SKIP
    PosixPath('out/summary.json')
    """
    out_dir = Path(out_dir)
    summary = mastercurve_summary(mc)
    master = mc.master_data()
    comments = _master_csv_comments(mc)
    written = {}
    with staged_run(out_dir) as stage:
        written["summary.json"] = atomic_write_text(
            stage / "summary.json",
            json.dumps(summary, indent=1, ensure_ascii=False, allow_nan=False) + "\n")
        written["master.csv"] = atomic_write_text(stage / "master.csv",
                                                  master.to_csv_text(comments))
        with _without_distributed():
            written[f"{mc.structure}.nc"] = save_netcdf(netcdf_of(mc),
                                                        stage / f"{mc.structure}.nc")
        if figures:
            from ..plotting.mastercurve import (
                plot_isotherm_residuals,
                plot_mastercurve,
                plot_van_gurp_palmen,
            )
            from ..plotting.output import save_figure
            from .mastercurve_report import write_mastercurve_report

            (stage / "figures").mkdir()
            drawn = {}
            for name, plot in zip(MASTERCURVE_FIGURES, (plot_mastercurve, plot_isotherm_residuals,
                                                        plot_van_gurp_palmen), strict=True):
                drawn[name] = stage / "figures" / f"{name}.png"
                save_figure(plot(mc).figure, drawn[name], close=True)
            written["figures"] = list(drawn.values())
            written["report.html"] = write_mastercurve_report(mc, stage, drawn)
    return {name: [final_path(p, stage, out_dir) for p in paths] if isinstance(paths, list)
            else final_path(paths, stage, out_dir) for name, paths in written.items()}
