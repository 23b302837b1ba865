"""The command-line parser for sphinx-argparse, with its help texts made safe for
reStructuredText.

``bayesfo --help`` is plain text: ``directory of *.csv`` or ``omega|freq`` would start emphasis
or a substitution reference in reStructuredText. The user guide renders the parser of
:func:`bayesfo.cli.build_parser` itself, with those characters escaped.
"""

from __future__ import annotations

import argparse
import re

from bayesfo.cli import build_parser as _build_parser

_SPECIAL = re.compile(r"([*|`\\])")


def _escape(text):
    return _SPECIAL.sub(r"\\\1", text) if isinstance(text, str) else text


def _escape_parser(parser: argparse.ArgumentParser) -> None:
    parser.description = _escape(parser.description)
    parser.epilog = _escape(parser.epilog)
    for action in parser._actions:
        if action.help not in (None, argparse.SUPPRESS):
            action.help = _escape(action.help)
        if isinstance(action, argparse._SubParsersAction):
            for choice in action._choices_actions:
                choice.help = _escape(choice.help)
            for sub in set(action.choices.values()):
                _escape_parser(sub)


def build_parser() -> argparse.ArgumentParser:
    """:func:`bayesfo.cli.build_parser` with reStructuredText special characters escaped."""
    parser = _build_parser()
    _escape_parser(parser)
    return parser
