"""The ``[cam]`` table of a rig file (issue 27): the rig's cam when it is not the paper's circle.

One of four forms (lengths in mm, angles in degrees, as the keys say)::

    [cam]                               # a table of lifts or radii (camdyn.model.cam_tables)
    table = "lifts.csv"                 # relative to the rig file
    base_radius_mm = 25.0               # a table of lifts only

    [cam]                               # a motion law (camdyn.model.motion_laws)
    law = "cycloidal"                   # or "345", "modified_trapezoid" (as rise_dwell_return takes)
    lift_rad = 0.05                     # the oscillating follower's angular lift (translating: lift_mm)
    angles_deg = [100, 80, 100, 80]     # rise, dwell, return, dwell
    base_radius_mm = 25.0

    [cam]                               # the classic circular-arc cam (ArcProfile.circular_arc_cam)
    arcs = { r_b_mm = 22, r_n_mm = 8, d_mm = 18, R_mm = 60 }

    [cam]                               # the cam's data as it is (what Rig.to_toml writes)
    kind = "spline"                     # or "arcs"
    block = [...]

The first three keep the follower's pivot where the ``[parameters]`` put it (on their eccentric
circle) and re-state the 0-state on the new cam at ``theta0_deg`` (default the file's theta0):
:func:`camdyn.model.followers.rig_on_cam`.  The last attaches the cam as it is: the parameters are
already those of the rig on it.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from ..errors import CamdynError, RigFileError
from ..vocabulary import ECCENTRIC

#: the keys each form takes (``theta0_deg`` besides, for all but the block)
FORMS = {"table": ("table", "base_radius_mm"), "law": ("law", "lift_rad", "lift_mm", "angles_deg", "base_radius_mm"),
         "arcs": ("arcs",), "block": ("kind", "block")}
_ARC_KEYS = ("r_b_mm", "r_n_mm", "d_mm", "R_mm", "nose_angle_deg")


def rig_with_cam(rig, cam: Any, source: str, folder: Path):
    """``rig`` on the cam a ``[cam]`` table describes (see the module docstring); a bad table is a
    :class:`RigFileError` naming the file and the key."""
    if not isinstance(cam, Mapping):
        raise RigFileError(source, "'cam' must be a table", key="cam")
    form = _form(cam, source)
    try:
        if form == "block":
            from .profiles import profile_from_block
            return rig.replace(profile=profile_from_block(cam["kind"], np.asarray(cam["block"], dtype=float)))
        from .followers import rig_on_cam
        theta0 = cam.get("theta0_deg")
        return rig_on_cam(rig, _profile(form, cam, rig, folder),
                          theta0=None if theta0 is None else math.radians(float(theta0)))
    except (CamdynError, TypeError, ValueError, KeyError) as exc:
        raise RigFileError(source, f"[cam]: {exc}", key="cam") from exc


def family(cam: Mapping) -> str:
    """The scene option ``profile`` a ``[cam]`` table needs: its block's kind, "arcs" for the arc
    cam, "spline" for a table or a law (their cams are splines)."""
    if "kind" in cam:
        return str(cam["kind"])
    return "arcs" if "arcs" in cam else "spline"


def file_family(path) -> str:
    """:func:`family` of a rig file's ``[cam]`` table, "eccentric" for a file without one (or
    for a name that is not a readable TOML file: reading the rig says what is wrong)."""
    import tomllib
    try:
        with open(path, "rb") as f:
            cam = tomllib.load(f).get("cam")
    except (OSError, ValueError):
        return ECCENTRIC
    return family(cam) if isinstance(cam, Mapping) else ECCENTRIC


def _form(cam: Mapping, source: str) -> str:
    forms = [name for name, keys in FORMS.items() if keys[0] in cam]
    if len(forms) != 1:
        raise RigFileError(source, "[cam] needs exactly one of 'table', 'law', 'arcs' or 'kind' + 'block', got "
                           f"{sorted(cam)}", key="cam")
    allowed = set(FORMS[forms[0]]) | ({"theta0_deg"} if forms[0] != "block" else set())
    unknown = sorted(set(cam) - allowed)
    if unknown:
        raise RigFileError(source, f"[cam] ({forms[0]}) does not take {unknown}: it takes {sorted(allowed)}",
                           key=unknown[0])
    return forms[0]


def _profile(form: str, cam: Mapping, rig, folder: Path):
    from .followers import follower_of_rig
    if form == "arcs":
        from .profiles import ArcProfile
        arcs = dict(cam["arcs"])
        lengths = {k[:-3]: float(arcs.pop(k)) / 1000 for k in _ARC_KEYS[:4]}
        nose = math.radians(float(arcs.pop("nose_angle_deg", 0.0)))
        if arcs:
            raise ValueError(f"arcs does not take {sorted(arcs)}: it takes {list(_ARC_KEYS)}")
        return ArcProfile.circular_arc_cam(**lengths, nose_angle=nose)
    r_b = cam.get("base_radius_mm")
    if form == "table":
        from .cam_tables import RadiusTable, cam_from_table, read_cam_table
        path = folder / cam["table"]
        if isinstance(read_cam_table(path), RadiusTable):
            return cam_from_table(path)
        if r_b is None:
            raise ValueError("a table of lifts needs base_radius_mm")
        return cam_from_table(path, follower_of_rig(rig), r_b=float(r_b) / 1000)
    from .motion_laws import rise_dwell_return
    from .synthesis import cam_from_law
    law = rise_dwell_return(_law_lift(cam, rig), tuple(math.radians(float(a)) for a in cam["angles_deg"]),
                            law=cam["law"])
    return cam_from_law(law, follower_of_rig(rig), r_b=float(r_b) / 1000)


#: a motion law's lift key by follower type: an angle for the rocker, a length for the translating follower
_LIFT_KEYS = {"oscillating": "lift_rad", "translating": "lift_mm"}


def _law_lift(cam: Mapping, rig) -> float:
    """The law's lift in SI (rad or m), under the key of the rig's follower type."""
    key = _LIFT_KEYS[rig.follower]
    other = [k for k in _LIFT_KEYS.values() if k != key and k in cam]
    if other or key not in cam:
        raise ValueError(f"a motion law for a {rig.follower} follower gives its lift as {key}"
                         + (f", not {other[0]}" if other else ""))
    return float(cam[key]) / (1000 if key == "lift_mm" else 1)


def cam_lines(profile) -> list[str]:
    """The ``[cam]`` table of the block form for a profile (exact: floats written with repr)."""
    block = ", ".join(repr(float(v)) for v in profile.block())
    return ["", "[cam]", f"kind = {profile.kind!r}".replace("'", '"'), f"block = [{block}]"]
