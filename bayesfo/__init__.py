"""bayesfo: uncertainty-aware model choice for fractional-order transfer functions.

From a measured complex frequency response G(jω) to the answer "which model structure do these
data support, and how sure can I be?". The data flow, package by package (the layers and the
words: ``docs/architecture.md``):
``data`` (FrequencyResponse, readers, temperatures) → ``structures`` (cards in
``bayesfo/models/*.toml``, evaluated by ``structures.response``) → ``identify`` (methods 1–5,
q grid, global optimisation: the seeds) → ``inference`` (likelihood, ``certified_posterior``,
diagnostics, evidence) → ``predictions`` (material functions with credible bands) →
``comparison`` (steps, schedule, criteria, results, ``load``) and ``tts`` (master curves) →
``planning`` (the frequencies to measure next) → ``plotting`` → ``output`` (``write_outputs``,
report, verdict) → ``batch`` (many data sets) and ``cli`` (the command line). ``options``
checks the options of a comparison before any work; ``outdir`` keeps each output directory the
output of one run; ``parallel`` is the executor; ``timeseries`` turns sine records into a
frequency response and simulates fitted models in time; ``studies`` reruns the thesis' Monte
Carlo studies.

Example
-------
>>> import bayesfo as bf                                               # doctest: +SKIP
>>> data = bf.read("examples/data/adhesive_468mp/Tp020C.csv")          # doctest: +SKIP
>>> result = bf.compare(data, "voigt,zener", workers=1)                # doctest: +SKIP
>>> result.ranking                                                     # doctest: +SKIP
['voigt', 'zener']
>>> bf.write_outputs(result, "out")                                    # doctest: +SKIP
>>> bf.load("out").table() == result.table()   # read back, nothing re-run  # doctest: +SKIP
True
"""


def _package_version() -> str:
    """The installed version (importlib.metadata takes a tenth of a second to load: it is
    loaded when ``bayesfo.__version__`` is first asked for)."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as _version

    try:
        return _version("bayesfo")
    except PackageNotFoundError:  # run from a source tree that is not installed
        return "0+unknown"

from .errors import BayesfoError, InputError, NonlinearityWarning, OutputError, StructureError  # noqa: E402

#: Names of the flat API loaded on first use, so that ``import bayesfo`` imports neither numpy
#: nor scipy: ``bayesfo --help`` stays fast, and a Ctrl-C while the command line's libraries
#: load reaches :func:`bayesfo.cli.main`, which says "interrupted" in one line (it gave a
#: traceback of 30 to 50 lines while ``import bayesfo`` loaded scipy).
_LAZY = {"compare": "comparison", "write_outputs": "output", "write_mastercurve": "output",
         "load": "comparison",
         "Comparison": "comparison", "StructureResult": "comparison", "Criteria": "comparison",
         "predict": "predictions", "Prediction": "predictions",
         "mastercurve": "tts", "MasterCurve": "tts", "design": "planning", "Design": "planning",
         "FrequencyResponse": "data", "read": "data", "read_csv": "data",
         "get_structure": "structures", "list_structures": "structures",
         "resolve_structures": "structures"}


#: Subpackages reachable as attributes without an import of their own (``bf.plotting``), loaded
#: on first use: matplotlib is imported only by a program that draws.
_LAZY_MODULES = ("plotting", "inference", "identify", "batch", "predictions", "tts", "output",
                 "timeseries", "planning", "data", "structures")


def __getattr__(name):
    import importlib

    if name == "__version__":
        globals()["__version__"] = version = _package_version()
        return version
    if name in _LAZY:
        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    if name in _LAZY_MODULES:
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module 'bayesfo' has no attribute {name!r}")

__all__ = [
    "BayesfoError",
    "Comparison",
    "Criteria",
    "Design",
    "OutputError",
    "Prediction",
    "StructureResult",
    "compare",
    "design",
    "load",
    "mastercurve",
    "predict",
    "read",
    "write_mastercurve",
    "write_outputs",
    "FrequencyResponse",
    "InputError",
    "MasterCurve",
    "NonlinearityWarning",
    "StructureError",
    "__version__",
    "get_structure",
    "list_structures",
    "read_csv",
    "resolve_structures",
]
