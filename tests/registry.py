"""One registry of scenes and solvers, fed to pytest.mark.parametrize across the suite."""
from __future__ import annotations

import math

import camdyn
from camdyn import generated
from camdyn.engine.config import METHODS as _METHODS
from camdyn.engine import BACKENDS as _BACKENDS  # "compiled", "python"

RIG = camdyn.example_rig()


def rig_for(scene: camdyn.Scene) -> camdyn.Rig:
    """The example rig of a scene's follower and cam family: the paper's follower (RIG) or the translating
    example, on the eccentric circle or on a cycloidal cam (a spline: camdyn.model.presets)."""
    from camdyn.model import presets
    if scene.follower == "translating":
        rig = presets.translating_cam_example_rig() if scene.profile == "spline" else presets.translating_example_rig()
    else:
        rig = presets.cam_example_rig() if scene.profile == "spline" else RIG
    return rig.replace(xi=0.8) if scene.contact == "rigid" and rig.xi is None else rig  # the rigid law's restitution


def scene_from_slug(slug: str) -> camdyn.Scene:
    """Rebuild a Scene from a generated module's SCENE table."""
    import importlib
    mod = importlib.import_module(f"camdyn.generated.{generated.SCENES[slug]}")
    return camdyn.Scene(**mod.SCENE)


def cam_for(scene: camdyn.Scene, speed_rpm: float = 300.0):
    if scene.motion == "constant":
        return camdyn.ConstantSpeed(speed_rpm)
    if scene.motion == "oscillating":
        return camdyn.Oscillating(amplitude_pp=math.pi, frequency_rpm=40.0)
    omega = speed_rpm * camdyn.model.cam.RPM
    th0 = RIG.theta0
    return camdyn.UserMotion(lambda t: th0 + omega * t, lambda t: omega + 0 * t, lambda t: 0 * t,
                             period=2 * math.pi / abs(omega) if omega else math.inf)


#: every generated scene, by slug
SCENES = sorted(generated.SCENES)
#: the engine's Runge-Kutta pairs
METHODS = list(_METHODS)
#: every backend of camdyn.simulate: the hard cases run on each (issue 5)
BACKENDS = list(_BACKENDS)

#: rigs with a small contact margin (issue 25), (rig, scene): a soft spring with impact damping B; a
#: soft spring, lightly damped D, no friction; a small preload (L_us 2 % shorter: the spring's
#: compression at the 0-state nearly halved); a large eccentricity (e = 0.2 r_c); the example rig with
#: a point (Hertz) contact.  tests/test_derivatives.py and benchmarks/small_margin_multipliers.py.
SMALL_MARGIN = {
    "soft spring": (RIG.replace(k_s=500.0), camdyn.Scene(damping="B", friction="coulomb")),
    "soft, light damping": (RIG.replace(k_s=500.0, zeta_D=1e-3), camdyn.Scene(damping="D", friction="none")),
    "small preload": (RIG.replace(L_us=0.1175), camdyn.Scene(damping="B", friction="coulomb")),
    "large eccentricity": (RIG.replace(e=0.2 * RIG.r_c), camdyn.Scene(damping="B", friction="coulomb")),
    "point contact": (RIG, camdyn.Scene(contact="point", damping="B", friction="coulomb")),
}
