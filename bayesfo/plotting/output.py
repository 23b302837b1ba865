"""Figure files: atomic saving, and every figure of a comparison written at once."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from ..errors import InputError
from ._compute import ok_results, order_parameter
from .captions import file_stem
from .posterior import plot_corner, plot_q_posteriors, plot_trace
from .ranking import plot_ranking
from .response import plot_bode, plot_nyquist, plot_residuals
from .style import comparison_styles, style


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


_file_stem = file_stem


def check_formats(formats, argument: str = "argument 'formats'") -> tuple[str, ...]:
    """Figure file formats, lower case without dots, each once; :class:`InputError` naming
    ``argument`` when none is given or matplotlib cannot write one."""
    from matplotlib.backend_bases import FigureCanvasBase

    if isinstance(formats, str):
        formats = (formats,)
    formats = tuple(dict.fromkeys(str(f).strip().lower().lstrip(".") for f in formats))
    if not formats:
        raise InputError(f"{argument} is empty")
    supported = FigureCanvasBase.get_supported_filetypes()
    bad = [f for f in formats if f not in supported]
    if bad:
        raise InputError(f"{argument}: cannot write '{bad[0]}' figures; use one of "
                         + ", ".join(sorted(supported)))
    return formats


def _combined_makers(comparison, seed: int) -> dict:
    """The figures drawn from the whole comparison, by name, in the order they are written."""
    makers = {
        "ranking": lambda: plot_ranking(comparison),
        "bode": lambda: plot_bode(comparison, seed=seed),
        "nyquist": lambda: plot_nyquist(comparison, seed=seed),
        "residuals": lambda: plot_residuals(comparison, seed=seed),
    }
    if any(order_parameter(r) is not None for r in ok_results(comparison)):
        makers["q_posteriors"] = lambda: plot_q_posteriors(comparison)
    return makers


def _structure_makers(result, color) -> dict:
    stem = _file_stem(result.name)
    return {
        f"corner_{stem}": lambda: plot_corner(result, color=color, linear=result.fit.linear),
        f"trace_{stem}": lambda: plot_trace(result, color=color),
    }


def figure_jobs(comparison, *, seed: int = 0) -> list[tuple[str, object]]:
    """``(name, make)`` for every figure of a comparison, ``make()`` returning a
    :class:`~bayesfo.plotting.Drawn`; structures that failed are left out."""
    jobs = list(_combined_makers(comparison, seed).items())
    styles = comparison_styles(comparison)
    for r in ok_results(comparison):
        jobs.extend(_structure_makers(r, styles[r.name].color).items())
    return jobs


def _save_all(makers: dict, out_dir: Path, formats) -> dict[str, list[Path]]:
    """Draw each figure of ``makers`` and write it in every format."""
    import matplotlib.pyplot as plt

    written = {}
    for name, make in makers.items():
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


def _draw_in_worker(task: tuple, out_dir: Path, formats, seed: int) -> dict[str, list[Path]]:
    """One task of a worker process: ``("combined", comparison, names)`` or
    ``("structure", result, color)``."""
    import matplotlib

    matplotlib.use("agg")  # a worker never shows a window
    if task[0] == "combined":
        _, comparison, names = task
        makers = {k: v for k, v in _combined_makers(comparison, seed).items() if k in names}
    else:
        _, result, color = task
        makers = _structure_makers(result, color)
    return _save_all(makers, out_dir, formats)


def write_figures(comparison, out_dir, formats=("png", "pdf"), *, seed: int = 0, pool=None
                  ) -> dict[str, list[Path]]:
    """Draw every figure of a comparison and write each in every format.

    Figures: ``ranking``, ``bode``, ``nyquist``, ``residuals``, ``q_posteriors`` (when some
    structure has a free fractional order), and ``corner_<structure>`` and
    ``trace_<structure>`` for every structure that ran (structures with ``error`` are
    skipped). Each file is written through a temporary file and a rename
    (:func:`save_figure`); each figure is closed once written.

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
    out_dir : str or path-like
        Directory (created when missing); files are ``<name>.<format>``.
    formats : sequence of str
        File formats matplotlib can write (``png``, ``pdf``, ``svg``, …).
    seed : int
        Seed of the posterior draws behind the response figures.
    pool : concurrent.futures.Executor, optional
        Worker processes that draw the figures side by side (e.g.
        :func:`bayesfo.parallel.process_pool`): the combined figures in two tasks, the figures
        of each structure in one. The files are the same as drawn here. A
        :class:`~bayesfo.parallel.LazyPool` that has not started its processes is not started
        for the figures: they are drawn here.

    Returns
    -------
    dict of str to list of Path
        ``{figure name: [path per format]}`` in the order above.

    Raises
    ------
    InputError
        If ``formats`` is empty or names a format matplotlib cannot write.
    """
    formats = check_formats(formats)
    out_dir = Path(out_dir)
    if pool is not None and getattr(pool, "started", True) is False:
        # A lazy pool that the comparison did not need: spawning processes now (each imports
        # matplotlib and the rest) costs more than drawing the figures here (measured on the
        # 2-core machine: 9 s here against 24-26 s in two fresh processes, PNG and PDF of
        # Voigt and Zener, busy machine).
        pool = None
    if pool is None:
        written: dict[str, list[Path]] = {}
        for name, make in figure_jobs(comparison, seed=seed):
            written.update(_save_all({name: make}, out_dir, formats))
        return written
    order = [name for name, _ in figure_jobs(comparison, seed=seed)]
    combined = list(_combined_makers(comparison, seed))
    styles = comparison_styles(comparison)
    # Per-structure tasks carry one result only; the combined figures need all of them.
    tasks = [("structure", r, styles[r.name].color)
             for r in ok_results(comparison)]
    tasks += [("combined", comparison, combined[0::2]), ("combined", comparison, combined[1::2])]
    futures = [pool.submit(_draw_in_worker, t, out_dir, formats, seed) for t in reversed(tasks)]
    drawn = {}
    for f in futures:
        drawn.update(f.result())
    return {name: drawn[name] for name in order}
