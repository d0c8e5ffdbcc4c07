"""Cams from tables (issue 27): lifts of the follower at cam angles, or radii h(phi) of the cam,
read from CSV or TOML with the units in the column names or keys.

CSV: a header naming the two columns, then one row per angle (``#`` starts a comment)::

    theta_deg, lift_mm
    0, 0.0
    10, 0.076
    ...

TOML: the same names as keys of two arrays (``theta_deg = [...]``, ``lift_mm = [...]``); optional
``name`` and ``description`` strings.

Columns: ``theta_deg`` (cam angle) with ``lift_mm`` / ``lift_m`` (a translating follower) or
``lift_deg`` / ``lift_rad`` (an oscillating one); or ``phi_deg`` (body angle of the contact
normal) with ``h_mm`` / ``h_m`` (the support function itself).

A table is interpolated by the periodic quintic spline through its rows (C4: make_interp_spline,
k = 5, periodic). It is refused when it cannot describe one revolution: fewer than
:data:`MIN_ROWS` rows, angles not increasing, a span of more than 360 deg, or a last row at the
first row's angle (mod 360) with another value (not periodic).
"""
from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._checks import integer
from ..errors import ParameterError
from .profiles import SplineProfile

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

__all__ = ["MIN_ROWS", "LiftTable", "RadiusTable", "read_cam_table", "cam_from_table"]

TWO_PI = 2 * math.pi
#: the fewest rows a table may have: a quintic spline through fewer samples of a revolution cannot
#: follow a rise of a quarter turn with any fidelity (four points per rise), and a short table is
#: more likely a truncated file than a cam
MIN_ROWS = 16

#: value column -> (the angle column it goes with, the SI factor, what it is)
_COLUMNS = {
    "lift_mm": ("theta_deg", 1e-3, "length"), "lift_m": ("theta_deg", 1.0, "length"),
    "lift_deg": ("theta_deg", math.pi / 180, "angle"), "lift_rad": ("theta_deg", 1.0, "angle"),
    "h_mm": ("phi_deg", 1e-3, "radius"), "h_m": ("phi_deg", 1.0, "radius"),
}


def _periodic_spline(angles, values, source: str, what: tuple[str, str]):
    """The periodic quintic B-spline through (angles rad, values), after the checks of the module
    docstring; returns (spline, first angle)."""
    from scipy.interpolate import make_interp_spline
    angle_name, value_name = what
    angles, values = np.asarray(angles, float), np.asarray(values, float)
    if angles.shape != values.shape or angles.ndim != 1:
        raise ParameterError(value_name, values.shape, f"one value per angle ({angles.shape} angles)", reason=source)
    if not (np.all(np.isfinite(angles)) and np.all(np.isfinite(values))):
        raise ParameterError(value_name, None, "finite numbers in every row", problem="has a value that is not finite",
                             reason=source)
    if not np.all(np.diff(angles) > 0):
        k = int(np.argmin(np.diff(angles)))
        raise ParameterError(angle_name, float(np.degrees(angles[k + 1])), "strictly increasing angles",
                             problem=f"is not increasing: row {k + 2} at {np.degrees(angles[k + 1]):.6g} deg after "
                                     f"{np.degrees(angles[k]):.6g} deg", reason=source)
    span = angles[-1] - angles[0]
    if np.isclose(span, TWO_PI, rtol=0, atol=1e-9):          # the last row repeats the first angle (mod 360)
        if not np.isclose(values[-1], values[0], rtol=1e-9, atol=0):
            raise ParameterError(value_name, float(values[-1]), f"the first row's value {values[0]!r} at the "
                                 "repeated angle (a table of one revolution is periodic)",
                                 problem="is not periodic: the last row repeats the first angle mod 360 deg with "
                                         "another value", reason=source)
        angles, values, span = angles[:-1], values[:-1], angles[-2] - angles[0]
    if span > TWO_PI:
        raise ParameterError(angle_name, float(np.degrees(span)), "angles spanning less than 360 deg (one revolution)",
                             problem=f"spans {np.degrees(span):.6g} deg", reason=source)
    if angles.size < MIN_ROWS:
        raise ParameterError(angle_name, angles.size, f"at least {MIN_ROWS} distinct angles over the revolution",
                             problem=f"has {angles.size} rows: too coarse for the spline", reason=source)
    x = np.append(angles, angles[0] + TWO_PI)
    y = np.append(values, values[0])
    return make_interp_spline(x, y, k=5, bc_type="periodic"), float(angles[0])


@dataclass(frozen=True, eq=False)
class LiftTable:
    """Lifts ``lifts`` (m, or rad) of the follower at cam angles ``theta`` (rad), ``kind``
    "length" (a translating follower) or "angle" (an oscillating one): a motion law for
    :func:`~camdyn.model.synthesis.cam_from_law` through the periodic quintic spline of its rows."""

    theta: np.ndarray
    lifts: np.ndarray
    kind: str
    source: str = "<table>"

    def __post_init__(self):
        if self.kind not in ("length", "angle"):
            raise ParameterError("kind", self.kind, "'length' or 'angle'")
        spline, first = _periodic_spline(self.theta, self.lifts, self.source, ("theta_deg", "lift"))
        object.__setattr__(self, "_spline", spline)
        object.__setattr__(self, "_first", first)

    def s(self, theta, derivative: int = 0) -> np.ndarray:
        """The spline's lift (derivative 0) or its theta-derivative 1..3 at cam angles theta (rad)."""
        derivative = integer("derivative", derivative, "0, 1, 2 or 3", lambda d: 0 <= d <= 3)
        theta = np.asarray(theta, float)
        return self._spline(self._first + np.mod(theta - self._first, TWO_PI), nu=derivative)

    @property
    def knots(self) -> np.ndarray:
        """The rows' angles in [0, 2 pi], with 0 and 2 pi: the spline's pieces end there."""
        rows = np.mod(np.asarray(self.theta, float), TWO_PI)
        return np.unique(np.concatenate([[0.0, TWO_PI], rows]))

    @property
    def lift(self) -> float:
        """The largest lift above the smallest (m or rad)."""
        return float(np.ptp(self.s(np.linspace(0, TWO_PI, 4096))))


@dataclass(frozen=True, eq=False)
class RadiusTable:
    """The cam's support function ``h`` (m) at body angles ``phi`` (rad)."""

    phi: np.ndarray
    h: np.ndarray
    source: str = "<table>"

    def profile(self) -> SplineProfile:
        """The periodic quintic spline of h through the rows as a spline profile: its pieces are
        the spline's own (between rows a quintic, reproduced by the Hermite data h, h', h'')."""
        spline, first = _periodic_spline(self.phi, self.h, self.source, ("phi_deg", "h"))
        rows = spline.t[5:-5]                      # a periodic spline of odd degree: its knots are the rows
        values = [spline(rows, nu=d) for d in range(3)]
        values[0][-1], values[1][-1], values[2][-1] = values[0][0], values[1][0], values[2][0]
        return SplineProfile.hermite(rows, *values)


def read_cam_table(path) -> LiftTable | RadiusTable:
    """A table of lifts or radii from a ``.csv`` or ``.toml`` file (module docstring)."""
    path = Path(path)
    source = str(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise ParameterError("path", source, "a readable CSV or TOML file", problem=f"cannot be read ({exc})") from None
    if path.suffix.lower() == ".toml":
        columns = _toml_columns(text, source)
    elif path.suffix.lower() == ".csv":
        columns = _csv_columns(text, source)
    else:
        raise ParameterError("path", source, "a file ending in .csv or .toml")
    return _table(columns, source)


def _toml_columns(text: str, source: str) -> dict[str, list]:
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError("path", source, "a valid TOML file", problem=f"is not valid TOML ({exc})") from None
    return {k: v for k, v in doc.items() if k not in ("name", "description")}


def _csv_columns(text: str, source: str) -> dict[str, list]:
    rows = [r for r in csv.reader(io.StringIO(text)) if r and not r[0].strip().startswith("#")]
    if not rows:
        raise ParameterError("path", source, "a header naming the columns, then the rows", problem="is empty")
    header = [h.strip() for h in rows[0]]
    columns = {h: [] for h in header}
    for number, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise ParameterError("row", number, f"{len(header)} values like the header {header}",
                                 problem=f"{number} has {len(row)} values", reason=source)
        for name, cell in zip(header, row):
            try:
                columns[name].append(float(cell))
            except ValueError:
                raise ParameterError(name, cell.strip(), "a number in every row",
                                     problem=f"has {cell.strip()!r} in row {number}", reason=source) from None
    return columns


def _table(columns: dict[str, list], source: str) -> LiftTable | RadiusTable:
    values = [k for k in columns if k in _COLUMNS]
    valid = ("two columns: theta_deg with one of lift_mm, lift_m, lift_deg, lift_rad; "
             "or phi_deg with h_mm or h_m")
    if len(values) != 1 or len(columns) != 2 or _COLUMNS[values[0]][0] not in columns:
        raise ParameterError("columns", tuple(columns), valid, problem=f"are {tuple(columns)}", reason=source)
    angle_name, factor, what = _COLUMNS[values[0]]
    try:
        angles = np.radians(np.asarray(columns[angle_name], float))
        numbers = np.asarray(columns[values[0]], float) * factor
    except (TypeError, ValueError):
        raise ParameterError("columns", tuple(columns), "arrays of numbers", reason=source) from None
    if what == "radius":
        return RadiusTable(angles, numbers, source)
    return LiftTable(angles, numbers, what, source)


def cam_from_table(path, follower=None, r_b: float | None = None, **options) -> SplineProfile:
    """The cam a table file describes: a table of radii is the profile itself (no follower, no
    r_b); a table of lifts goes through :func:`~camdyn.model.synthesis.cam_from_law` for
    ``follower`` and ``r_b`` (m), its lifts lengths for a translating follower and angles for an
    oscillating one. ``options`` go to ``cam_from_law``."""
    from .synthesis import cam_from_law
    table = read_cam_table(path)
    if isinstance(table, RadiusTable):
        if follower is not None or r_b is not None:
            raise ParameterError("r_b", r_b, "not given for a table of radii (it is the cam itself)")
        return table.profile()
    wanted = {"translating": "length", "oscillating": "angle"}.get(getattr(follower, "kind", None))
    if wanted is None:
        raise ParameterError("follower", follower, "a TranslatingFollower or an OscillatingFollower (a table of lifts)")
    if table.kind != wanted:
        unit = "lift_mm or lift_m" if wanted == "length" else "lift_deg or lift_rad"
        raise ParameterError("follower", follower.kind, f"a follower for lifts that are {table.kind}s, or a table "
                             f"with {unit}", problem=f"= {follower.kind!r} does not go with lifts that are "
                             f"{table.kind}s", reason=table.source)
    return cam_from_law(table, follower, r_b, **options)
