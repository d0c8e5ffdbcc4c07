"""What leaves camdyn: files of runs (files), their self-description (metadata), figures (plots)."""
from __future__ import annotations

from .._lazy import lazy

#: public name -> the module (relative to this package) that defines it; loaded on first use
_EXPORTS = {
}

__getattr__, __dir__ = lazy(__name__, _EXPORTS)
__all__ = sorted(_EXPORTS)
