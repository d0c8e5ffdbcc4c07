"""camdyn: contact dynamics of a rotational cam-follower.

Implements the model of Sundar, Dreyer & Singh, "Rotational sliding contact
dynamics in a non-linear cam-follower system as excited by a periodic motion",
J. Sound Vib. 332 (2013) 4280-4295, as a symbolic-to-numeric model generator:

* ``camdyn.derive`` (needs SymPy) derives the model from the Fig. 1 geometry
  and writes plain-arithmetic code into ``camdyn.generated``;
* this runtime package imports only the generated code, NumPy and SciPy.

The public names below are loaded lazily (PEP 562), so ``import camdyn`` is
cheap and ``import camdyn.derive`` does not pull in the runtime.
"""
from __future__ import annotations

import importlib

__version__ = "0.1.0"

_EXPORTS = {
    "Rig": "camdyn.rig",
    "load_rig": "camdyn.presets",
    "example_rig": "camdyn.presets",
    "Scene": "camdyn.scene",
    "ConstantSpeed": "camdyn.cam",
    "Oscillating": "camdyn.cam",
    "UserMotion": "camdyn.cam",
    "Model": "camdyn.model",
    "simulate": "camdyn.simulation",
    "Result": "camdyn.result",
    "Outcome": "camdyn.outcome",
    "static_equilibrium": "camdyn.analysis",
    "natural_frequency": "camdyn.analysis",
    "contact_loss_speed": "camdyn.analysis",
    "rigid_contact_angle": "camdyn.analysis",
    "energy_balance_peak": "camdyn.analysis",
    "ParameterError": "camdyn.errors",
    "GeometryError": "camdyn.errors",
    "EquilibriumError": "camdyn.errors",
    "SceneError": "camdyn.errors",
    "CompileNotice": "camdyn.errors",
    "periodic_orbit": "camdyn.orbits",
    "PeriodicOrbit": "camdyn.orbits",
    "OrbitOutcome": "camdyn.orbits",
    "StroboscopicMap": "camdyn.section_map",
    "lyapunov_exponents": "camdyn.lyapunov",
    "LyapunovExponents": "camdyn.lyapunov",
    "LyapunovSettings": "camdyn.lyapunov",
    "continue_orbit": "camdyn.continuation",
    "ContinuationSettings": "camdyn.continuation",
    "ContinuationOutcome": "camdyn.continuation",
    "zero_one_test": "camdyn.chaos01",
    "StopWhenPeriodic": "camdyn.stopping",
    "quasi_static_orbit": "camdyn.quasistatic",
    "QuasiStaticOrbit": "camdyn.quasistatic",
    "QuasiStaticOutcome": "camdyn.quasistatic",
}

__all__ = sorted(_EXPORTS) + ["__version__"]


def __getattr__(name: str):
    try:
        module = _EXPORTS[name]
    except KeyError:
        raise AttributeError(f"module 'camdyn' has no attribute {name!r}") from None
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__():
    return __all__
