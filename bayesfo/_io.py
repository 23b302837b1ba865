"""Atomic file output: a reader never sees a half-written file."""

from __future__ import annotations

import csv
import errno
import math
import os
import re
import stat
import tempfile
from pathlib import Path

from .errors import InputError


def atomic_write_text(path: str | os.PathLike, text: str, encoding: str = "utf-8", *,
                      named: bool = False) -> Path:
    """Write ``text`` to ``path`` through a temporary file in the same directory and a rename.

    The rename is atomic on POSIX and Windows file systems, so an interrupted run leaves either
    the previous file or the complete new one, never a truncated file.

    With ``named`` (a file the user named: ``--out FILE``), a symbolic link is written through
    (the file it names is replaced, the link stays) and a device or FIFO is written into, never
    replaced (:func:`write_target`). Without it (a file inside an output directory), what is
    at ``path`` is replaced, a link included: nothing outside the directory is written.
    """
    given = Path(path)
    path = write_target(given) if named else given
    if named and is_special(path):  # /dev/null, a FIFO: written into, never renamed over
        write_into(path, text.encode(encoding))
        return given
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding=encoding, newline="") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        publish(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return given


def write_target(path: str | os.PathLike) -> Path:
    """Where a file named by the user is written without replacing what ``path`` names.

    A symbolic link is followed to the file it names (the link stays a link: the file it
    points to is replaced); a link that leads nowhere is refused, since writing through it would
    create a file elsewhere than where the user looked. An existing device, FIFO or socket is
    returned as it is, to be written into (:func:`is_special`, :func:`write_into`), never
    renamed over.

    Raises
    ------
    OSError
        For a symbolic link that points to nothing (with a ``strerror`` that says so).
    """
    path = Path(path)
    if not path.is_symlink():
        return path
    try:
        os.stat(path)
    except OSError:
        raise OSError(errno.ENOENT, f"a symbolic link to '{os.readlink(path)}', which does not "
                      "exist; give the path of a file") from None
    # /dev/fd/N and /proc/self/fd/N (a shell's process substitution) lead to a pipe that has no
    # path: written into through the link itself.
    return path if is_special(path) else Path(os.path.realpath(path))


def is_special(path: str | os.PathLike) -> bool:
    """Whether ``path`` names (after links) an existing node that is neither a regular file
    nor a directory: a device such as ``/dev/null``, a FIFO or a socket."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return False
    return not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))


def write_into(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` into the existing device, FIFO or socket ``path`` (opened for writing
    without creating or truncating anything: the node stays what it was)."""
    fd = os.open(path, os.O_WRONLY | getattr(os, "O_BINARY", 0))
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]
    finally:
        os.close(fd)


#: What to do with a directory where a data file was expected.
DIRECTORY_HINT = ("give a file of it (bayesfo batch and bayesfo mastercurve take a directory of "
                  "data sets or isotherms)")


def write_error(path: str | os.PathLike, exc: OSError) -> str:
    """Why ``path`` could not be written, in words: the nearest existing folder on its way
    that is a file ("'out/run' is a file, not a folder"; the system says "File exists" or
    "Not a directory"), else the system's reason."""
    for parent in Path(path).parents:
        if parent.exists():
            if not parent.is_dir():
                return f"'{parent}' is a file, not a folder"
            break
    return exc.strerror or str(exc)


def publish(tmp: str | os.PathLike, path: str | os.PathLike) -> None:
    """Give a finished temporary file the usual permissions (mkstemp makes it private) and
    rename it over ``path`` atomically."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    os.replace(tmp, path)


#: Largest text file read by default (bytes): far above any data file, record or manifest of the
#: sizes bayesfo handles (a frequency response of the largest allowed size is well below a
#: megabyte), and small enough that reading a wrong file (an image, a log, a disk dump) never
#: exhausts memory.
MAX_TEXT_BYTES = 256 * 1024 * 1024

# Invisible characters that no text data file holds: C0 and C1 control characters other than
# tab, line feed and carriage return, DEL, and a byte-order mark after the start of the file
# (files joined together). A NUL byte is the usual sign of a UTF-16 or binary file.
INVISIBLE = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ufeff]")
_LINE_BREAK = re.compile(r"\r\n|\r|\n")


def read_text_file(path: str | os.PathLike, what: str = "file",
                   max_bytes: int | None = MAX_TEXT_BYTES) -> str:
    """The text of a UTF-8 file, or an :class:`~bayesfo.errors.InputError` naming the file.

    The file must be a regular file (a FIFO, socket or device would block or never end: it is
    refused before it is opened), at most ``max_bytes`` long, UTF-8 (a leading byte-order mark is
    dropped), and free of invisible control characters (NUL and the other C0/C1 controls except
    tab and line breaks, or a byte-order mark after the start); the first such character is named
    by line and character position.
    """
    where = f"{what} '{path}'"
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise InputError(f"{where} does not exist") from None
    except OSError as exc:
        raise InputError(f"{where} cannot be read: {exc.strerror}") from None
    if stat.S_ISDIR(info.st_mode):
        raise InputError(f"{where} is a directory: {DIRECTORY_HINT}")
    if not stat.S_ISREG(info.st_mode):
        kind = ("a FIFO (named pipe)" if stat.S_ISFIFO(info.st_mode)
                else "a socket" if stat.S_ISSOCK(info.st_mode)
                else "a device" if stat.S_ISCHR(info.st_mode) or stat.S_ISBLK(info.st_mode)
                else "not a file")
        raise InputError(f"{where} is not a regular file ({kind}); save the data to a file "
                         "and give its path")
    if max_bytes is not None and info.st_size > max_bytes:
        raise InputError(f"{where} has {info.st_size} bytes, more than the {max_bytes} a "
                         "text data file of bayesfo can have; is it the right file?")
    try:
        # O_NONBLOCK: should the path have become a FIFO since the stat, opening it does not
        # wait for a writer, and the fstat below refuses it.
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
        with open(fd, "rb") as fh:
            if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
                raise InputError(f"{where} is not a regular file")
            raw = fh.read() if max_bytes is None else fh.read(max_bytes + 1)
    except IsADirectoryError:
        raise InputError(f"{where} is a directory: {DIRECTORY_HINT}") from None
    except OSError as exc:
        raise InputError(f"{where} cannot be read: {exc.strerror}") from None
    if max_bytes is not None and len(raw) > max_bytes:
        raise InputError(f"{where} has more than the {max_bytes} bytes a text data file of "
                         "bayesfo can have; is it the right file?")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        hint = " (it looks like UTF-16)" if raw[:2] in (b"\xff\xfe", b"\xfe\xff") else ""
        raise InputError(f"{where} is not a UTF-8 text file{hint}: undecodable byte at line "
                         f"{line}; save it as UTF-8 text") from None
    bad = INVISIBLE.search(text)
    if bad:
        line, char = text_position(text, bad.start())
        code = ord(bad.group())
        name = {0: "a NUL byte", 0xFEFF: "a byte-order mark"}.get(code, "a control character")
        hint = ("the file may be UTF-16 or binary; save it as UTF-8 text" if code == 0
                else "remove it (files joined together?)" if code == 0xFEFF
                else "remove it")
        raise InputError(f"{where}, line {line}, character {char}: {name} (U+{code:04X}, "
                         f"invisible); {hint}")
    return text


def text_position(text: str, index: int) -> tuple[int, int]:
    """(line, character), both counted from 1, of ``text[index]``; a line ends at LF, CR or CRLF."""
    breaks = list(_LINE_BREAK.finditer(text, 0, index))
    start = breaks[-1].end() if breaks else 0
    return len(breaks) + 1, index - start + 1


def split_lines(text: str) -> list[str]:
    """The lines of ``text``, split at LF, CR and CRLF only (not at the other characters
    :meth:`str.splitlines` treats as line breaks), so that line numbers match an editor's."""
    lines = _LINE_BREAK.split(text)
    if lines and lines[-1] == "":
        lines.pop()
    return lines


def csv_cells(line: str, where: str, lineno: int, delimiter: str = ",",
              delimiter_name: str = "comma") -> list[str]:
    """The cells of one delimited line (comma-separated by default), or an InputError naming the
    file and line."""
    try:
        return next(csv.reader([line], delimiter=delimiter), [])
    except csv.Error as exc:
        if "field limit" in str(exc):
            raise InputError(f"{where}, line {lineno}: a cell has more than "
                             f"{csv.field_size_limit()} characters, far more than any value "
                             "needs; is it the right file?") from None
        what = ("read as comma-separated values" if delimiter == ","
                else f"split at {delimiter_name}s")
        raise InputError(f"{where}, line {lineno}: cannot be {what} ({exc})") from None


#: Longest cell :func:`parse_number` reads: a double has 17 significant digits, so even a
#: number written with every digit of a long-precision export fits many times over.
MAX_NUMBER_CHARS = 1000

_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_NON_FINITE = re.compile(r"[+-]?(?:nan|inf|infinity)", re.IGNORECASE)


def show(text: str, limit: int = 40, *, ascii_only: bool = True) -> str:
    """``text`` quoted for a one-line message: invisible and (with ``ascii_only``, for cells
    of a data file, where a look-alike letter such as a Cyrillic е in 1.2е5 would hide) non-ASCII
    characters escaped, long text shortened (with its length)."""
    plain = text.isprintable() and (text.isascii() or not ascii_only)
    shown = text if plain else ascii(text)[1:-1]
    if len(shown) > limit:
        shown = f"{shown[:limit]}... ({len(text)} characters)"
    return f"'{shown}'"


def parse_number(cell: str) -> float:
    """A finite number in plain decimal notation (``1``, ``-2.5``, ``.5``, ``3e-4``).

    Stricter than :func:`float`, which also reads ``1_0`` as 10, Unicode digits, and
    ``inf``/``nan``: a data file's numbers are ASCII, and a non-finite value cannot be fitted.

    Raises
    ------
    ValueError
        With a message saying what is wrong with the cell and how to write it, for the caller to
        put after the file, line and column.
    """
    text = cell.strip()
    if not text:
        raise ValueError("the cell is empty")
    if len(text) > MAX_NUMBER_CHARS:
        raise ValueError(f"the cell has {len(text)} characters, more than any number needs "
                         f"(at most {MAX_NUMBER_CHARS})")
    if _NUMBER.fullmatch(text):
        value = float(text)
        if not math.isfinite(value):
            raise ValueError(f"value is {show(text)[1:-1]}, not a finite number (beyond "
                             "1.8e308, the largest double)")
        return value
    if _NON_FINITE.fullmatch(text):
        raise ValueError(f"value is {text}, not a finite number")
    if "_" in text and _NUMBER.fullmatch(text.replace("_", "")):
        raise ValueError(f"{show(text)} is not a number: underscores are not allowed in "
                         f"numbers (write '{text.replace('_', '')}')")
    if text.count(",") == 1 and _NUMBER.fullmatch(text.replace(",", ".")):
        raise ValueError(f"{show(text)} is not a number: write the decimal point as '.'")
    raise ValueError(f"{show(text)} is not a number")
