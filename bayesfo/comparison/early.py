"""The optimisations of a comparison begun early, in a process forked from this one before it
loads the libraries that the later steps use (ArviZ and xarray, emcee, matplotlib), whose
imports keep one CPU busy while the other waits (BENCHMARKS.md, "The optimisations in a
process forked before the imports"). The
optimisations need none of them, so they run on that CPU meanwhile.

The schedule (:mod:`.schedule`) takes each structure's optimum from here once it has come
(:meth:`EarlyFits.take`), and otherwise optimises as before: the optimisation uses the
comparison's seed wherever it runs, so the numbers are the same either way. The process
optimises the structures one after the other in the order the schedule takes them, and is ended
once the worker processes have overtaken it (:meth:`EarlyFits.stop`).
"""

from __future__ import annotations

import os
import pickle
import warnings

from ..parallel import fork_safe, init_worker
from .steps import RunOptions, _fit


def _fit_each(structures, data, options: RunOptions, conn, parent: int) -> None:
    """In the forked process: ``(name, (noise candidates, fit, warnings as (category,
    message)))`` for each structure in turn, ``(name, None)`` where its optimisation raised (the
    schedule then optimises it itself, and so reports the error as it always does)."""
    init_worker(parent)
    for s in structures:
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                candidates, fit = _fit(s, data, options)
            value = (candidates, fit, [(w.category, str(w.message)) for w in caught])
        except Exception:  # noqa: BLE001  (reported where the schedule optimises it again)
            value = None
        conn.send((s.name, value))
    conn.close()


class EarlyFits:
    """The optimisations of ``structures`` (in that order), running in a process forked now.

    Use :meth:`start`, which forks only where it is safe (:func:`~bayesfo.parallel.fork_safe`)."""

    def __init__(self, structures, data, options: RunOptions):
        import multiprocessing

        context = multiprocessing.get_context("fork")
        self._conn, child = context.Pipe(duplex=False)
        self._process = context.Process(
            target=_fit_each, args=(list(structures), data, options, child, os.getpid()),
            name="bayesfo-fits", daemon=True)
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=".*multi-threaded.*fork",
                                    category=DeprecationWarning)
            self._process.start()
        child.close()
        self._fits: dict = {}
        self._ended = False

    @classmethod
    def start(cls, structures, data, options: RunOptions) -> EarlyFits | None:
        """The optimisations begun in a forked process, or None where this process cannot
        fork safely."""
        return cls(structures, data, options) if fork_safe() else None

    def _receive(self) -> None:
        try:
            name, value = self._conn.recv()
        except (EOFError, OSError, pickle.UnpicklingError):  # the process has ended
            self._ended = True
            return
        self._fits[name] = value

    def take(self, name: str, *, wait: bool) -> tuple | None:
        """``(noise candidates, fit, warnings)`` of structure ``name`` if the process has
        optimised it (with ``wait``, waiting for it while the process runs), else None. Each
        optimum is taken once."""
        while name not in self._fits and not self._ended and (wait or self._conn.poll()):
            self._receive()
        return self._fits.pop(name, None)

    def stop(self) -> None:
        """Keep what has come, and end the process."""
        while not self._ended and self._conn.poll():
            self._receive()
        self._ended = True
        if self._process.is_alive():
            self._process.terminate()
        self._process.join()
        self._conn.close()
