"""Scenes: the physics one study needs, and the generated module that models exactly that.

A :class:`Scene` names the contact law, damping model, friction model, cam motion, model kind
and the misprint and switch options (the vocabulary is ``camdyn.derive.vocabulary``, shared
with the derivation).  The scenes of ``derive/catalog.py`` are generated into
``camdyn.generated``; any other valid scene is derived on first use into the per-user cache
(:mod:`camdyn.ondemand`, needs SymPy).
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass
from types import ModuleType

from camdyn import generated

from .derive.vocabulary import SceneOptionError, SceneSpec
from . import ondemand
from .errors import SceneError


@dataclass(frozen=True)
class Scene(SceneSpec):
    """Physics of one study.

    Its options (the vocabulary is :class:`camdyn.derive.vocabulary.SceneSpec`)::

        contact:  "line" (Eq. 13) or "point" (Eq. 34)
        damping:  "none" or "A".."E" (Eqs. 24-28)
        friction: "none", "coulomb" (model I) or "tanh" (model II)
        motion:   "constant", "oscillating" or "user" (Section 7)
        model:    "nonlinear", "linear_paper" (Eqs. 36-38 as printed) or "linear_exact"
        sliding_velocity: "kinematic" (derived) or "printed" (misprint 8; Figs. 12-15)
        damping_sign:     "dissipative" (derived) or "printed" (misprint 2; B and D only)
        damping_switch:   "episode" (Sec. 3.4: the impact law from contact to maximum compression,
                          then the viscous law until separation) or "memoryless" (D and E only)
        follower: "dynamic" (the hybrid model) or "quasistatic" (the quasi-static contact orbit,
                  :mod:`camdyn.quasistatic`: no integration, for a follower that never leaves the cam)
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
        first use (:mod:`camdyn.ondemand`)."""
        if self.in_catalog:
            return importlib.import_module(f"camdyn.generated.{generated.SCENES[self.derived.slug]}")
        return ondemand.load(self.derived)

    @staticmethod
    def available() -> list[str]:
        return sorted(generated.SCENES)
