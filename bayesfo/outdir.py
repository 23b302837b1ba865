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

Which entries belong to the earlier run is read from the manifest that every run moves in with
its outputs, ``.bayesfo-run.json``; a name is only taken from there if it is a single name of the
kinds bayesfo writes (:func:`is_output_name`). Without a manifest (a directory no run of this
version wrote into), nothing is taken as the earlier run's: only files of the names the new run
writes are replaced, and a directory of such a name that no run recorded (a ``figures/`` of your
own) is refused rather than replaced. Other files in the output directory are never touched.
Runs into the same directory take turns: a lock (``.bayesfo-lock``) is held while a run swaps
its outputs in, and removed by the run before it lets go of it (:func:`_locked` says why that is
safe), so a finished run leaves no lock file behind.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import os
import re
import secrets
import shutil
import stat
import time
from pathlib import Path, PurePosixPath

from ._io import atomic_write_text
from ._signals import held
from .errors import InputError, OutputError

JOURNAL = ".bayesfo-swap.json"
MANIFEST = ".bayesfo-run.json"
LOCK = ".bayesfo-lock"
STAGING_PREFIX = ".bayesfo-staging-"
_FORMAT = 1

#: Top-level names a bayesfo run may own in an output directory.
_OUTPUT_NAME = re.compile(
    r"^(?:summary\.json|ranking\.csv|report\.html|figures|batch\.json|error\.txt|master\.csv"
    r"|[A-Za-z0-9][A-Za-z0-9_.+\-]*\.nc)$")
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


#: Largest journal or manifest read [bytes]: a manifest names a run's top-level entries and
#: their digests (a few kilobytes); anything larger is not one.
MAX_RECORD_BYTES = 16 * 1024 * 1024


def _read_json(path: Path):
    """The JSON of a journal or manifest, or None where it is missing, unreadable, not JSON,
    nested too deeply, or not a regular file of at most :data:`MAX_RECORD_BYTES` (a FIFO would
    block the reader, a link to ``/dev/zero`` never end: neither is opened for reading)."""
    try:
        info = os.lstat(path)
        if not stat.S_ISREG(info.st_mode) or info.st_size > MAX_RECORD_BYTES:
            return None
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0)
                     | getattr(os, "O_NOFOLLOW", 0))
        with open(fd, "rb") as f:
            if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
                return None
            raw = f.read(MAX_RECORD_BYTES + 1)
        if len(raw) > MAX_RECORD_BYTES:
            return None
        return json.loads(raw.decode("utf-8"))
    except (OSError, ValueError, RecursionError):  # unreadable, not JSON, nested too deeply
        return None


def _digest(path: Path) -> str:
    """SHA-256 of a file, in hex."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


@contextlib.contextmanager
def one_run(out_dir, checked=lambda name: True):
    """Read the files of ``out_dir`` as the output of one run: a run swapping its outputs in
    is waited for (its lock is held while the block reads), and every file for which
    ``checked(name)`` holds and whose digest the run recorded must still have it.

    A reader never deletes or renames anything: a swap that a killed run left half-done is
    refused (the next run of the command that wrote the directory completes it), and so is a
    manifest that cannot be read (it would switch the digest checks off).

    Raises
    ------
    InputError
        A file that another run wrote, or that was changed since (copied in, truncated); a
        swap left half-done; a damaged manifest.
    """
    out_dir = Path(out_dir)
    with contextlib.ExitStack() as stack:
        try:
            stack.enter_context(_locked(out_dir))
        except OSError:  # a directory that cannot be written: read what it holds, unlocked
            pass
        if os.path.lexists(out_dir / JOURNAL):
            raise InputError(f"'{out_dir}' holds a half-done move of a run's outputs "
                             f"('{JOURNAL}': that run was interrupted), so its files may be of "
                             "two runs; run the command that wrote it again into the directory "
                             "(it completes the move first)")
        if os.path.lexists(out_dir / MANIFEST):
            record = _read_json(out_dir / MANIFEST)
            if not (isinstance(record, dict) and isinstance(record.get("sha256", {}), dict)):
                raise InputError(f"'{out_dir / MANIFEST}' (the record of the run that wrote "
                                 f"'{out_dir}') is damaged or not a regular file, so its files "
                                 "cannot be checked; run the command that wrote it again into "
                                 "the directory, or remove the record to read the files "
                                 "unchecked")
        path = changed_file(out_dir, checked)
        if path is not None:
            raise InputError(f"'{path}' is not the file that the run which wrote "
                             f"'{out_dir}' left there (changed, truncated or copied in "
                             "from another run); run the command that wrote it again into "
                             "the directory")
        yield


def changed_file(out_dir, checked=lambda name: True) -> Path | None:
    """The first file of ``out_dir`` (among those for which ``checked(name)`` holds) whose
    SHA-256 is not the one its run recorded, or None (also where no digests were recorded)."""
    out_dir = Path(out_dir)
    record = _read_json(out_dir / MANIFEST)
    digests = record.get("sha256") if isinstance(record, dict) else None
    for name, digest in (digests.items() if isinstance(digests, dict) else ()):
        path = out_dir / name
        if (isinstance(name, str) and is_output_name(name) and checked(name)
                and path.is_file() and _digest(path) != digest):
            return path
    return None


def owned_entries(out_dir) -> list[str]:
    """The entries of ``out_dir`` that the earlier run recorded in its manifest and that exist
    now, each checked with :func:`is_output_name` (none without a manifest)."""
    out_dir = Path(out_dir)
    record = _read_json(out_dir / MANIFEST)
    names = record.get("entries") if isinstance(record, dict) else None
    if not isinstance(names, list):
        return []
    return [name for name in dict.fromkeys(n for n in names if isinstance(n, str))
            if is_output_name(name) and os.path.lexists(out_dir / name)]


def _unrecorded(out_dir: Path, new) -> None:
    """Warn of the output-named files left from an earlier run whose record is unreadable: they
    cannot be told apart from a user's own, so they are left in place, and said so."""
    import warnings

    left = sorted(n for n in os.listdir(out_dir)
                  if is_output_name(n) and n not in new and not n.startswith("."))
    if left:
        warnings.warn(
            f"'{out_dir / MANIFEST}' (the record of the earlier run) is unreadable, so its files "
            f"cannot be told from others: {', '.join(repr(n) for n in left)} left in place; "
            "remove them by hand if they are that run's outputs", RuntimeWarning, stacklevel=4)


def _real_directory(path: Path) -> bool:
    return path.is_dir() and not path.is_symlink()


_OWNER = ".owner"


def _claim(staging: Path):
    """Lock the staging directory's owner file for the life of the run (closed at its end);
    None where the platform has no file locks."""
    try:
        import fcntl
    except ImportError:
        return None
    fd = os.open(staging / _OWNER, os.O_RDWR | os.O_CREAT, 0o644)
    fcntl.flock(fd, fcntl.LOCK_EX)
    return fd


def _abandoned(staging: Path) -> bool:
    """Whether no live run owns ``staging`` (its owner file is not locked by another process;
    a staging directory without one is taken as abandoned once it is a minute old)."""
    owner = staging / _OWNER
    if not owner.is_file() or owner.is_symlink():
        try:
            return time.time() - staging.lstat().st_mtime > 60
        except OSError:
            return False
    try:
        import fcntl
    except ImportError:
        return True
    try:
        fd = os.open(owner, os.O_RDWR)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:  # held by a running process
        return False
    finally:
        os.close(fd)
    return True


def _order(names, first) -> list[str]:
    return sorted(names, key=lambda n: (n not in first, first.index(n) if n in first else 0, n))


def _swap(out_dir: Path, staging: Path, old: list[str], new: list[str]) -> None:
    """Steps 2-4 of the module docstring; safe to repeat after an interruption."""
    src, trash = staging / "new", staging / "old"
    trash.mkdir(exist_ok=True)
    if not (_real_directory(src) and _real_directory(trash)):  # never renamed through a link
        raise OutputError(f"the staging directory '{staging}' is not bayesfo's; remove it")
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
    does not exist or holds no such leftovers; waits for a run that is swapping its outputs in."""
    out_dir = Path(out_dir)
    if not _real_directory(out_dir) or not any(out_dir.glob(".bayesfo-s*")):
        return
    with _locked(out_dir):
        _recover_unlocked(out_dir)


def _recover_unlocked(out_dir: Path, keep: str | None = None) -> None:
    record = _read_json(out_dir / JOURNAL)
    if isinstance(record, dict):
        staging_name = record.get("staging")
        old, new = record.get("old"), record.get("new")
        staging = out_dir / staging_name if isinstance(staging_name, str) else None
        if (staging is not None and staging_name.startswith(STAGING_PREFIX)
                and "/" not in staging_name and isinstance(old, list) and isinstance(new, list)
                and all(isinstance(n, str) and (is_output_name(n) or n == MANIFEST)
                        for n in old + new)
                and _real_directory(staging) and _real_directory(staging / "new")
                and (not os.path.lexists(staging / "old") or _real_directory(staging / "old"))):
            _swap(out_dir, staging, old, new)
    (out_dir / JOURNAL).unlink(missing_ok=True)
    # A staging directory without a journal belongs to a run that died before its swap, or to
    # one still writing in another process (which holds the lock on its owner file).
    for leftover in out_dir.glob(STAGING_PREFIX + "*"):
        if leftover.name == keep:
            continue
        if leftover.is_symlink() or not leftover.is_dir():
            leftover.unlink(missing_ok=True)
        elif _abandoned(leftover):
            shutil.rmtree(leftover, ignore_errors=True)


def _describe_os_error(exc: OSError, out_dir: Path) -> str:
    if exc.errno == errno.ENOSPC:
        return f"no space left on the device of '{out_dir}'; the earlier outputs there are kept"
    if exc.errno == errno.EDQUOT:
        return f"disk quota exceeded writing into '{out_dir}'; the earlier outputs there are kept"
    return f"cannot write into '{out_dir}': {exc.strerror or exc}"


def check_output_directory(out_dir, option: str = "--out", directories=()) -> Path:
    """Create ``out_dir`` if missing and make sure files can be written into it, before any
    work starts.

    Parameters
    ----------
    directories : sequence of str
        Directory entries the run will write (``figures``): one that exists in ``out_dir``
        without an earlier run having recorded it is refused now, not after the work.

    Raises
    ------
    InputError
        If it is a file, lies below a file, cannot be created or written to, or holds one of
        ``directories`` that no bayesfo run recorded.
    """
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"{option} '{out_dir}' is a file, not a directory; give a directory")
    try:  # first complete a swap that a killed run left half-done: its entries are recorded
        recover(out_dir)
    except OSError:
        pass  # not writable: said below
    foreign = [n for n in directories
               if _real_directory(out_dir / n) and n not in owned_entries(out_dir)]
    if foreign:
        raise InputError(f"{option} '{out_dir}' holds a directory '{foreign[0]}' that no "
                         "bayesfo run recorded; bayesfo would replace it: move it away or "
                         "choose another output directory")
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


def _same_file(a: os.stat_result, b: os.stat_result) -> bool:
    return (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)


def _acquire(path: Path, fcntl) -> int:
    """A descriptor of the lock file ``path``, flock-ed, that ``path`` still names."""
    while True:
        try:  # O_NOFOLLOW: a link named like the lock never makes a file outside the directory
            fd = os.open(path, os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0)
                         | getattr(os, "O_NONBLOCK", 0), 0o644)
        except OSError as exc:
            if exc.errno == errno.ELOOP:
                raise OutputError(f"'{path}' is a symbolic link, not bayesfo's lock file; "
                                  "remove it") from None
            raise
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # a FIFO or device named like the lock
            os.close(fd)
            raise OutputError(f"'{path}' is not a regular file, so not bayesfo's lock file; "
                              "remove it")
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
            try:
                now = os.stat(path, follow_symlinks=False)
            except FileNotFoundError:
                now = None
            if now is not None and _same_file(os.fstat(fd), now):
                return fd
        except BaseException:
            os.close(fd)
            raise
        os.close(fd)  # the run before removed the file we waited on: lock the one there now


@contextlib.contextmanager
def _locked(out_dir: Path):
    """Hold the output directory's lock (waiting for another run's swap to finish).

    The lock is an ``flock`` on ``out_dir/.bayesfo-lock``, removed while still held, so that no
    lock file stays behind. That keeps the runs taking turns because a run only counts the lock
    as taken once, holding it, it has seen that the path still names the file it locked: a run
    that waited on a file its holder has since removed goes round again and locks the file now
    at the path (a new one, created by whichever waiting run opens it first). Only the holder
    removes the file, so two runs never both hold a file that the path names. (A bayesfo older
    than this check, running into the same directory at the same moment, would not go round
    again; runs of one version take turns.)
    """
    try:
        import fcntl
    except ImportError:  # not POSIX: runs into one directory must not overlap
        yield
        return
    path = out_dir / LOCK
    fd = _acquire(path, fcntl)
    try:
        yield
    finally:
        try:
            if _same_file(os.fstat(fd), os.stat(path, follow_symlinks=False)):
                os.unlink(path)
        except OSError:  # already gone, or not removable: the next run locks it as it is
            pass
        os.close(fd)


@contextlib.contextmanager
def staged_run(out_dir):
    """Write one run's outputs into ``out_dir`` as one unit.

    Yields the staging directory to write every output into (top-level names as in the output
    directory). When the block ends without an exception, the earlier run's entries are replaced
    by the new ones (see the module docstring); when it raises (``KeyboardInterrupt``
    included), the staging directory is deleted and the earlier output stays as it was.

    Raises
    ------
    OutputError
        If the outputs cannot be written (no space left, permissions), or a new entry would
        replace a directory that no bayesfo run recorded; the earlier outputs stay.
    """
    out_dir = Path(out_dir)
    created = not os.path.lexists(out_dir)  # a first run that fails leaves no directory
    token = secrets.token_hex(6)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        staging = out_dir / f"{STAGING_PREFIX}{token}"
        staging.mkdir()
        owner = _claim(staging)
        (staging / "new").mkdir()
    except OSError as exc:
        if created:  # what this call made, and only if nothing else came into it
            shutil.rmtree(out_dir / f"{STAGING_PREFIX}{token}", ignore_errors=True)
            with contextlib.suppress(OSError):
                out_dir.rmdir()
        raise OutputError(_describe_os_error(exc, out_dir)) from None
    swapping = False  # from the journal on, the staging directory holds both runs' files
    try:
        yield staging / "new"
        new = sorted(p.name for p in (staging / "new").iterdir()
                     if not p.name.startswith("."))
        bad = [n for n in new if not is_output_name(n)]
        if bad:
            raise ValueError(f"output entry {bad[0]!r} is not a name a run may write")
        digests = {n: _digest(staging / "new" / n) for n in new
                   if (staging / "new" / n).is_file()}
        atomic_write_text(staging / "new" / MANIFEST,
                          json.dumps({"format": _FORMAT, "entries": new, "sha256": digests},
                                     indent=2) + "\n")
        with _locked(out_dir):
            _recover_unlocked(out_dir, keep=staging.name)
            old = owned_entries(out_dir)
            foreign = [n for n in new if n not in old and _real_directory(out_dir / n)]
            if foreign:
                raise OutputError(
                    f"'{out_dir / foreign[0]}' is a directory that no bayesfo run recorded; "
                    "bayesfo would replace it: move it away or choose another output directory")
            if os.path.lexists(out_dir / MANIFEST):
                old.append(MANIFEST)
                if not isinstance(_read_json(out_dir / MANIFEST), dict):
                    _unrecorded(out_dir, new)
            # From the journal on, the swap only renames (milliseconds): Ctrl-C and SIGTERM
            # wait until it is done, and a SIGKILL in between is completed by the next run.
            with held():
                atomic_write_text(out_dir / JOURNAL, json.dumps(
                    {"format": _FORMAT, "staging": staging.name, "old": old,
                     "new": new + [MANIFEST]}))
                swapping = True
                _swap(out_dir, staging, old, new + [MANIFEST])
    except BaseException as exc:
        if swapping:  # never delete: the journal lets the next run complete the swap
            if isinstance(exc, OSError):
                raise OutputError(f"the outputs were not all moved into '{out_dir}' "
                                  f"({exc.strerror or exc}); the next run into it completes "
                                  "the move") from None
            raise
        shutil.rmtree(staging, ignore_errors=True)
        if created:
            with contextlib.suppress(OSError):
                out_dir.rmdir()  # only if empty
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise OutputError(_describe_os_error(exc, out_dir)) from None
        raise
    finally:
        if owner is not None:
            os.close(owner)


def final_path(path, staging, out_dir) -> Path:
    """Where a file written under ``staging`` lies once the run is swapped into ``out_dir``."""
    return Path(out_dir) / Path(path).relative_to(staging)
