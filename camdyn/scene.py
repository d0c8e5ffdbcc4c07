"""Scenes: the physics one study needs, and the generated module that models exactly that.

A :class:`Scene` names the contact law, damping model, friction model, cam
motion kind and model kind.  Only scenes generated into ``camdyn.generated``
can run; to add one, add it to ``derive/catalog.py`` and run
``python -m camdyn.derive`` (no edit in ``camdyn/`` is needed).
"""
from __future__ import annotations

import importlib
from dataclasses import asdict, dataclass, fields
from types import ModuleType

from .errors import SceneError
from camdyn import generated


@dataclass(frozen=True)
class Scene:
    """Physics of one study.

    contact:  "line" (Eq. 13) or "point" (Eq. 34)
    damping:  "none" or "A".."E" (Eqs. 24-28)
    friction: "none", "coulomb" (model I) or "tanh" (model II)
    motion:   "constant", "oscillating" or "user" (Section 7)
    model:    "nonlinear", "linear_paper" (Eqs. 36-38 as printed) or "linear_exact"
    sliding_velocity: "kinematic" (derived) or "printed" (misprint 8; Figs. 12-15)
    damping_sign:     "dissipative" (derived) or "printed" (misprint 2; B and D only)
    """

    contact: str = "line"
    damping: str = "D"
    friction: str = "coulomb"
    motion: str = "constant"
    model: str = "nonlinear"
    sliding_velocity: str = "kinematic"
    damping_sign: str = "dissipative"

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            valid = generated.OPTIONS[f.name]
            if value not in valid:
                raise SceneError(f"scene option {f.name}={value!r} is not one of {valid}")
        if self.slug not in generated.SCENES:
            near = [s for s in generated.SCENES if s.startswith(f"{self.contact}_{self.damping.lower()}_")]
            raise SceneError(
                f"scene {self.slug!r} is not generated. To generate it, add SceneSpec({self._options()}) "
                f"to derive/catalog.py and run 'python -m camdyn.derive' (derive refuses combinations "
                f"that make no sense, e.g. a linear model with impact damping)"
                + (f"; generated scenes with this contact and damping: {', '.join(sorted(near))}" if near else ""))

    def _options(self) -> str:
        return ", ".join(f"{k}={v!r}" for k, v in asdict(self).items() if v != generated.DEFAULTS[k])

    @property
    def slug(self) -> str:
        """The generated module's key (same rule as camdyn.derive.scenes.SceneSpec.slug)."""
        parts = [self.contact, self.damping.lower(), self.friction, self.motion, self.model]
        if self.sliding_velocity == "printed":
            parts.append("vrprinted")
        if self.damping_sign == "printed":
            parts.append("printedsign")
        return "_".join(parts)

    def kernels(self) -> ModuleType:
        """The generated module of this scene."""
        return importlib.import_module(f"camdyn.generated.{generated.SCENES[self.slug]}")

    @staticmethod
    def available() -> list[str]:
        return sorted(generated.SCENES)
