"""Compare structures on one data set: run each (optimisation, posterior, criteria, evidence),
rank them, and write the output directory.

``run`` (:func:`compare`) → ``criteria`` (per structure) → ``results`` (:class:`Comparison`)
→ ``output`` (:func:`write_outputs`).
"""

from .criteria import LADDER_SHORTFALL, PARETO_K_WARN
from .output import ranking_csv, write_outputs
from .results import RANKING_FIELDS, Comparison, StructureResult
from .run import compare

__all__ = ["LADDER_SHORTFALL", "PARETO_K_WARN", "RANKING_FIELDS", "Comparison", "StructureResult",
           "compare", "ranking_csv", "write_outputs"]
