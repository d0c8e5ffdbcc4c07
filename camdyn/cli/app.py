"""The ``camdyn`` command: simulate, analyse, sweep, regenerate and reproduce from a shell.

This module assembles the parser from the command modules (run: simulate, spectrum; analyses:
equilibrium, contact-loss, lyapunov, continue; chart; sweep; basins; model: regenerate, scenes, cache;
reproduce), each adding its own subparser, and runs the command: :func:`main`.

Run ``camdyn --help`` for the commands and ``camdyn <command> --help`` for each one's
options and examples.  Everything is SI except where an option's name says otherwise
(``--speed-rpm``, ``--sample-rate-Hz``).

Errors print as one line, ``camdyn: error: ...``, never a traceback (``--traceback``
shows it).  Exit codes, for scripts:

  0  success
  1  a check failed (``regenerate --check``: generated/ differs from what derive/ produces)
  2  bad input: an unknown option or value, an invalid rig or parameter, an unreadable
     or unwritable file, a scene that is not generated, a derive/ edit that makes an
     expression complex (``regenerate``)
  3  a simulation stopped before the end (see its outcome: chatter, angle limit, ...), or
     a sweep has points that did not succeed (not those skipped with --skip-invalid);
     whatever was computed is still written
  4  an optional part is missing: matplotlib for plots (``pip install "camdyn[plot]"``),
     SymPy for regenerate (``camdyn[derive]``), or a module not installed in this version
  5  internal error (a bug in camdyn: please report it with ``--traceback``)
  130 interrupted (Ctrl-C); 141 the output pipe was closed (e.g. ``| head``)
"""
from __future__ import annotations

import argparse
import os
import sys
import warnings

from ..errors import CamdynError
from . import analyses, basins, chart, model, reproduce, run, sweep
from .common import (EXIT_BROKEN_PIPE, EXIT_CODES_HELP, EXIT_INTERNAL, EXIT_INTERRUPTED, EXIT_MISSING, EXIT_USAGE,
                     MissingPart, _flags, _in_flags, _parameter_line, _version)
from .parser import _Formatter, _Parser

#: the commands, in the order ``camdyn --help`` lists them: each adds its subparser
COMMANDS = (run.add_simulate, run.add_spectrum, analyses.add_equilibrium, analyses.add_contact_loss,
            analyses.add_lyapunov, sweep.add_sweep, basins.add_basins, analyses.add_continue, chart.add_chart,
            model.add_regenerate,
            reproduce.add_reproduce, model.add_scenes, model.add_cache)


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="camdyn", formatter_class=_Formatter,
                     description="Contact dynamics of a rotational cam-follower (Sundar, Dreyer & Singh, "
                                 "J. Sound Vib. 2013).\nRun 'camdyn <command> --help' for a command's options.",
                     epilog=EXIT_CODES_HELP + "\n\nexample:\n  camdyn simulate --speed-rpm 1100 --plot run.png")
    parser.add_argument("--version", action="version", version=f"camdyn {_version()}")
    parser.add_argument("--traceback", action="store_true", help="show the Python traceback on errors")
    parser.add_argument("--no-progress", action="store_true", dest="no_progress",
                        help="never show progress bars (they show only on a terminal anyway)")
    sub = parser.add_subparsers(dest="command", metavar="<command>", parser_class=_Parser)
    sub.required = True
    parser.commands = sub.choices
    for add in COMMANDS:
        add(sub)
    for p in sub.choices.values():  # each command's flags by dest, and its own parser (sweep --resume reads it)
        p.set_defaults(flags=_flags(p), command_parser=p)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    show_traceback = "--traceback" in argv
    args = None
    try:
        args = _parser().parse_args(argv)
        args.argv = argv
        with warnings.catch_warnings():
            warnings.showwarning = _show_notice
            code = args.func(args)
        sys.stdout.flush()  # here, so that a closed pipe is handled below, not at exit
        return code
    except KeyboardInterrupt:
        print("camdyn: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # e.g. 'camdyn scenes | head': the reader left; say nothing more
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_BROKEN_PIPE
    except Exception as exc:  # one line, never a traceback (unless asked for)
        if show_traceback:
            import traceback

            traceback.print_exc()
        code, line = _classify(exc, args)
        print(f"camdyn: {line}", file=sys.stderr)
        return code


def _show_notice(message, category, filename, lineno, file=None, line=None):
    """Warnings on the command line as one line, ``camdyn: note: ...`` (not Python's source line):
    the user of the CLI did not write the code the warning points at."""
    print(f"camdyn: note: {message}", file=file or sys.stderr)


def _classify(exc: BaseException, args=None) -> tuple[int, str]:
    """Exit code and the one-line message of an exception (a parameter's name as the command's
    flag when it has one)."""
    from ..errors import ParameterError

    text = " ".join(str(exc).split()) or type(exc).__name__
    if isinstance(exc, ParameterError):
        text = _parameter_line(exc, args) or _in_flags(text, args)
    if isinstance(exc, MissingPart):
        return EXIT_MISSING, f"error: {text}"
    if isinstance(exc, ImportError):
        return EXIT_MISSING, f"error: a module is missing: {text}"
    if isinstance(exc, (CamdynError, ValueError)):
        return EXIT_USAGE, f"error: {text}"
    if isinstance(exc, OSError):
        if exc.filename and exc.strerror:
            return EXIT_USAGE, f"error: {exc.filename}: {exc.strerror}"
        return EXIT_USAGE, f"error: {text}"
    return EXIT_INTERNAL, f"internal error ({type(exc).__name__}: {text}); please report it with --traceback"


if __name__ == "__main__":
    sys.exit(main())
