"""One figure style for every bayesfo plot, applied through a context manager.

The style is a matplotlib rc dictionary (:data:`RC`) entered with :func:`style`; nothing is
changed globally, so a user's own rc settings outside bayesfo plots stay as they were. Sizes
are chosen for a journal column: :data:`COLUMN_WIDTH` = 3.5 in with 8 pt text, and
:data:`PAGE_WIDTH` = 7.1 in for figures that need the full page (corner plots of many
parameters).

Colours follow the ranking: the best structure of a comparison gets the first colour of the
Okabe–Ito palette (distinguishable with the common forms of colour blindness) in every figure.
"""

from __future__ import annotations

import contextlib

COLUMN_WIDTH = 3.5
PAGE_WIDTH = 7.1

#: Okabe & Ito (2008), "Color universal design", without yellow (too light on white) and black
#: (reserved for data).
PALETTE = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#56B4E9", "#E69F00", "#999999")
DATA_COLOR = "black"
FLAG_COLOR = "#C00000"

RC = {
    "font.size": 8.0,
    "axes.titlesize": 8.0,
    "axes.labelsize": 8.0,
    "xtick.labelsize": 7.0,
    "ytick.labelsize": 7.0,
    "legend.fontsize": 7.0,
    "figure.titlesize": 8.5,
    "legend.frameon": False,
    "legend.handlelength": 1.6,
    "legend.borderaxespad": 0.3,
    "legend.columnspacing": 1.0,
    "axes.linewidth": 0.6,
    "axes.grid": True,
    "axes.grid.which": "major",
    "grid.linewidth": 0.4,
    "grid.alpha": 0.35,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "xtick.major.width": 0.6,
    "ytick.major.width": 0.6,
    "xtick.minor.width": 0.4,
    "ytick.minor.width": 0.4,
    "xtick.direction": "out",
    "ytick.direction": "out",
    "lines.linewidth": 1.2,
    "lines.markersize": 3.5,
    "errorbar.capsize": 0.0,
    "figure.dpi": 100,
    "savefig.dpi": 300,
    "savefig.bbox": "standard",
    "figure.constrained_layout.use": True,
    "figure.constrained_layout.h_pad": 0.03,
    "figure.constrained_layout.w_pad": 0.03,
    "mathtext.default": "regular",
    "pdf.fonttype": 42,  # TrueType in PDFs: editable text, accepted by journals
    "ps.fonttype": 42,
}


def _rc() -> dict:
    """:data:`RC` with the colour cycle of :data:`PALETTE`."""
    from cycler import cycler

    rc = dict(RC)
    rc["axes.prop_cycle"] = cycler(color=list(PALETTE))
    return rc


@contextlib.contextmanager
def style():
    """Context in which figures get the bayesfo style (matplotlib ``rc_context``).

    Examples
    --------
    >>> import matplotlib
    >>> with style():
    ...     inside = matplotlib.rcParams["font.size"]
    >>> inside
    8.0
    """
    import matplotlib

    with matplotlib.rc_context(_rc()):
        yield


def colors_for(names) -> dict[str, str]:
    """``{name: colour}`` in the order given (the ranking), cycling through :data:`PALETTE`."""
    return {n: PALETTE[i % len(PALETTE)] for i, n in enumerate(names)}


QUANTITY = {"compliance": "J^*", "modulus": "G^*", "generic": "G"}


def quantity_symbol(kind: str) -> str:
    """Mathtext symbol of the response for data of ``kind`` (J*, G*, or G)."""
    return QUANTITY.get(kind, "G")


def unit_suffix(units: str) -> str:
    """`` [units]`` for an axis label, or an empty string when the data give no units."""
    units = (units or "").strip()
    if not units:
        return ""
    return " [" + units.replace("$", r"\$") + "]"
