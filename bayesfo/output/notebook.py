"""Results in a notebook: one HTML rendering per result type, which the results'
``_repr_html_`` call (Jupyter shows a :class:`~bayesfo.comparison.results.Comparison`,
:class:`~bayesfo.tts.result.MasterCurve`, :class:`~bayesfo.predictions.functions.Prediction`
or :class:`~bayesfo.predictions.prony.Prony` as a short table, the way lmfit shows its
``ModelResult``). Each rendering lives in its result's own layer; this module gathers them.

Examples
--------
>>> from bayesfo.output.notebook import table
>>> table(["x", "y"], [["1", "<2"]])
'<table><tr><th>x</th><th>y</th></tr><tr><td>1</td><td>&lt;2</td></tr></table>'
"""

from __future__ import annotations

from .._text import MAX_ROWS, table  # noqa: F401
from ..comparison.notebook import comparison_html  # noqa: F401
from ..predictions.notebook import prediction_html, prony_html  # noqa: F401
from ..tts.notebook import mastercurve_html  # noqa: F401
