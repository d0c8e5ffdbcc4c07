"""The ``camdyn`` command (app: the parser and main; one module per family of commands)."""
from __future__ import annotations

from .app import main

__all__ = ["main"]
