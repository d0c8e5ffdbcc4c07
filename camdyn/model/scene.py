"""Scenes: the physics one study needs, and the generated module that models exactly that.

A :class:`Scene` names the contact law, damping model, friction model, cam motion, model kind
and the misprint and switch options (the vocabulary is ``camdyn.vocabulary``, shared
with the derivation).  The scenes of ``derive/catalog.py`` are generated into
``camdyn.generated``; any other valid scene is derived on first use into the per-user cache
(:mod:`camdyn.model.ondemand`, needs SymPy).  A scene's variational kernels are in a companion module
beside its own, which :func:`variational_kernels` imports only when they are asked for.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

from camdyn import generated

from ..vocabulary import SceneOptionError, SceneSpec
from . import ondemand
from ..errors import SceneError


@dataclass(frozen=True)
class Scene(SceneSpec):
    """Physics of one study: the options of :class:`camdyn.vocabulary.SceneSpec` (contact, damping,
    friction, motion, model, the misprint and switch options, follower, profile; see its
    docstring), validated, with the generated module they select (:meth:`kernels`).
    """

    def __post_init__(self):
        try:
            super().__post_init__()
        except SceneOptionError as exc:
            raise SceneError(str(exc)) from None
        if self.derived.slug not in generated.SCENES:
            ondemand.check_derivable(self.derived)

    @property
    def in_catalog(self) -> bool:
        """Whether the scene is in the catalog (``camdyn.generated``) rather than derived on demand."""
        return self.derived.slug in generated.SCENES

    def kernels(self) -> ModuleType:
        """The generated module of this scene (of its ``derived`` spec: ``follower`` has no kernels
        of its own): from ``camdyn.generated``, else from the per-user cache, derived there on
        first use (:mod:`camdyn.model.ondemand`)."""
        if self.in_catalog:
            return importlib.import_module(f"camdyn.generated.{generated.SCENES[self.derived.slug]}")
        return ondemand.load(self.derived)

    @staticmethod
    def available() -> list[str]:
        return sorted(generated.SCENES)


#: what a companion module shares with its scene's module: the scene, the layout of the
#: parameter vector p its kernels read and the indices of the modes and surfaces they take
_SHARED = ("SLUG", "PARAMS", "MODES", "SURFACES")


def variational_kernels(kernels: ModuleType) -> ModuleType | None:
    """The variational kernels of a scene's generated module ``kernels`` (``surface_gradient``,
    ``field_sensitivity``), from its companion module, which this imports on first use (a run
    never does); None for a scene without them (``VARIATIONAL`` None: the linear models).

    The companion is beside the scene's module: in its package (``camdyn.generated``, or a
    generated folder imported as a package), or in its folder for a module imported from a
    file (the scenes derived on demand, :mod:`camdyn.model.ondemand`)."""
    name = kernels.VARIATIONAL
    if name is None:
        return None
    path = Path(kernels.__file__).with_name(name + ".py")
    if not path.is_file():
        raise SceneError(f"the variational kernels of scene {kernels.SLUG!r} are missing: no {path}. Regenerate "
                         "them with 'python -m camdyn.derive' (a scene derived on demand: 'camdyn cache --clear')")
    if kernels.__package__:
        module = importlib.import_module(f"{kernels.__package__}.{name}")
    else:
        module = ondemand.import_file(f"{kernels.__name__}__{name}", path)
    differ = [k for k in _SHARED if getattr(module, k, None) != getattr(kernels, k)]
    if differ:
        raise SceneError(f"{path} does not belong to the scene module {kernels.__file__} (they differ in "
                         f"{', '.join(differ)}): regenerate both with 'python -m camdyn.derive'")
    return module
