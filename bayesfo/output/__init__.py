"""The output layer: from a comparison's results to files a user opens.

``write`` (:func:`write_outputs`: ``ranking.csv``, ``summary.json``, the NetCDF posteriors,
figures and report, staged and swapped in as one run by :mod:`bayesfo.outdir`; and
:func:`write_mastercurve`, a master curve's directory) → ``report``
(``report.html``) ← ``verdict`` (the plain-language verdict at the top of the report and the
terminal). It reads results and writes files; nothing below it imports it.
"""

from .report import render_report, write_report
from .verdict import verdict
from .write import mastercurve_summary, ranking_csv, write_mastercurve, write_outputs

__all__ = ["mastercurve_summary", "ranking_csv", "render_report", "verdict", "write_mastercurve",
           "write_outputs", "write_report"]
