"""The model of one rig: its parameters (rig), cam motions (cam), scenes (scene), a scene's
generated kernels bound to a rig and a cam (model), the shipped rigs (presets, data/) and the
scenes derived on first use (ondemand)."""
from __future__ import annotations

from .._lazy import lazy

#: public name -> the module (relative to this package) that defines it; loaded on first use
_EXPORTS = {
    'ConstantSpeed': '.cam',
    'Equilibrium': '.model',
    'Model': '.model',
    'NEUTRAL': '.rig',
    'Oscillating': '.cam',
    'PARAMETERS': '.rig',
    'Parameter': '.rig',
    'Rate': '.model',
    'Rig': '.rig',
    'Rule': '.rig',
    'Scene': '.scene',
    'UserMotion': '.cam',
    'add_neutral_values': '.presets',
    'at_rest': '.model',
    'available': '.presets',
    'cam_motion': '.cam',
    'example_rig': '.presets',
    'lacking_neutral_values': '.presets',
    'load_rig': '.presets',
    'periodic_cam': '.cam',
    'preset_files': '.presets',
    'solve_equilibrium': '.model',
    'static_parameters': '.model',
    'variational_kernels': '.scene',
}

__getattr__, __dir__ = lazy(__name__, _EXPORTS)
__all__ = sorted(_EXPORTS)
