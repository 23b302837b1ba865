"""bayesfo: uncertainty-aware model choice for fractional-order transfer functions.

From a measured complex frequency response G(jω) to the answer "which model structure do these
data support, and how sure can I be?". The data flow, module by module:

``data`` (FrequencyResponse, CSV reader) → ``structures`` (model cards in ``models/*.toml``,
evaluated by ``response``) → ``identify`` (methods 1–5, q grid, global optimisation: the seeds)
→ ``inference`` (likelihood, emcee posterior, diagnostics) → ``compare`` (criteria, ranking,
output files). ``timeseries`` turns raw sine records into frequency responses; ``timedomain``
simulates fitted models in the time domain for validation; ``studies`` reruns the thesis'
Monte Carlo studies.

Example
-------
>>> from bayesfo import read_csv, get_structure                   # doctest: +SKIP
>>> from bayesfo.compare import compare                           # doctest: +SKIP
>>> data = read_csv("examples/data/adhesive_468mp/Tp020C.csv")       # doctest: +SKIP
>>> result = compare(data, [get_structure("voigt"), get_structure("zener")])  # doctest: +SKIP
>>> result.ranking                                                   # doctest: +SKIP
['voigt', 'zener']
"""

from .data import FrequencyResponse, read_csv
from .errors import BayesfoError, InputError, NonlinearityWarning, StructureError
from .structures import get_structure, resolve_structures

__version__ = "0.1.0"

__all__ = [
    "BayesfoError",
    "FrequencyResponse",
    "InputError",
    "NonlinearityWarning",
    "StructureError",
    "__version__",
    "get_structure",
    "read_csv",
    "resolve_structures",
]
