"""The legend above the response figures (Bode, Nyquist, residuals): as many columns as the
labels fit, and the note of coinciding curves as its title."""

from __future__ import annotations

import numpy as np


def _legend(fig, handles, labels, note: str = ""):
    """The legend above the axes; ``note`` (what coincides) as its title."""
    from matplotlib.legend_handler import HandlerTuple

    ncols = _legend_columns(fig, labels)
    leg = fig.legend(handles, labels, loc="outside upper center", ncols=ncols,
                     handler_map={tuple: HandlerTuple(ndivide=1, pad=0.0)},
                     title=_wrapped(note) or None, title_fontsize=7.0)
    return leg


def _legend_columns(fig, labels, max_columns: int = 3) -> int:
    """The most columns (at most ``max_columns``) in which the legend entries fit the figure's
    width, from the labels' widths in the legend's font: three columns of long structure names
    ("fractional_maxwell_gel (misfits)") ran past both edges of the figure and were cut."""
    import matplotlib as mpl
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextToPath

    if len(labels) < 2:
        return 1
    prop = FontProperties(size=mpl.rcParams["legend.fontsize"])
    size = prop.get_size_in_points()
    widths = [TextToPath().get_text_width_height_descent(str(label), prop,
                                                         ismath=str(label).count("$") >= 2)[0]
              for label in labels]
    per_entry = (mpl.rcParams["legend.handlelength"] + mpl.rcParams["legend.handletextpad"]
                 + mpl.rcParams["legend.columnspacing"]) * size
    available = fig.get_figwidth() * 72.0 - 2 * (mpl.rcParams["legend.borderpad"] + 1.0) * size
    for n in range(min(len(labels), max_columns), 1, -1):
        # matplotlib fills the columns one after the other, the first len % n columns with one
        # entry more than the rest (four entries in three columns: 2, 1, 1).
        rows, extra = divmod(len(labels), n)
        sizes = [rows + 1] * extra + [rows] * (n - extra)
        starts = np.cumsum([0, *sizes])
        columns = [widths[a:b] for a, b in zip(starts[:-1], starts[1:], strict=True) if b > a]
        if sum(max(c) + per_entry for c in columns) <= available:
            return n
    return 1


def _wrapped(note: str, width: int = 60) -> str:
    """The note in lines of at most ``width`` characters, one clause (``;``) per line: a note
    naming several groups would otherwise run past both edges of the figure (BENCHMARKS.md,
    "Measurements behind design choices")."""
    import textwrap

    return "\n".join(line for part in note.split("; ") if part
                     for line in textwrap.wrap(part, width))


def _note_artists(legend, note: str) -> dict:
    return {"note": legend.get_title()} if note else {}
