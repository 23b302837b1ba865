"""Output directories that always hold the complete output of one run.

A run never writes into its output directory directly. It writes into a staging directory inside
it (``.bayesfo-staging-<token>/new/``) and, once every file is complete, swaps the new entries in:

1. a journal ``.bayesfo-swap.json`` names the staging directory, the earlier run's entries and the
   new ones (written atomically);
2. the earlier run's entries are renamed into the staging directory (``summary.json`` first, so
   that a ``summary.json`` in the output directory always means that the rest is complete);
3. the new entries are renamed into the output directory (``summary.json`` last);
4. the journal is removed and the staging directory with the earlier run's entries deleted.

Renames within one file system are atomic and never follow symbolic links, so nothing outside the
output directory is ever written or deleted, whatever an earlier run's files say. A run killed
before step 1 leaves the earlier output as it was (its staging directory is removed by the next
run); a run killed during steps 2-4 is completed by the next run into the same directory
(:func:`recover`), as the journal says.

The earlier run's entries are the fixed names a run writes and one NetCDF per structure named in
its ``summary.json``; a name read from there is only used if it is a single name of the kinds
bayesfo writes (:func:`is_output_name`). Other files in the output directory are never touched.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import secrets
import shutil
import signal
from pathlib import Path, PurePosixPath

from ._io import atomic_write_text
from .errors import InputError, OutputError

JOURNAL = ".bayesfo-swap.json"
STAGING_PREFIX = ".bayesfo-staging-"
_FORMAT = 1

#: Top-level names a bayesfo run may own in an output directory.
_OUTPUT_NAME = re.compile(
    r"^(?:summary\.json|ranking\.csv|report\.html|figures|batch\.json|error\.txt"
    r"|[A-Za-z0-9][A-Za-z0-9_.+\-]*\.nc)$")
#: Entries every kind of run may write besides its NetCDF files.
FIXED_NAMES = ("summary.json", "ranking.csv", "report.html", "figures", "batch.json", "error.txt")
#: The names of a run's entries, in the order they are moved out (and, reversed, in).
_FIRST_OUT = ("summary.json", "batch.json")


def is_output_name(name) -> bool:
    """Whether ``name`` is one top-level entry of the kinds a bayesfo run writes (a single path
    component: no separator, no ``..``, not absolute)."""
    return (isinstance(name, str) and "/" not in name and "\\" not in name and "\0" not in name
            and bool(_OUTPUT_NAME.match(name)))


def is_output_path(name) -> bool:
    """Whether ``name`` is a relative POSIX path inside an entry a run writes
    (``figures/bode.png``), with no ``..``, ``\\`` or absolute part."""
    if not isinstance(name, str) or not name or "\\" in name or "\0" in name:
        return False
    path = PurePosixPath(name)
    return (not path.is_absolute() and ".." not in path.parts and "." not in name.split("/")
            and is_output_name(path.parts[0]))


def _read_json(path: Path):
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def owned_entries(out_dir) -> list[str]:
    """The entries of ``out_dir`` that an earlier bayesfo run wrote and that exist now: the
    fixed names and one NetCDF per structure of its ``summary.json``, each checked with
    :func:`is_output_name`."""
    out_dir = Path(out_dir)
    names = list(FIXED_NAMES)
    summary = _read_json(out_dir / "summary.json")
    structures = summary.get("structures") if isinstance(summary, dict) else None
    if isinstance(structures, list):
        names += [f"{s.get('name')}.nc" for s in structures if isinstance(s, dict)]
    return [name for name in dict.fromkeys(names)
            if is_output_name(name) and os.path.lexists(out_dir / name)]


def _order(names, first) -> list[str]:
    return sorted(names, key=lambda n: (n not in first, first.index(n) if n in first else 0, n))


def _swap(out_dir: Path, staging: Path, old: list[str], new: list[str]) -> None:
    """Steps 2-4 of the module docstring; safe to repeat after an interruption."""
    src, trash = staging / "new", staging / "old"
    trash.mkdir(exist_ok=True)
    for name in _order(old, _FIRST_OUT):
        # An entry that is also new and has already been moved in is the new one: keep it.
        if name in new and not os.path.lexists(src / name):
            continue
        if os.path.lexists(out_dir / name) and not os.path.lexists(trash / name):
            os.rename(out_dir / name, trash / name)
        elif os.path.lexists(out_dir / name):
            os.rename(out_dir / name, trash / f"{name}.{secrets.token_hex(4)}")
    for name in reversed(_order(new, _FIRST_OUT)):
        if os.path.lexists(src / name):
            target = out_dir / name
            if os.path.islink(target) or os.path.isdir(target):  # never written through a link
                os.rename(target, trash / f"{name}.{secrets.token_hex(4)}")
            os.replace(src / name, target)
    (out_dir / JOURNAL).unlink(missing_ok=True)
    shutil.rmtree(staging, ignore_errors=True)


def recover(out_dir) -> None:
    """Complete a swap that an interrupted run left in ``out_dir`` (its journal), and delete the
    staging directories of runs that never reached the swap. Does nothing in a directory that
    does not exist or holds no such leftovers."""
    out_dir = Path(out_dir)
    if not out_dir.is_dir():
        return
    record = _read_json(out_dir / JOURNAL)
    if isinstance(record, dict):
        staging_name = record.get("staging")
        old, new = record.get("old"), record.get("new")
        if (isinstance(staging_name, str) and staging_name.startswith(STAGING_PREFIX)
                and "/" not in staging_name and isinstance(old, list) and isinstance(new, list)
                and all(is_output_name(n) for n in old + new)
                and (out_dir / staging_name).is_dir()
                and not (out_dir / staging_name).is_symlink()):
            _swap(out_dir, out_dir / staging_name, old, new)
    (out_dir / JOURNAL).unlink(missing_ok=True)
    for leftover in out_dir.glob(STAGING_PREFIX + "*"):
        if leftover.is_symlink() or not leftover.is_dir():
            leftover.unlink(missing_ok=True)
        else:
            shutil.rmtree(leftover, ignore_errors=True)


def _describe_os_error(exc: OSError, out_dir: Path) -> str:
    if exc.errno == errno.ENOSPC:
        return f"no space left on the device of '{out_dir}'; the earlier outputs there are kept"
    if exc.errno == errno.EDQUOT:
        return f"disk quota exceeded writing into '{out_dir}'; the earlier outputs there are kept"
    return f"cannot write into '{out_dir}': {exc.strerror or exc}"


def check_output_directory(out_dir, option: str = "--out") -> Path:
    """Create ``out_dir`` if missing and make sure files can be written into it, before any
    work starts.

    Raises
    ------
    InputError
        If it is a file, lies below a file, or cannot be created or written to.
    """
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"{option} '{out_dir}' is a file, not a directory; give a directory")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        probe = out_dir / f"{STAGING_PREFIX}probe-{secrets.token_hex(4)}"
        probe.mkdir()
        probe.rmdir()
    except (NotADirectoryError, FileExistsError):
        raise InputError(f"{option} '{out_dir}' cannot be created: a part of the path is a "
                         "file") from None
    except PermissionError:
        raise InputError(f"{option} '{out_dir}' is not writable (permission denied); "
                         "choose another directory") from None
    except OSError as exc:
        raise InputError(f"{option} '{out_dir}' cannot be used: {exc.strerror or exc}") from None
    return out_dir


@contextlib.contextmanager
def staged_run(out_dir):
    """Write one run's outputs into ``out_dir`` as one unit.

    Yields the staging directory to write every output into (top-level names as in the output
    directory). When the block ends without an exception, the earlier run's entries are replaced
    by the new ones (see the module docstring); when it raises
    (``KeyboardInterrupt`` included), the staging directory is deleted and the earlier output
    stays as it was.

    Raises
    ------
    OutputError
        If the outputs cannot be written (no space left, permissions); the earlier outputs stay.
    """
    out_dir = Path(out_dir)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        recover(out_dir)
        staging = out_dir / f"{STAGING_PREFIX}{secrets.token_hex(6)}"
        (staging / "new").mkdir(parents=True)
    except OSError as exc:
        raise OutputError(_describe_os_error(exc, out_dir)) from None
    try:
        yield staging / "new"
        new = sorted(p.name for p in (staging / "new").iterdir()
                     if not p.name.startswith("."))
        bad = [n for n in new if not is_output_name(n)]
        if bad:
            raise ValueError(f"output entry {bad[0]!r} is not a name a run may write")
        old = owned_entries(out_dir)
        atomic_write_text(out_dir / JOURNAL, json.dumps(
            {"format": _FORMAT, "staging": staging.name, "old": old, "new": new}))
    except OSError as exc:
        shutil.rmtree(staging, ignore_errors=True)
        (out_dir / JOURNAL).unlink(missing_ok=True)
        raise OutputError(_describe_os_error(exc, out_dir)) from None
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        (out_dir / JOURNAL).unlink(missing_ok=True)
        raise
    # From here on the swap only renames (milliseconds): Ctrl-C and SIGTERM wait until it is
    # done, and a SIGKILL in between is completed by the next run's recover().
    held = {signal.SIGINT, signal.SIGTERM}
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        _swap(out_dir, staging, old, new)
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def final_path(path, staging, out_dir) -> Path:
    """Where a file written under ``staging`` lies once the run is swapped into ``out_dir``."""
    return Path(out_dir) / Path(path).relative_to(staging)
