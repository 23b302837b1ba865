"""Figure files: atomic saving, and every figure of a comparison written at once."""

from __future__ import annotations

import os
import re
import tempfile
from pathlib import Path

from ..errors import InputError
from ..identify.optimize import linear_fits
from ._compute import ok_results, order_parameter
from .posterior import plot_corner, plot_q_posteriors, plot_trace
from .ranking import plot_ranking
from .response import plot_bode, plot_nyquist, plot_residuals
from .style import colors_for, style


def save_figure(fig, path) -> None:
    """Save ``fig`` to ``path`` (format from the suffix) through a temporary file."""
    from .._io import publish

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=200)
        publish(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _file_stem(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]", "_", name)


def _check_formats(formats) -> tuple[str, ...]:
    from matplotlib.backend_bases import FigureCanvasBase

    if isinstance(formats, str):
        formats = (formats,)
    formats = tuple(str(f).lower().lstrip(".") for f in formats)
    if not formats:
        raise InputError("argument 'formats' is empty")
    supported = FigureCanvasBase.get_supported_filetypes()
    bad = [f for f in formats if f not in supported]
    if bad:
        raise InputError(f"argument 'formats': cannot write '{bad[0]}' figures; use one of "
                         + ", ".join(sorted(supported)))
    return formats


def figure_jobs(comparison, *, seed: int = 0) -> list[tuple[str, object]]:
    """``(name, make)`` for every figure of a comparison, ``make()`` returning a
    :class:`~bayesfo.plotting.Drawn`; structures that failed are left out."""
    jobs = [
        ("ranking", lambda: plot_ranking(comparison)),
        ("bode", lambda: plot_bode(comparison, seed=seed)),
        ("nyquist", lambda: plot_nyquist(comparison, seed=seed)),
        ("residuals", lambda: plot_residuals(comparison, seed=seed)),
    ]
    ranked = ok_results(comparison)
    if any(order_parameter(r) is not None for r in ranked):
        jobs.append(("q_posteriors", lambda: plot_q_posteriors(comparison)))
    colors = colors_for(comparison.ranking)
    for r in ranked:
        stem = _file_stem(r.name)
        jobs.append((f"corner_{stem}", lambda r=r: plot_corner(
            r, color=colors[r.name], linear=linear_fits(r.structure, comparison.data))))
        jobs.append((f"trace_{stem}", lambda r=r: plot_trace(r, color=colors[r.name])))
    return jobs


def write_figures(comparison, out_dir, formats=("png", "pdf"), *, seed: int = 0
                  ) -> dict[str, list[Path]]:
    """Draw every figure of a comparison and write each in every format.

    Figures: ``ranking``, ``bode``, ``nyquist``, ``residuals``, ``q_posteriors`` (when some
    structure has a free fractional order), and ``corner_<structure>`` and
    ``trace_<structure>`` for every structure that ran (structures with ``error`` are
    skipped). Each file is written through a temporary file and a rename
    (:func:`save_figure`); each figure is closed once written.

    Parameters
    ----------
    comparison : bayesfo.compare.Comparison
    out_dir : str or path-like
        Directory (created when missing); files are ``<name>.<format>``.
    formats : sequence of str
        File formats matplotlib can write (``png``, ``pdf``, ``svg``, …).
    seed : int
        Seed of the posterior draws behind the response figures.

    Returns
    -------
    dict of str to list of Path
        ``{figure name: [path per format]}`` in the order above.

    Raises
    ------
    InputError
        If ``formats`` is empty or names a format matplotlib cannot write.
    """
    import matplotlib.pyplot as plt

    formats = _check_formats(formats)
    out_dir = Path(out_dir)
    written: dict[str, list[Path]] = {}
    for name, make in figure_jobs(comparison, seed=seed):
        drawn = make()
        try:
            paths = [out_dir / f"{name}.{fmt}" for fmt in formats]
            with style():
                for i, path in enumerate(paths):
                    save_figure(drawn.figure, path)
                    if i == 0 and drawn.figure.get_layout_engine() is not None:
                        # The layout of the first format holds for the others: computing it
                        # again is a third of the drawing time.
                        drawn.figure.set_layout_engine("none")
            written[name] = paths
        finally:
            plt.close(drawn.figure)
    return written
