"""The ``bayesfo`` command line.

Exit status 0 on success, 2 on bad input (one line on stderr naming the file, column, row or
argument), 1 on an internal error; 130 and 143 when interrupted or terminated, and 141 (as a
shell reports a process ended by SIGPIPE) when whatever reads the output closes it early, as
``bayesfo inspect FILE | head`` does, without a message.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import os
import re
import sys
import warnings

from .._signals import cause
from ..errors import InputError, OutputError

#: The commands, in the order of ``bayesfo --help``; each is the module ``bayesfo.cli.<name>``
#: with ``add_parser(subparsers)`` and ``run(args) -> int``, imported when the parser is built
#: (they import the computing modules only when they run).
COMMANDS = ("inspect", "compare", "predict", "export", "mastercurve", "design", "identify",
            "simulate", "structures", "extract", "batch")

#: The flags of the API's options whose names differ from the option's (``--name`` for the
#: option ``name``, underscores as hyphens, otherwise): how an :class:`InputError` that names
#: an option (:attr:`InputError.option`) is said on the command line.
FLAGS = {"priors": "--prior"}


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit status 2."""

    def error(self, message):
        raise InputError(f"{message} (see '{self.prog} --help')")


def build_parser() -> argparse.ArgumentParser:
    from .. import __version__

    parser = _Parser(
        prog="bayesfo",
        description="Uncertainty-aware model choice for fractional-order transfer functions.",
    )
    parser.add_argument("--version", action="version", version=f"bayesfo {__version__}")
    parser.add_argument("--models", action="append", default=[], metavar="PATH",
                        help="extra structure card (.toml) or directory of cards; repeatable")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    for name in COMMANDS:
        p = importlib.import_module(f"{__name__}.{name}").add_parser(sub)
        # Also after the command (bayesfo structures --models DIR); SUPPRESS keeps a value
        # given before the command instead of resetting it to the default.
        p.add_argument("--models", action="append", default=argparse.SUPPRESS, metavar="PATH",
                       help="extra structure card (.toml) or directory of cards; repeatable")
    return parser


#: Warnings of one kind that several structures raise, held and said once at the end of the
#: command (one line naming the structures) instead of once per structure.
_PARETO = re.compile(r"(?P<name>.+?): Pareto k up to (?P<k>[0-9.]+) at (?P<where>.+); "
                     r"PSIS-LOO is unreliable there")
_held: list = []


def _one_line_warning(message, category, filename, lineno, file=None, line=None):
    text = str(message)
    match = _PARETO.fullmatch(text)
    if match:
        _held.append(match)
        return
    print(f"bayesfo: warning: {text}", file=sys.stderr)


def _held_warnings() -> None:
    """Print the held warnings, one line per kind: a single structure's as it was raised."""
    if not _held:
        return
    if len(_held) == 1:
        print(f"bayesfo: warning: {_held[0].string}", file=sys.stderr)
    else:
        parts = [f"{m['name']} ({m['k']} at {m['where'].removeprefix('omega = ')})"
                 for m in _held]
        print("bayesfo: warning: PSIS-LOO is unreliable (Pareto k above 0.7) at some "
              f"frequencies for {', '.join(parts)}; elpd_loo of these structures is rough",
              file=sys.stderr)
    _held.clear()


class Terminated(BaseException):
    """SIGTERM arrived: unwinds like Ctrl-C, so that outputs are left as they were and worker
    processes are ended."""


def _on_sigterm(signum, frame):
    raise Terminated


def _interrupted(exc: BaseException) -> int:
    """Exit status 130 after Ctrl-C, 143 after SIGTERM, with a one-line message."""
    what, status = ("terminated", 143) if isinstance(exc, Terminated) else ("interrupted", 130)
    print(f"bayesfo: {what} (no output is left half-written)", file=sys.stderr)
    return status


def _internal_error(exc: BaseException) -> int:
    if os.environ.get("BAYESFO_DEBUG"):
        raise exc
    print(f"bayesfo: internal error: {type(exc).__name__}: {exc} "
          "(set BAYESFO_DEBUG=1 for a traceback)", file=sys.stderr)
    return 1


def _stdout_gone() -> bool:
    """Whether standard output is a pipe whose reader has closed it."""
    import select

    try:
        poll = select.poll()
        poll.register(sys.stdout.fileno(), select.POLLOUT)
        return any(event & select.POLLERR for _, event in poll.poll(0))
    except (AttributeError, OSError, ValueError):  # no poll (Windows), or no file descriptor
        return False


#: Options whose value may start with a minus sign: a temperature below zero (``--block
#: -40C``), or a list whose first number is negative (``--time -1,2``, refused then by its own
#: check with a message that says why).
NEGATIVE_VALUES = ("--block", "--time", "--omega", "--tau", "--temperatures", "--holdout",
                   "--window", "--temperature", "--reference-temperature")


def _negative_values(argv) -> list[str]:
    """``--block -40C`` as ``--block=-40C`` (and so for :data:`NEGATIVE_VALUES`): argparse
    takes a value that starts with '-' and is not a plain number for an option ("expected one
    argument")."""
    argv = [str(a) for a in argv]
    out, i = [], 0
    while i < len(argv):
        if argv[i] in NEGATIVE_VALUES and i + 1 < len(argv) and re.match(r"-[0-9.]",
                                                                        argv[i + 1]):
            out.append(f"{argv[i]}={argv[i + 1]}")
            i += 2
            continue
        out.append(argv[i])
        i += 1
    return out


def main(argv=None) -> int:
    """Run the command line; returns the exit status."""
    import signal
    import threading

    # The commands write figures to files and show no window: matplotlib's file backend unless
    # the user chose one (a desktop session would otherwise load a GUI toolkit, whose state a
    # process forked to draw figures must not share; bayesfo.plotting.output.can_fork).
    os.environ.setdefault("MPLBACKEND", "agg")
    previous = None
    thaw = not gc.get_freeze_count()  # a caller's own frozen objects stay frozen
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        # Inside the try: a Ctrl-C while the commands' modules load is one line, not a
        # traceback.
        parser = build_parser()
        args = parser.parse_args(_negative_values(sys.argv[1:] if argv is None else argv))
        if args.command is None:
            parser.print_help()
            return 2
        import numpy as np

        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.showwarning = _one_line_warning
            _held.clear()
            try:
                status = importlib.import_module(f"{__name__}.{args.command}").run(args)
            finally:
                _held_warnings()
        sys.stdout.flush()  # a closed pipe shows here, not at the interpreter's exit
        return status
    except BrokenPipeError as exc:
        if not _stdout_gone():  # another pipe (a FIFO given as a file, ...): a real failure
            return _internal_error(exc)
        # The reader has gone (e.g. `| head`): nothing more to say, and the interpreter's own
        # flush at exit must not fail again.
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            os.close(devnull)
        except (OSError, ValueError):
            pass
        return 141
    except InputError as exc:
        print(f"bayesfo: error: {exc.in_command_line(FLAGS)}", file=sys.stderr)
        return 2
    except OutputError as exc:
        print(f"bayesfo: error: {exc}", file=sys.stderr)
        return 1
    except (KeyboardInterrupt, Terminated) as exc:
        return _interrupted(exc)
    except Exception as exc:  # the contract: exit 1 on internal errors, no traceback by default
        # A signal that broke an import (or a library's clean-up) shows as another exception
        # raised from it: the user interrupted, and is told so.
        signalled = cause(exc, (KeyboardInterrupt, Terminated))
        if signalled is not None:
            return _interrupted(signalled)
        return _internal_error(exc)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
        if thaw:  # what the command froze (load_libraries) is collectable again
            gc.unfreeze()


def script() -> None:
    """The ``bayesfo`` executable: :func:`main`, then exit with its status. Every object is
    frozen out of the garbage collector first, as the process ends anyway: its last
    collections, at the interpreter's exit, would otherwise walk every object of the libraries
    once more (files are closed and output flushed as usual). After an interrupt, standard
    error ends with the command's one line."""
    status = main()
    gc.freeze()
    if status in (130, 143):
        # Interrupted: its one line is said. What the interpreter's exit hooks may still
        # print (a process pool's hook writing to a pipe the signal already closed: "Exception
        # ignored in ...") would bury it; the hooks still run, their noise goes to /dev/null.
        try:
            sys.stderr.flush()
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stderr.fileno())
            os.close(devnull)
        except (OSError, ValueError):
            pass
    sys.exit(status)


if __name__ == "__main__":  # pragma: no cover
    script()
