"""Exceptions and warnings raised by bayesfo: all of them, in this one module.

Every exception subclasses a built-in one, so ``except ValueError`` keeps working for callers
that do not know about bayesfo. The command line maps :class:`InputError` to exit status 2 with a
single message line, and any other exception to exit status 1.
"""

from __future__ import annotations


class BayesfoError(Exception):
    """Base class of all bayesfo exceptions."""


class InputError(BayesfoError, ValueError):
    """Bad input from the user: a file, a column, a row or an argument that cannot be used.

    The message names what is wrong and where (file, column, row or argument name).

    Attributes
    ----------
    command_line : str or None
        The same message in the words of the command line (``--block 2`` where the message says
        ``block=2``), where the two differ and :attr:`option` cannot say how; the command line
        prints it instead of the message.
    option : str or None
        The argument of the API the message is about (``"workers"``, ``"window"``), where it
        names one as ``argument 'window'`` or at its start (``workers must be ...``); the
        command line says its flag instead (``--workers``, ``--window``: :meth:`in_command_line`).
    where : str or None
        The API function that raised it (``"predict"``), which the message starts with
        (``predict: ...``); the command line, which names the command already, leaves it out.
    """

    def __init__(self, *args, command_line: str | None = None, option: str | None = None,
                 where: str | None = None):
        super().__init__(*args)
        self.command_line = command_line
        self.option = option
        self.where = where

    def in_command_line(self, flags: dict | None = None) -> str:
        """The message in the words of the command line: :attr:`command_line` where given,
        else the message without its function's name (:attr:`where`) and with the option
        (:attr:`option`) as its flag: ``flags[option]`` where given, else the option's name
        (``argument 'per_decade'`` → ``--per-decade``)."""
        # getattr: a subclass may set its attributes without this class's __init__.
        if getattr(self, "command_line", None):
            return self.command_line
        text, where, option = str(self), getattr(self, "where", None), getattr(self, "option", None)
        if where and text.startswith(f"{where}: "):
            text = text[len(where) + 2:]
        if option:
            flag = (flags or {}).get(option) or "--" + option.replace("_", "-")
            if f"argument '{option}'" in text:
                return text.replace(f"argument '{option}'", flag, 1)
            if text.startswith(f"{option} "):
                return flag + text[len(option):]
        return text


class StructureError(InputError):
    """A structure card or structure name that cannot be used."""


class OutputError(BayesfoError, OSError):
    """The outputs cannot be written (no space left, no permission); the earlier outputs in the
    output directory are kept. The command line maps it to exit status 1 with one line."""


class NonlinearityWarning(UserWarning):
    """A sine record whose harmonics show that the system is not linear at that amplitude."""


class DataWarning(UserWarning):
    """The data hold points that no structure of the kind can fit (e.g. negative loss)."""


class ConvergenceWarning(UserWarning):
    """The sampler stopped before its diagnostics reached the targets."""


class CertifiedWarning(UserWarning):
    """A posterior is reported from another sampler than emcee (the tempered ladder's
    particles), certified by the agreement of independent runs."""


class PredictiveWarning(UserWarning):
    """PSIS-LOO is unreliable for some frequency (Pareto k above 0.7)."""


class EvidenceWarning(UserWarning):
    """The two evidence estimates disagree, or the evidence could not be computed."""



class NoiseWarning(UserWarning):
    """A structure's exponents (q, α, β) have non-overlapping 94 % HDIs under the two noise
    models between which the evidence chose: the conclusion depends on the noise model."""
