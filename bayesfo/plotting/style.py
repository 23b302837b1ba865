"""One figure style for every bayesfo plot, applied through a context manager.

The style is a matplotlib rc dictionary (:data:`RC`) entered with :func:`style`; nothing is
changed globally, so a user's own rc settings outside bayesfo plots stay as they were. Sizes
are chosen for a journal column: :data:`COLUMN_WIDTH` = 3.5 in with 8 pt text, and
:data:`PAGE_WIDTH` = 7.1 in for figures that need the full page (corner plots of many
parameters).

Every structure has one style in every figure, from :func:`structure_styles`: a colour of the
Okabe–Ito palette (distinguishable with the common forms of colour blindness), a line style and
a marker, each cycling with its own period (7, 4 and 5), so that neighbours differ in all three
and the first 140 structures get distinct combinations. The index of a structure is its
position in the structures as requested (the order of ``Comparison.results``, the order given to
a batch), which is the same for every data set of a batch: a structure looks the same in the
figures of a comparison and in the batch figures.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass

from ..data.symbols import response_symbol

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

    Yields
    ------
    None
        Figures drawn inside the ``with`` block get the style.

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


#: Line styles of the structures' curves, cycled with period 4 (coprime with the palette's 7).
LINESTYLES = ("-", "--", ":", "-.")
#: Markers of the structures (all fillable: filled and open forms carry meaning), period 5.
MARKERS = ("o", "s", "^", "D", "v")


@dataclass(frozen=True)
class StructureStyle:
    """How one structure is drawn: ``color``, ``linestyle``, ``marker`` (and its ``index``)."""

    index: int
    color: str
    linestyle: object
    marker: str

    @property
    def key(self) -> tuple:
        """(colour, line style, marker): distinct for distinct indices below 140."""
        return (self.color, self.linestyle, self.marker)

    def line(self, **kwargs) -> dict:
        """Keyword arguments of ``Axes.plot`` for a curve of this structure."""
        return {"color": self.color, "linestyle": self.linestyle, **kwargs}


def structure_style(index: int) -> StructureStyle:
    """The style of the structure at position ``index`` (from 0) of the requested structures.

    Examples
    --------
    >>> structure_style(0).key
    ('#0072B2', '-', 'o')
    >>> len({structure_style(i).key for i in range(20)})
    20
    """
    i = int(index)
    return StructureStyle(i, PALETTE[i % len(PALETTE)], LINESTYLES[i % len(LINESTYLES)],
                          MARKERS[i % len(MARKERS)])


def structure_styles(names) -> dict[str, StructureStyle]:
    """``{name: style}`` by position in ``names`` (the structures as requested)."""
    return {n: structure_style(i) for i, n in enumerate(dict.fromkeys(names))}


def comparison_styles(comparison) -> dict[str, StructureStyle]:
    """The styles of a comparison's structures: by their order in ``comparison.results`` (the
    order requested), the order a batch of the same structures uses too."""
    return structure_styles([r.name for r in comparison.results])


def colors_for(names) -> dict[str, str]:
    """``{name: colour}`` of :func:`structure_styles`."""
    return {n: st.color for n, st in structure_styles(names).items()}


QUANTITY = {"compliance": "J^*", "modulus": "G^*", "generic": "G"}


def quantity_symbol(kind: str, symbol: str = "G") -> str:
    """Mathtext symbol of the response for data of ``kind`` measured as ``symbol``
    (:attr:`~bayesfo.data.FrequencyResponse.symbol`): G* or J* for shear, E* or D* for
    tensile data, the plain letter for a generic response."""
    letter = response_symbol(symbol, kind)
    return f"{letter}^*" if kind in ("modulus", "compliance") else letter


def unit_suffix(units: str) -> str:
    """`` [units]`` for an axis label, or an empty string when the data give no units."""
    units = (units or "").strip()
    if not units:
        return ""
    return " [" + units.replace("$", r"\$") + "]"


#: How arguments beyond the measured window are shaded (prediction and Prony figures): hatched,
#: so that they do not read as a credible band.
EXTRAPOLATED = {"facecolor": "0.96", "edgecolor": "0.78", "hatch": "///", "lw": 0, "zorder": 0}


def temperature_colormap():
    """The colours of isotherms by temperature: plasma from dark blue to orange, without the
    pale end (or the pale middle of a diverging map), so that every isotherm shows on white."""
    import matplotlib as mpl
    import numpy as np

    return mpl.colors.ListedColormap(mpl.colormaps["plasma"](np.linspace(0.0, 0.82, 256)),
                                     name="bayesfo_temperature")
