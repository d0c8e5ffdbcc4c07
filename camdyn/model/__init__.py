"""The model of one rig: its parameters (rig), cam motions (cam), scenes (scene), a scene's
generated kernels bound to a rig and a cam (model), the shipped rigs (presets, data/) and the
scenes derived on first use (ondemand); cam profiles as support functions (profiles), follower
motion laws (motion_laws), flat-faced followers in rigid contact (followers), cams from laws
(synthesis) and from tables (cam_tables)."""
from __future__ import annotations

from .._lazy import lazy

#: public name -> the module (relative to this package) that defines it; loaded on first use
_EXPORTS = {
    'ArcProfile': '.profiles',
    'ConstantSpeed': '.cam',
    'EccentricCircle': '.profiles',
    'Equilibrium': '.model',
    'Model': '.model',
    'MotionLaw': '.motion_laws',
    'NEUTRAL': '.rig',
    'Oscillating': '.cam',
    'OscillatingFollower': '.followers',
    'PARAMETERS': '.rig',
    'Parameter': '.rig',
    'Rate': '.model',
    'Rig': '.rig',
    'Rule': '.rig',
    'Scene': '.scene',
    'Segment': '.motion_laws',
    'SplineProfile': '.profiles',
    'TranslatingFollower': '.followers',
    'UserMotion': '.cam',
    'add_neutral_values': '.presets',
    'at_rest': '.model',
    'available': '.presets',
    'cam_from_law': '.synthesis',
    'cam_from_table': '.cam_tables',
    'cam_motion': '.cam',
    'example_rig': '.presets',
    'lacking_neutral_values': '.presets',
    'load_rig': '.presets',
    'periodic_cam': '.cam',
    'preset_files': '.presets',
    'read_cam_table': '.cam_tables',
    'rigid_contact': '.followers',
    'rise_dwell_return': '.motion_laws',
    'smallest_base_radius': '.synthesis',
    'solve_equilibrium': '.model',
    'static_parameters': '.model',
    'variational_kernels': '.scene',
}

__getattr__, __dir__ = lazy(__name__, _EXPORTS)
__all__ = sorted(_EXPORTS)
