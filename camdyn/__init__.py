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

from ._lazy import lazy

from ._version import __version__

_EXPORTS = {
    "Rig": "camdyn.model.rig",
    "load_rig": "camdyn.model.presets",
    "example_rig": "camdyn.model.presets",
    "Scene": "camdyn.model.scene",
    "ConstantSpeed": "camdyn.model.cam",
    "Oscillating": "camdyn.model.cam",
    "UserMotion": "camdyn.model.cam",
    "Model": "camdyn.model.model",
    "simulate": "camdyn.runs.simulation",
    "Result": "camdyn.runs.result",
    "Outcome": "camdyn.outcome",
    "static_equilibrium": "camdyn.analysis.statics",
    "natural_frequency": "camdyn.analysis.statics",
    "contact_loss_speed": "camdyn.analysis.statics",
    "rigid_contact_angle": "camdyn.analysis.statics",
    "energy_balance_peak": "camdyn.analysis.statics",
    "ParameterError": "camdyn.errors",
    "GeometryError": "camdyn.errors",
    "EquilibriumError": "camdyn.errors",
    "SceneError": "camdyn.errors",
    "CompileNotice": "camdyn.errors",
    "periodic_orbit": "camdyn.orbits.shooting",
    "PeriodicOrbit": "camdyn.orbits.shooting",
    "OrbitOutcome": "camdyn.orbits.shooting",
    "StroboscopicMap": "camdyn.orbits.section_map",
    "lyapunov_exponents": "camdyn.orbits.lyapunov",
    "LyapunovExponents": "camdyn.orbits.lyapunov",
    "LyapunovSettings": "camdyn.orbits.lyapunov",
    "continue_orbit": "camdyn.orbits.continuation",
    "ContinuationSettings": "camdyn.orbits.continuation",
    "ContinuationOutcome": "camdyn.orbits.continuation",
    "zero_one_test": "camdyn.analysis.chaos01",
    "StopWhenPeriodic": "camdyn.runs.stopping",
    "basins": "camdyn.sweep.attractors",
    "Span": "camdyn.runs.request",
    "SolverOptions": "camdyn.engine",
    "quasi_static_orbit": "camdyn.runs.quasistatic",
    "QuasiStaticOrbit": "camdyn.runs.quasistatic",
    "QuasiStaticOutcome": "camdyn.runs.quasistatic",
}

__getattr__, __dir__ = lazy(__name__, _EXPORTS)
__all__ = sorted(_EXPORTS) + ["__version__"]
