"""Keep numba's disk cache of the compiled loop in step with its sources.

numba keys a cached function on its own source file only: when ``engine.run`` is cached
and ``events.py`` (which it calls, and partly inlines) changes, numba still loads the old
machine code -- silently stale results after an edit or a partial checkout.  Before the
loop is loaded, :func:`refresh` hashes the sources of every module of this package; when
the hash differs from the one stored beside the cache, it deletes this package's cache
files (they are rebuilt on the next call: one cold start) and stores the new hash.

The generated scenes' kernels need no such care: each is one self-contained function in
its own file, which numba's own check covers.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
STAMP = "camdyn-compiled-sources.sha256"


def sources_hash(package: Path = PACKAGE) -> str:
    h = hashlib.sha256()
    for path in sorted(package.glob("*.py")):
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def refresh(cache_dir: Path | None, package: Path = PACKAGE) -> bool:
    """Delete the package's numba cache files in ``cache_dir`` if its sources changed since
    they were written.  Returns whether it deleted them.  A read-only or missing cache
    directory is left alone (numba then does not write there either)."""
    if cache_dir is None:
        return False
    cache_dir = Path(cache_dir)
    stamp = cache_dir / STAMP
    current = sources_hash(package)
    try:
        if stamp.read_text() == current:
            return False
    except OSError:
        pass
    try:
        cache_dir.mkdir(parents=True, exist_ok=True)
        stale = [p for p in cache_dir.iterdir() if p.suffix in (".nbi", ".nbc")]
        for p in stale:
            p.unlink(missing_ok=True)
        stamp.write_text(current)
    except OSError:
        return False
    return bool(stale)


def cache_dir_of(dispatcher) -> Path | None:
    """Where numba caches a dispatcher compiled with cache=True (numba's locator: the
    package's __pycache__ when writable, else NUMBA_CACHE_DIR or the user-wide cache)."""
    cache = getattr(dispatcher, "_cache", None)
    path = getattr(cache, "_cache_path", None)
    return Path(path) if path else None
