"""Compare structures on one data set: run each (optimisation, posterior, criteria, evidence),
rank them, and write the output directory; read it back.

``run`` (:func:`compare`) → ``criteria`` (per structure; ``criteria_types``: :class:`Criteria`)
→ ``results`` (:class:`Comparison`); ``stored`` (:func:`load`) reads back what
:func:`bayesfo.output.write_outputs` wrote.
"""

from ..inference.certified import LADDER_SHORTFALL
from .criteria import PARETO_K_WARN
from .criteria_types import Criteria
from .results import Comparison, StructureResult
from .run import compare
from .stored import load
from .table import RANKING_FIELDS, ranking_rows

__all__ = ["LADDER_SHORTFALL", "PARETO_K_WARN", "RANKING_FIELDS", "Comparison", "Criteria",
           "StructureResult", "compare", "load", "ranking_rows"]

