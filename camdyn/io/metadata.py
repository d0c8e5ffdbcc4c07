"""What a saved run says about itself: the units and meaning of each time history, and the
scene, rig, cam motion and solver settings that produced it -- enough to run it again.

* :data:`VARIABLES` and :func:`variable_attributes`: unit and long name of every quantity of a
  :class:`~camdyn.Result` (NetCDF ``units``/``long_name``, CSV headers ``alpha (rad)``);
* :func:`run_attributes`: the global attributes of a saved run (flat, NetCDF-3 compatible:
  strings and numbers only);
* :func:`from_attributes`: those attributes back to a :class:`SavedRun` (rig, scene, cam,
  settings) whose :meth:`SavedRun.simulate` runs it again;
* :func:`describe_scene` and :func:`describe_cam`: the physics in words, for titles.

Example::

    import xarray as xr
    from camdyn import metadata

    with xr.open_dataset("run.nc", engine="scipy") as ds:
        again = metadata.from_attributes(ds.attrs).simulate()
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

__all__ = ["VARIABLES", "units", "variable_attributes", "column_header", "parse_column_header",
           "scene_options", "describe_scene", "describe_cam", "run_attributes", "from_attributes", "SavedRun"]

#: unit (SI) and long name of each time history of a Result, and of the energy ledger's outputs
VARIABLES: dict[str, tuple[str, str]] = {
    "t": ("s", "time"),
    "alpha": ("rad", "follower angle from the horizontal, clockwise"),
    "alpha_dot": ("rad/s", "follower angular velocity"),
    "Theta": ("rad", "cam angle, counter-clockwise"),
    "alpha_i": ("rad", "follower angle in rigid contact (Eq. 29)"),
    "alpha_r": ("rad", "residual response alpha - alpha_i (Section 4)"),
    "y": ("m", "translating follower: its face's distance from the cam's centre along the guide"),
    "y_dot": ("m/s", "translating follower: its velocity along the guide"),
    "y_i": ("m", "translating follower in rigid contact, h(gamma - Theta)"),
    "y_r": ("m", "residual response y - y_i"),
    "psi_i": ("m", "normal gap at the contact: > 0 apart, < 0 contact deflection (Eq. 6)"),
    "psi_j": ("m", "slide of the contact point along the follower (Eq. 7)"),
    "psi_i_dot": ("m/s", "rate of the normal gap psi_i"),
    "F_s": ("N", "follower spring force (Eq. 11)"),
    "F_n": ("N", "normal contact force (Eq. 12)"),
    "F_f": ("N", "friction force at the contact"),
    "v_r": ("m/s", "relative sliding velocity at the contact"),
    "N_x": ("N", "horizontal bearing force at the follower pivot (Eq. 35)"),
    "energy": ("J", "mechanical energy of the follower (kinetic + spring + contact)"),
    "P_in": ("W", "power put in by the cam"),
    "D_c": ("W", "power dissipated by contact damping"),
    "D_f": ("W", "power dissipated by friction"),
    "work_in": ("J", "work done by the cam drive since the start (energy ledger)"),
    "dissipated_contact": ("J", "energy dissipated by contact damping since the start (energy ledger)"),
    "dissipated_friction": ("J", "energy dissipated by friction since the start (energy ledger)"),
    "regime": ("", "contact regime at the sample"),
}

_RIG_TEXT = ("name", "description", "follower")  # (a file without the follower: the paper's, oscillating)
_BOOL_SETTINGS = ("energy_ledger",)


def units(name: str) -> str:
    """The SI unit of a quantity of a Result (``""`` when dimensionless or unknown)."""
    return VARIABLES.get(name, ("", ""))[0]


def variable_attributes(name: str) -> dict[str, str]:
    """``{"units": ..., "long_name": ...}`` of a quantity (NetCDF variable attributes)."""
    unit, long_name = VARIABLES.get(name, ("", name))
    return {"units": unit, "long_name": long_name}


def column_header(name: str) -> str:
    """A CSV column header with its unit, e.g. ``alpha (rad)``; ``regime`` has none."""
    unit = units(name)
    return f"{name} ({unit})" if unit else name


def parse_column_header(header: str) -> str:
    """The quantity's name of a CSV header, ``alpha (rad)`` -> ``alpha``."""
    return header.split(" (", 1)[0].strip()


# ----------------------------------------------------------------------------- words
def scene_options(scene) -> dict[str, str]:
    """The options of a :class:`~camdyn.Scene`, or of a scene's slug (``result.scene``)."""
    from ..vocabulary import SceneSpec

    if isinstance(scene, str):
        scene = SceneSpec.from_slug(scene)
    return {f.name: getattr(scene, f.name) for f in fields(scene)}


_FRICTION = {"none": "no friction", "coulomb": "Coulomb friction", "tanh": "tanh-smoothed friction"}
_MODEL = {"nonlinear": "", "linear_paper": "linearized as printed (Eqs. 36-38)",
          "linear_exact": "exact linearization"}


def describe_scene(scene) -> str:
    """The physics of a scene in words, e.g. ``line contact, damping D, Coulomb friction``."""
    o = scene_options(scene)
    words = [f"{o['contact']} contact", "no damping" if o["damping"] == "none" else f"damping {o['damping']}",
             _FRICTION.get(o["friction"], f"{o['friction']} friction")]
    if _MODEL.get(o["model"], o["model"]):
        words.append(_MODEL.get(o["model"], o["model"]))
    if o["sliding_velocity"] == "printed":
        words.append("printed v_r")
    if o["damping_sign"] == "printed":
        words.append("printed damping sign")
    if o.get("damping_switch") == "memoryless":
        words.append("memoryless D/E switch")
    if o.get("follower", "oscillating") != "oscillating":
        words.append(f"{o['follower']} follower")
    if o.get("profile", "eccentric") != "eccentric":
        words.append(f"{o['profile']} cam")
    if o.get("face") == "bounded":
        words.append("bounded face")
    return ", ".join(words)


def describe_cam(cam) -> str:
    """The cam motion in words: ``1100 rev/min``, ``oscillating 40 /min, 3.14 rad peak-to-peak``."""
    kind = getattr(cam, "kind", None)
    if kind == "constant":
        return "cam at rest" if cam.speed_rpm == 0 else f"{cam.speed_rpm:g} rev/min"
    if kind == "oscillating":
        return f"oscillating {cam.frequency_rpm:g} /min, {cam.amplitude_pp:.3g} rad peak-to-peak"
    if kind == "user":
        return "user cam motion"
    return ""


# ----------------------------------------------------------------------------- attributes
def _plain(value):
    """A NetCDF-3 attribute value: str, int or float (bools as 0/1)."""
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, (int, float, str)):
        return value
    if hasattr(value, "item"):  # NumPy scalars
        return _plain(value.item())
    return repr(value)


def _rig_attributes(rig, source: str | None) -> dict[str, Any]:
    from ..model.rig import PARAMETERS

    out = {f"rig_{k}": str(getattr(rig, k)) for k in _RIG_TEXT}
    out["rig_source"] = source or rig.origin or "not recorded (a Rig built in code: pass rig_source=)"
    for p in PARAMETERS:
        value = getattr(rig, p.name)
        if value is not None:
            out[f"rig_{p.name}"] = float(value)
    out["rig_units"] = "; ".join(f"{p.name} {p.unit}" for p in PARAMETERS)
    return out


def _cam_attributes(cam) -> dict[str, Any]:
    if cam is None:
        return {}
    out = {"cam_motion": getattr(cam, "kind", type(cam).__name__), "cam_description": describe_cam(cam)}
    if out["cam_motion"] == "user":
        out["cam_note"] = "a user motion is Python code: it is not saved, so this run cannot be re-run from the file"
        return out
    for f in fields(cam):
        out[f"cam_{f.name}"] = _plain(getattr(cam, f.name))
    return out


def run_attributes(result, rig=None, *, rig_source: str | None = None,
                   settings: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The global attributes of a saved run: enough to know what it is and to run it again.

    Parameters
    ----------
    result : camdyn.Result
        The run.
    rig : camdyn.Rig, optional
        The rig it ran on; needed because ``result.meta`` holds only the rig's name
        (used from ``result.meta["rig"]`` when that is a Rig).
    rig_source : str, optional
        Where the rig came from; by default ``rig.origin`` (a preset's name or a rig file's path).
    settings : mapping, optional
        The keyword arguments given to :func:`camdyn.simulate` (``method``, ``rtol``,
        ``atol``, ``backend``, ``sample_rate_Hz``, ``revolutions`` or ``t_end``...; a ``span``
        or ``options`` given whole is recorded as those loose keywords:
        :func:`camdyn.runs.request.loose_keywords`); default ``result.meta["settings"]`` when present.

    Returns
    -------
    dict
        Flat attributes (strings and numbers): ``scene`` and ``scene_<option>``,
        ``rig_<parameter>`` (SI) with ``rig_name``, ``rig_description``, ``rig_source``,
        ``cam_<field>``, ``solver_<setting>``, ``outcome``, ``period_s``, ``alpha_star_rad``
        and ``camdyn_version``.

    Raises
    ------
    camdyn.ParameterError
        If no rig is given and ``result.meta`` does not hold one.
    """
    from .._version import __version__
    from ..errors import ParameterError
    from ..model.rig import Rig
    from ..runs.request import loose_keywords

    rig = rig if rig is not None else result.meta.get("rig")
    if not isinstance(rig, Rig):
        raise ParameterError("rig", None, "the Rig the run used (result.meta holds only its name)")
    settings = loose_keywords(settings if settings is not None else result.meta.get("settings", {}))
    cam = result.meta.get("cam")
    scene = scene_options(result.scene)
    title = describe_scene(result.scene) + (f", {describe_cam(cam)}" if describe_cam(cam) else "")
    attrs: dict[str, Any] = {
        "title": f"camdyn run: {title}, rig {rig.name}",
        "source": f"camdyn {__version__}", "camdyn_version": __version__,
        "scene": result.scene, **{f"scene_{k}": v for k, v in scene.items()},
        **_rig_attributes(rig, rig_source), **_cam_attributes(cam),
        **{f"solver_{k}": _plain(v) for k, v in settings.items() if v is not None},
        "initial_state": "static equilibrium (alpha*, 0)" if "y0" not in settings else "y0",
        "outcome": result.outcome.name, "outcome_message": result.outcome.message,
        "period_s": float(result.period) if math.isfinite(result.period) else -1.0,
        "alpha_star_rad": float(result.q_star),
    }
    return attrs


# ----------------------------------------------------------------------------- and back
@dataclass
class SavedRun:
    """A run rebuilt from saved attributes: ``simulate()`` runs it again."""

    rig: Any
    scene: Any
    cam: Any
    settings: dict = field(default_factory=dict)

    def simulate(self, **overrides):
        """:func:`camdyn.simulate` with the saved rig, scene, cam and settings (``overrides`` win;
        a ``span`` or ``options`` among them replaces the saved settings of its fields)."""
        from ..runs.request import SOLVER_KEYWORDS, SPAN_KEYWORDS
        from ..runs.simulation import simulate

        replaced = {"span": SPAN_KEYWORDS, "options": SOLVER_KEYWORDS}
        dropped = {k for whole, keys in replaced.items() if whole in overrides for k in keys}
        settings = {k: v for k, v in self.settings.items() if k not in dropped}
        return simulate(self.rig, self.scene, self.cam, **{**settings, **overrides})


def _python(value):
    return value.item() if hasattr(value, "item") else value


def _prefixed(attrs: Mapping[str, Any], prefix: str) -> dict[str, Any]:
    return {k[len(prefix):]: _python(v) for k, v in attrs.items() if k.startswith(prefix)}


def from_attributes(attrs: Mapping[str, Any]) -> SavedRun:
    """The rig, scene, cam motion and solver settings of a saved run (see :func:`run_attributes`).

    Parameters
    ----------
    attrs : mapping
        The global attributes of a file written by ``camdyn simulate --netcdf`` or
        :func:`camdyn.io.files.write_netcdf` (e.g. ``xarray.open_dataset(path).attrs``).

    Returns
    -------
    SavedRun
        With ``rig`` (a validated :class:`~camdyn.Rig`), ``scene``, ``cam`` and ``settings``.

    Raises
    ------
    ValueError
        If the attributes lack the rig, the scene or the cam motion, or the cam motion was
        user code (not saved).
    """
    from ..model.cam import ConstantSpeed, Oscillating
    from ..model.rig import PARAMETERS, Rig
    from ..model.scene import Scene

    names = {p.name for p in PARAMETERS}
    rig_values = _prefixed(attrs, "rig_")
    params = {k: float(v) for k, v in rig_values.items() if k in names}
    if not params:
        raise ValueError("these attributes hold no rig parameters (rig_<name>): not written by camdyn's run writer")
    origin = f"a saved run's attributes (rig from: {rig_values.get('source', 'not recorded')})"
    rig = Rig(**params, **{k: str(rig_values[k]) for k in _RIG_TEXT if k in rig_values}, origin=origin)
    scene_values = _prefixed(attrs, "scene_")
    scene = Scene(**{f.name: str(scene_values[f.name]) for f in fields(Scene) if f.name in scene_values})
    cam_values = _prefixed(attrs, "cam_")
    kinds = {"constant": ConstantSpeed, "oscillating": Oscillating}
    kind = cam_values.get("motion")
    if kind not in kinds:
        raise ValueError(f"cam motion {kind!r} cannot be rebuilt from the file"
                         + (": a user motion is code, not saved" if kind == "user" else ""))
    cls = kinds[kind]
    cam = cls(**{f.name: float(cam_values[f.name]) for f in fields(cls)})
    settings = _prefixed(attrs, "solver_")
    for key in _BOOL_SETTINGS:
        if key in settings:
            settings[key] = bool(settings[key])
    return SavedRun(rig, scene, cam, settings)
