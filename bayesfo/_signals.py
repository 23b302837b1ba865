"""Ctrl-C and SIGTERM held back while a block runs that must not be cut in two: a rename of
the outputs, or the import of the compiled libraries (an import interrupted inside an
extension module's initialisation leaves the module half-made: ``ImportError: initialization
failed``, or a crash at the interpreter's exit)."""

from __future__ import annotations

import contextlib
import signal


@contextlib.contextmanager
def held():
    """Ctrl-C and SIGTERM wait until the block is done (where the platform allows it); one
    that arrived meanwhile is acted on as the block ends."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def cause(exc: BaseException, kinds: tuple[type, ...]) -> BaseException | None:
    """The first exception of one of ``kinds`` among ``exc`` and the exceptions it was raised
    from or while handling (``__cause__``, ``__context__``), or None."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, kinds):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None
