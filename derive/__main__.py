"""python -m camdyn.derive [--check] [--out DIR] [--jobs N]: regenerate camdyn.generated."""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from .codegen import ComplexExpressionError
from .writer import DEFAULT_OUT, check, render, write


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m camdyn.derive", description=__doc__)
    parser.add_argument("--check", action="store_true",
                        help="exit 1 if the generated files differ from what derive produces now")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help="generated package folder")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="processes to use")
    args = parser.parse_args(argv)
    try:
        files = render(jobs=max(1, args.jobs))
    except ComplexExpressionError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.check:
        problems = check(files, args.out)
        for p in problems:
            print(p, file=sys.stderr)
        print(f"{len(files)} files checked: " + ("in sync" if not problems else f"{len(problems)} differ"))
        return 1 if problems else 0
    changed = write(files, args.out)
    print(f"{len(files)} files generated in {args.out}; changed: {', '.join(changed) or 'none'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
