"""``camdyn reproduce``: a study of the paper on the reference rig (camdyn.studies)."""
from __future__ import annotations

import importlib
import sys

from .common import EXIT_OK, MissingPart, UsageError
from .parser import add_command


def _studies_module():
    try:
        return importlib.import_module("camdyn.studies")
    except ImportError as exc:
        if getattr(exc, "name", None) and not str(exc.name).startswith("camdyn.studies"):
            raise
        raise MissingPart("the paper's studies (camdyn.studies) are not part of this version of camdyn") from None


def cmd_reproduce(args) -> int:
    studies = _studies_module()
    names = list(studies.STUDIES)
    if args.list or args.study in (None, "list"):
        for name, (_, text) in studies.STUDIES.items():
            print(f"{name:14s} {text}")
        if args.study is None and not args.list:
            print("run one with: camdyn reproduce <study> [--fast] (or 'all')")
        return EXIT_OK
    if args.study not in names + ["all"]:
        import difflib

        close = difflib.get_close_matches(args.study, names, n=1)
        raise UsageError(f"no study {args.study!r}" + (f" (did you mean {close[0]!r}?)" if close else "")
                         + f"; one of: {', '.join(names)}, all")
    quiet = args.json or args.study == "numbers"
    log = (lambda *a, **k: print(*a, file=sys.stderr, **k)) if quiet else print
    from ..studies.common import to_json

    for name in names if args.study == "all" else [args.study]:
        output = studies.run(name, fast=True if args.fast else None, out=args.out, write_docs=not args.no_docs,
                             data_dir=args.data_dir, log=log)
        if quiet:
            print(to_json(output.numbers))
        else:
            for figure in output.figures:
                print(f"wrote {figure}")
    return EXIT_OK


def add_reproduce(sub) -> None:
    """The reproduce command and its options."""
    p = add_command(sub, "reproduce", "reproduce a study of the paper on the reference rig: its figure and numbers",
                    "examples:\n  camdyn reproduce --list\n  camdyn reproduce fig10 --fast --out /tmp/repro\n"
                    "  camdyn reproduce numbers --json\n\n"
                    "Writes the study's figure (<out>/img/repro_<study>.png) and its section of\n"
                    "<out>/reproduction.md, the paper's statement beside camdyn's result (camdyn.studies;\n"
                    "the same as 'python -m camdyn.studies <study>'). <out> is the checkout's docs/ when camdyn\n"
                    "runs from a source checkout (pip install -e .), else ./camdyn-reproduction in the current\n"
                    "folder; nothing is ever written inside the installed package.",
                    cmd_reproduce)
    p.add_argument("study", nargs="?", help="the study (see --list), or 'all'")
    p.add_argument("--list", action="store_true", help="list the studies")
    p.add_argument("--fast", action="store_true", help="reduced speeds and revolutions (also: CAMDYN_FAST=1)")
    p.add_argument("--out", metavar="DIR", help="folder of reproduction.md and img/ (default: the checkout's "
                                                "docs/, or ./camdyn-reproduction outside a checkout)")
    p.add_argument("--json", action="store_true", help="print the study's numbers as JSON on stdout")
    p.add_argument("--no-docs", action="store_true", dest="no_docs", help="do not update the report")
    p.add_argument("--data-dir", metavar="DIR", dest="data_dir",
                   help="where 'reference-rig' writes the rig presets (default: the checkout's camdyn/model/data, "
                        "or <out>/rigs outside a checkout)")
