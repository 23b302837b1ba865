"""Many data sets: :func:`~bayesfo.compare.compare` on each, on local processes or a Dask cluster.

``bayesfo batch INPUT... --out DIR`` expands its inputs (files, directories of ``*.csv``, glob
patterns, manifests) into data sets, runs the comparison of each in a worker, and writes

* ``DIR/<id>/`` per data set: what ``bayesfo compare`` writes (``summary.json``, ``ranking.csv``,
  one NetCDF per structure, and unless ``--no-figures`` the figures and ``report.html``), plus
  ``batch.json`` (the task: data-file hash, options, seed, bayesfo version; the status,
  warnings and timings) and, for a data set that failed, ``error.txt``;
* ``DIR/batch_summary.csv``: one row per data set and structure (ln Z, posterior probability,
  criteria, posterior of q), and one row with the error for a data set that failed;
* ``DIR/batch_summary.png`` and ``.pdf``: the posterior model probabilities and the posterior of
  q per data set;
* when the data sets have temperatures (isotherms), ``DIR/temperature_summary.csv`` and
  ``DIR/temperature_q.png``/``.pdf``: the posterior of q (mean, 94 % HDI) against temperature
  per structure, and the best structure at each temperature.

Design
------
*Tasks are plain data.* A task is a dict of the data file's path and bytes, the options and the
seed; the worker (:func:`run_task`) reads the CSV itself, runs the comparison, writes its outputs
into a private temporary directory and returns their bytes. Only the client process writes into
``DIR``, each file through a temporary file and a rename, ``summary.json`` after the NetCDF files
and ``batch.json`` last, so workers need no shared file system and an interrupted run never
leaves a data set that looks complete but is not.

*Resume.* A data set is complete when ``DIR/<id>/batch.json`` records status ``ok`` for the same
task (SHA-256 of the data file, options, seed, bayesfo version) and the files it lists exist. A
re-run reads such data sets back from their ``summary.json`` and runs the others, including
those that failed before.

*Failures are per data set.* Bad input (:class:`~bayesfo.errors.InputError`: an unreadable file,
a bad cell, too few points for every structure) and internal errors are caught in the worker
and recorded in ``error.txt``, ``batch.json`` and the summary table; a worker that dies is
recorded the same way. The others always finish.

*Seeds.* Every data set runs with the same seed (the ``--seed`` of the command, or its
manifest's ``seed`` cell), so numbers do not depend on the number of workers, on the executor or
on the order in which tasks finish, and ``DIR/<id>/`` holds what ``bayesfo compare FILE --seed N``
would write for that file.

*Executors.* ``workers=1``: in this process. ``workers > 1``: a
:class:`concurrent.futures.ProcessPoolExecutor` with the ``spawn`` start method, one
single-threaded BLAS per worker. ``scheduler=ADDRESS``: a :class:`distributed.Client` connected to
a running Dask scheduler (``client.submit`` and ``distributed.as_completed``); workers should run
one thread each (``dask worker ADDRESS --nthreads 1``), as the comparison holds the GIL most of
the time and its warnings are captured per process. With ``--models``, the card paths must be
readable on the workers.
"""

from __future__ import annotations

import csv
import glob
import hashlib
import io
import json
import math
import os
import re
import socket
import sys
import tempfile
import time
import traceback
import warnings
from concurrent.futures import FIRST_COMPLETED, wait
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from . import __version__
from ._io import atomic_write_text, read_text_file
from .errors import InputError
from .outdir import check_output_directory, is_output_path, recover, staged_run

#: Options of one data set, with the defaults of ``bayesfo compare``.
DEFAULT_OPTIONS = {
    "kind": None,            # None: the file's '# kind:' line, else generic
    "reciprocal": False,     # compare 1/G of the data
    "structures": None,      # comma list; None: DEFAULT_STRUCTURES of the command line
    "noise": "auto",
    "priors": (),            # NAME=TYPE:A:B specifications
    "holdout": None,         # angular frequencies [rad/s] left out of the fit
    "evidence": "auto",      # ln Z from the emcee draws (bridge), a tempered ladder, or auto
    "evidence_check": False,
    "models": (),            # extra structure cards (paths)
    "figures": True,         # per-data-set figures and report.html, as bayesfo compare
}

KINDS = ("compliance", "modulus", "generic")
EVIDENCE_ROUTES = ("auto", "bridge", "ladder")
NOISE_MODELS = ("auto", "known", "constant", "proportional")

#: Manifest columns; ``invert`` is another name for ``reciprocal``.
MANIFEST_COLUMNS = ("path", "id", "kind", "reciprocal", "invert", "structures", "noise", "prior",
                    "seed", "holdout", "evidence", "evidence_check", "temperature")

#: Files written at the top of the output directory (no data-set id may take these names).
COMBINED_FILES = ("batch_summary.csv", "batch_summary.png", "batch_summary.pdf",
                  "temperature_summary.csv", "temperature_q.png", "temperature_q.pdf")

BATCH_FIELDS = ("dataset", "path", "temperature_C", "status", "structure", "rank", "best",
                "n_params", "log_evidence", "log_evidence_err", "delta_log_evidence",
                "posterior_probability", "loo", "loo_se", "waic", "aic", "aicc", "bic",
                "max_log_likelihood", "rmse", "q_parameter", "q_mean", "q_sd", "q_hdi_low",
                "q_hdi_high", "q_map", "rhat_max", "ess_min", "converged", "pareto_k_max",
                "noise", "kind", "n_frequencies", "warnings", "error")

TEMPERATURE_FIELDS = ("temperature_C", "dataset", "structure", "rank", "best", "best_structure",
                      "log_evidence", "log_evidence_err", "posterior_probability", "q_parameter",
                      "q_mean", "q_sd", "q_hdi_low", "q_hdi_high", "converged")

#: Status of a data set: compared, bad input, or anything else that went wrong.
OK, INPUT_ERROR, INTERNAL_ERROR = "ok", "input_error", "internal_error"

#: Seconds to wait for a Dask scheduler to answer.
SCHEDULER_TIMEOUT = 15.0

_BATCH_JSON = "batch.json"
_ERROR_TXT = "error.txt"
_FORMAT = 1  # version of batch.json

# BLAS/OpenMP thread pools of the worker processes: one thread each, as the workers already use
# the cores (set before the worker imports numpy, unless the user set them).


# ====================================================================== data sets
@dataclass(frozen=True, eq=False)
class DataSet:
    """One data set of a batch: a CSV file with the options of its comparison.

    Attributes
    ----------
    id : str
        Name of its sub-directory of the output directory (unique, case-insensitively).
    path : str
        The CSV file, as given (relative to the working directory, or absolute).
    options : dict
        Keys of :data:`DEFAULT_OPTIONS`; ``structures`` is a tuple of resolved names.
    seed : int
    temperature : float or None
        Temperature [°C] of an isotherm, if known.
    origin : str
        Where the data set was named (an argument, or a manifest line), for messages.
    error : str or None
        Bad input found while the inputs were read (a ``# temperature:`` line that is not a
        temperature): the data set is recorded as an input error and not run; the others run.
    """

    id: str
    path: str
    options: dict
    seed: int
    temperature: float | None = None
    origin: str = ""
    error: str | None = None

    def task(self) -> dict:
        """The picklable task of :func:`run_task`, carrying the data file's bytes (a few kB)
        so that a worker on another machine needs no access to the file."""
        try:
            content = Path(self.path).read_bytes()
        except OSError:
            content = None  # the worker reports the problem
        return {"id": self.id, "path": str(Path(self.path).resolve()), "content": content,
                "options": dict(self.options), "seed": self.seed}

    def fingerprint(self) -> dict:
        """What makes a stored result valid for this data set: the data file's content, the
        options, the seed and the bayesfo version."""
        return {"sha256": _sha256(self.path), "options": _jsonable(self.options),
                "seed": self.seed, "bayesfo": __version__}


def _jsonable(obj):
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    return obj


def _sha256(path) -> str | None:
    digest = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            for chunk in iter(lambda: fh.read(1 << 20), b""):
                digest.update(chunk)
    except OSError:
        return None
    return digest.hexdigest()


def check_options(options: dict, where: str) -> dict:
    """Check the options of one data set before any work and put them in canonical form.

    Parameters
    ----------
    options : dict
        Keys of :data:`DEFAULT_OPTIONS` (missing keys take the defaults).
    where : str
        Names the source of the options in messages (e.g. ``"manifest 'm.csv', line 3"``).

    Returns
    -------
    dict
        The options with ``structures`` as a tuple of structure names, ``priors`` a tuple of
        specifications, ``holdout`` a tuple of floats or None, ``models`` a tuple of absolute
        paths.

    Raises
    ------
    InputError
        For an unknown option, kind, noise model or structure, a malformed or unused prior, or a
        hold-out frequency that is not a positive number; the message starts with ``where``.
    """
    from .cli import DEFAULT_STRUCTURES, _parse_priors
    from .structures import default_library, load_library, resolve_structures

    unknown = set(options) - set(DEFAULT_OPTIONS)
    if unknown:
        raise InputError(f"{where}: unknown option '{sorted(unknown)[0]}'")
    opts = {**DEFAULT_OPTIONS, **options}
    if opts["kind"] is not None and opts["kind"] not in KINDS:
        raise InputError(f"{where}: kind must be one of {', '.join(KINDS)}, got {opts['kind']!r}")
    if opts["noise"] not in NOISE_MODELS:
        raise InputError(f"{where}: noise must be one of {', '.join(NOISE_MODELS)}, "
                         f"got {opts['noise']!r}")
    models = tuple(str(Path(m).resolve()) for m in opts["models"])
    try:
        library = load_library(extra=models) if models else default_library()
        spec = opts["structures"] or DEFAULT_STRUCTURES
        names = spec if isinstance(spec, str) else ",".join(spec)
        structures = resolve_structures(names, library)
        priors = tuple(opts["priors"])
        parsed = _parse_priors(priors)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    known = {p for s in structures for p in s.param_names} | {"sigma", "sigma_rel"}
    unused = [k for k in parsed if k not in known]
    if unused:
        raise InputError(f"{where}: prior '{unused[0]}' names a parameter no selected "
                         "structure has")
    holdout = opts["holdout"]
    if holdout is not None:
        holdout = tuple(float(w) for w in holdout)
        if not holdout:
            holdout = None
        elif not all(math.isfinite(w) and w > 0 for w in holdout):
            raise InputError(f"{where}: hold-out frequencies must be positive numbers, "
                             f"got {holdout}")
    return {"kind": opts["kind"], "reciprocal": bool(opts["reciprocal"]),
            "structures": tuple(s.name for s in structures), "noise": opts["noise"],
            "priors": priors, "holdout": holdout, "evidence": opts["evidence"],
            "evidence_check": bool(opts["evidence_check"]),
            "models": models, "figures": bool(opts["figures"])}


#: Seeds are 32-bit: every random generator in the chain (numpy, scipy, emcee) accepts them.
MAX_SEED = 2**32 - 1


def _check_seed(seed, where: str) -> int:
    if (isinstance(seed, bool) or not isinstance(seed, (int, np.integer))
            or not 0 <= seed <= MAX_SEED):
        raise InputError(f"{where}: the seed must be an integer from 0 to {MAX_SEED}, "
                         f"got {seed!r}")
    return int(seed)


def seed_argument(text: str) -> int:
    """argparse type of ``--seed``."""
    import argparse

    try:
        value = int(text)
    except ValueError:
        value = None
    if value is None or not 0 <= value <= MAX_SEED:
        raise argparse.ArgumentTypeError(f"expected an integer from 0 to {MAX_SEED}, got {text!r}")
    return value


# ---------------------------------------------------------------------- temperatures
_NUMBER = r"[+\-\u2212]?\d+(?:\.\d*)?(?:[eE][+\-]?\d+)?"
_TEMPERATURE_VALUE = re.compile(rf"^\s*({_NUMBER})\s*(°\s*C|deg\s*C|C|K)?\s*$", re.IGNORECASE)
_TEMPERATURE_IN_NAME = re.compile(rf"({_NUMBER})\s*°\s*C")
_TEMPERATURE_IN_STEM = re.compile(r"(?:^|[_\-\s.])T([mp+\-])?(\d+)(?:[.p](\d+))?C(?=$|[_\-\s.])",
                                  re.IGNORECASE)


def parse_temperature(text: str) -> float | None:
    """A temperature in °C from text such as ``"20"``, ``"-10 °C"``, ``"20 C"`` or ``"293.15 K"``.

    Returns None when the text is not a temperature.

    Examples
    --------
    >>> parse_temperature("293.15 K")
    20.0
    >>> parse_temperature("-10 °C")
    -10.0
    """
    m = _TEMPERATURE_VALUE.match(text)
    if not m:
        return None
    value = float(m.group(1).replace("\u2212", "-"))
    if (m.group(2) or "").upper() == "K":
        value = round(value - 273.15, 10)
    return value


def temperature_from_stem(stem: str) -> float | None:
    """A temperature in °C from a file stem such as ``T020C``, ``Tp020C``, ``Tm010C`` (−10 °C).

    ``m`` or ``-`` before the digits is a minus sign, ``p`` or ``+`` a plus sign; ``T20p5C`` is
    20.5 °C. The pattern must stand alone in the stem (at its start or end, or between ``_``,
    ``-``, ``.`` or spaces).

    Examples
    --------
    >>> temperature_from_stem("Tm010C"), temperature_from_stem("run3_T20p5C")
    (-10.0, 20.5)
    """
    m = _TEMPERATURE_IN_STEM.search(stem)
    if not m:
        return None
    value = float(m.group(2) + ("." + m.group(3) if m.group(3) else ""))
    return -value if (m.group(1) or "").lower() in ("m", "-") else value


def temperature_of_file(path) -> float | None:
    """The temperature [°C] of a data file: a ``# temperature:`` comment (``20``, ``20 C``,
    ``293.15 K``), else the file stem (:func:`temperature_from_stem`), else a ``# name:`` comment
    holding ``<number> °C``; None if none of these gives one or the file cannot be read (the
    comparison reports that).

    Raises
    ------
    InputError
        If a ``# temperature:`` comment is not a temperature (naming the file and line).
    """
    try:
        text = read_text_file(path)
    except InputError:
        return None
    meta = {}
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped.startswith("#"):
            continue
        key, sep, value = stripped.lstrip("#").partition(":")
        key = key.strip().lower()
        if sep and key == "temperature" and key not in meta:
            meta[key] = parse_temperature(value)
            if meta[key] is None:
                raise InputError(f"file '{path}', line {lineno}: '# temperature:' expects a "
                                 f"temperature such as 20, 20 C or 293.15 K, got {value.strip()!r}")
        elif sep and key == "name":
            meta.setdefault(key, value.strip())
    if meta.get("temperature") is not None:
        return meta["temperature"]
    value = temperature_from_stem(Path(path).stem)
    if value is not None:
        return value
    found = _TEMPERATURE_IN_NAME.findall(meta.get("name", ""))
    return float(found[-1].replace("\u2212", "-")) if found else None


def _temperature_or_error(path) -> tuple[float | None, str | None]:
    """:func:`temperature_of_file`, with its input error as a message instead: one bad file
    does not stop the batch."""
    try:
        return temperature_of_file(path), None
    except InputError as exc:
        return None, str(exc)


# ---------------------------------------------------------------------- inputs and manifests
def _looks_like_manifest(path: Path) -> bool:
    """A CSV whose header row has a ``path`` column (data files never have one)."""
    try:
        text = read_text_file(path)
    except InputError:
        return False
    for line in text.splitlines():
        stripped = line.strip()
        if stripped and not stripped.startswith("#"):
            cells = next(csv.reader([line]))
            return "path" in {c.strip().lower() for c in cells}
    return False


_TRUE = {"1", "true", "yes", "y"}
_FALSE = {"0", "false", "no", "n"}


def _bool_cell(cell: str, where: str) -> bool:
    value = cell.strip().lower()
    if value in _TRUE:
        return True
    if value in _FALSE:
        return False
    raise InputError(f"{where}: expected true or false, got {cell!r}")


def _float_list(text: str, where: str) -> tuple[float, ...]:
    try:
        return tuple(float(v) for v in re.split(r"[,;\s]+", text.strip()) if v)
    except ValueError:
        raise InputError(f"{where}: expected numbers separated by ',' or ';', "
                         f"got {text!r}") from None


@dataclass(frozen=True, eq=False)
class _Entry:
    """A data set before its id is assigned."""

    path: Path
    options: dict
    seed: int
    temperature: float | None
    origin: str
    id: str | None = None  # given in a manifest
    error: str | None = None  # see DataSet.error


def _read_manifest(path, *, defaults: dict | None = None, seed: int = 0) -> list[_Entry]:
    """Read a manifest: a CSV naming data files, one per row, with per-file options.

    Columns (header row required, case-insensitive, ``#`` comment lines allowed):
    ``path`` (required; relative paths are relative to the manifest's directory), and optionally
    ``id`` (the sub-directory name), ``kind``, ``reciprocal`` (or ``invert``: compare 1/G of the
    data; true/false), ``structures`` (a comma list, quoted), ``noise``, ``prior`` (specifications
    ``NAME=TYPE:A:B`` separated by ``;``), ``seed``, ``holdout`` (angular frequencies separated by
    ``;``), ``evidence`` (auto, bridge or ladder), ``evidence_check`` (true/false) and ``temperature`` (``20``, ``20 C``, ``293.15 K``).
    An empty cell takes the command line's value.

    Parameters
    ----------
    path : path-like
    defaults : dict, optional
        Options of the command line (keys of :data:`DEFAULT_OPTIONS`).
    seed : int
        The command line's seed.

    Returns
    -------
    list
        One entry per row, options checked (see :func:`check_options`).

    Raises
    ------
    InputError
        Naming the manifest, the line and the column: an unreadable file, no ``path`` column, an
        unknown or repeated column, a row with the wrong number of cells, an empty path, a file
        that does not exist, or a value that cannot be used.
    """
    path = Path(path)
    where = f"manifest '{path}'"
    text = read_text_file(path, "manifest")
    base = dict(DEFAULT_OPTIONS, **(defaults or {}))
    header, header_line = None, 0
    entries = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        cells = [c.strip() for c in next(csv.reader([line]))]
        if header is None:
            header, header_line = [c.lower() for c in cells], lineno
            for col in header:
                if col not in MANIFEST_COLUMNS:
                    raise InputError(f"{where}, line {lineno}: unknown column '{col}' "
                                     f"(known: {', '.join(MANIFEST_COLUMNS)})")
                if header.count(col) > 1:
                    raise InputError(f"{where}, line {lineno}: column '{col}' appears twice")
            if "path" not in header:
                raise InputError(f"{where}, line {lineno}: no 'path' column")
            if "reciprocal" in header and "invert" in header:
                raise InputError(f"{where}, line {lineno}: give 'reciprocal' or 'invert', not both")
            continue
        if len(cells) != len(header):
            raise InputError(f"{where}, line {lineno}: expected {len(header)} cells as in the "
                             f"header, got {len(cells)}")
        row = dict(zip(header, cells))
        at = f"{where}, line {lineno}"
        opts = dict(base)
        row_seed = seed
        temperature = None
        entry_id = None
        for col, cell in row.items():
            if not cell:
                continue
            here = f"{at}, column '{col}'"
            if col == "kind":
                if cell not in KINDS:
                    raise InputError(f"{here}: kind must be one of {', '.join(KINDS)}, "
                                     f"got {cell!r}")
                opts["kind"] = cell
            elif col in ("reciprocal", "invert"):
                opts["reciprocal"] = _bool_cell(cell, here)
            elif col == "evidence_check":
                opts["evidence_check"] = _bool_cell(cell, here)
            elif col == "evidence":
                if cell not in EVIDENCE_ROUTES:
                    raise InputError(f"{here}: evidence must be one of "
                                     f"{', '.join(EVIDENCE_ROUTES)}, got {cell!r}")
                opts["evidence"] = cell
            elif col == "structures":
                opts["structures"] = cell
            elif col == "noise":
                opts["noise"] = cell
            elif col == "prior":
                opts["priors"] = tuple(p.strip() for p in cell.split(";") if p.strip())
            elif col == "holdout":
                opts["holdout"] = _float_list(cell, here)
            elif col == "seed":
                try:
                    row_seed = int(cell)
                except ValueError:
                    raise InputError(f"{here}: the seed must be an integer, got {cell!r}") from None
                _check_seed(row_seed, here)
            elif col == "temperature":
                temperature = parse_temperature(cell)
                if temperature is None:
                    raise InputError(f"{here}: expected a temperature such as 20, 20 C or "
                                     f"293.15 K, got {cell!r}")
            elif col == "id":
                if not re.fullmatch(r"[A-Za-z0-9_+\-][A-Za-z0-9._+\-]*", cell):
                    raise InputError(f"{here}: an id may hold only letters, digits, '.', '_', "
                                     f"'+' and '-' (and not start with '.'), got {cell!r}")
                if cell.lower() in COMBINED_FILES:
                    raise InputError(f"{here}: the id {cell!r} is the name of a combined output")
                entry_id = cell
        if not row["path"]:
            raise InputError(f"{at}, column 'path': the path is empty")
        file = Path(row["path"]).expanduser()
        file = file if file.is_absolute() else path.parent / file
        if not file.is_file():
            problem = ("is a directory" if file.is_dir() else "is not a regular file (a pipe, "
                       "device or socket)" if file.exists() else "does not exist")
            raise InputError(f"{at}, column 'path': file '{file}' {problem}")
        opts = check_options(opts, at)
        error = None
        if temperature is None:
            temperature, error = _temperature_or_error(file)
        entries.append(_Entry(file, opts, row_seed, temperature, at, entry_id, error))
    if header is None:
        raise InputError(f"{where} is empty: expected a header row with a 'path' column")
    if not entries:
        raise InputError(f"{where}, line {header_line}: a header but no data sets")
    return entries


def expand_inputs(inputs=(), *, manifests=(), options: dict | None = None, seed: int = 0,
                  exclude=None) -> list[DataSet]:
    """The data sets named by command-line inputs and manifests, with unique ids.

    Parameters
    ----------
    inputs : sequence of str
        Each a CSV file, a manifest (a CSV whose header has a ``path`` column, see
        :func:`_read_manifest`), a directory (its ``*.csv`` files, not recursive, manifests
        excepted) or a glob pattern (``*``, ``?``, ``[...]``; ``**`` recurses).
    manifests : sequence of path-like
        Manifests named explicitly (``--manifest``).
    options : dict, optional
        Options of every data set (keys of :data:`DEFAULT_OPTIONS`); a manifest row may override
        them.
    seed : int
        Seed of every data set (a manifest row may override it).
    exclude : path-like, optional
        A directory whose files are never inputs (the output directory).

    Returns
    -------
    list of DataSet
        In the order given; a file named twice with the same options counts once. The id is the
        file stem, or, when stems clash (case-insensitively), the stem prefixed by as many parent
        directory names as make the clashing ids distinct (``run1-T020C``), else numbered
        (``T020C-1``, ``T020C-2``); a manifest's ``id`` column wins.

    Raises
    ------
    InputError
        If nothing is given, an input does not exist or matches no file, a manifest is bad, an
        option is bad, or two manifest rows give the same id.
    """
    seed = _check_seed(seed, "--seed")
    where = "the command line"
    opts = check_options(dict(options or {}), where)
    exclude = Path(exclude).resolve() if exclude is not None else None
    entries: list[_Entry] = []

    def data_file(file: Path, origin: str):
        temperature, error = _temperature_or_error(file)
        entries.append(_Entry(file, opts, seed, temperature, origin, error=error))

    def excluded(file: Path) -> bool:
        return exclude is not None and exclude in file.resolve().parents

    for raw in inputs:
        text = str(raw)
        p = Path(text).expanduser()
        origin = f"INPUT '{text}'"
        if p.is_file():
            if _looks_like_manifest(p):
                entries.extend(_read_manifest(p, defaults=opts, seed=seed))
            else:
                data_file(p, origin)
        elif p.is_dir():
            files = [f for f in sorted(p.glob("*.csv"))
                     if f.is_file() and not f.name.startswith(".") and not excluded(f)
                     and not _looks_like_manifest(f)]
            if not files:
                raise InputError(f"{origin}: directory holds no .csv data file")
            for f in files:
                data_file(f, origin)
        elif glob.has_magic(text):
            matches = [Path(m) for m in sorted(glob.glob(os.path.expanduser(text), recursive=True))]
            files = []
            for m in matches:
                if m.is_dir():
                    files.extend(f for f in sorted(m.glob("*.csv")) if f.is_file())
                elif m.is_file():
                    files.append(m)
            files = [f for f in files if not excluded(f) and not f.name.startswith(".")]
            if not files:
                raise InputError(f"{origin}: the pattern matches no file")
            for f in files:
                data_file(f, origin)
        elif p.exists():
            raise InputError(f"{origin}: not a regular file (a pipe, device or socket); "
                             "give a CSV file, a directory or a pattern")
        else:
            raise InputError(f"{origin}: no such file or directory")
    for m in manifests:
        entries.extend(_read_manifest(m, defaults=opts, seed=seed))
    if not entries:
        raise InputError("no data set: give INPUT files, directories, patterns or --manifest")
    return _assign_ids(_unique(entries))


def _unique(entries: list[_Entry]) -> list[_Entry]:
    seen, out = set(), []
    for e in entries:
        key = (str(e.path.resolve()), json.dumps(_jsonable(e.options), sort_keys=True), e.seed,
               e.temperature, e.id)
        if key not in seen:
            seen.add(key)
            out.append(e)
    return out


def _safe_id(stem: str) -> str:
    out = re.sub(r"[^A-Za-z0-9._+\-]", "_", stem)
    if out.startswith("."):
        out = "_" + out[1:]
    return out or "data"


def _assign_ids(entries: list[_Entry]) -> list[DataSet]:
    taken: dict[str, str] = {name: "combined output" for name in COMBINED_FILES}
    for e in entries:
        if e.id is not None:
            key = e.id.lower()
            if key in taken:
                raise InputError(f"{e.origin}, column 'id': the id '{e.id}' is already used "
                                 f"({taken[key]})")
            taken[key] = e.origin
    auto = [e for e in entries if e.id is None]
    groups: dict[str, list[_Entry]] = {}
    for e in auto:
        groups.setdefault(_safe_id(e.path.stem).lower(), []).append(e)
    ids: dict[int, str] = {}
    for key, group in groups.items():
        base = _safe_id(group[0].path.stem)
        if len(group) == 1 and key not in taken:
            ids[id(group[0])] = base
            continue
        parents = [list(reversed(e.path.resolve().parent.parts)) for e in group]
        chosen = None
        for depth in range(1, max(len(p) for p in parents) + 1):
            names = ["-".join([_safe_id(x) for x in reversed(p[:depth])] + [_safe_id(e.path.stem)])
                     for p, e in zip(parents, group)]
            lowered = [n.lower() for n in names]
            if len(set(lowered)) == len(names) and not set(lowered) & set(taken):
                chosen = names
                break
        if chosen is None:
            chosen, k = [], 1
            for _ in group:
                while f"{base}-{k}".lower() in taken or f"{base}-{k}" in chosen:
                    k += 1
                chosen.append(f"{base}-{k}")
                k += 1
        for e, name in zip(group, chosen):
            ids[id(e)] = name
    for e in auto:
        taken[ids[id(e)].lower()] = e.origin
    return [DataSet(e.id if e.id is not None else ids[id(e)], str(e.path), e.options, e.seed,
                    e.temperature, e.origin, e.error) for e in entries]


# ====================================================================== the task
def _read_task_data(task: dict, read_csv):
    """The data of a task, from the bytes it carries (through a private copy with the file's
    name), with the original path as its source and in error messages."""
    kind = task["options"]["kind"]
    if task.get("content") is None:
        return read_csv(task["path"], kind=kind)
    with tempfile.TemporaryDirectory(prefix="bayesfo-batch-") as tmp:
        copy = Path(tmp) / Path(task["path"]).name
        copy.write_bytes(task["content"])
        try:
            data = read_csv(copy, kind=kind)
        except InputError as exc:
            raise InputError(str(exc).replace(str(copy), task["path"])) from None
    return replace(data, source=task["path"])


def run_task(task: dict) -> dict:
    """Compare the structures on one data set: the function a worker runs.

    Reads the CSV, runs :func:`~bayesfo.compare.compare`, writes its outputs
    (:func:`~bayesfo.compare.write_outputs`) into a private temporary directory and returns them.
    Never raises for a failure of the data set (only for ``KeyboardInterrupt`` and the like).

    Parameters
    ----------
    task : dict
        ``{"id", "path" (absolute), "content" (the file's bytes, or None to read ``path``),
        "options" (see :func:`check_options`), "seed"}``: plain, picklable data, as made by
        :meth:`DataSet.task`.

    Returns
    -------
    dict
        ``id``; ``status`` (``"ok"``, ``"input_error"``, ``"internal_error"``); ``error`` (the
        message, or None); ``traceback`` (internal errors); ``files`` ({file name: bytes}, empty on
        failure; names relative to the data set's directory, e.g. ``figures/bode.png``);
        ``warnings`` (messages raised during the comparison, each once);
        ``compare_seconds`` (wall time of the comparison alone), ``compare_cpu_seconds`` (CPU
        time of the worker process during it: much less than the wall time means the worker
        waited for a core), ``task_seconds`` (the whole task), ``host`` and ``pid``.
    """
    t0 = time.perf_counter()
    out = {"id": task["id"], "status": OK, "error": None, "traceback": None, "files": {},
           "warnings": [], "compare_seconds": None, "compare_cpu_seconds": None,
           "task_seconds": None, "host": socket.gethostname(), "pid": os.getpid()}
    opts = task["options"]
    caught = []
    try:
        with warnings.catch_warnings(record=True) as caught, np.errstate(all="ignore"):
            warnings.simplefilter("always")
            from .cli import _parse_priors
            from .compare import compare, write_outputs
            from .data import read_csv
            from .structures import default_library, load_library, resolve_structures

            data = _read_task_data(task, read_csv)
            if opts["reciprocal"]:
                data = data.reciprocal()
            library = load_library(extra=opts["models"]) if opts["models"] else default_library()
            structures = resolve_structures(list(opts["structures"]), library)
            priors = _parse_priors(opts["priors"])
            t1, c1 = time.perf_counter(), time.process_time()
            # One process per data set: the batch runs data sets side by side (and a Dask
            # worker, a daemonic process, could not start compare's own process pool).
            comparison = compare(data, structures, noise=opts["noise"], seed=task["seed"],
                                 priors=priors, progress=False,
                                 evidence=opts["evidence"],
                                 evidence_check=opts["evidence_check"],
                                 holdout=list(opts["holdout"]) if opts["holdout"] else None,
                                 workers=1)
            out["compare_seconds"] = time.perf_counter() - t1
            out["compare_cpu_seconds"] = time.process_time() - c1
            with tempfile.TemporaryDirectory(prefix="bayesfo-batch-") as tmp:
                write_outputs(comparison, tmp, figures=opts["figures"])
                out["files"] = {f.relative_to(tmp).as_posix(): f.read_bytes()
                                for f in sorted(Path(tmp).rglob("*")) if f.is_file()}
    except InputError as exc:
        out.update(status=INPUT_ERROR, error=str(exc), files={})
    except Exception as exc:  # recorded per data set: one failure never stops the batch
        out.update(status=INTERNAL_ERROR, error=f"{type(exc).__name__}: {exc}",
                   traceback=traceback.format_exc(), files={})
    seen = []
    for w in caught:
        msg = f"{w.category.__name__}: {w.message}"
        if msg not in seen:
            seen.append(msg)
    out["warnings"] = seen
    out["task_seconds"] = time.perf_counter() - t0
    return out


# ====================================================================== results
@dataclass(frozen=True, eq=False)
class Outcome:
    """What became of one data set.

    Attributes
    ----------
    dataset : DataSet
    status : str
        ``"ok"``, ``"input_error"`` or ``"internal_error"``.
    error : str or None
    reused : bool
        Complete from an earlier run (not recomputed).
    rows : tuple of dict
        Its rows of ``batch_summary.csv``.
    warnings : tuple of str
    compare_seconds, compare_cpu_seconds, task_seconds : float or None
        Wall and CPU time of the comparison alone, and wall time of the whole task in the
        worker (None when reused).
    """

    dataset: DataSet
    status: str
    error: str | None = None
    reused: bool = False
    rows: tuple = ()
    warnings: tuple = ()
    compare_seconds: float | None = None
    compare_cpu_seconds: float | None = None
    task_seconds: float | None = None


@dataclass(frozen=True, eq=False)
class BatchResult:
    """Result of :func:`run_batch`.

    Attributes
    ----------
    out_dir : Path
    outcomes : tuple of Outcome
        In the order of the data sets.
    executor : str
        ``"in-process"``, ``"processes (N)"``, ``"dask (ADDRESS)"``, or
        ``"none (every data set complete)"``.
    wall_seconds : float
        Wall time of the run, combined outputs included.
    written : dict
        Combined output files by name.
    """

    out_dir: Path
    outcomes: tuple
    executor: str
    wall_seconds: float
    written: dict = field(default_factory=dict)

    @property
    def rows(self) -> list[dict]:
        """The rows of ``batch_summary.csv``."""
        return [row for o in self.outcomes for row in o.rows]

    @property
    def failed(self) -> list[Outcome]:
        return [o for o in self.outcomes if o.status != OK]

    @property
    def exit_status(self) -> int:
        """0 if every data set was compared, 1 if one had an internal error, else 2 if one had
        bad input."""
        statuses = {o.status for o in self.outcomes}
        if INTERNAL_ERROR in statuses:
            return 1
        return 2 if INPUT_ERROR in statuses else 0


def summary_rows(summary: dict) -> list[dict]:
    """Rows of ``batch_summary.csv`` for one data set from its ``summary.json`` (without the
    data-set columns), ranked by ln Z; structures that could not be run come last."""
    structures = {s["name"]: s for s in summary["structures"]}
    ranking = list(summary.get("ranking", []))
    zs = [s.get("log_evidence") for s in structures.values() if s.get("log_evidence") is not None]
    best_z = max(zs) if zs else None
    best = ranking[0] if ranking else None
    rows = []
    for name in ranking + [n for n in structures if n not in ranking]:
        s = structures[name]
        row = {"structure": name, "n_params": s.get("n_params"),
               "kind": summary["data"].get("kind"),
               "n_frequencies": summary["data"].get("n_frequencies")}
        if "error" in s:
            row["error"] = s["error"]
            rows.append(row)
            continue
        params = s.get("parameters", {})
        qname = "q" if "q" in params else ("beta" if "beta" in params else None)
        q = params.get(qname, {}) if qname else {}
        z = s.get("log_evidence")
        row.update(
            rank=ranking.index(name) + 1, best=name == best,
            log_evidence=z, log_evidence_err=s.get("log_evidence_err"),
            delta_log_evidence=None if z is None or best_z is None else z - best_z,
            posterior_probability=s.get("posterior_probability"),
            q_parameter=qname, q_mean=q.get("mean"), q_sd=q.get("sd"),
            q_hdi_low=q.get("hdi_low"), q_hdi_high=q.get("hdi_high"), q_map=q.get("map"),
            noise=s.get("noise"), warnings="; ".join(s.get("warnings", [])),
        )
        for key in ("loo", "loo_se", "waic", "aic", "aicc", "bic", "max_log_likelihood", "rmse",
                    "rhat_max", "ess_min", "converged", "pareto_k_max"):
            row[key] = s.get(key)
        rows.append(row)
    return rows


def _dataset_rows(ds: DataSet, status: str, error: str | None, rows=()) -> tuple:
    head = {"dataset": ds.id, "path": ds.path, "temperature_C": ds.temperature, "status": status}
    if status != OK:
        return ({**head, "error": error},)
    return tuple({**head, **row} for row in rows)


def _csv_text(rows, fields) -> str:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=fields, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: "" if row.get(k) is None else row.get(k) for k in fields})
    return buf.getvalue()


def batch_summary_csv(rows) -> str:
    """The text of ``batch_summary.csv`` (columns :data:`BATCH_FIELDS`)."""
    return _csv_text(rows, BATCH_FIELDS)


def temperature_rows(rows) -> list[dict]:
    """Rows of ``temperature_summary.csv``: the structures of every compared data set with a
    temperature, by temperature then rank, with the best structure of each data set."""
    out = []
    best = {r["dataset"]: r["structure"] for r in rows if r.get("best")}
    for r in rows:
        if r.get("status") != OK or r.get("temperature_C") is None or r.get("rank") is None:
            continue
        out.append({k: r.get(k) for k in TEMPERATURE_FIELDS if k in r}
                   | {"best_structure": best.get(r["dataset"])})
    return sorted(out, key=lambda r: (r["temperature_C"], r["dataset"], r["rank"]))


# ====================================================================== output directory
def _stored_rows(ds: DataSet, out_dir: Path, fingerprint: dict) -> tuple | None:
    """The rows of a data set whose stored result is complete for ``fingerprint``, else None."""
    sub = out_dir / ds.id
    if sub.is_symlink():  # never followed: its files would lie outside the output directory
        return None
    try:
        recover(sub)  # a swap that an interrupted run left half done
        record = json.loads((sub / _BATCH_JSON).read_text(encoding="utf-8"))
        if (record.get("format") != _FORMAT or record.get("status") != OK
                or record.get("task") != fingerprint):
            return None
        files = record.get("files")
        if not isinstance(files, list) or not all(
                is_output_path(name) and (sub / name).is_file() for name in files):
            return None
        summary = json.loads((sub / "summary.json").read_text(encoding="utf-8"))
        return _dataset_rows(ds, OK, None, summary_rows(summary))
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _store(ds: DataSet, result: dict, out_dir: Path, fingerprint: dict) -> Outcome:
    """Write a worker's result into ``out_dir/<id>/`` as one unit (:func:`bayesfo.outdir.staged_run`):
    the outputs of an earlier run there are replaced by this one's, ``batch.json`` included."""
    sub = out_dir / ds.id
    files = (result.get("files") or {}) if result["status"] == OK else {}
    for name in files:
        if not is_output_path(name):
            raise ValueError(f"output file name {name!r} leaves the data set's directory")
    if sub.is_symlink():  # a link in the output directory is replaced, never followed
        sub.unlink()
    with staged_run(sub) as stage:
        for name in files:
            target = stage / name
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(files[name])
        if result["status"] == OK:
            summary = json.loads(files["summary.json"].decode("utf-8"))
            rows = _dataset_rows(ds, OK, None, summary_rows(summary))
        else:
            text = f"{result['error']}\n"
            if result.get("traceback"):
                text += "\n" + result["traceback"]
            (stage / _ERROR_TXT).write_text(text, encoding="utf-8")
            rows = _dataset_rows(ds, result["status"], result["error"])
        record = {
            "format": _FORMAT, "id": ds.id, "path": ds.path, "temperature_C": ds.temperature,
            "task": fingerprint, "status": result["status"], "error": result["error"],
            "warnings": result.get("warnings", []), "files": sorted(files),
            "compare_seconds": result.get("compare_seconds"),
            "compare_cpu_seconds": result.get("compare_cpu_seconds"),
            "task_seconds": result.get("task_seconds"), "host": result.get("host"),
            "pid": result.get("pid"), "finished": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        }
        (stage / _BATCH_JSON).write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    return Outcome(ds, result["status"], result["error"], False, rows,
                   tuple(result.get("warnings", [])), result.get("compare_seconds"),
                   result.get("compare_cpu_seconds"), result.get("task_seconds"))


def _lost(ds: DataSet, exc: BaseException, why: str = "the worker failed") -> dict:
    """The result of a task whose worker failed (died, or lost its connection)."""
    return {"id": ds.id, "status": INTERNAL_ERROR, "files": {}, "warnings": [],
            "error": f"{why}: {type(exc).__name__}: {exc}", "traceback": None}


def write_batch_outputs(result_rows, out_dir, structures=None) -> dict[str, Path]:
    """Write the combined outputs: ``batch_summary.csv`` and its figure, and, when data sets have
    temperatures, ``temperature_summary.csv`` and the figure of q against temperature.

    Each file is written through a temporary file and a rename; ``structures`` orders the
    structures in the figures. Returns the written files by name.
    """
    out_dir = Path(out_dir)
    rows = list(result_rows)
    written = {"batch_summary.csv": atomic_write_text(out_dir / "batch_summary.csv",
                                                      batch_summary_csv(rows))}
    trows = temperature_rows(rows)
    if trows:
        written["temperature_summary.csv"] = atomic_write_text(
            out_dir / "temperature_summary.csv", _csv_text(trows, TEMPERATURE_FIELDS))
    if not any(r.get("status") == OK for r in rows):
        return written
    from .plotting import save_figure
    from .plotting.batch import plot_batch_summary, plot_q_temperature

    fig = plot_batch_summary(rows, structures)
    for suffix in ("png", "pdf"):
        save_figure(fig, out_dir / f"batch_summary.{suffix}")
        written[f"batch_summary.{suffix}"] = out_dir / f"batch_summary.{suffix}"
    if trows:
        fig = plot_q_temperature(trows, structures)
        for suffix in ("png", "pdf"):
            save_figure(fig, out_dir / f"temperature_q.{suffix}")
            written[f"temperature_q.{suffix}"] = out_dir / f"temperature_q.{suffix}"
    return written


# ====================================================================== executors
def _run_in_process(todo, on_result):
    for ds in todo:
        on_result(ds, run_task(ds.task()))


def _run_pool(todo, workers, on_result, task=run_task) -> list:
    """Run ``task`` (:func:`run_task`) on ``todo`` in one pool of ``workers`` processes; return
    the data sets whose pool broke (a worker died) before they finished, each with the
    exception."""
    from concurrent.futures.process import BrokenProcessPool

    from .parallel import new_pool, terminate, worker_environment

    broken = []
    with worker_environment():  # processes are spawned while tasks are submitted
        pool = new_pool(workers)
        try:
            futures = {pool.submit(task, ds.task()): ds for ds in todo}
            pending = set(futures)
            while pending:
                done, pending = wait(pending, return_when=FIRST_COMPLETED)
                for fut in done:
                    ds = futures.pop(fut)  # drop the future and its output files once stored
                    try:
                        result = fut.result()
                    except BrokenProcessPool as exc:
                        broken.append((ds, exc))
                        continue
                    except Exception as exc:  # e.g. a result that cannot be unpickled
                        result = _lost(ds, exc)
                    on_result(ds, result)
                del done
        except BaseException:
            terminate(pool)
            raise
        if broken:
            terminate(pool)
        else:
            pool.shutdown(wait=True)
    return broken


def _run_processes(todo, workers, on_result, task=run_task):
    """Run the data sets in worker processes. When a worker dies (killed, out of memory, a
    crash in native code), the pool breaks and every unfinished data set is run again in a new
    pool; if that breaks too, the rest run one by one, each in a pool of its own, so that only
    the data set whose worker dies is recorded as failed."""
    broken = _run_pool(todo, workers, on_result, task)
    if broken:
        broken = _run_pool([ds for ds, _ in broken], min(workers, len(broken)), on_result, task)
    for ds, _ in broken:
        again = _run_pool([ds], 1, on_result, task)
        for ds_, exc in again:
            on_result(ds_, _lost(ds_, exc, "its worker process died in each of three attempts "
                                           "(killed, out of memory, or a crash in native code)"))


def _dask_client(scheduler):
    """A connected :class:`distributed.Client` and whether we own it."""
    if hasattr(scheduler, "submit"):  # a Client given by the caller
        return scheduler, False
    try:
        from distributed import Client
    except ImportError:
        raise InputError("--scheduler needs dask.distributed: pip install 'bayesfo[cluster]' "
                         "(or pip install distributed)") from None
    try:
        client = Client(scheduler, timeout=SCHEDULER_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(f"--scheduler: cannot reach the Dask scheduler at '{scheduler}': "
                         f"{type(exc).__name__}: {exc}") from None
    return client, True


def _run_dask(todo, client, on_result):
    from distributed import as_completed

    futures = {}
    for ds in todo:
        fut = client.submit(run_task, ds.task(), pure=False,
                            key=f"bayesfo-batch-{ds.id}-{os.urandom(4).hex()}")
        futures[fut] = ds
    try:
        for fut in as_completed(list(futures), loop=client.loop):
            ds = futures.pop(fut)
            try:
                result = fut.result()
            except Exception as exc:  # KilledWorker, lost connection
                result = _lost(ds, exc)
            fut.release()  # the cluster may forget the output files
            on_result(ds, result)
    except BaseException:
        client.cancel(list(futures))
        raise


def run_batch(datasets, out_dir, *, workers: int | None = None, scheduler=None,
              progress: bool | None = None, write_combined: bool = True) -> BatchResult:
    """Compare the structures on every data set; resume, record failures, write the tables.

    Parameters
    ----------
    datasets : sequence of DataSet
        From :func:`expand_inputs`.
    out_dir : path-like
        Output directory (created); one sub-directory per data set.
    workers : int, optional
        Local worker processes, each running one data set at a time (default, or 0: one per
        available CPU), at most one per data set to run; 1 runs in this process. Not with
        ``scheduler``. A script that calls this with several workers needs the usual
        ``if __name__ == "__main__":`` guard (the workers are spawned).
    scheduler : str or distributed.Client, optional
        Address of a Dask scheduler (``tcp://host:8786``), or a connected client, to run the
        tasks on a Dask cluster instead.
    progress : bool, optional
        A progress bar over data sets (default: when stderr is a terminal).
    write_combined : bool
        Write ``batch_summary.csv``, the temperature table and the figures
        (:func:`write_batch_outputs`).

    Returns
    -------
    BatchResult

    Raises
    ------
    InputError
        For a bad ``workers``, both ``workers`` and ``scheduler``, duplicate ids, distributed
        not installed or a scheduler that cannot be reached. Failures of data sets are not
        raised: they are in the result.
    """
    from tqdm.auto import tqdm

    t0 = time.perf_counter()
    datasets = list(datasets)
    ids = [ds.id.lower() for ds in datasets]
    if len(set(ids)) != len(ids):
        raise InputError("two data sets have the same id")
    if workers is not None and scheduler is not None:
        raise InputError("--workers applies to local processes; with --scheduler the Dask "
                         "cluster's workers run the tasks")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 0):
        raise InputError(f"--workers must be a non-negative integer, got {workers!r}")
    out_dir = check_output_directory(out_dir)

    outcomes: dict[str, Outcome] = {}
    fingerprints = {}
    todo = []
    for ds in datasets:
        fingerprints[ds.id] = fp = ds.fingerprint()
        if ds.error is not None:
            outcomes[ds.id] = _store(ds, {"id": ds.id, "status": INPUT_ERROR, "error": ds.error,
                                          "files": {}, "warnings": []}, out_dir, fp)
        elif (rows := _stored_rows(ds, out_dir, fp)) is not None:
            outcomes[ds.id] = Outcome(ds, OK, None, True, rows)
        else:
            todo.append(ds)

    if progress is None:
        progress = sys.stderr.isatty()
    bar = tqdm(total=len(datasets), initial=len(datasets) - len(todo), desc="data sets",
               unit="set", disable=not progress, leave=False)

    def on_result(ds, result):
        outcomes[ds.id] = _store(ds, result, out_dir, fingerprints[ds.id])
        bar.update(1)

    try:
        if not todo:
            executor = "none (every data set complete)"
        elif scheduler is not None:
            client, own = _dask_client(scheduler)
            try:
                executor = f"dask ({client.scheduler.address})"
                _run_dask(todo, client, on_result)
            finally:
                if own:
                    client.close()
        else:
            from .parallel import available_cpus

            n = min(workers or available_cpus(), len(todo))
            if n == 1:
                executor = "in-process"
                _run_in_process(todo, on_result)
            else:
                executor = f"processes ({n})"
                _run_processes(todo, n, on_result)
    finally:
        bar.close()

    ordered = tuple(outcomes[ds.id] for ds in datasets)
    written = {}
    if write_combined:
        order = list(dict.fromkeys(n for ds in datasets for n in ds.options["structures"]))
        written = write_batch_outputs([r for o in ordered for r in o.rows], out_dir, order)
    return BatchResult(out_dir, ordered, executor, time.perf_counter() - t0, written)


# ====================================================================== command line
def add_parser(subparsers):
    """Register the ``batch`` sub-command on the ``bayesfo`` command line.

    Parameters
    ----------
    subparsers
        The object returned by ``ArgumentParser.add_subparsers``.

    Returns
    -------
    argparse.ArgumentParser
        The ``batch`` parser (its command is :func:`cmd_batch`).
    """
    from .cli import DEFAULT_STRUCTURES

    p = subparsers.add_parser(
        "batch", help="compare structures on many data sets (local processes or a Dask cluster)",
        description="Run 'compare' on every data set; write DIR/<id>/ per data set, "
                    "DIR/batch_summary.csv and its figure, and, for isotherms, "
                    "DIR/temperature_summary.csv and the figure of q against temperature. "
                    "A re-run skips the data sets whose results are complete.")
    p.add_argument("inputs", nargs="*", metavar="INPUT",
                   help="CSV file, directory of *.csv, glob pattern, or manifest (a CSV with a "
                        "'path' column and per-file options)")
    p.add_argument("--manifest", action="append", default=[], metavar="FILE",
                   help="manifest CSV: path[,id,kind,reciprocal|invert,structures,noise,prior,"
                        "seed,holdout,evidence,evidence_check,temperature]; repeatable")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--kind", choices=KINDS,
                   help="what the responses are (default: each file's '# kind:' line, "
                        "else generic)")
    p.add_argument("--reciprocal", action="store_true",
                   help="use 1/G of the data (sigma propagated)")
    p.add_argument("--structures", default=DEFAULT_STRUCTURES,
                   help=f"comma list, with shortcuts maxN and all (default {DEFAULT_STRUCTURES})")
    p.add_argument("--noise", default="auto", choices=NOISE_MODELS,
                   help="noise model (default: known if the data give sigma, else relative "
                        "or constant)")
    p.add_argument("--prior", action="append", default=[], metavar="NAME=TYPE:A:B",
                   help="override a prior, e.g. q=uniform:0.2:1; repeatable")
    p.add_argument("--seed", type=seed_argument, default=0,
                   help="seed of every data set (the same numbers whatever the workers)")
    p.add_argument("--holdout", default=None, metavar="W1,W2",
                   help="angular frequencies [rad/s] left out of every fit for validation")
    p.add_argument("--evidence", default="auto", choices=EVIDENCE_ROUTES,
                   help="ln Z by bridge sampling from the emcee draws (bridge) or from a tempered "
                        "ladder (ladder); auto: the ladder where the posterior did not converge")
    p.add_argument("--evidence-check", action="store_true",
                   help="also compute ln Z by dynesty nested sampling and flag disagreements")
    p.add_argument("--no-figures", action="store_true",
                   help="skip each data set's figures and report.html (the combined figures "
                        "are still drawn)")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="processes running data sets side by side (default 0: one per CPU; "
                        "1: in this process); the numbers do not depend on it")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on a Dask cluster (e.g. tcp://10.0.0.5:8786); needs bayesfo[cluster]")
    p.add_argument("--quiet", action="store_true",
                   help="no progress bar or table; only the one-line summary and errors")
    return p


def cmd_batch(args) -> int:
    """Run ``bayesfo batch``; returns the exit status (0 all compared, 2 bad input in some data
    set, 1 an internal error in some data set). Problems with the command itself (arguments,
    manifests, scheduler) raise :class:`~bayesfo.errors.InputError`."""
    from .cli import _parse_floats

    options = {"kind": args.kind, "reciprocal": args.reciprocal, "structures": args.structures,
               "noise": args.noise, "priors": tuple(args.prior),
               "holdout": _parse_floats(args.holdout, "--holdout") if args.holdout else None,
               "evidence": args.evidence, "evidence_check": args.evidence_check,
               "models": tuple(getattr(args, "models", None) or ()),
               "figures": not args.no_figures}
    datasets = expand_inputs(args.inputs, manifests=args.manifest, options=options,
                             seed=args.seed, exclude=args.out)
    progress = not args.quiet and sys.stderr.isatty()
    result = run_batch(datasets, args.out, workers=args.workers, scheduler=args.scheduler,
                       progress=progress)
    for o in result.failed:
        print(f"bayesfo: error: {o.dataset.id}: {o.error}", file=sys.stderr)
    if not args.quiet:
        _print_table(result)
    n_ok = sum(o.status == OK for o in result.outcomes)
    reused = sum(o.reused for o in result.outcomes)
    names = ", ".join(n for n in result.written)
    print(f"batch: {len(result.outcomes)} data sets, {n_ok} compared ({reused} complete from an "
          f"earlier run), {len(result.failed)} failed; {result.executor}, "
          f"{result.wall_seconds:.1f} s; wrote {result.out_dir}/{{<id>/, {names}}}")
    return result.exit_status


def _print_table(result: BatchResult) -> None:
    width = max([7] + [len(o.dataset.id) for o in result.outcomes])
    print(f"{'dataset':<{width}} {'T [°C]':>7}  {'best':<14} {'P':>6}  {'q (94% HDI)':<26} status")
    for o in result.outcomes:
        t = "" if o.dataset.temperature is None else f"{o.dataset.temperature:g}"
        if o.status != OK:
            print(f"{o.dataset.id:<{width}} {t:>7}  {'-':<14} {'-':>6}  {'-':<26} "
                  f"{o.status.replace('_', ' ')}")
            continue
        best = next((r for r in o.rows if r.get("best")), None)
        if best is None:
            print(f"{o.dataset.id:<{width}} {t:>7}  no ranked structure")
            continue
        p = best.get("posterior_probability")
        q = "" if best.get("q_mean") is None else (
            f"{best['q_mean']:.3f} [{best['q_hdi_low']:.3f}, {best['q_hdi_high']:.3f}]")
        flags = "reused" if o.reused else "ok"
        if not best.get("converged"):
            flags += ", not converged"
        print(f"{o.dataset.id:<{width}} {t:>7}  {best['structure']:<14} "
              f"{'-' if p is None else f'{p:.3f}':>6}  {q:<26} {flags}")


__all__ = ["DataSet", "Outcome", "BatchResult", "expand_inputs",
           "check_options", "run_task", "run_batch", "write_batch_outputs", "summary_rows",
           "temperature_rows", "batch_summary_csv", "parse_temperature", "temperature_from_stem",
           "temperature_of_file", "add_parser", "cmd_batch"]
