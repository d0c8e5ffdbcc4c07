"""argparse as the command uses it: one-line errors with suggestions, values that start with a
minus sign, help with the engine's default backend filled in, and a command's subparser."""
from __future__ import annotations

import argparse
import re
import sys

from .common import EXIT_CODES_HELP, UsageError
from .options import _default_backend


class _Parser(argparse.ArgumentParser):
    """argparse that raises UsageError (one line, exit 2) instead of printing usage and exiting;
    misspelled options and values get a suggestion, and the help pointed at is the command's."""

    commands: dict | None = None  # command name -> its parser (set on the top-level parser)

    def error(self, message):
        raise UsageError(f"{message}{_suggest_choice(message)} (see '{self.prog} --help')")

    def parse_args(self, args=None, namespace=None):
        args = _values_with_a_minus(list(sys.argv[1:] if args is None else args), self)
        namespace, extras = self.parse_known_args(args, namespace)
        if extras:
            parser = (self.commands or {}).get(getattr(namespace, "command", None), self)
            raise UsageError(f"{_unrecognized(extras, parser)} (see '{parser.prog} --help')")
        return namespace


def _option_strings(parser, single_value: bool = False) -> list[str]:
    """The option strings of a parser (with single_value: only those taking exactly one value)."""
    return [o for a in parser._actions for o in a.option_strings if not single_value or a.nargs is None]


def _unrecognized(extras: list[str], parser) -> str:
    """'unrecognized option --x (did you mean --y?)' for the first stray word of the command line."""
    import difflib

    word = extras[0]
    if not word.startswith("-"):
        return f"unexpected argument {word!r}"
    name = word.split("=", 1)[0]
    close = difflib.get_close_matches(name, _option_strings(parser), n=1, cutoff=0.6)
    return f"unrecognized option {name}" + (f" (did you mean {close[0]}?)" if close else "")


def _suggest_choice(message: str) -> str:
    """' (did you mean 'D'?)' for argparse's "invalid choice: 'd' (choose from ...)"."""
    import difflib
    import re

    m = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)", message)
    if not m:
        return ""
    choices = re.findall(r"'([^']*)'", m.group(2))
    close = [c for c in choices if c.lower() == m.group(1).lower()] or difflib.get_close_matches(m.group(1), choices, n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


_MINUS_VALUE = re.compile(r"^-(\d|\.\d|inf|nan)", re.IGNORECASE)


def _values_with_a_minus(argv: list[str], parser) -> list[str]:
    """``--k-s -500:8000:5`` as ``--k-s=-500:8000:5``: argparse takes a word starting with '-'
    for an option unless it is a plain number; here a value that starts with a minus sign and a
    digit (a range, -inf) follows an option that takes one value, so it is that value."""
    options = set(_option_strings(parser, single_value=True))
    for sub in (parser.commands or {}).values():
        options.update(_option_strings(sub, single_value=True))
    out: list[str] = []
    i = 0
    while i < len(argv):
        word = argv[i]
        if word in options and i + 1 < len(argv) and _MINUS_VALUE.match(argv[i + 1]):
            out.append(f"{word}={argv[i + 1]}")
            i += 2
            continue
        out.append(word)
        i += 1
    return out


class _Formatter(argparse.RawDescriptionHelpFormatter):
    """Help text with the engine's default backend filled in only when help is shown
    (``{default_backend}``)."""

    def _get_help_string(self, action):
        text = super()._get_help_string(action)
        if "{default_backend}" in text:
            text = text.replace("{default_backend}", str(_default_backend()))
        return text


def add_command(sub, name: str, help_: str, epilog: str, func, **kw) -> argparse.ArgumentParser:
    """The subparser of command ``name`` (its description from ``help_``, the exit codes after
    ``epilog``), which runs ``func(args)``."""
    p = sub.add_parser(name, help=help_, description=help_[0].upper() + help_[1:] + ".",
                       epilog=epilog + "\n\n" + EXIT_CODES_HELP, formatter_class=_Formatter, **kw)
    p.set_defaults(func=func)
    return p
