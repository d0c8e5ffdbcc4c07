"""Where camdyn's compiled code is kept: a per-user cache, never the installed package.

numba caches compiled functions on disk (``cache=True``).  By default it writes next to the
source file when that folder is writable, i.e. inside an installed camdyn; a later ``pip
install -e`` then leaves a folder of cache files in site-packages that shadows the editable
install.  :func:`install` registers a cache locator for camdyn's own files (the package, its
generated scenes, scenes generated on demand) that puts their compiled code under

    <user cache>/camdyn/<version>-<hash of the engine's sources>/numba/

where ``<user cache>`` is ``$CAMDYN_CACHE_DIR``, else the platform's per-user cache folder
(``$XDG_CACHE_HOME`` or ``~/.cache`` on Linux, ``~/Library/Caches`` on macOS,
``%LOCALAPPDATA%`` on Windows).  The key changes whenever any module of the engine changes,
so a cached loop is never older than the rules it was compiled from (numba itself checks
only the file that defines a function, not the ones it calls).  ``camdyn cache`` lists and
clears it.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import sys
import tempfile
import warnings
from functools import lru_cache
from pathlib import Path

CACHE_ENV = "CAMDYN_CACHE_DIR"
PACKAGE = Path(__file__).resolve().parent.parent          # camdyn/
ENGINE = Path(__file__).resolve().parent                   # camdyn/engine/
#: folders of the user cache root that are not compiled code (camdyn.model.ondemand's scenes)
OTHER_FOLDERS = ("scenes",)


def user_cache_root() -> Path:
    """The folder of camdyn's caches for this user ($CAMDYN_CACHE_DIR or the platform's)."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV]).expanduser()
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA", Path.home() / "AppData" / "Local"))
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches"
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "camdyn"


def source_hash(folder: Path, salt: str = "") -> str:
    """12 hex digits of a hash of ``salt`` and the names and bytes of ``folder``'s modules."""
    h = hashlib.sha256(salt.encode())
    for path in sorted(folder.glob("*.py")):
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:12]


@lru_cache(maxsize=None)
def engine_key() -> str:
    """camdyn's version and a hash of the engine's sources: the name of the current cache."""
    from .._version import __version__
    return f"{__version__}-{source_hash(ENGINE)}"


def cache_dir() -> Path:
    """The current cache folder (compiled code of this camdyn and this engine)."""
    return user_cache_root() / engine_key()


def cache_entries() -> list[tuple[Path, int, bool]]:
    """(folder, bytes, current) for each cache folder under the user cache root."""
    root = user_cache_root()
    if not root.is_dir():
        return []
    out = []
    for d in sorted(p for p in root.iterdir() if p.is_dir() and p.name not in OTHER_FOLDERS):
        size = sum(f.stat().st_size for f in d.rglob("*") if f.is_file())
        out.append((d, size, d.name == engine_key()))
    return out


def clear_cache(stale_only: bool = False) -> list[Path]:
    """Delete the cache folders (only those of other versions or engines with ``stale_only``)."""
    return remove_folders(cache_entries(), stale_only)


def remove_folders(listed, stale_only: bool) -> list[Path]:
    """Delete the folders of ``listed`` ((folder, ..., current) rows), all or only the stale ones."""
    removed = []
    for d, *_, current in listed:
        if stale_only and current:
            continue
        shutil.rmtree(d, ignore_errors=True)
        removed.append(d)
    return removed


def _ours(py_file: str) -> bool:
    """A source file of camdyn (package, generated scenes) or generated into its cache."""
    path = Path(py_file).resolve()
    roots = [PACKAGE, user_cache_root().resolve()]
    try:
        from .. import generated
        roots.append(Path(generated.__file__).resolve().parent)
    except ImportError:  # pragma: no cover - a broken installation
        pass
    return any(path.is_relative_to(root) for root in roots)


def _locator_class():
    """numba's cache locator API (0.60-0.68 names), or None if it moved."""
    try:
        from numba.core import caching
    except ImportError:  # pragma: no cover
        return None, None
    base = getattr(caching, "_CacheLocator", None)
    mixin = getattr(caching, "_SourceFileBackedLocatorMixin", None)
    impl = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl", None)
    if base is None or mixin is None or impl is None:
        return None, None

    class CamdynCacheLocator(mixin, base):
        """numba cache locator: camdyn's files -> the per-user cache (see the module docstring)."""

        def __init__(self, py_func, py_file, root=None):
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            self._cache_path = str((root or cache_dir()) / "numba" / self.get_suitable_cache_subpath(py_file))

        def get_cache_path(self):
            return self._cache_path

        @classmethod
        def from_function(cls, py_func, py_file):
            if not os.path.exists(py_file) or not _ours(py_file):
                return None
            for root in (None, Path(tempfile.gettempdir()) / f"camdyn-cache-{os.getuid() if hasattr(os, 'getuid') else 'user'}" / engine_key()):
                locator = cls(py_func, py_file, root)
                try:
                    locator.ensure_cache_path()
                    return locator
                except OSError:  # an unwritable cache folder: the next candidate
                    continue
            return None

    return CamdynCacheLocator, impl


def install() -> bool:
    """Route numba's cache of camdyn's files to the per-user cache; True if it is in place."""
    locator, impl = _locator_class()
    if locator is None:
        warnings.warn("camdyn could not direct numba's cache (its internal API changed): compiled code may be "
                      "cached next to camdyn's files", RuntimeWarning, stacklevel=2)
        return False
    classes = impl._locator_classes
    if not any(getattr(c, "__name__", "") == locator.__name__ for c in classes):
        classes.insert(0, locator)
    return True
