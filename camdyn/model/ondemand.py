"""Scenes that are not in the catalog, derived on first use into the per-user cache.

A :class:`camdyn.Scene` whose options are valid but were not generated into
``camdyn.generated`` (``derive/catalog.py`` lists those) is derived when it is first used:
``python -m camdyn.derive.single`` runs in a separate process (``import camdyn`` never
imports SymPy) and writes the module that ``python -m camdyn.derive`` would write for that
scene, byte for byte, to ``<user cache>/scenes/<key>/scene_<slug>.py``, with its companion
``variational_<slug>.py`` beside it (the variational kernels, if it has any: imported only
for the tangent dynamics).

``<user cache>`` is the folder of compiled code (``camdyn.engine.cache``: ``$CAMDYN_CACHE_DIR``
or the platform's); ``<key>`` hashes the installed ``camdyn.derive`` sources and the SymPy
version, so an edited derivation or another SymPy derives anew.  Later runs, in any process,
load the cached file.  It needs SymPy (``pip install "camdyn[derive]"``); without it, a scene
that is neither generated nor cached is a :class:`~camdyn.errors.SceneError` that says so.
``camdyn cache`` lists these scenes and clears them.
"""
from __future__ import annotations

import importlib.metadata
import importlib.util
import json
import subprocess
import sys
import time
import warnings
from functools import lru_cache
from pathlib import Path
from types import ModuleType

from ..vocabulary import SceneSpec
from ..engine import remove_folders, source_hash, user_cache_root
from ..errors import CompileNotice, SceneError

SCENES_FOLDER = "scenes"
#: how long one scene's derivation may take before it is stopped (s; docs/design-notes.md,
#: *Deriving a scene on first use*)
DERIVE_TIMEOUT = 600.0


def sympy_version() -> str | None:
    """The installed SymPy's version, or None: found without importing SymPy."""
    if importlib.util.find_spec("sympy") is None:
        return None
    try:
        return importlib.metadata.version("sympy")
    except importlib.metadata.PackageNotFoundError:  # pragma: no cover - sympy without metadata
        return "unknown"


@lru_cache(maxsize=None)
def derive_key() -> str:
    """A hash of the installed derivation's sources and the SymPy version."""
    derive = Path(importlib.util.find_spec("camdyn.derive").submodule_search_locations[0])
    return source_hash(derive, salt=str(sympy_version()))


def scenes_root() -> Path:
    """The folder of every derived-on-demand scene of this user (all keys)."""
    return user_cache_root() / SCENES_FOLDER


def module_path(spec: SceneSpec) -> Path:
    """Where the scene's module is (or will be) for the current derivation."""
    return scenes_root() / derive_key() / f"scene_{spec.slug}.py"


def check_derivable(spec: SceneSpec) -> None:
    """Raise :class:`SceneError` if the scene is not cached and cannot be derived here."""
    if module_path(spec).is_file() or sympy_version() is not None:
        return
    raise SceneError(
        f"scene {spec.slug!r} is not among the generated scenes, and deriving it on first use needs SymPy: "
        f'pip install "camdyn[derive]" (or add SceneSpec({spec.options_text()}) to derive/catalog.py and '
        "run 'python -m camdyn.derive' in a checkout)")


def load(spec: SceneSpec) -> ModuleType:
    """The scene's generated module from the cache, derived first if it is not there."""
    path = module_path(spec)
    if not path.is_file():
        check_derivable(spec)
        _derive(spec, path)
    return import_file(f"camdyn_scene_{derive_key()}_{spec.slug}", path)


def import_file(name: str, path: Path) -> ModuleType:
    """The module of the file ``path``, imported under ``name`` once per process."""
    if name in sys.modules:
        return sys.modules[name]
    module_spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(module_spec)
    sys.modules[name] = module
    module_spec.loader.exec_module(module)
    return module


def _derive(spec: SceneSpec, path: Path) -> None:
    warnings.warn(f"camdyn derives the scene {spec.slug!r} on first use (SymPy, typically 10-40 s, once; later "
                  f"runs load it from {path.parent}). Silence this with "
                  "warnings.filterwarnings('ignore', category=camdyn.CompileNotice).", CompileNotice, stacklevel=4)
    start = time.perf_counter()
    command = [sys.executable, "-m", "camdyn.derive.single", json.dumps(spec.as_dict()), str(path)]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=DERIVE_TIMEOUT)
    except subprocess.TimeoutExpired:
        raise SceneError(f"deriving scene {spec.slug!r} took more than {DERIVE_TIMEOUT:g} s and was stopped") from None
    if done.returncode != 0 or not path.is_file():
        last = (done.stderr.strip().splitlines() or ["no message"])[-1]
        raise SceneError(f"deriving scene {spec.slug!r} failed after {time.perf_counter() - start:.0f} s: {last}")


def entries() -> list[tuple[Path, list[str], bool]]:
    """(folder, scene slugs, current) for each key folder of derived scenes."""
    root = scenes_root()
    if not root.is_dir():
        return []
    return [(d, sorted(p.stem.removeprefix("scene_") for p in d.glob("scene_*.py")), d.name == derive_key())
            for d in sorted(p for p in root.iterdir() if p.is_dir())]


def clear(stale_only: bool = False) -> list[Path]:
    """Delete the folders of derived scenes (only those of other derivations with ``stale_only``)."""
    return remove_folders(entries(), stale_only)
