"""Named rigs shipped with camdyn (TOML files in camdyn/data)."""
from __future__ import annotations

from importlib import resources

from . import __version__
from .errors import ParameterError
from .rig import Rig


def available() -> list[str]:
    return sorted(p.name[:-5] for p in resources.files("camdyn.data").iterdir() if p.name.endswith(".toml"))


def load_rig(name: str) -> Rig:
    """A shipped rig by name (see :func:`available`), or a TOML file path."""
    if name in available():
        with resources.as_file(resources.files("camdyn.data") / f"{name}.toml") as path:
            rig = Rig.from_toml(path)
        return rig.replace(origin=f"camdyn preset {name!r} (camdyn {__version__})")
    if str(name).endswith(".toml"):
        return Rig.from_toml(name)
    raise ParameterError("name", name, f"one of {available()} or a path to a .toml rig file")


def example_rig() -> Rig:
    """The illustrative rig of the README (not the paper's identified rig)."""
    return load_rig("example")
