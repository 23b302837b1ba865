"""Figure files: atomic saving, and every figure of a comparison written at once."""

from __future__ import annotations

import math
import os
import tempfile
import warnings
from pathlib import Path

from .._io import is_special, publish, write_into, write_target
from .._signals import cause
from ..comparison.table import CRITERIA, CRITERIA_DIRECTION
from ..errors import InputError
from ..options import (
    LEADING,
    LEADING_STRUCTURES,
    STRUCTURE_FIGURES,
    STRUCTURE_FIGURES_TAKES,
    VERY_STRONG,
    figure_format_names,
    structure_figures_ok,
)
from ..parallel import fork_safe, single_blas_thread
from ._compute import ok_results, order_parameter
from .captions import file_stem
from .material import plot_time_functions
from .moduli import PARTS, plot_moduli
from .orders import plot_q_posteriors
from .posterior import plot_corner, plot_trace
from .ranking import plot_ranking
from .response import plot_bode, plot_nyquist, plot_residuals
from .style import comparison_styles, style


def save_figure(fig, path, *, close: bool = False, named: bool = False) -> None:
    """Save ``fig`` to ``path`` (format from the suffix) through a temporary file; with
    ``close``, close it afterwards (also when the save fails). With ``named`` (a file the user
    named: ``--figure FILE``), a symbolic link is written through and a device or FIFO written
    into, never replaced (:func:`bayesfo._io.write_target`)."""
    if close:
        import matplotlib.pyplot as plt

        try:
            return save_figure(fig, path, named=named)
        finally:
            plt.close(fig)
    path = write_target(path) if named else Path(path)
    if named and is_special(path):
        import io

        buffer = io.BytesIO()
        fig.savefig(buffer, dpi=200, format=path.suffix.lower().lstrip(".") or "png")
        write_into(path, buffer.getvalue())
        return None
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        # zlib level 1 for PNG: less saving time for slightly larger files (BENCHMARKS.md,
        # "PNG figures at zlib level 1").
        extra = {"pil_kwargs": {"compress_level": 1}} if path.suffix.lower() == ".png" else {}
        fig.savefig(tmp, dpi=200, **extra)
        publish(tmp, path)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        written = cause(exc, (OSError,)) if not isinstance(exc, OSError) else None
        if isinstance(exc, Exception) and written is not None:
            # The file could not be written (no space left, ...): matplotlib's writer fails
            # again while ending the file (a zlib or attribute error), which hides the cause.
            raise written from None
        raise


_file_stem = file_stem


#: Formats that matplotlib's own backends (Agg, PDF, SVG, PostScript) always write: these are
#: checked without importing matplotlib, which the command loads later, beside other work.
ALWAYS_WRITTEN = frozenset({"png", "pdf", "svg", "eps", "ps"})


def check_formats(formats, argument: str = "argument 'formats'") -> tuple[str, ...]:
    """Figure file formats, lower case without dots, each once; :class:`InputError` naming
    ``argument`` when none is given or matplotlib cannot write one."""
    formats = figure_format_names(formats, argument)
    if ALWAYS_WRITTEN.issuperset(formats):
        return formats
    from matplotlib.backend_bases import FigureCanvasBase

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
        "moduli": lambda: plot_moduli(comparison, seed=seed),
        "time_functions": lambda: plot_time_functions(comparison, seed=seed),
        "nyquist": lambda: plot_nyquist(comparison, seed=seed),
        "residuals": lambda: plot_residuals(comparison, seed=seed),
    }
    if comparison.data.kind not in PARTS:  # a transfer function has no storage and loss parts
        del makers["moduli"]  # nor a relaxation modulus and creep compliance
        del makers["time_functions"]
    if any(order_parameter(r) is not None for r in ok_results(comparison)):
        makers["q_posteriors"] = lambda: plot_q_posteriors(comparison)
    return makers


def has_trace(result) -> bool:
    """Whether ``result`` gets a ``trace_`` figure: the walkers of emcee, or the runs of a
    tempered ladder side by side (they certify the posterior by agreeing). Draws resampled from
    importance weights have neither: their histograms are the corner plot's diagonal, and
    the weights' diagnostics are the report's text."""
    return getattr(result.posterior, "sampler", None) != "importance"


def _structure_makers(result, color) -> dict:
    stem = _file_stem(result.name)
    makers = {
        f"corner_{stem}": lambda: plot_corner(result, color=color, linear=result.fit.linear),
        f"trace_{stem}": lambda: plot_trace(result, color=color),
    }
    if not has_trace(result):
        del makers[f"trace_{stem}"]
    return makers




def leading(comparison) -> list:
    """The leading structures, in the order of the ranking: of the best
    :data:`~bayesfo.options.LEADING_STRUCTURES`, those that the evidence does not rule out (ln Z
    less than :data:`~bayesfo.options.VERY_STRONG` below the best: the best always,
    and any without a ln Z), and every structure that PSIS-LOO, WAIC, AIC or BIC ranks first."""
    ranked = ok_results(comparison)
    if not ranked:
        return []
    best = ranked[0].log_z
    keep = {ranked[0].name}
    for r in ranked[1:LEADING_STRUCTURES]:
        z = r.log_z
        if best is None or z is None or not best - z >= VERY_STRONG:
            keep.add(r.name)
    for criterion in CRITERIA:
        sign = CRITERIA_DIRECTION[criterion]
        scores = [(sign * v, r.name) for r in ranked
                  if (v := getattr(r.criteria, criterion)) is not None and math.isfinite(v)]
        if scores:
            keep.add(max(scores, key=lambda t: t[0])[1])
    return [r for r in ranked if r.name in keep]


def _detailed(comparison, structure_figures) -> list:
    """The structures that get their own figures: the leading ones (:data:`LEADING`, see
    :func:`leading`), the best ``structure_figures`` (a number) or all (None)."""
    if not structure_figures_ok(structure_figures):
        raise InputError(f"argument 'structure_figures' must be {STRUCTURE_FIGURES_TAKES}, got "
                         f"{structure_figures!r}")
    if structure_figures == LEADING:
        return leading(comparison)
    ranked = ok_results(comparison)
    return ranked if structure_figures is None else ranked[:structure_figures]


def figure_jobs(comparison, *, seed: int = 0,
                structure_figures: int | str | None = STRUCTURE_FIGURES) -> list[tuple[str, object]]:
    """``(name, make)`` for every figure of a comparison, ``make()`` returning a
    :class:`~bayesfo.plotting.Drawn`; structures that failed are left out, and only the
    structures of ``structure_figures`` (see :func:`write_figures`) get corner figures, and trace figures
    where :func:`has_trace`."""
    jobs = list(_combined_makers(comparison, seed).items())
    styles = comparison_styles(comparison)
    for r in _detailed(comparison, structure_figures):
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


def write_figures(comparison, out_dir, formats=("png",), *, seed: int = 0, pool=None,
                  processes: int = 1, meanwhile=None,
                  structure_figures: int | str | None = STRUCTURE_FIGURES) -> dict[str, list[Path]]:
    """Draw every figure of a comparison and write each in every format.

    Figures: ``ranking``, ``bode``, ``moduli`` (modulus or compliance data), ``nyquist``,
    ``residuals``, ``q_posteriors`` (when some structure has a free fractional order), and
    ``corner_<structure>`` for the structures of ``structure_figures`` (by default the leading
    ones; structures with ``error`` are skipped), with ``trace_<structure>`` where the
    posterior has walkers or ladder runs to show (:func:`has_trace`; not for draws resampled
    from importance weights).
    Each file is written through a temporary file and a rename
    (:func:`save_figure`); each figure is closed once written.

    Parameters
    ----------
    comparison : bayesfo.comparison.Comparison
    out_dir : str or path-like
        Directory (created when missing); files are ``<name>.<format>``.
    formats : sequence of str
        File formats matplotlib can write (``png``, ``pdf``, ``svg``, …); PNG alone by
        default (the report embeds it; each further format costs about as much again).
    seed : int
        Seed of the posterior draws behind the response figures.
    pool : concurrent.futures.Executor, optional
        Worker processes that draw the figures side by side (e.g.
        :func:`bayesfo.parallel.process_pool`): each combined figure in a task of its own,
        the figures of each structure in one, the costliest first. The files are the same as
        drawn here. A
        :class:`~bayesfo.parallel.LazyPool` that has not started its processes is not started
        for the figures: they are drawn here.
    processes : int
        Without a pool: 2 draws the figures in this process and in one forked from it
        (:func:`draw_forked`; only where :func:`can_fork`, else here alone), 1 here alone. The
        files are the same.
    meanwhile : callable, optional
        Called once in this process before it draws (with two processes or a pool: while the
        forked process or the workers already draw), e.g. to write other files.
    structure_figures : "leading", int or None
        Which structures get corner (and trace) figures: the leading ones (:func:`leading`:
        of the best three, those the evidence does not rule out, and each structure that an
        information criterion ranks first), the best that many by the ranking, or every one
        (None).

    Returns
    -------
    dict of str to list of Path
        ``{figure name: [path per format]}`` in the order above.

    Raises
    ------
    InputError
        If ``formats`` is empty or names a format matplotlib cannot write, or ``processes``
        is not 1 or 2.
    """
    formats = check_formats(formats)
    out_dir = Path(out_dir)
    if processes not in (1, 2):
        raise InputError(f"argument 'processes' must be 1 or 2, got {processes!r}")
    if pool is not None and getattr(pool, "started", True) is False:
        # A lazy pool that the comparison did not need: spawning processes now (each imports
        # matplotlib and the rest) costs more than drawing the figures here (BENCHMARKS.md,
        # "Measurements behind design choices").
        pool = None
    _detailed(comparison, structure_figures)  # checks the argument before any drawing
    if pool is None and processes == 2 and can_fork():
        return draw_forked(comparison, out_dir, formats, seed=seed, meanwhile=meanwhile,
                           structure_figures=structure_figures)
    if pool is None:
        if meanwhile is not None:
            meanwhile()
        written: dict[str, list[Path]] = {}
        for name, make in figure_jobs(comparison, seed=seed,
                                      structure_figures=structure_figures):
            written.update(_save_all({name: make}, out_dir, formats))
        return written
    order = [name for name, _ in figure_jobs(comparison, seed=seed,
                                             structure_figures=structure_figures)]
    combined = list(_combined_makers(comparison, seed))
    styles = comparison_styles(comparison)
    # One task per figure, the costliest first (:func:`_draw_order`), so that the workers end
    # close together. Per-structure tasks carry one result only; the combined figures need all
    # of them (a comparison pickles in a small part of a figure's drawing time).
    by_name = {f"corner_{_file_stem(r.name)}": ("structure", r, styles[r.name].color)
               for r in _detailed(comparison, structure_figures)}
    by_name.update({name: ("combined", comparison, [name]) for name in combined})
    tasks = [by_name[name] for name in _draw_order(comparison, list(by_name))]
    from concurrent.futures import wait
    from concurrent.futures.process import BrokenProcessPool

    futures, pending = [], meanwhile
    try:
        futures = [pool.submit(_draw_in_worker, t, out_dir, formats, seed) for t in tasks]
        if pending is not None:
            # While the workers draw (this process would otherwise wait for them).
            pending, run = None, pending
            try:
                run()
            except Exception:
                # The workers' figures go into ``out_dir``, which the caller removes on an
                # error: those being drawn end first, the others are not started.
                for f in futures:
                    f.cancel()
                wait(futures)
                raise
        drawn = {}
        for f in futures:
            drawn.update(f.result())
    except BrokenProcessPool:
        # A worker died (killed, out of memory): the figures are drawn here (a figure's file is
        # written through a rename, so one the worker left half-done is replaced whole).
        if pending is not None:
            pending()
        drawn = {}
        for name, make in figure_jobs(comparison, seed=seed,
                                      structure_figures=structure_figures):
            drawn.update(_save_all({name: make}, out_dir, formats))
    return {name: drawn[name] for name in order}


# Drawing in two processes: this one and one forked from it.


def can_fork() -> bool:
    """Whether :func:`draw_forked` can fork this process (:func:`bayesfo.parallel.fork_safe`:
    on Linux, no other Python thread running once tqdm's idle monitor is ended, and no
    on-screen matplotlib backend)."""
    return fork_safe()


def _draw_order(comparison, names) -> list[str]:
    """The figures in the order both processes take them: the costliest first (corner plots,
    larger structures first; the q densities; the response figures; traces), so that the two
    processes end close together. The relative costs below follow the time each figure takes
    (BENCHMARKS.md, "Measurements behind design choices")."""
    n_params = {_file_stem(r.name): r.structure.n_params for r in ok_results(comparison)}
    base = {"q_posteriors": 7.0, "bode": 6.0, "moduli": 6.0, "time_functions": 6.0,
            "ranking": 5.5, "residuals": 5.0,
            "nyquist": 4.0}

    def cost(name: str) -> float:
        if name.startswith("corner_"):
            return 8.0 + 0.5 * n_params.get(name[7:], 0) ** 2
        if name.startswith("trace_"):
            return 3.5 + 0.1 * n_params.get(name[6:], 0)
        return base.get(name, 4.5)

    return sorted(names, key=cost, reverse=True)


#: Seconds :func:`draw_forked` waits for the forked process once this one has no figure left
#: to take (it is then drawing its last one, which takes far less than this: BENCHMARKS.md,
#: "Measurements behind design choices").
CHILD_TIMEOUT = 120.0

#: States of a figure in :func:`draw_forked`'s shared table.
_FREE, _HERE, _TAKEN, _DONE = 0, 1, 2, 3


def _take(state, lock, mark: int, child=None):
    """Index of the next free figure, marked ``mark``; ``None`` when none is left.

    With ``child`` (the forked process, given by the parent), a lock that the child still
    holds after it has died (killed inside this short section, e.g. by the kernel's
    out-of-memory killer) does not block the parent: once the child is gone the table is the
    parent's alone, and a figure the child had marked is drawn by the parent afterwards."""
    held = lock.acquire(timeout=None if child is None else 1.0)
    while not held and child.is_alive():
        held = lock.acquire(timeout=1.0)
    try:
        for i in range(len(state)):
            if state[i] == _FREE:
                state[i] = mark
                return i
        return None
    finally:
        if held:
            lock.release()


def _draw_in_child(jobs: dict, order: list[str], state, lock, out_dir: Path, formats,
                   parent: int | None = None) -> None:
    """The forked process: take figures until none is left. It ignores Ctrl-C and ends with
    its parent (:func:`bayesfo.parallel.init_worker`); on any error it stops quietly and the
    parent draws what it had taken (raising there whatever it raises)."""
    try:
        from ..parallel import init_worker

        init_worker(parent)
        while (i := _take(state, lock, _TAKEN)) is not None:
            _save_all({order[i]: jobs[order[i]]}, out_dir, formats)
            state[i] = _DONE
    except BaseException:
        os._exit(1)


def preload(formats) -> None:
    """Import what drawing and saving the figures in ``formats`` needs (matplotlib's pyplot,
    corner, the backends), now rather than at the first figure."""
    import matplotlib.pyplot  # noqa: F401

    _load_before_fork(formats)


def _load_before_fork(formats) -> None:
    """Import, before forking, the modules every figure needs that nothing has imported yet
    (corner, the PDF backend and its font subsetter, the PNG writer) and build the mathtext
    parser, so that both processes share them instead of each loading them. Drawing a first
    figure here would share more but cost this process more before the fork than the two
    processes gain (BENCHMARKS.md, "Measurements behind design choices")."""
    import corner  # noqa: F401
    from matplotlib import mathtext

    if "pdf" in formats:
        import fontTools.subset  # noqa: F401
        import matplotlib.backends.backend_pdf  # noqa: F401
    if "png" in formats:
        import PIL.PngImagePlugin  # noqa: F401
    mathtext.MathTextParser("path").parse(r"$|J^*|\ \alpha\ 10^{3}$", 72)


def draw_forked(comparison, out_dir, formats=("png",), *, seed: int = 0,
                meanwhile=None, structure_figures: int | str | None = STRUCTURE_FIGURES
                ) -> dict[str, list[Path]]:
    """Draw every figure of a comparison in this process and in one forked from it.

    Both take the figures one at a time from one shared table, costliest first
    (:func:`_draw_order`), so that they end close together; ``meanwhile()``, when given, runs
    here first while the forked process already draws. A fork shares everything this process
    has loaded (a spawned process would import matplotlib, arviz and scipy again, which on a
    busy machine made the command slower, not faster: BENCHMARKS.md, "Measurements behind
    design choices"). BLAS runs one thread in both
    (:func:`bayesfo.parallel.single_blas_thread`): no BLAS thread pool is used across the fork.
    If the forked process fails, this one draws the figures it had taken, so the files and any
    error are those of drawing here. The files are those of :func:`write_figures` in one
    process; the result is in its order. Call it where :func:`can_fork` holds.

    Two processes make the command faster on a machine with an idle core, and slower when
    another job keeps a core busy (BENCHMARKS.md, "Measurements behind design choices"), so
    the command forks only when a CPU is idle (:func:`bayesfo.parallel.figure_processes`).
    """
    import multiprocessing


    formats = check_formats(formats)
    out_dir = Path(out_dir)
    jobs = dict(figure_jobs(comparison, seed=seed, structure_figures=structure_figures))
    order = _draw_order(comparison, list(jobs))
    ctx = multiprocessing.get_context("fork")
    lock = ctx.Lock()
    state = ctx.RawArray("b", len(order))
    drawn: dict[str, list[Path]] = {}
    with single_blas_thread():
        _load_before_fork(formats)
        child = ctx.Process(target=_draw_in_child, name="bayesfo-figures", daemon=True,
                            args=(jobs, order, state, lock, out_dir, formats, os.getpid()))
        with warnings.catch_warnings():
            # Python 3.12+ warns at any fork of a process with several OS threads; those here
            # are idle BLAS threads (OpenBLAS re-creates its pool in a child, and both
            # processes run with one BLAS thread), no Python thread runs (can_fork).
            warnings.filterwarnings("ignore", message=".*multi-threaded.*fork",
                                    category=DeprecationWarning)
            child.start()
        try:
            if meanwhile is not None:
                meanwhile()
            while (i := _take(state, lock, _HERE, child)) is not None:
                drawn.update(_save_all({order[i]: jobs[order[i]]}, out_dir, formats))
            # The forked process draws one figure at most by now (a few seconds); one that
            # has not ended in CHILD_TIMEOUT (or holds no figure and has not ended at once) is
            # stopped and its figure drawn here.
            busy = any(state[i] == _TAKEN for i in range(len(order)))
            child.join(CHILD_TIMEOUT if busy else 5.0)
            if child.is_alive():
                child.terminate()
                child.join()
        except BaseException:
            child.terminate()
            child.join()
            raise
        for i, name in enumerate(order):
            if state[i] == _TAKEN:  # the forked process failed: draw its figure here
                for fmt in formats:  # the temporary file of a save it did not finish
                    for stray in out_dir.glob(f".{name}.*.{fmt}"):
                        stray.unlink(missing_ok=True)
                drawn.update(_save_all({name: jobs[name]}, out_dir, formats))
            elif state[i] == _DONE:
                drawn[name] = [out_dir / f"{name}.{fmt}" for fmt in formats]
    return {name: drawn[name] for name in jobs}
