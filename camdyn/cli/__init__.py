"""The ``camdyn`` command (commands: the parser and the commands)."""
from __future__ import annotations

from .commands import main

__all__ = ["main"]
