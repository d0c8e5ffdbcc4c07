"""python -m camdyn.derive.single OPTIONS_JSON OUT_FILE: write one scene's generated module.

The module is :func:`camdyn.derive.codegen.module_source` of the scene, the same text
``python -m camdyn.derive`` writes for it into ``generated/``.  The runtime calls this in a
separate process to derive a scene on demand (``camdyn.ondemand``), so ``import camdyn``
itself never imports SymPy.  The file appears whole or not at all (written beside, then
renamed), so two processes deriving the same scene do not read half a module.
"""
from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path

from .codegen import module_source
from .vocabulary import SceneOptionError, SceneSpec


def write_scene(spec: SceneSpec, out: Path) -> None:
    """Write ``spec``'s generated module to the file ``out``, atomically."""
    text = module_source(spec)
    out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=out.parent, prefix=out.stem, suffix=".tmp")
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, out)


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 2:
        print(__doc__.splitlines()[0], file=sys.stderr)
        return 2
    try:
        spec = SceneSpec(**json.loads(args[0]))
    except (ValueError, TypeError, SceneOptionError) as exc:
        print(f"not a scene: {exc}", file=sys.stderr)
        return 2
    write_scene(spec, Path(args[1]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
