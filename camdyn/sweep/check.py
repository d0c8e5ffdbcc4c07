"""Every point of a sweep checked before any work, with the checks :func:`camdyn.simulate` makes.

The settings shared by every point (simulate's keywords) are checked once, by building the
:class:`~camdyn.runs.request.RunRequest` of the sweep as simulate builds its own
(:attr:`SweepSpec.request`): a bad one raises at once.  The grid is checked point by point, by
building what simulate builds: the point's rig (``Rig.replace`` validates every parameter), its
cam (``ConstantSpeed`` validates the speed), the :class:`camdyn.model.model.Model` of rig, scene
and cam (geometry, friction lock, static equilibrium, the fastest rate of its linearized motion:
``checked_model``), and the run-length limits of the point's :class:`~camdyn.runs.request.Span`
(a cam period for ``revolutions``, at most ``MAX_CONTACT_PERIODS`` periods of the contact mode, at
most ``MAX_SAMPLES`` samples).  A Model is built once per distinct rig of the grid, with one of
the grid's cams: it depends on the cam only through its kind and constants, which every cam of
a grid shares; what joins a rig to a speed is the run-length limits, checked per point.
What only the backend checks (its methods, the scenes and cam motions it runs) is caught by
:func:`check_by_running`: the run itself, for a moment, at one valid point.  Anything all this
misses still fails inside the run, where the point is recorded as ERROR.
"""
from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np

from ..errors import CamdynError, ParameterError
from ..model.cam import ConstantSpeed
from ..runs.request import Span
from ..runs.simulation import checked_model, run
from .spec import CAM_NAMES, STATE_NAMES, SweepSpec

#: lines of an InvalidGridError's message at the most (its ``invalid`` lists every point)
MAX_LINES = 50


class InvalidGridError(CamdynError, ValueError):
    """Some points of a sweep's grid cannot run; nothing was run.

    ``invalid`` maps each invalid point's flat index to its reason; ``lines`` are the
    message's list (a rig or speed invalid at every point of the other axes is one line).
    """

    def __init__(self, size: int, invalid: dict[int, str], lines: list[str]):
        self.size, self.invalid, self.lines = size, invalid, lines
        shown = lines[:MAX_LINES] + ([f"... and {len(lines) - MAX_LINES} more (InvalidGridError.invalid "
                                      "has every point)"] if len(lines) > MAX_LINES else [])
        super().__init__(f"{len(invalid)} of {size} grid points are invalid, so the sweep did not start "
                         "(invalid='skip' runs the others and records these as INVALID):\n  " + "\n  ".join(shown))

    def __reduce__(self):
        return type(self), (self.size, self.invalid, self.lines)


def check_settings(spec: SweepSpec) -> None:
    """Check simulate's keywords shared by every point (raises at once: no point could run)."""
    if spec.samples_per_revolution is not None and "sample_rate_Hz" in spec.settings:
        raise ParameterError("samples_per_revolution", spec.samples_per_revolution, "not given with sample_rate_Hz")
    spec.request  # built from the settings by simulate's own run_request: a bad one raises here


def check_by_running(spec: SweepSpec, index: int) -> None:
    """The run at one valid point for a moment (one sample): a setting that only the backend
    rejects raises here, once, rather than at every point.  Other exceptions are left to the
    point's own run (recorded as ERROR there)."""
    rig, cam, request = spec.inputs(index)
    moment = Span(t_end=1e-6 * (cam.period if math.isfinite(cam.period) else 1.0),
                  sample_rate_Hz=request.span.sample_rate_Hz, t_start=request.span.t_start)
    try:
        run(rig, spec.scene, cam, dataclasses.replace(request, span=moment))
    except CamdynError:
        raise
    except Exception:  # not a setting: the point's own run will record it
        pass


def check_grid(spec: SweepSpec) -> tuple[dict[int, str], list[str]]:
    """({flat index: reason} of every invalid point, the lines listing them, grouped)."""
    names = spec.names
    rig_at = [k for k, n in enumerate(names) if n not in CAM_NAMES and n not in STATE_NAMES]
    cam_at = next((k for k, n in enumerate(names) if n in CAM_NAMES), None)
    cams = _cams(spec, cam_at)
    valid_cams = [c for c in cams.values() if not isinstance(c, str)]
    rigs = _rigs(spec, rig_at, valid_cams[0] if valid_cams else ConstantSpeed(0.0))
    invalid: dict[int, str] = {}
    lines = _group_lines(spec, rigs, rig_at, cam_at, "rig") + _group_lines(spec, cams, [cam_at], rig_at, "cam")
    for index, where in enumerate(np.ndindex(spec.shape)):
        rig = rigs[tuple(where[k] for k in rig_at)]
        cam = cams[where[cam_at] if cam_at is not None else 0]
        reason = rig if isinstance(rig, str) else cam if isinstance(cam, str) else _run_limits(spec, rig, cam)
        if reason:
            invalid[index] = reason
            if not isinstance(rig, str) and not isinstance(cam, str):
                lines.append(f"{spec.label(index)}: {reason}")
    return invalid, lines


def _cams(spec: SweepSpec, cam_at: int | None) -> dict[int, object]:
    """The cam of each speed of the grid (or the one cam of the settings), or why it is invalid."""
    if cam_at is None:
        return {0: spec.settings["cam"]}
    return {i: _attempt(ConstantSpeed, float(v)) for i, v in enumerate(spec.axes[spec.names[cam_at]])}


def _rigs(spec: SweepSpec, rig_at: list[int], cam) -> dict[tuple, object]:
    """Each distinct rig of the grid as (rig, contact-mode angular frequency), or why it is invalid."""
    names = [spec.names[k] for k in rig_at]
    out = {}
    for where in itertools.product(*(range(spec.shape[k]) for k in rig_at)):
        values = {n: float(spec.axes[n][i]) for n, i in zip(names, where)}
        rig = _attempt(spec.rig.replace, **values) if values else spec.rig
        model = rig if isinstance(rig, str) else _attempt(checked_model, rig, spec.scene, cam)
        out[where] = model if isinstance(model, str) else (rig, model.equilibrium.vartheta)
    return out


def _attempt(build, *args, **kwargs):
    """build(...), or the reason it cannot be built (the error's message)."""
    try:
        return build(*args, **kwargs)
    except CamdynError as exc:
        return str(exc)
    except Exception as exc:  # not a camdyn check, but the point cannot run either
        return f"{type(exc).__name__}: {exc}"


def _run_limits(spec: SweepSpec, rig, cam) -> str:
    """The checks of camdyn.simulate that join a rig to a cam: run length and sample count."""
    _, vartheta = rig
    per_rev = spec.samples_per_revolution
    try:
        duration = spec.request.span.duration(cam, vartheta)
        fs = per_rev / cam.period if per_rev is not None else None
        if fs is not None and not (math.isfinite(fs) and fs > 0):
            raise ParameterError("sample_rate_Hz", fs, "sample_rate_Hz > 0 (samples_per_revolution needs a cam period)")
        spec.request_at(cam).span.samples(duration)
    except ParameterError as exc:
        return str(exc)
    return ""


def _group_lines(spec: SweepSpec, reasons: dict, at: list, others: list | int | None, kind: str) -> list[str]:
    """One line per invalid rig (or speed): it is invalid at every value of the other axes."""
    at = [k for k in at if k is not None]
    others = [others] if isinstance(others, int) else [k for k in (others or []) if k is not None]
    every = f" (every {', '.join(spec.names[k] for k in others)})" if others else ""
    lines = []
    for where, reason in reasons.items():
        if isinstance(reason, str):
            where = where if isinstance(where, tuple) else (where,)
            label = ", ".join(f"{spec.names[k]}={spec.axes[spec.names[k]][i]:g}" for k, i in zip(at, where))
            lines.append(f"{label or kind}{every}: {reason}")
    return lines
