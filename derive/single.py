"""python -m camdyn.derive.single OPTIONS_JSON OUT_FILE: write one scene's generated modules.

The modules are :func:`camdyn.derive.codegen.sources` of the scene, the same text
``python -m camdyn.derive`` writes for it into ``generated/``: the scene's module to OUT_FILE
and, where the scene has variational kernels, their companion module beside it.  The runtime
calls this in a separate process to derive a scene on demand (``camdyn.model.ondemand``), so
``import camdyn`` itself never imports SymPy.  Each file appears whole or not at all (written
beside, then renamed), so two processes deriving the same scene do not read half a module;
the companion is written first, so a scene module on disk always has its companion.
"""
from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path

from .codegen import ComplexExpressionError, module_name, sources
from camdyn.vocabulary import SceneOptionError, SceneSpec


def _write(text: str, out: Path) -> None:
    fd, tmp = tempfile.mkstemp(dir=out.parent, prefix=out.stem, suffix=".tmp")
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, out)


def write_scene(spec: SceneSpec, out: Path) -> None:
    """Write ``spec``'s generated module to the file ``out`` and its companion module (if any)
    beside it, each atomically, the companion first."""
    files = sources(spec)
    scene = files.pop(module_name(spec) + ".py")
    out.parent.mkdir(parents=True, exist_ok=True)
    for name, text in files.items():
        _write(text, out.parent / name)
    _write(scene, out)


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
    try:
        write_scene(spec, Path(args[1]))
    except ComplexExpressionError as exc:
        print(f"not derived: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
