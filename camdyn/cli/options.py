"""The options several commands take, and what they build: the rig, the cam motion, the scene,
and the run's span and solver options (built here, once, for every command that runs the engine);
the engine's names (backends, methods); options that name a file."""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from .common import UsageError, _built, _plot_modules
from ..vocabulary import ECCENTRIC


# --------------------------------------------------------------------------- rig, cam, scene
def _rig(args):
    """The rig of --rig: a shipped preset's name or a .toml file."""
    from ..errors import ParameterError
    from ..model.presets import available, load_rig

    try:
        return _on_cam(load_rig(args.rig), args)
    except ParameterError as exc:  # not a preset and not a .toml path
        if exc.name != "name":
            raise
        import difflib

        close = difflib.get_close_matches(args.rig, available(), n=1)
        raise UsageError(f"--rig {args.rig}: no shipped rig of that name"
                         + (f" (did you mean {close[0]!r}?)" if close else "")
                         + f"; shipped rigs: {', '.join(available())}, or a rig file ending in .toml") from None


def _on_cam(rig, args):
    """The rig on the cam of --cam (a table of lifts or radii, camdyn.model.cam_tables), its pivot
    kept where it is and its 0-state re-stated on that cam (camdyn.model.followers.rig_on_cam)."""
    path = getattr(args, "cam", None)
    if path is None:
        return rig
    from ..model.cam_tables import RadiusTable, cam_from_table, read_cam_table
    from ..model.followers import follower_of_rig, rig_on_cam

    if isinstance(read_cam_table(path), RadiusTable):
        return rig_on_cam(rig, cam_from_table(path))
    if args.base_radius_mm is None:
        raise UsageError(f"--cam {path} is a table of lifts: give the cam's base circle with --base-radius-mm")
    return rig_on_cam(rig, cam_from_table(path, follower_of_rig(rig), r_b=args.base_radius_mm / 1000))


def _cam(args):
    from ..model.cam import ConstantSpeed, Oscillating

    if getattr(args, "oscillating_rpm", None) is not None:
        if args.speed_rpm is not None:
            raise UsageError("give either --speed-rpm or --oscillating-rpm, not both")
        return Oscillating(args.amplitude_pp, args.oscillating_rpm)
    if args.speed_rpm is None:
        raise UsageError("a cam motion is needed: --speed-rpm S (constant speed) or --oscillating-rpm F")
    return ConstantSpeed(args.speed_rpm)


def _scene(args, motion: str = "constant"):
    from ..model.scene import Scene

    return Scene(contact=getattr(args, "contact", "line"), damping=args.damping, friction=args.friction,
                 motion=motion, model=getattr(args, "model", "nonlinear"),
                 sliding_velocity=getattr(args, "sliding_velocity", "kinematic"),
                 damping_sign=getattr(args, "damping_sign", "dissipative"),
                 damping_switch=getattr(args, "damping_switch", "episode"),
                 response=getattr(args, "response", "dynamic"), follower=_follower(args),
                 profile=_profile(args))


def _follower(args) -> str:
    """The scene's follower type: --follower, else the --rig file's (camdyn.model.rig: ``follower``)."""
    given = getattr(args, "follower", None)
    if given:
        return given
    from ..errors import CamdynError
    from ..model.presets import load_rig
    try:
        return load_rig(getattr(args, "rig", "example")).follower
    except CamdynError:  # the rig's own error is raised where the rig is read (_rig)
        return "oscillating"


def _profile(args) -> str:
    """The scene's cam family: a spline for --cam, else the --rig file's [cam] (camdyn.model.cam_files)."""
    if getattr(args, "cam", None) is not None:
        return "spline"
    rig = getattr(args, "rig", "example")
    if not str(rig).endswith(".toml"):
        return ECCENTRIC
    from ..model.cam_files import file_family
    return file_family(rig)


def _options():
    from ..vocabulary import OPTIONS

    return OPTIONS


def _add_physics(p, contact: bool = True, full: bool = True):
    opts = _options()
    g = p.add_argument_group("rig and scene")
    g.add_argument("--rig", default="example", help="shipped rig name (see 'camdyn scenes') or a .toml rig file "
                                                    "(default: example)")
    g.add_argument("--cam", type=Path, default=None, metavar="FILE",
                   help="the cam as a table (CSV or TOML): lifts of the follower (theta_deg with lift_deg or "
                        "lift_rad) or the cam's radii (phi_deg with h_mm or h_m); the rig's follower keeps its "
                        "pivot (default: the rig's eccentric circle)")
    g.add_argument("--base-radius-mm", type=float, default=None, dest="base_radius_mm", metavar="MM",
                   help="base circle of a --cam table of lifts, mm")
    if contact:
        g.add_argument("--contact", default="line", choices=opts["contact"], help="contact law (default: line)")
    g.add_argument("--damping", default="D", choices=opts["damping"], help="damping model, Eqs. 24-28 (default: D)")
    g.add_argument("--friction", default="coulomb", choices=opts["friction"],
                   help="friction model: coulomb (I) or tanh (II) (default: coulomb)")
    if full:
        g.add_argument("--model", default="nonlinear", choices=opts["model"],
                       help="non-linear, or a linearization (Section 8) (default: nonlinear)")
        g.add_argument("--sliding-velocity", default="kinematic", choices=opts["sliding_velocity"],
                       dest="sliding_velocity", help="v_r: derived, or as printed (misprint 8) (default: kinematic)")
        g.add_argument("--damping-sign", default="dissipative", choices=opts["damping_sign"], dest="damping_sign",
                       help="B/D coefficient: dissipative, or as printed (misprint 2) (default: dissipative)")
        g.add_argument("--damping-switch", default="episode", choices=opts["damping_switch"], dest="damping_switch",
                       help="D/E: the impact law once per contact, until maximum compression (episode, Sec. 3.4), "
                            "or whenever the gap closes (memoryless) (default: episode)")
        g.add_argument("--response", default="dynamic", choices=opts["response"],
                       help="the hybrid model (dynamic), or the quasi-static contact orbit with no integration "
                            "(quasistatic: a follower that never leaves the cam) (default: dynamic)")
        g.add_argument("--follower", default=None, choices=opts["follower"],
                       help="the follower's type: the paper's oscillating rocker or a translating flat face "
                            "(default: the --rig file's follower, else oscillating)")


def _add_cam(p, required_speed: bool = False):
    g = p.add_argument_group("cam motion (one of)")
    g.add_argument("--speed-rpm", type=float, dest="speed_rpm", metavar="S",
                   help="constant cam speed in rev/min; > 0 counter-clockwise (de-energizing), < 0 clockwise")
    g.add_argument("--oscillating-rpm", type=float, dest="oscillating_rpm", metavar="F",
                   help="oscillating cam, F oscillations per minute (Section 7.2: 40)")
    g.add_argument("--amplitude-pp", type=float, default=math.pi, dest="amplitude_pp", metavar="RAD",
                   help="peak-to-peak angle of the oscillating cam in rad (default: pi)")


# --- solvers: the one place the command learns the engine's backend and method names -----------
def _solvers() -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(backends, methods) of the engine: every backend runs every method (one loop)."""
    from ..engine import BACKENDS, METHODS

    return BACKENDS, METHODS


def _default_backend() -> str:
    """The backend a run uses when not told (camdyn.runs.request.DEFAULT_BACKEND)."""
    from ..runs.request import DEFAULT_BACKEND

    return DEFAULT_BACKEND


class _Lazy:
    """A sequence (argparse choices) or text (help) computed on first use: the engine's names need
    the engine's import, which a command that does not simulate should not pay for."""

    def __init__(self, load):
        self._load, self._value = load, None

    def _get(self):
        if self._value is None:
            self._value = self._load()
        return self._value

    def __contains__(self, item):
        return item in self._get()

    def __iter__(self):
        return iter(self._get())

    def __str__(self):
        return str(self._get())


def _backend(args) -> str:
    """The backend of --backend, or the default one."""
    backend = getattr(args, "backend", None)
    return _default_backend() if backend is None else backend


def _add_run(p, revolutions: float = 3.0, sample_rate: float = 20_000.0):
    g = p.add_argument_group("run and solver")
    g.add_argument("--revolutions", type=float, default=revolutions,
                   help=f"run length in cam periods (default: {revolutions:g})")
    g.add_argument("--t-end", type=float, dest="t_end", metavar="SECONDS", help="run length in seconds instead")
    g.add_argument("--sample-rate-Hz", type=float, default=sample_rate, dest="sample_rate_Hz", metavar="HZ",
                   help=f"output samples per second (default: {sample_rate:g})")
    _add_solver(g)


def _add_solver(g, backend_help: str = "who runs the engine's loop: %(choices)s (default: {default_backend}; "
                                      "python: the same loop in Python, slow, for checking)",
                rtol: float = 1e-8, atol: float = 1e-12):
    g.add_argument("--method", default="DOP853", metavar="METHOD", choices=_Lazy(lambda: _solvers()[1]),
                   help="Runge-Kutta pair with dense output: %(choices)s (default: DOP853)")
    g.add_argument("--rtol", type=float, default=rtol, help=f"relative tolerance (default: {rtol:g})")
    g.add_argument("--atol", type=float, default=atol, help=f"absolute tolerance (default: {atol:g})")
    g.add_argument("--backend", metavar="BACKEND", choices=_Lazy(lambda: _solvers()[0]), default=None,
                   help=backend_help)
    g.add_argument("--max-step", type=float, default=math.inf, dest="max_step", metavar="SECONDS",
                   help="largest step the integrator may take (default: no limit)")
    g.add_argument("--max-events", type=int, default=1_000_000, dest="max_events", metavar="N",
                   help="most regime switches one run may have before it stops as MAX_EVENTS (default: 1000000)")


def _MAP_OPTIONS():
    """The tolerances of the periodic analyses (camdyn.engine.config.MAP_OPTIONS), their default on
    the command line too (numba-free: the parser is built without it)."""
    from ..engine import MAP_OPTIONS

    return MAP_OPTIONS


def _solver_options(args):
    """The engine's SolverOptions from the solver options of ``_add_solver``: built here, for
    every command that takes them."""
    from ..engine import EventSettings, SolverOptions

    return SolverOptions(method=args.method, rtol=args.rtol, atol=args.atol, max_step=args.max_step,
                         events=EventSettings(max_events=args.max_events))


def _span(args, cam):
    """The run's Span from the run options of ``_add_run``: --t-end seconds, or --revolutions of
    the cam (a cam at rest has no period: --t-end only), sampled at --sample-rate-Hz."""
    from ..runs.request import Span

    if args.t_end is not None:
        return Span(t_end=args.t_end, sample_rate_Hz=args.sample_rate_Hz)
    if not math.isfinite(cam.period):
        raise UsageError(f"--speed-rpm {args.speed_rpm:g} holds the cam still: with no cam period, the run "
                         "length cannot be counted in --revolutions; give it in seconds with --t-end SECONDS")
    return Span(revolutions=args.revolutions, sample_rate_Hz=args.sample_rate_Hz)


# --- file options: their kind is checked while the command line is read, before any work -------
_KINDS = {"csv": "a CSV file", "netcdf": "a NetCDF file", "plot": "a figure", "run": "a saved run"}


# --------------------------------------------------------------------------- continuation
def _add_arclength(g) -> None:
    """The step control and corrector options of a continuation (continue, chart)."""
    g.add_argument("--max-points", type=int, default=400, dest="max_points", metavar="N",
                   help="at most this many orbits per branch or curve (default: 400)")
    g.add_argument("--arclength-step", type=float, default=0.01, dest="arclength_step", metavar="DS",
                   help="first step in scaled arclength (the parameter range is 1) (default: 0.01)")
    g.add_argument("--min-arclength-step", type=float, default=1e-5, dest="min_arclength_step", metavar="DS",
                   help="the branch ends where the corrector fails at this arclength step (default: 1e-5)")
    g.add_argument("--max-arclength-step", type=float, default=0.05, dest="max_arclength_step", metavar="DS",
                   help="largest step in scaled arclength (default: 0.05)")
    g.add_argument("--tol", type=float, default=1e-8,
                   help="scaled residual the corrector and the first orbit's Newton stop at (default: 1e-8)")
    g.add_argument("--max-iterations", type=int, default=8, dest="max_iterations", metavar="N",
                   help="corrector iterations per step (default: 8; the first orbit's Newton takes 20)")


def _continuation_settings(args, **extra):
    """The ContinuationSettings of the options of :func:`_add_arclength` (and ``extra`` fields),
    a bad value told by its flag."""
    from ..orbits.continuation import ContinuationSettings

    return _built(ContinuationSettings, {"step": "arclength_step", "min_step": "min_arclength_step",
                                         "max_step": "max_arclength_step", "max_corrector": "max_iterations"},
                  args, step=args.arclength_step, min_step=args.min_arclength_step,
                  max_step=args.max_arclength_step, max_points=args.max_points, tol=args.tol,
                  max_corrector=args.max_iterations, **extra)


def _plot_formats() -> dict[str, str]:
    _plot_modules()
    from matplotlib.backend_bases import FigureCanvasBase

    return FigureCanvasBase.get_supported_filetypes()


def _file_of_kind(kind: str, flag: str, value: str) -> str:
    """``value`` checked for ``kind`` (csv, netcdf, plot, run): the path to use (a missing ending
    gets the default one), or UsageError naming ``flag``."""
    from ..io.files import SUFFIXES, FileFormatError, check_suffix

    if kind == "plot":
        formats = _plot_formats()
        suffix = Path(value).suffix.lower()
        if not suffix:
            return value + ".png"
        if suffix[1:] not in formats:
            raise UsageError(f"{flag} {value}: matplotlib cannot write {suffix} figures; use one of "
                             f"{', '.join('.' + f for f in sorted(formats))}")
        return value
    if kind == "run":
        suffix = Path(value).suffix.lower()
        if suffix not in SUFFIXES["csv"] + SUFFIXES["netcdf"]:
            raise UsageError(f"{flag} {value}: a saved run is a .csv or .nc file written by 'camdyn simulate'")
        return value
    try:
        return check_suffix(value, kind)
    except FileFormatError as exc:
        raise UsageError(f"{flag} {exc}") from None


class _FileOption(argparse.Action):
    """An option naming a file of one kind; checks the kind and records which flag gave it
    (``args.flags[dest]``), so that later messages name the flag the user typed."""

    def __init__(self, option_strings, dest, kind: str, deprecated_for: str | None = None, **kwargs):
        self.kind, self.deprecated_for = kind, deprecated_for
        super().__init__(option_strings, dest, **kwargs)

    def __call__(self, parser, namespace, value, option_string=None):
        if self.deprecated_for:
            print(f"camdyn: {option_string} is deprecated here; use {self.deprecated_for}", file=sys.stderr)
        setattr(namespace, self.dest, _file_of_kind(self.kind, option_string, value))
        flags = dict(getattr(namespace, "flags", None) or {})
        flags[self.dest] = option_string
        namespace.flags = flags


def _add_file(g, flag: str, kind: str, help_: str, *aliases: str, dest: str | None = None, **kw):
    """An option naming a file of one kind (checked when read: see _FileOption)."""
    g.add_argument(flag, *aliases, action=_FileOption, kind=kind, metavar="FILE", dest=dest, help=help_, **kw)
