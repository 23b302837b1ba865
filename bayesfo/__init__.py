"""bayesfo: uncertainty-aware model choice for fractional-order transfer functions.

From a measured complex frequency response G(jω) to the answer "which model structure do these
data support, and how sure can I be?". The data flow, module by module:

``data`` (FrequencyResponse, CSV reader) → ``structures`` (model cards in ``models/*.toml``,
evaluated by ``response``) → identification seeds → posteriors → evidence and criteria → ranking.
``timeseries`` turns raw sine records into frequency responses; ``timedomain`` simulates fitted
models in the time domain for validation.
"""

from .data import FrequencyResponse, read_csv
from .errors import BayesfoError, InputError, NonlinearityWarning, StructureError

__version__ = "0.1.0"

__all__ = [
    "BayesfoError",
    "FrequencyResponse",
    "InputError",
    "NonlinearityWarning",
    "StructureError",
    "__version__",
    "read_csv",
]
