"""``python -m camdyn.studies <name> [--fast] [--out DIR]``: run one of the paper's studies."""
from __future__ import annotations

import argparse
import sys

from . import STUDIES, run
from .common import to_json


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m camdyn.studies",
                                     description="Reproduce one study of Sundar, Dreyer & Singh (2013).")
    parser.add_argument("name", help="a study name, 'all', or 'list'")
    parser.add_argument("--fast", action="store_true", default=None,
                        help="reduced speeds and revolutions (also: CAMDYN_FAST=1)")
    parser.add_argument("--out", default=None, help="folder of reproduction.md and img/ (default: the checkout's "
                                                    "docs/ in a source checkout, else ./camdyn-reproduction)")
    parser.add_argument("--data-dir", default=None, help="where reference-rig writes the presets (default: the "
                                                         "checkout's camdyn/model/data, else <out>/rigs)")
    parser.add_argument("--reuse", action="store_true",
                        help="reuse the results of expensive stages recorded in the report with the same "
                             "settings (chaos-scan: stage 1)")
    parser.add_argument("--no-docs", action="store_true", help="do not update the report")
    parser.add_argument("--json", action="store_true", help="print the study's numbers as JSON on stdout "
                                                            "(always on for 'numbers')")
    args = parser.parse_args(argv)
    if args.name == "list":
        for name, (_, text) in STUDIES.items():
            print(f"{name:14s} {text}")
        return 0
    names = list(STUDIES) if args.name == "all" else [args.name]
    if args.name not in STUDIES and args.name != "all":
        parser.error(f"no study {args.name!r}; choose from: {', '.join(STUDIES)}, all, list")
    quiet = args.json or args.name == "numbers"
    log = (lambda *a, **k: print(*a, file=sys.stderr, **k)) if quiet else print
    for name in names:
        output = run(name, fast=args.fast, out=args.out, write_docs=not args.no_docs,
                     data_dir=args.data_dir, log=log, reuse=args.reuse)
        if quiet:
            print(to_json(output.numbers))
        else:
            for f in output.figures:
                print(f"wrote {f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
