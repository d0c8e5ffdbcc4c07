"""Names of a package loaded on first use (PEP 562), so that importing the package is cheap."""
from __future__ import annotations

import importlib
import sys


def lazy(package: str, exports: dict[str, str]):
    """A module's ``__getattr__`` and ``__dir__`` for ``exports`` (public name -> the module that
    defines it, absolute or relative to ``package``): a name is imported when first read, then
    kept in the package's namespace."""
    def __getattr__(name: str):
        try:
            module = exports[name]
        except KeyError:
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
        value = getattr(importlib.import_module(module, package), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__():
        return sorted(set(exports) | set(vars(sys.modules[package])))

    return __getattr__, __dir__
