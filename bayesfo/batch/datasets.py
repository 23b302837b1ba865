"""The data sets of a batch: command-line inputs (files, directories, patterns) and manifests,
expanded into :class:`DataSet` objects with unique ids and checked options.

This module is longer than the project's 500-line guide: command-line inputs and manifests
share one path of option checks, id assignment and isotherm splitting, and splitting it would
separate each manifest column from its parsing.
"""

from __future__ import annotations

import glob
import hashlib
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path

from .. import __version__
from .._io import csv_cells, read_text_file, split_lines
from ..data import contract_text, is_contract_csv, read_isotherms
from ..data.temperature import parse_temperature, temperature_of_file
from ..errors import InputError
from ..options import (
    DEFAULT_OPTIONS,
    EVIDENCE_ROUTES,
    KINDS,
    LATER_OPTIONS,
    check_options,
    check_seed,
)

#: Manifest columns; ``invert`` is another name for ``reciprocal``.
MANIFEST_COLUMNS = ("path", "id", "kind", "reciprocal", "invert", "structures", "noise", "prior",
                    "seed", "holdout", "evidence", "evidence_check", "temperature",
                    "sampler", "max_steps", "walkers")


#: Files written at the top of the output directory (no data-set id may take these names).
COMBINED_FILES = ("batch_summary.csv", "batch_summary.png", "batch_summary.pdf",
                  "temperature_summary.csv", "temperature_q.png", "temperature_q.pdf")


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
        temperature, a lab file that cannot be read): the data set is recorded as an input error
        and not run; the others run.
    block : str or None
        For a lab file of several data sets (steps, intervals, isotherms; see
        :func:`bayesfo.data.read_isotherms`), the label of this one.
    content : bytes or None
        For a lab file (any file that is not a CSV of the bayesfo contract), this data set as a
        contract CSV, read when the inputs were expanded (see :func:`_lab_entries`); the
        worker reads it as it reads any contract file.
    notes : tuple of str
        For a lab file, how it was read (:meth:`bayesfo.data.Reading.notes`), carried in the
        task for the worker to add to the notes of the data.
    """

    id: str
    path: str
    options: dict
    seed: int
    temperature: float | None = None
    origin: str = ""
    error: str | None = None
    block: str | None = None
    content: bytes | None = None
    notes: tuple[str, ...] = ()

    def task(self) -> dict:
        """The picklable task of :func:`run_task`, carrying the data file's bytes (a few kB),
        or for a lab file this data set as a contract CSV, so that a worker on another machine
        needs no access to the file."""
        content = self.content
        if content is None:
            try:
                content = Path(self.path).read_bytes()
            except OSError:
                content = None  # the worker reports the problem
        task = {"id": self.id, "path": str(Path(self.path).resolve()), "content": content,
                "options": dict(self.options), "seed": self.seed}
        if self.block is not None:
            task["block"] = self.block
        if self.notes:
            task["notes"] = list(self.notes)
        return task

    def fingerprint(self) -> dict:
        """What makes a stored result valid for this data set: the data file's content, the
        options, the seed and the bayesfo version (and the data set of a lab file)."""
        options = {k: v for k, v in self.options.items()
                   if k not in LATER_OPTIONS or v != LATER_OPTIONS[k]}
        fp = {"sha256": _sha256(self.path), "options": _jsonable(options),
              "seed": self.seed, "bayesfo": __version__}
        if self.block is not None:
            fp["block"] = self.block
        return fp


def _jsonable(obj):
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    return obj


def _sha256(path) -> str | None:
    try:
        with open(path, "rb") as fh:
            return hashlib.file_digest(fh, "sha256").hexdigest()
    except OSError:
        return None


def _temperature_or_error(path) -> tuple[float | None, str | None]:
    """:func:`temperature_of_file`, with its input error as a message instead: one bad file
    does not stop the batch."""
    try:
        return temperature_of_file(path), None
    except InputError as exc:
        return None, str(exc)


def _looks_like_manifest(path: Path) -> bool:
    """A CSV whose header row has a ``path`` column (data files never have one)."""
    try:
        text = read_text_file(path)
    except InputError:
        return False
    for lineno, line in enumerate(split_lines(text), start=1):
        stripped = line.strip()
        if stripped and not stripped.startswith("#"):
            try:
                cells = csv_cells(line, f"file '{path}'", lineno)
            except InputError:  # not a manifest; reading it as data names the problem
                return False
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
    block: str | None = None  # see DataSet.block
    content: bytes | None = None  # see DataSet.content
    suffix: str = ""  # appended to the file stem of an automatic id (the data set of a lab file)
    notes: tuple[str, ...] = ()  # see DataSet.notes


def _lab_entries(file: Path, opts: dict, seed: int, temperature: float | None, origin: str,
                 entry_id: str | None = None) -> list[_Entry]:
    """The entries of a file that is not a contract CSV (a lab export): one per data set of
    :func:`bayesfo.data.read_isotherms`, each carrying its data as a contract CSV; a file that
    cannot be read is one entry with its error."""
    try:
        sets = read_isotherms(file, kind=opts.get("kind"))
    except InputError as exc:
        return [_Entry(file, opts, seed, temperature, origin, entry_id, str(exc))]
    if len(sets) == 1:
        iso = sets[0]
        error = None
        t = temperature if temperature is not None else iso.temperature
        if t is None:
            t, error = _temperature_or_error(file)
        return [_Entry(file, opts, seed, t, origin, entry_id, error,
                       content=contract_text(iso.data, t).encode("utf-8"), notes=iso.data.notes)]
    out = []
    for k, iso in enumerate(sets, start=1):
        suffix = _temperature_tag(iso.temperature) if iso.temperature is not None else f"{k:02d}"
        out.append(_Entry(file, opts, seed, iso.temperature, f"{origin}, data set {k} "
                          f"({iso.label})", f"{entry_id}-{suffix}" if entry_id else None,
                          block=iso.label, content=contract_text(iso.data, iso.temperature)
                          .encode("utf-8"), suffix=f"-{suffix}", notes=iso.data.notes))
    return out


def _temperature_tag(t: float) -> str:
    """``Tp150C``, ``Tm040C``, ``Tp020p5C``: the temperature in an id, as the bundled isotherms
    are named (read back by :func:`temperature_from_stem`)."""
    sign = "m" if t < 0 else "p"
    whole, _, frac = f"{abs(t):.2f}".rstrip("0").rstrip(".").partition(".")
    return f"T{sign}{int(whole):03d}" + (f"p{frac}" if frac else "") + "C"


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
    for lineno, line in enumerate(split_lines(text), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        cells = [c.strip() for c in csv_cells(line, where, lineno)]
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
            elif col == "sampler":
                opts["sampler"] = cell  # checked with the other options below
            elif col == "structures":
                opts["structures"] = cell
            elif col == "noise":
                opts["noise"] = cell
            elif col == "prior":
                opts["priors"] = tuple(p.strip() for p in cell.split(";") if p.strip())
            elif col == "holdout":
                opts["holdout"] = _float_list(cell, here)
            elif col in ("max_steps", "walkers"):
                try:
                    opts[col] = int(cell)
                except ValueError:
                    raise InputError(f"{here}: {col} must be an integer, got {cell!r}") from None
            elif col == "seed":
                try:
                    row_seed = int(cell)
                except ValueError:
                    raise InputError(f"{here}: the seed must be an integer, got {cell!r}") from None
                check_seed(row_seed, here)
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
        if not is_contract_csv(file):
            entries.extend(_lab_entries(file, opts, row_seed, temperature, at, entry_id))
            continue
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
        excepted) or a glob pattern (``*``, ``?``, ``[...]``; ``**`` recurses). A file that is
        not a CSV of the contract is read by :func:`bayesfo.data.read_isotherms` (a lab export)
        and gives one data set per step, interval or isotherm, with its temperature: a file of
        isotherms is a temperature series.
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
        file stem (for a data set of a lab file of several, the stem and its temperature,
        ``run-Tp150C``, or its number), or, when stems clash (case-insensitively), the stem prefixed by as many parent
        directory names as make the clashing ids distinct (``run1-T020C``), else numbered
        (``T020C-1``, ``T020C-2``); a manifest's ``id`` column wins.

    Raises
    ------
    InputError
        If nothing is given, an input does not exist or matches no file, a manifest is bad, an
        option is bad, or two manifest rows give the same id.
    """
    seed = check_seed(seed, "--seed")
    where = "the command line"
    opts = check_options(dict(options or {}), where)
    exclude = Path(exclude).resolve() if exclude is not None else None
    entries: list[_Entry] = []

    def data_file(file: Path, origin: str):
        if not is_contract_csv(file):
            entries.extend(_lab_entries(file, opts, seed, None, origin))
            return
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
               e.temperature, e.id, e.block)
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
        groups.setdefault(_safe_id(e.path.stem + e.suffix).lower(), []).append(e)
    ids: dict[int, str] = {}
    for key, group in groups.items():
        base = _safe_id(group[0].path.stem + group[0].suffix)
        if len(group) == 1 and key not in taken:
            ids[id(group[0])] = base
            continue
        parents = [list(reversed(e.path.resolve().parent.parts)) for e in group]
        chosen = None
        for depth in range(1, max(len(p) for p in parents) + 1):
            names = ["-".join([_safe_id(x) for x in reversed(p[:depth])]
                              + [_safe_id(e.path.stem + e.suffix)])
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
                    e.temperature, e.origin, e.error, e.block, e.content, e.notes)
            for e in entries]

