"""The ``camdyn`` command: simulate, analyse, sweep, regenerate and reproduce from a shell.

Run ``camdyn --help`` for the commands and ``camdyn <command> --help`` for each one's
options and examples.  Everything is SI except where an option's name says otherwise
(``--speed-rpm``, ``--sample-rate-Hz``).

Errors print as one line, ``camdyn: error: ...``, never a traceback (``--traceback``
shows it).  Exit codes, for scripts:

  0  success
  1  a check failed (``regenerate --check``: generated/ differs from what derive/ produces)
  2  bad input: an unknown option or value, an invalid rig or parameter, an unreadable
     or unwritable file, a scene that is not generated, a derive/ edit that makes an
     expression complex (``regenerate``)
  3  a simulation stopped before the end (see its outcome: chatter, angle limit, ...), or
     a sweep has points that did not succeed (not those skipped with --skip-invalid);
     whatever was computed is still written
  4  an optional part is missing: matplotlib for plots (``pip install "camdyn[plot]"``),
     SymPy for regenerate (``camdyn[derive]``), or a module not installed in this version
  5  internal error (a bug in camdyn: please report it with ``--traceback``)
  130 interrupted (Ctrl-C); 141 the output pipe was closed (e.g. ``| head``)
"""
from __future__ import annotations

import argparse
import contextlib
import csv
import importlib
import importlib.util
import inspect
import json
import math
import os
import re
import subprocess
import sys
import threading
import warnings
import time
from pathlib import Path
from typing import NamedTuple

from ..errors import CamdynError

EXIT_OK, EXIT_CHECK_FAILED, EXIT_USAGE, EXIT_INCOMPLETE, EXIT_MISSING, EXIT_INTERNAL = 0, 1, 2, 3, 4, 5
EXIT_INTERRUPTED, EXIT_BROKEN_PIPE = 130, 141

EXIT_CODES_HELP = """exit codes:
  0 success; 1 a check failed (regenerate --check); 2 bad input; 3 a simulation stopped
  early, or sweep points did not succeed (outputs still written); 4 an optional part is
  missing (matplotlib, SymPy, ...); 5 internal error (please report, with --traceback);
  130 interrupted; 141 output pipe closed"""


class UsageError(CamdynError, ValueError):
    """Bad command-line input (exit code 2)."""


class MissingPart(CamdynError):
    """An optional dependency or module is not available (exit code 4)."""


# --------------------------------------------------------------------------- API names and flags
#: names the library's messages use, and the option of a command that sets the same thing (its
#: dest); a name that is a command's dest itself needs no entry
API_TO_DEST = {"transient": "transient_revolutions", "warmup_revolutions": "warmup", "frequency_rpm": "oscillating_rpm",
               "max_corrector": "max_iterations"}
#: the library's option names without an underscore (other words of a message are left as they are)
API_WORDS = ("rtol", "atol", "tol")
#: phrases of the library's advice that name a value, and the option that sets it ({flag}: its flag)
API_PHRASES = {"jacobian=camdyn.orbits.tangent.variational": ("jacobian", "{flag} variational"),
               "ContinuationSettings.min_step": ("min_arclength_step", "{flag}"),
               "ContinuationSettings.max_step": ("max_arclength_step", "{flag}"),
               "ContinuationSettings.max_points": ("max_points", "{flag}"),
               "friction='tanh'": ("friction", "{flag} tanh"), "follower='dynamic'": ("follower", "{flag} dynamic"), "another start value": ("start", "another {flag}")}


def _flags(parser) -> dict[str, str]:
    """dest -> flag (its longest option string) of a (sub)parser's options."""
    return {a.dest: max(a.option_strings, key=len) for a in parser._actions if a.option_strings}


def _in_flags(text: str, args) -> str:
    """``text`` (a message of the library) with the names it gives advice about replaced by the
    command's options that set them (``min_step`` -> ``--min-step``), where it has them."""
    flags = getattr(args, "flags", {})
    for phrase, (dest, form) in API_PHRASES.items():
        if dest in flags:
            text = text.replace(phrase, form.format(flag=flags[dest]))

    def flag(match):
        word = match.group(0)
        if "_" not in word and word not in API_WORDS:
            return word
        return flags.get(API_TO_DEST.get(word, word), word)
    return re.sub(r"(?<![-\w.=])[a-z][a-z0-9]*(?:_[a-zA-Z0-9]+)*(?![\w(=])", flag, text)


def _parameter_line(exc, args, dests: dict[str, str] | None = None) -> str | None:
    """A ParameterError's message with its name as the command's flag (``--transient-revolutions 0
    is out of range ...``, not ``transient = 0 ...``), or None when the command has no such flag;
    ``dests``: the option of each name, where it is not its dest (nor in API_TO_DEST)."""
    flags, dests = getattr(args, "flags", {}), dests or {}
    flag = flags.get(dests.get(exc.name) or API_TO_DEST.get(exc.name, exc.name))
    text = " ".join(str(exc).split())
    if flag is None:
        return None
    for prefix in (f"{exc.name} = ", f"{exc.name} "):
        if text.startswith(prefix):
            return f"{flag} {text[len(prefix):]}"
    return None


def _built(factory, dests: dict[str, str], args, **kwargs):
    """``factory(**kwargs)`` (a settings object), its ParameterError told by the command's flag:
    ``dests`` maps the factory's field names to the options that set them."""
    from ..errors import ParameterError

    try:
        return factory(**kwargs)
    except ParameterError as exc:
        line = _parameter_line(exc, args, dests)
        if line is None:
            raise
        raise UsageError(line) from None


# --------------------------------------------------------------------------- helpers
def _progress_enabled(args) -> bool | None:
    """tqdm's ``disable``: None shows bars only on a terminal; --no-progress hides them."""
    return True if getattr(args, "no_progress", False) else None


class _Share:
    """The share of a long call done, as its progress callback reports it (None: unknown)."""

    def __init__(self):
        self.fraction: float | None = None

    def __call__(self, fraction: float) -> None:
        self.fraction = fraction


@contextlib.contextmanager
def _busy(description: str, args, after: float = 1.0):
    """A bar for one long call, shown once it has taken ``after`` seconds, on a terminal only
    (and never with --no-progress): the percentage done, if the call reports it to the
    :class:`_Share` this yields, and the elapsed time."""
    from tqdm import tqdm

    stop = threading.Event()
    disable = _progress_enabled(args)
    share = _Share()

    def tick():
        if stop.wait(after):
            return
        started = time.monotonic() - after
        bar = tqdm(total=None, bar_format="{desc}", disable=disable, file=sys.stderr, leave=False)
        while True:
            done = "" if share.fraction is None else f"{100 * share.fraction:3.0f} % done, "
            bar.set_description_str(f"{description}: {done}{time.monotonic() - started:.0f} s")
            if stop.wait(0.5):
                break
        bar.close()

    thread = threading.Thread(target=tick, daemon=True)
    thread.start()
    try:
        yield share
    finally:
        stop.set()
        thread.join()


def _parse_values(text: str, name: str) -> list[float]:
    """'a:b:n' (n values from a to b, inclusive), 'a:b:n:log' (geometric) or 'v1,v2,...'."""
    import numpy as np

    try:
        if ":" in text:
            parts = text.split(":")
            if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] != "log"):
                raise ValueError
            a, b, n = float(parts[0]), float(parts[1]), int(parts[2])
            if n < 1:
                raise UsageError(f"{name} {text}: the count (the third field) must be at least 1, got {n}")
            if len(parts) == 4:
                if a <= 0 or b <= 0:
                    raise UsageError(f"{name}: a log range needs positive ends, got {text!r}")
                return [float(v) for v in np.geomspace(a, b, n)]
            return [float(v) for v in np.linspace(a, b, n)]
        values = [float(v) for v in text.split(",") if v.strip()]
        if not values:
            raise ValueError
        return values
    except UsageError:
        raise
    except ValueError:
        raise UsageError(f"{name}: expected 'start:stop:count', 'start:stop:count:log' or 'v1,v2,...', "
                         f"got {text!r}") from None


def _rig(args):
    """The rig of --rig: a shipped preset's name or a .toml file."""
    from ..errors import ParameterError
    from ..model.presets import available, load_rig

    try:
        return load_rig(args.rig)
    except ParameterError as exc:  # not a preset and not a .toml path
        if exc.name != "name":
            raise
        import difflib

        close = difflib.get_close_matches(args.rig, available(), n=1)
        raise UsageError(f"--rig {args.rig}: no shipped rig of that name"
                         + (f" (did you mean {close[0]!r}?)" if close else "")
                         + f"; shipped rigs: {', '.join(available())}, or a rig file ending in .toml") from None


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
                 follower=getattr(args, "follower", "dynamic"))


# --- solvers: the one place the command learns the engine's backend and method names -----------
def _solvers() -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(backends, methods) of the engine: every backend runs every method (one loop)."""
    from ..engine.config import BACKENDS, METHODS

    return BACKENDS, METHODS


def _default_backend() -> str | None:
    """The backend simulate() uses when not told (its keyword's default)."""
    from ..runs.simulation import simulate

    param = inspect.signature(simulate).parameters.get("backend")
    return None if param is None or param.default is inspect.Parameter.empty else param.default


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


def _backend_kwargs(args) -> dict:
    """``backend=`` for simulate() when asked for on the command line."""
    backend = getattr(args, "backend", None)
    return {} if backend is None else {"backend": backend}


class _Run(NamedTuple):
    result: object
    rig: object
    settings: dict


def _simulate(args) -> _Run:
    """One run from the command-line options (cam, scene, run length, solver), with the rig and
    the settings that made it (for the saved run's attributes)."""
    from ..io.metadata import describe_cam, describe_scene
    from ..runs.simulation import simulate

    cam = _cam(args)
    scene = _scene(args, cam.kind)
    options = _solver_options(args)
    kwargs = dict(sample_rate_Hz=args.sample_rate_Hz, method=options.method, rtol=options.rtol, atol=options.atol,
                  **({"max_step": options.max_step} if math.isfinite(options.max_step) else {}),
                  **({"events": options.events} if args.max_events != 1_000_000 else {}), **_backend_kwargs(args))
    if args.t_end is not None:
        kwargs["t_end"] = args.t_end
    elif not math.isfinite(cam.period):
        raise UsageError(f"--speed-rpm {args.speed_rpm:g} holds the cam still: with no cam period, the run "
                         "length cannot be counted in --revolutions; give it in seconds with --t-end SECONDS")
    else:
        kwargs["revolutions"] = args.revolutions
    rig = _rig(args)
    with _busy(f"simulating {describe_scene(scene)}, {describe_cam(cam)}", args) as share:
        result = simulate(rig, scene, cam, progress=share, **kwargs)
    settings = {"backend": _default_backend(), **kwargs}
    return _Run(result, rig, settings)


def _plot_modules():
    """camdyn.io.plots with a non-interactive backend (files only), or MissingPart."""
    try:
        import matplotlib
    except ImportError:
        raise MissingPart("plots need matplotlib, which is not installed: pip install \"camdyn[plot]\"") from None
    matplotlib.use("Agg")
    from ..io import plots

    return plots


def _save_figure(fig, path: str) -> None:
    fig.savefig(path)
    import matplotlib.pyplot as plt

    plt.close(fig)
    print(f"  wrote {path}")


# --- file options: their kind is checked while the command line is read, before any work -------
_KINDS = {"csv": "a CSV file", "netcdf": "a NetCDF file", "plot": "a figure", "run": "a saved run"}


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


def _flag(args, name: str) -> str:
    return (getattr(args, "flags", None) or {}).get(name, "--" + name.replace("_", "-"))


def _check_outputs(args, *names: str) -> None:
    """Fail before a long run, not after it: output folders must exist, plots need matplotlib."""
    for name in names:
        path = getattr(args, name, None)
        if not path:
            continue
        folder = Path(path).resolve().parent
        if not folder.is_dir():
            raise UsageError(f"{_flag(args, name)} {path}: folder {folder} does not exist")
        if not os.access(folder, os.W_OK):
            raise UsageError(f"{_flag(args, name)} {path}: folder {folder} is not writable")
    if getattr(args, "plot", None):
        _plot_modules()


def _version() -> str:
    from .. import __version__

    return __version__


# --------------------------------------------------------------------------- commands
def cmd_simulate(args) -> int:
    from ..analysis.statics import residual_stats
    from ..io.files import write_csv, write_netcdf

    _check_outputs(args, "csv", "netcdf", "plot")
    run = _simulate(args)
    result = run.result
    print(result.summary())
    if result.t.size > 1 and math.isfinite(result.period):
        transient = min(args.transient_revolutions, max(0.0, (result.t[-1] - result.t[0]) / result.period - 1e-9))
        stats = residual_stats(result, transient_revolutions=transient)
        print(f"  alpha_r: rms {stats.rms:.6g} rad, peak-to-peak {stats.peak_to_peak:.6g} rad"
              + (f" (after {transient:g} revolutions)" if transient else ""))
    if args.csv:
        write_csv(result, args.csv)
        print(f"  wrote {args.csv}")
    if args.netcdf:
        write_netcdf(result, args.netcdf, run.rig, settings=run.settings,
                     attrs={"command": " ".join(["camdyn"] + (args.argv or []))})
        print(f"  wrote {args.netcdf}")
    if args.plot:
        plots = _plot_modules()
        _save_figure(plots.overview(result), args.plot)
    if not result.ok:
        print(f"camdyn: the run stopped early: {_in_flags(result.outcome.message, args)}", file=sys.stderr)
        return EXIT_INCOMPLETE
    return EXIT_OK


class _Series:
    """A minimal stand-in for a Result (t, period and one quantity) for spectra of saved runs."""

    scene = None

    def __init__(self, t, period, **values):
        self.t, self.period, self._values = t, period, values

    def __getattr__(self, name):
        values = self.__dict__.get("_values", {})
        if name in values:
            return values[name]
        raise AttributeError(name)

    def after(self, t0):
        keep = self.t >= t0
        return _Series(self.t[keep], self.period, **{k: v[keep] for k, v in self._values.items()})


def cmd_spectrum(args) -> int:
    import numpy as np

    from ..analysis import signal
    from ..io.metadata import units

    _check_outputs(args, "csv", "plot")
    natural = None
    status = EXIT_OK
    if args.input:
        from ..io.files import read_series

        t, x, period = read_series(args.input, args.quantity)
        source = _Series(t, period, **{args.quantity: x})
    else:
        result = _simulate(args).result
        print(result.summary())
        if not result.ok:
            print(f"camdyn: the run stopped early: {result.outcome.message}", file=sys.stderr)
            status = EXIT_INCOMPLETE
        source, period = result, result.period
        if args.speed_rpm is not None:  # the linearization about the static equilibrium (Eq. 23)
            from ..analysis.statics import natural_frequency
            from ..model.cam import ConstantSpeed

            try:
                natural = natural_frequency(_rig(args), _scene(args), ConstantSpeed(args.speed_rpm)).Hz
            except CamdynError:
                natural = None
    transient = args.transient_revolutions if math.isfinite(period) else 0.0
    t = np.asarray(source.t, dtype=float)
    if transient and transient * period >= t[-1] - t[0]:
        raise UsageError(f"--transient-revolutions {transient:g} drops the whole run "
                         f"({(t[-1] - t[0]) / period:.3g} revolutions)")
    keep = signal.whole_periods(t, period, transient)  # after the transient; cam harmonics on bins
    values = np.asarray(getattr(source, args.quantity), dtype=float)[keep]
    times = t[keep]
    source = source.after(times[0])  # the plot takes the same whole periods from here
    f, amp = signal.spectrum(times, values)
    periods = values.size * (times[1] - times[0]) / period if math.isfinite(period) else math.nan
    f0 = 1 / period if math.isfinite(period) else math.nan
    print(f"spectrum of {args.quantity}: {values.size} samples"
          + (f" ({round(periods)} cam periods, to the nearest sample)" if math.isfinite(periods) else "")
          + f", resolution {f[1] - f[0]:.4g} Hz, "
          f"up to {f[-1]:.6g} Hz" + (f"; cam frequency Omega_c = {f0:.6g} Hz" if math.isfinite(f0) else ""))
    if natural:
        print(f"  linearized natural frequency (Eq. 23): {natural:.6g} Hz")
    fmax = args.fmax if args.fmax is not None else f[-1]
    band = (f > 0) & (f <= fmax)
    peaks = np.flatnonzero((amp[1:-1] > amp[:-2]) & (amp[1:-1] >= amp[2:])) + 1
    peaks = peaks[band[peaks]]
    peaks = peaks[np.argsort(amp[peaks])[::-1][:args.peaks]]
    unit = units(args.quantity)
    for k in sorted(peaks, key=lambda i: f[i]):
        fk = signal.peak_frequency(f, amp, fmin=f[k], fmax=f[k])  # bin k, refined with its neighbours
        order = f"  = {fk / f0:.3f} x Omega_c" if math.isfinite(f0) else ""
        print(f"  peak {fk:12.6g} Hz  amplitude {amp[k]:.4g} {unit}{order}")
    if args.csv:
        with open(args.csv, "w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(["f (Hz)", f"amplitude of {args.quantity}" + (f" ({unit})" if unit else "")])
            for fi, ai in zip(f, amp):
                writer.writerow([repr(float(fi)), repr(float(ai))])
        print(f"  wrote {args.csv}")
    if args.plot:
        plots = _plot_modules()
        bands = [tuple(b) for b in args.band] if args.band else None
        marks = {r"$\vartheta$ (Eq. 23)": natural} if natural else None
        fig = plots.spectrum(source, args.quantity, bands=bands, fmax=args.fmax, mark_Hz=marks)
        _save_figure(fig, args.plot)
    return status


def cmd_equilibrium(args) -> int:
    from ..analysis.statics import natural_frequency, static_equilibrium
    from ..model.cam import ConstantSpeed

    rig = _rig(args)
    eq = static_equilibrium(rig, args.contact)
    nf = natural_frequency(rig, _scene(args), ConstantSpeed(args.speed_rpm))
    out = {"alpha_star_rad": eq.alpha, "psi_i_star_m": eq.psi_i, "psi_j_star_m": eq.psi_j, "chi_star_m": eq.chi,
           "contact_stiffness_N_per_m": eq.contact_stiffness, "natural_frequency_Hz": nf.Hz,
           "natural_frequency_rad_s": nf.damped_rad_s, "undamped_natural_frequency_Hz": nf.undamped_Hz,
           "damping_ratio": nf.damping_ratio, "regime": nf.regime}
    print(json.dumps(out, indent=2))
    return EXIT_OK


def cmd_contact_loss(args) -> int:
    from ..analysis.statics import contact_loss_speed

    rig = _rig(args)
    if args.k_s:
        values = _parse_values(args.k_s, "--k-s")
        rows = [(k, contact_loss_speed(rig.replace(k_s=k))) for k in values]
        print("k_s (N/m),contact_loss_speed (rev/min)")
        for k, v in rows:
            print(f"{k:.6g},{v:.6g}")
    else:
        print(f"{contact_loss_speed(rig):.6g}")
    return EXIT_OK


def cmd_lyapunov(args) -> int:
    from ..orbits.lyapunov import LyapunovSettings, lyapunov_exponents
    from ..io.metadata import describe_cam, describe_scene

    cam = _cam(args)
    scene = _scene(args, cam.kind)
    settings = LyapunovSettings(args.revolutions, args.transient_revolutions, args.batches)
    options = _solver_options(args)
    rig = _rig(args)
    with _busy(f"Lyapunov exponents of {describe_scene(scene)}, {describe_cam(cam)}", args):
        L = lyapunov_exponents(rig, scene, cam, settings=settings, options=options, **_backend_kwargs(args))
    if args.json:
        print(json.dumps({"exponents_per_s": [float(x) for x in L.exponents],
                          "standard_error_per_s": [float(x) for x in L.standard_error],
                          "per_revolution": [float(x) for x in L.per_revolution], "period_s": L.period,
                          "revolutions": L.revolutions, "transient_revolutions": L.transient,
                          "divergence_mean_per_s": L.divergence_mean, "saltation_rate_per_s": L.saltation_rate,
                          "switches": L.switches}, indent=2))
        return EXIT_OK
    for i, (lam, se, rev) in enumerate(zip(L.exponents, L.standard_error, L.per_revolution), start=1):
        print(f"lambda_{i} = {lam:.6g} 1/s +- {se:.2g} (standard error), {rev:.6g} per revolution")
    print(f"over {L.revolutions} revolutions after {L.transient} of transient, {L.switches} switches")
    return EXIT_OK


# --- continue --------------------------------------------------------------------------
def cmd_continue(args) -> int:
    from ..orbits.continuation import SPEED, ContinuationOutcome, ContinuationSettings, continue_orbit, events_table

    rig, scene = _rig(args), _scene(args)
    if args.param != SPEED and args.speed_rpm is None:
        raise UsageError(f"--param {args.param} is continued at a constant cam speed: give --speed-rpm")
    if args.param == SPEED and args.speed_rpm is not None:
        raise UsageError("--speed-rpm is for a rig parameter's continuation; the speed itself runs from --start "
                         "to --end")
    _check_outputs(args, "netcdf", "plot")
    settings = _built(ContinuationSettings, {"step": "arclength_step", "min_step": "min_arclength_step",
                                             "max_step": "max_arclength_step", "max_corrector": "max_iterations"},
                      args, step=args.arclength_step, min_step=args.min_arclength_step,
                      max_step=args.max_arclength_step, max_points=args.max_points, tol=args.tol,
                      max_corrector=args.max_iterations, switch_depth=args.switch_depth)
    kwargs = dict(speed_rpm=args.speed_rpm, periods=args.periods, phase_fraction=args.phase_fraction,
                  warmup_revolutions=args.warmup, settings=settings, options=_solver_options(args),
                  **_backend_kwargs(args))
    if args.jacobian == "variational":
        from ..orbits.tangent import variational
        kwargs["jacobian"] = variational
    with _busy("continuing the branch", args):
        ds = continue_orbit(rig, scene, args.param, args.start, args.end, **kwargs)
    unit = ds.attrs["parameter_units"]
    print(f"continuation of {scene.slug} on rig {rig.name!r} in {args.param} ({unit}): {ds.sizes['point']} orbits "
          f"on {ds.sizes['branch']} branch(es)")
    for i in range(ds.sizes["branch"]):
        print(f"  branch {i} (period {int(ds['branch_periods'][i])} T): "
              f"{_in_flags(ds.attrs[f'branch_{i}_message'], args)}")
    print("event,parameter,branch,point" if ds.sizes["event"] else "no events")
    for kind, lam, branch, point in events_table(ds):
        print(f"{kind},{lam:.8g},{branch},{point}")
    if args.netcdf:
        ds.to_netcdf(args.netcdf, engine="scipy")
        print(f"  wrote {args.netcdf}")
    if args.plot:
        _save_figure(_plot_modules().branches(ds), args.plot)
    started = int(ds["branch_outcome"][0]) != list(ContinuationOutcome).index(ContinuationOutcome.START_FAILED)
    return EXIT_OK if started else EXIT_INCOMPLETE


# --- sweep ---------------------------------------------------------------------------
def _sweep_module():
    try:
        return importlib.import_module("camdyn.sweep.api")
    except ImportError as exc:
        if getattr(exc, "name", None) in ("camdyn.sweep.api", None):
            raise MissingPart("sweeps (camdyn.sweep.api) are not part of this version of camdyn") from None
        raise


@contextlib.contextmanager
def _executor(args, sweeps):
    """None (serial), a local process pool (--jobs N: its workers end with this process, even
    killed), or a dask cluster (--dask ADDRESS)."""
    if args.dask:
        try:
            from distributed import Client
        except ImportError:
            raise MissingPart("--dask needs dask.distributed: pip install \"dask[distributed]\"") from None
        with Client(args.dask) as client:
            yield client.get_executor()
    elif args.jobs > 1:
        with sweeps.process_pool(args.jobs) as pool:
            yield pool
    else:
        yield None


def _outcome_names(ds) -> dict[int, str]:
    text = ds.attrs.get("outcome_codes", "")
    pairs = [item.strip().split("=") for item in text.split(",") if "=" in item]
    return {int(code): name for code, name in pairs}


def cmd_sweep(args) -> int:
    sweeps = _sweep_module()
    if args.resume:
        return _resume_sweep(sweeps, args)
    if not args.speeds:
        raise UsageError("give --speeds (a new sweep) or --resume FILE (continue one)")
    rig, scene = _rig(args), _scene(args)
    speeds = _parse_values(args.speeds, "--speeds")
    param = args.param
    if param and args.values is None:
        raise UsageError("--param needs --values")
    if not param and args.values:
        raise UsageError("--values needs --param (the rig parameter to vary)")
    values = _parse_values(args.values, "--values") if param else None
    if param:
        from ..model.rig import PARAMETERS

        if param not in {p.name for p in PARAMETERS}:
            raise UsageError(f"--param {param!r} is not a rig parameter; one of "
                             f"{', '.join(p.name for p in PARAMETERS)}")
    if args.transient_revolutions >= args.revolutions:
        raise UsageError("--transient-revolutions must be less than --revolutions")
    if args.samples_per_revolution < 1:
        raise UsageError("--samples-per-revolution must be at least 1")
    _check_outputs(args, "out", "plot")
    solver = dict(method=args.method, rtol=args.rtol, atol=args.atol)
    if args.backend:
        solver["backend"] = args.backend
    with _executor(args, sweeps) as executor, _sweep_interrupted(args, args.out):
        common = dict(executor=executor, progress=_sweep_progress(args), out=args.out, overwrite=args.overwrite,
                      invalid="skip" if args.skip_invalid else "raise", **solver)
        try:
            ds = _new_sweep(sweeps, args, rig, scene, speeds, values, common)
        except sweeps.InvalidGridError as exc:
            print(str(exc).split("\n", 1)[1], file=sys.stderr)  # every invalid point, one a line
            raise UsageError(f"{len(exc.invalid)} of {exc.size} grid points are invalid (listed above); "
                             "--skip-invalid runs the others") from None
    if args.out:
        print(f"  wrote {args.out}")
    return _sweep_report(ds, args, sweeps, args.out)


def _resume_sweep(sweeps, args) -> int:
    """--resume FILE: the sweep's own grid, rig, scene and settings; the options that say how to
    run it apply, and any other option typed must match the sweep's (else it is refused)."""
    attrs, grid = sweeps.settings_of(args.resume)   # a file that is not a sweep is refused here
    applied, matched = _resume_options(args, attrs, grid, sweeps)
    _check_outputs(args, "plot")
    running = sweeps.parts_folder(args.resume).exists()
    if running:
        sweeps.refuse_if_in_use(args.resume)
        print(f"  resuming {args.resume} with its own grid, rig, scene and settings"
              + (f"; applied: {', '.join(applied)}" if applied else "")
              + (f"; the same as the sweep's: {', '.join(matched)}" if matched else ""))
    with _executor(args, sweeps) as executor, _sweep_interrupted(args, args.resume):
        ds = sweeps.resume(args.resume, executor=executor, progress=_sweep_progress(args))
    print(f"  wrote {args.resume}" if running else f"  {args.resume} was complete: nothing to run")
    return _sweep_report(ds, args, sweeps, args.resume)


#: sweep options that say how to run a resumed sweep, or what to draw: --resume applies them
_RESUME_APPLIES = ("resume", "jobs", "dask", "plot")


def _resume_options(args, attrs: dict, grid: dict, sweeps) -> tuple[list[str], list[str]]:
    """(the options typed that --resume applies, those that match the sweep's own settings);
    UsageError naming the first that differs from the sweep's (or that makes no sense there)."""
    applied, matched = [], []
    recorded = _recorded_settings(attrs, grid, args.resume, sweeps)
    for dest in _typed_options(args):
        flag = _flag(args, dest)
        if dest in _RESUME_APPLIES:
            applied += [] if dest == "resume" else [_shown_option(args, dest, flag)]
        elif dest not in recorded:
            raise UsageError(f"{flag} starts a new sweep: it does not go with --resume, which continues "
                             f"{args.resume} as it was started")
        elif not _same_setting(typed := _typed_setting(args, dest), recorded[dest]):
            raise UsageError(f"{_shown_option(args, dest, flag)}: {args.resume} was swept "
                             f"{_recorded_text(dest, recorded[dest], typed)}; --resume takes every setting from "
                             f"it: drop {flag} (or start a new sweep to change it)")
        else:
            matched.append(flag)
    return applied, matched


def _typed_options(args) -> list[str]:
    """The sweep options typed on the command line (dests), not their defaults: the command line
    read again with every default of the command suppressed."""
    parser = _parser()
    command = parser.commands[args.command]
    argv = getattr(args, "argv", None)
    if argv is None:   # called without main(): the options that differ from their defaults
        return [a.dest for a in command._actions if a.dest != "help" and getattr(args, a.dest, None) != a.default]
    for action in command._actions:
        action.default = argparse.SUPPRESS
        if isinstance(action, _FileOption):
            action.deprecated_for = None   # said once already
    typed = parser.parse_args(argv)
    return [a.dest for a in command._actions if a.dest != "help" and hasattr(typed, a.dest)]


def _recorded_settings(attrs: dict, grid: dict, out: str, sweeps) -> dict:
    """The resumed sweep's settings as the sweep options would give them, by option dest."""
    import dataclasses

    from ..model.scene import Scene

    param = next((name for name in grid if name != "speed_rpm"), None)
    recorded = {f.name: attrs.get(f"scene_{f.name}") for f in dataclasses.fields(Scene)}
    recorded.update({name: attrs.get(f"simulate_{name}") for name in ("revolutions", "method", "rtol", "atol",
                                                                         "backend")})
    recorded.update(transient_revolutions=attrs.get("measure_transient_revolutions"),
                    samples_per_revolution=attrs.get("samples_per_revolution"), no_stop="simulate_stop" not in attrs,
                    speeds=grid.get("speed_rpm"), param=param, values=grid.get(param), out=Path(out),
                    rig=sweeps.rig_of(attrs))
    return recorded


def _typed_setting(args, dest: str):
    """An option's value in the terms of :func:`_recorded_settings`."""
    if dest == "rig":
        return _rig(args)
    if dest in ("speeds", "values"):
        return _parse_values(getattr(args, dest), "--" + dest)
    return Path(args.out) if dest == "out" else getattr(args, dest)


def _same_setting(typed, recorded) -> bool:
    import numpy as np

    from ..model.rig import PARAMETERS

    if hasattr(recorded, "k_s"):  # a rig: the same physics (its name may differ)
        return all(getattr(typed, p.name) == getattr(recorded, p.name) for p in PARAMETERS)
    if isinstance(recorded, Path):
        return typed.resolve() == recorded.resolve()
    if isinstance(typed, list) or isinstance(recorded, np.ndarray):
        return recorded is not None and np.array_equal(np.asarray(typed, dtype=float), np.asarray(recorded))
    if isinstance(typed, (int, float)) and not isinstance(typed, bool) and recorded is not None:
        return not isinstance(recorded, str) and float(typed) == float(recorded)
    return typed == recorded


def _shown_option(args, dest: str, flag: str) -> str:
    value = getattr(args, dest)
    return flag if isinstance(value, bool) else f"{flag} {value}"


def _recorded_text(dest: str, value, typed) -> str:
    """How the resumed sweep was run, for 'FILE was swept ...' (``typed``: the option's value)."""
    import numpy as np

    from ..model.rig import PARAMETERS

    if hasattr(value, "k_s"):
        name = next(p.name for p in PARAMETERS if getattr(typed, p.name) != getattr(value, p.name))
        return f"on rig {value.name!r}, whose {name} is {getattr(value, name)!r} (not {getattr(typed, name)!r})"
    if isinstance(value, bool):
        return "with it" if value else "without it"
    if isinstance(value, Path):
        return f"into {value}"
    if isinstance(value, np.ndarray):
        return f"over {value.size} values of {dest}, {value.min():g} to {value.max():g}"
    if value is None:
        return f"without {dest}"
    return f"with {dest} = " + (repr(value) if isinstance(value, str) else f"{value:g}")


def _resume_command(args, out) -> str:
    """The command that resumes ``out`` with the options of this one that say how to run it."""
    import shlex

    words = ["camdyn"] + (["--no-progress"] if args.no_progress else []) + ["sweep", "--resume", str(out)]
    words += (["--jobs", str(args.jobs)] if args.jobs > 1 else []) + (["--dask", args.dask] if args.dask else [])
    words += ["--plot", args.plot] if args.plot else []
    return shlex.join(words)


def _new_sweep(sweeps, args, rig, scene, speeds, values, common):
    """The sweep the options ask for: bifurcation (--speeds only), contact map (--param k_s), or
    the same map over another rig parameter."""
    param = args.param
    if not param:
        revolutions, transient = args.revolutions, args.transient_revolutions
        if revolutions != int(revolutions) or transient != int(transient):
            raise UsageError("a bifurcation sweep needs whole --revolutions and --transient-revolutions")
        stop = None if args.no_stop else sweeps.StopWhenPeriodic()
        return sweeps.bifurcation(rig, scene, speeds, revolutions=int(revolutions),
                                  transient_revolutions=int(transient), stop=stop, **common)
    if param == "k_s":
        return sweeps.contact_loss_map(rig, scene, values, speeds, revolutions=args.revolutions,
                                       transient_revolutions=args.transient_revolutions,
                                       samples_per_revolution=args.samples_per_revolution, **common)
    return sweeps.sweep(rig, scene, {param: values, "speed_rpm": speeds}, sweeps.Summary(args.transient_revolutions),
                        revolutions=args.revolutions, samples_per_revolution=args.samples_per_revolution, **common)


def _sweep_progress(args) -> bool:
    return not args.no_progress and sys.stderr.isatty()


@contextlib.contextmanager
def _sweep_interrupted(args, out):
    """On Ctrl-C, say where the finished points are and how to go on (with this run's options)."""
    try:
        yield
    except KeyboardInterrupt:
        if out:
            print(f"camdyn: the finished points are kept in {out}.parts; '{_resume_command(args, out)}' runs the rest",
                  file=sys.stderr)
        raise


def _sweep_report(ds, args, sweeps, out) -> int:
    """Print what the sweep found, plot it; exit 3 if a point did not succeed (a point skipped as
    INVALID, as --skip-invalid asked, is not a failure)."""
    import numpy as np

    rig, scene = sweeps.rig_of(ds.attrs), sweeps.scene_of(ds.attrs)
    names = _outcome_names(ds)
    codes = {name: code for code, name in names.items()}
    outcome = ds["outcome"].values
    ok, skipped = outcome == codes.get("SUCCESS", 0), outcome == codes.get("INVALID")
    impacts = ds["impacts_per_rev"].values if "impacts_per_rev" in ds else np.zeros(ok.shape)  # an API sweep's measure
    impacting = np.nan_to_num(impacts) > 0
    regimes = np.where(ok, np.where(impacting, "impacting", "sliding"), np.where(skipped, "skipped", "failed"))
    failed = int(np.sum(~ok & ~skipped))
    print(f"sweep of {scene.slug} on rig {rig.name!r}: {outcome.size} points, "
          f"{int(np.sum(ok & ~impacting))} without impacts after the transient, {int(np.sum(ok & impacting))} "
          f"impacting, " + (f"{int(np.sum(skipped))} skipped as invalid (--skip-invalid), " if skipped.any() else "")
          + f"{failed} did not succeed")
    for code in sorted(set(outcome.ravel().tolist()) - {codes.get("SUCCESS", 0)}):
        print(f"  {int(np.sum(outcome == code))} {names.get(int(code), code)}")
    if "revolutions_run_total" in ds.attrs:
        print(f"  {sweeps.stop_summary(ds)}")
    not_run = int(np.sum(outcome == codes.get("NOT_RUN")))
    if not_run and out:
        print(f"  the {not_run} NOT_RUN points are kept for later: '{_resume_command(args, out)}' runs them")
    if args.plot:
        if "alpha_section" not in ds and (ds["outcome"].ndim != 2 or "speed_rpm" not in ds.dims):
            raise UsageError("--plot draws a bifurcation sweep or a (parameter, speed_rpm) map, not this sweep")
        _save_figure(_sweep_plot(ds, rig, scene, regimes), args.plot)
    return EXIT_INCOMPLETE if failed else EXIT_OK


def _sweep_plot(ds, rig, scene, regimes):
    """The bifurcation diagram or the map; points skipped as invalid are left out of its axes."""
    from ..io.metadata import describe_scene

    plots = _plot_modules()
    title = f"{describe_scene(scene)}, rig {rig.name}"
    speeds = ds["speed_rpm"].values
    if "alpha_section" not in ds:
        param = next(name for name in ds.attrs["grid"].split() if name != "speed_rpm")
        values = ds[param].values
        loss = (ds["loss_speed_predicted"].values, ds["k_s"].values) if "loss_speed_predicted" in ds else None
        fig = plots.contact_map(speeds, values, regimes.reshape(len(values), len(speeds)), loss_curve=loss,
                                log_k=param == "k_s", title=title)
        if param != "k_s":
            fig.axes[0].set_ylabel(param)
        return fig
    from ..analysis.statics import contact_loss_speed, static_equilibrium

    alpha_star = static_equilibrium(rig, scene.contact).alpha
    span = f"{ds.attrs.get('measure_transient_revolutions', 0):g}-{ds.attrs.get('simulate_revolutions', 0):g}"
    ran = regimes != "skipped"
    return plots.bifurcation(speeds[ran], ds["alpha_section"].values[ran], relative_to=alpha_star,
                             contact_loss_rpm=contact_loss_speed(rig), title=f"{title}: revolutions {span}")


# --- regenerate ----------------------------------------------------------------------
_REGENERATE = r'''
import importlib, sys
from pathlib import Path
derive_dir, out, check_only, jobs = sys.argv[1], Path(sys.argv[2]), sys.argv[3] == "1", int(sys.argv[4])
if derive_dir:
    sys.path.insert(0, str(Path(derive_dir).resolve().parent))
    package = Path(derive_dir).resolve().name
else:
    package = "camdyn.derive"
try:
    import sympy  # noqa: F401
except ImportError:
    print("camdyn: error: regenerate needs SymPy: pip install \"camdyn[derive]\"", file=sys.stderr)
    sys.exit(4)
writer = importlib.import_module(package + ".writer")
catalog = importlib.import_module(package + ".catalog")
codegen = importlib.import_module(package + ".codegen")
from tqdm import tqdm
specs = tuple(sorted(set(catalog.CATALOG), key=lambda s: s.slug))
bar = dict(total=len(specs), desc="deriving scenes", unit="scene", file=sys.stderr, disable=None)
try:
    files = writer.render(specs, jobs=jobs, progress=lambda done: tqdm(done, **bar))
except codegen.ComplexExpressionError as exc:  # the edit made a law complex: nothing is written
    print(f"camdyn: error: {exc}", file=sys.stderr)
    sys.exit(2)
if not check_only:
    changed = writer.write(files, out)
    print(f"{len(files)} files generated in {out}; changed: {', '.join(changed) or 'none'}")
problems = writer.check(files, out)
for p in problems:
    print(p, file=sys.stderr)
print(f"drift check: {len(files)} files " + ("in sync with derive/" if not problems else f"-- {len(problems)} differ"))
sys.exit(1 if problems else 0)
'''

_IMPORT_CHECK = r'''
import importlib.util, sys
from pathlib import Path
out = Path(sys.argv[1])
name = "camdyn_regenerated_check"
spec = importlib.util.spec_from_file_location(name, out / "__init__.py", submodule_search_locations=[str(out)])
pkg = importlib.util.module_from_spec(spec); sys.modules[name] = pkg; spec.loader.exec_module(pkg)
bad = []
for slug, module in sorted(pkg.SCENES.items()):
    try:
        m = importlib.import_module(name + "." + module)
        assert m.SLUG == slug, f"{module}.SLUG is {m.SLUG!r}"
        if m.VARIATIONAL is not None:
            v = importlib.import_module(name + "." + m.VARIATIONAL)
            assert v.SLUG == slug and v.PARAMS == m.PARAMS, f"{m.VARIATIONAL} is not {module}'s companion"
    except Exception as exc:
        bad.append(f"{module}: {type(exc).__name__}: {exc}")
if "sympy" in sys.modules:
    bad.append("the generated code imports SymPy")
for b in bad:
    print(b, file=sys.stderr)
print(f"import check: {len(pkg.SCENES) - len(bad)} of {len(pkg.SCENES)} scene modules import without SymPy")
sys.exit(1 if bad else 0)
'''


def _default_generated() -> Path:
    from .. import generated

    return Path(generated.__file__).resolve().parent


def cmd_regenerate(args) -> int:
    if args.derive:
        derive_dir = Path(args.derive)
        if not (derive_dir / "writer.py").is_file() or not (derive_dir / "catalog.py").is_file():
            raise UsageError(f"--derive {args.derive}: not a camdyn derive/ folder (no writer.py and catalog.py)")
        out = Path(args.out) if args.out else derive_dir.resolve().parent / "generated"
    else:
        out = Path(args.out) if args.out else _default_generated()
    if args.check and not out.is_dir():
        raise UsageError(f"{out}: no generated package to check")
    jobs = args.jobs or (os.cpu_count() or 1)
    code = subprocess.call([sys.executable, "-c", _REGENERATE, str(args.derive or ""), str(out),
                            "1" if args.check else "0", str(jobs)])
    if code != 0:
        return {4: EXIT_MISSING, 1: EXIT_CHECK_FAILED, 2: EXIT_USAGE}.get(code, EXIT_INTERNAL)
    code = subprocess.call([sys.executable, "-c", _IMPORT_CHECK, str(out)])
    if code != 0:
        return EXIT_CHECK_FAILED
    if not _regenerates_own_package(args, out):
        if not args.check:
            print(f"  the scenes in {out} are not camdyn.generated; see docs/model-editing.md to use them")
        return EXIT_OK
    return _neutral_values_in_presets(args.check)


def _regenerates_own_package(args, out: Path) -> bool:
    """Whether this regenerate derives camdyn.derive into camdyn.generated (not a copy)."""
    own_derive = Path(importlib.util.find_spec("camdyn.derive").submodule_search_locations[0]).resolve()
    return out.resolve() == _default_generated() and (not args.derive or Path(args.derive).resolve() == own_derive)


def _neutral_values_in_presets(check: bool) -> int:
    """The shipped rig files give every parameter declared with a neutral value (the value that
    gives the paper's law, camdyn.vocabulary.parameters): write the missing ones and say so, or,
    with --check, fail while one is missing."""
    from ..model import presets

    if check:
        lacking = presets.lacking_neutral_values()
        for path, names in lacking.items():
            print(f"{path.name}: does not give {', '.join(names)} (declared with a neutral value in "
                  "camdyn/vocabulary/parameters.py): run camdyn regenerate", file=sys.stderr)
        print(f"presets check: {len(presets.preset_files()) - len(lacking)} of {len(presets.preset_files())} "
              "shipped rig files give every parameter declared with a neutral value")
        return EXIT_CHECK_FAILED if lacking else EXIT_OK
    for path, names in presets.add_neutral_values().items():
        values = ", ".join(f"{n} = {presets.NEUTRAL[n]!r}" for n in names)
        print(f"updated the shipped rig {path}: added {values}, the neutral value declared in "
              "camdyn/vocabulary/parameters.py (the paper's law), so the scenes that read it run this rig as before")
    return EXIT_OK


# --- reproduce -----------------------------------------------------------------------
def _studies_module():
    try:
        return importlib.import_module("camdyn.studies")
    except ImportError as exc:
        if getattr(exc, "name", None) and not str(exc.name).startswith("camdyn.studies"):
            raise
        raise MissingPart("the paper's studies (camdyn.studies) are not part of this version of camdyn") from None


def cmd_reproduce(args) -> int:
    studies = _studies_module()
    names = list(studies.STUDIES)
    if args.list or args.study in (None, "list"):
        for name, (_, text) in studies.STUDIES.items():
            print(f"{name:14s} {text}")
        if args.study is None and not args.list:
            print("run one with: camdyn reproduce <study> [--fast] (or 'all')")
        return EXIT_OK
    if args.study not in names + ["all"]:
        import difflib

        close = difflib.get_close_matches(args.study, names, n=1)
        raise UsageError(f"no study {args.study!r}" + (f" (did you mean {close[0]!r}?)" if close else "")
                         + f"; one of: {', '.join(names)}, all")
    quiet = args.json or args.study == "numbers"
    log = (lambda *a, **k: print(*a, file=sys.stderr, **k)) if quiet else print
    from ..studies.common import to_json

    for name in names if args.study == "all" else [args.study]:
        output = studies.run(name, fast=True if args.fast else None, out=args.out, write_docs=not args.no_docs,
                             data_dir=args.data_dir, log=log)
        if quiet:
            print(to_json(output.numbers))
        else:
            for figure in output.figures:
                print(f"wrote {figure}")
    return EXIT_OK


def cmd_scenes(args) -> int:
    from .. import generated
    from ..model import presets

    if args.json:
        print(json.dumps({"scenes": sorted(generated.SCENES), "rigs": presets.available(),
                          "options": {k: list(v) for k, v in _options().items()}}, indent=2))
        return EXIT_OK
    print("generated scenes (contact_damping_friction_motion_model[_vrprinted][_printedsign][_memoryless]):")
    for slug in sorted(generated.SCENES):
        print(f"  {slug}")
    print("shipped rigs: " + ", ".join(presets.available()) + "  (or a path to a .toml rig file)")
    return EXIT_OK


def cmd_cache(args) -> int:
    """List camdyn's caches of this user (compiled code, scenes derived on demand), or clear them."""
    from ..model import ondemand
    from ..engine import cache

    if args.clear or args.clear_stale:
        removed = cache.clear(stale_only=args.clear_stale)
        removed += ondemand.clear(stale_only=args.clear_stale)
        print(f"removed {len(removed)} cache folder(s)" + "".join(f"\n  {d}" for d in removed))
        return EXIT_OK
    entries = cache.entries()
    print(f"camdyn's compiled code for this user: {cache.user_cache_root()} (set {cache.ENV} to move it)")
    if not entries:
        print("  empty: the first run compiles the engine")
    for folder, size, current in entries:
        print(f"  {folder.name}  {size / 1e6:.1f} MB  {'current' if current else 'stale (another camdyn or engine)'}")
    scenes = ondemand.entries()
    print(f"scenes derived on demand: {ondemand.scenes_root()}")
    if not scenes:
        print("  none: a scene outside the catalog is derived on first use")
    for folder, slugs, current in scenes:
        state = "current" if current else "stale (another derivation or SymPy)"
        print(f"  {folder.name}  {state}: {', '.join(slugs) or 'no scenes'}")
    return EXIT_OK


# --------------------------------------------------------------------------- parser
class _Parser(argparse.ArgumentParser):
    """argparse that raises UsageError (one line, exit 2) instead of printing usage and exiting;
    misspelled options and values get a suggestion, and the help pointed at is the command's."""

    commands: dict | None = None  # command name -> its parser (set on the top-level parser)

    def error(self, message):
        raise UsageError(f"{message}{_suggest_choice(message)} (see '{self.prog} --help')")

    def parse_args(self, args=None, namespace=None):
        args = _values_with_a_minus(list(sys.argv[1:] if args is None else args), self)
        namespace, extras = self.parse_known_args(args, namespace)
        if extras:
            parser = (self.commands or {}).get(getattr(namespace, "command", None), self)
            raise UsageError(f"{_unrecognized(extras, parser)} (see '{parser.prog} --help')")
        return namespace


def _option_strings(parser, single_value: bool = False) -> list[str]:
    """The option strings of a parser (with single_value: only those taking exactly one value)."""
    return [o for a in parser._actions for o in a.option_strings if not single_value or a.nargs is None]


def _unrecognized(extras: list[str], parser) -> str:
    """'unrecognized option --x (did you mean --y?)' for the first stray word of the command line."""
    import difflib

    word = extras[0]
    if not word.startswith("-"):
        return f"unexpected argument {word!r}"
    name = word.split("=", 1)[0]
    close = difflib.get_close_matches(name, _option_strings(parser), n=1, cutoff=0.6)
    return f"unrecognized option {name}" + (f" (did you mean {close[0]}?)" if close else "")


def _suggest_choice(message: str) -> str:
    """' (did you mean 'D'?)' for argparse's "invalid choice: 'd' (choose from ...)"."""
    import difflib
    import re

    m = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)", message)
    if not m:
        return ""
    choices = re.findall(r"'([^']*)'", m.group(2))
    close = [c for c in choices if c.lower() == m.group(1).lower()] or difflib.get_close_matches(m.group(1), choices, n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


_MINUS_VALUE = re.compile(r"^-(\d|\.\d|inf|nan)", re.IGNORECASE)


def _values_with_a_minus(argv: list[str], parser) -> list[str]:
    """``--k-s -500:8000:5`` as ``--k-s=-500:8000:5``: argparse takes a word starting with '-'
    for an option unless it is a plain number; here a value that starts with a minus sign and a
    digit (a range, -inf) follows an option that takes one value, so it is that value."""
    options = set(_option_strings(parser, single_value=True))
    for sub in (parser.commands or {}).values():
        options.update(_option_strings(sub, single_value=True))
    out: list[str] = []
    i = 0
    while i < len(argv):
        word = argv[i]
        if word in options and i + 1 < len(argv) and _MINUS_VALUE.match(argv[i + 1]):
            out.append(f"{word}={argv[i + 1]}")
            i += 2
            continue
        out.append(word)
        i += 1
    return out


class _Formatter(argparse.RawDescriptionHelpFormatter):
    """Help text with the engine's default backend filled in only when help is shown
    (``{default_backend}``)."""

    def _get_help_string(self, action):
        text = super()._get_help_string(action)
        if "{default_backend}" in text:
            text = text.replace("{default_backend}", str(_default_backend()))
        return text


_FORMATTER = _Formatter


def _options():
    from ..vocabulary import OPTIONS

    return OPTIONS


def _add_physics(p, contact: bool = True, full: bool = True):
    opts = _options()
    g = p.add_argument_group("rig and scene")
    g.add_argument("--rig", default="example", help="shipped rig name (see 'camdyn scenes') or a .toml rig file "
                                                    "(default: example)")
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
        g.add_argument("--follower", default="dynamic", choices=opts["follower"],
                       help="the hybrid model (dynamic), or the quasi-static contact orbit with no integration "
                            "(quasistatic: a follower that never leaves the cam) (default: dynamic)")


def _add_cam(p, required_speed: bool = False):
    g = p.add_argument_group("cam motion (one of)")
    g.add_argument("--speed-rpm", type=float, dest="speed_rpm", metavar="S",
                   help="constant cam speed in rev/min; > 0 counter-clockwise (de-energizing), < 0 clockwise")
    g.add_argument("--oscillating-rpm", type=float, dest="oscillating_rpm", metavar="F",
                   help="oscillating cam, F oscillations per minute (Section 7.2: 40)")
    g.add_argument("--amplitude-pp", type=float, default=math.pi, dest="amplitude_pp", metavar="RAD",
                   help="peak-to-peak angle of the oscillating cam in rad (default: pi)")


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
    from ..engine.config import MAP_OPTIONS

    return MAP_OPTIONS


def _solver_options(args):
    """The engine's SolverOptions from the solver options of ``_add_solver``: built here, for
    every command that takes them."""
    from ..engine.config import EventSettings, SolverOptions

    return SolverOptions(method=args.method, rtol=args.rtol, atol=args.atol, max_step=args.max_step,
                         events=EventSettings(max_events=args.max_events))


def _add_file(g, flag: str, kind: str, help_: str, *aliases: str, dest: str | None = None, **kw):
    """An option naming a file of one kind (checked when read: see _FileOption)."""
    g.add_argument(flag, *aliases, action=_FileOption, kind=kind, metavar="FILE", dest=dest, help=help_, **kw)


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="camdyn", formatter_class=_FORMATTER,
                     description="Contact dynamics of a rotational cam-follower (Sundar, Dreyer & Singh, "
                                 "J. Sound Vib. 2013).\nRun 'camdyn <command> --help' for a command's options.",
                     epilog=EXIT_CODES_HELP + "\n\nexample:\n  camdyn simulate --speed-rpm 1100 --plot run.png")
    parser.add_argument("--version", action="version", version=f"camdyn {_version()}")
    parser.add_argument("--traceback", action="store_true", help="show the Python traceback on errors")
    parser.add_argument("--no-progress", action="store_true", dest="no_progress",
                        help="never show progress bars (they show only on a terminal anyway)")
    sub = parser.add_subparsers(dest="command", metavar="<command>", parser_class=_Parser)
    sub.required = True
    parser.commands = sub.choices

    def command(name, help_, epilog, func, **kw):
        p = sub.add_parser(name, help=help_, description=help_[0].upper() + help_[1:] + ".",
                           epilog=epilog + "\n\n" + EXIT_CODES_HELP, formatter_class=_FORMATTER, **kw)
        p.set_defaults(func=func)
        return p

    p = command("simulate", "simulate a run and save its time histories and a plot",
                "examples:\n"
                "  camdyn simulate --speed-rpm 300 --revolutions 2 --plot run.png\n"
                "  camdyn simulate --speed-rpm 1100 --damping B --csv run.csv --netcdf run.nc\n"
                "  camdyn simulate --oscillating-rpm 40 --friction tanh --revolutions 1 --plot osc.png\n\n"
                "The run starts at the static equilibrium. CSV: one column per quantity (SI units) and the\n"
                "regime; NetCDF: the same with units, regime codes and impact times. The plot shows\n"
                "alpha_r, F_n and v_r over t/T with free flight shaded.", cmd_simulate)
    _add_physics(p)
    _add_cam(p)
    _add_run(p)
    g = p.add_argument_group("outputs")
    _add_file(g, "--csv", "csv", "write the time histories to this CSV file (.csv; units in the headers)")
    _add_file(g, "--netcdf", "netcdf", "write the time histories to this NetCDF file (.nc), with units and "
                                       "everything needed to re-run it")
    _add_file(g, "--plot", "plot", "save an overview figure (.png, .pdf, .svg...: by the file's ending; "
                                   "none: .png)")
    g.add_argument("--transient-revolutions", type=float, default=0.0, dest="transient_revolutions",
                   metavar="N", help="revolutions left out of the alpha_r statistics (default: 0)")

    p = command("spectrum", "amplitude spectrum of a run, with the harmonics of the cam speed",
                "examples:\n"
                "  camdyn spectrum --speed-rpm 300 --revolutions 10 --band 0 60 --band 1800 2600 --plot s.png\n"
                "  camdyn spectrum --input run.nc --quantity alpha_r\n\n"
                "Simulates a run (same options as simulate) or reads one written by 'camdyn simulate\n"
                "--csv/--netcdf', prints the strongest peaks as multiples of the cam frequency and the\n"
                "linearized natural frequency, and plots the spectrum with k*Omega_c marked.", cmd_spectrum)
    _add_physics(p)
    _add_cam(p)
    _add_run(p, revolutions=10.0, sample_rate=10_000.0)
    g = p.add_argument_group("spectrum")
    _add_file(g, "--input", "run", "a .csv or .nc written by 'camdyn simulate' (no simulation)")
    g.add_argument("--quantity", default="alpha", help="time history to analyse (default: alpha; e.g. alpha_r, F_n)")
    g.add_argument("--transient-revolutions", type=float, default=1.0, dest="transient_revolutions", metavar="N",
                   help="revolutions dropped before the transform (default: 1)")
    g.add_argument("--peaks", type=int, default=8, help="how many peaks to list (default: 8)")
    g.add_argument("--fmax", type=float, metavar="HZ", help="highest frequency listed and plotted")
    g.add_argument("--band", type=float, nargs=2, action="append", metavar=("LO", "HI"),
                   help="plot this band (Hz) in its own panel; repeat for more panels")
    _add_file(g, "--csv", "csv", "write the frequency (Hz) and amplitude to this CSV file")
    _add_file(g, "--plot", "plot", "save the spectrum figure (.png, .pdf, .svg...)")

    p = command("equilibrium", "static equilibrium and linearized natural frequency (Eqs. 16-23), as JSON",
                "example:\n  camdyn equilibrium --contact point --speed-rpm 300\n\n"
                "The cam speed (default: at rest) sets the direction of Coulomb friction, which is why\n"
                "de- and self-energizing rigs differ (Section 7.1).", cmd_equilibrium,
                aliases=["natural-frequency"])
    _add_physics(p, full=False)
    p.add_argument("--speed-rpm", type=float, default=0.0, dest="speed_rpm",
                   help="cam speed setting the friction direction (default: 0, at rest)")

    p = command("contact-loss", "cam speed (rev/min) above which the follower leaves the cam",
                "examples:\n  camdyn contact-loss --rig my_rig.toml\n  camdyn contact-loss --k-s 100:10000:5:log\n\n"
                "By inverse kinematics (Section 6): the speed at which rigid contact would need a\n"
                "pulling contact force. With --k-s, one line per spring stiffness (CSV).", cmd_contact_loss)
    p.add_argument("--rig", default="example", help="shipped rig name or a .toml rig file (default: example)")
    p.add_argument("--k-s", dest="k_s", metavar="VALUES",
                   help="spring stiffnesses in N/m: 'start:stop:count[:log]' or 'v1,v2,...'")

    p = command("lyapunov", "Lyapunov exponents of a run (tangent dynamics with saltation matrices)",
                "examples:\n"
                "  camdyn lyapunov --speed-rpm 1100\n"
                "  camdyn lyapunov --rig reference-experiment --speed-rpm 196 --revolutions 400 --json\n\n"
                "From the static equilibrium, after --transient-revolutions, the tangent vectors are\n"
                "propagated over each cam period and re-orthonormalised (camdyn.orbits.lyapunov); prints both\n"
                "exponents (1/s, largest first) with the standard error of their batch means.", cmd_lyapunov)
    _add_physics(p)
    _add_cam(p)
    g = p.add_argument_group("run and solver")
    g.add_argument("--revolutions", type=int, default=200, help="revolutions measured (default: 200)")
    g.add_argument("--transient-revolutions", type=int, default=50, dest="transient_revolutions", metavar="N",
                   help="revolutions discarded first (default: 50)")
    g.add_argument("--batches", type=int, default=10,
                   help="batches for the standard error; divides --revolutions (default: 10)")
    _add_solver(g, rtol=_MAP_OPTIONS().rtol, atol=_MAP_OPTIONS().atol)
    p.add_argument("--json", action="store_true", help="print the exponents and their estimate as JSON")

    p = command("sweep", "sweep the cam speed (and one rig parameter): bifurcation diagram or contact map",
                "examples:\n"
                "  camdyn sweep --speeds 600:1500:91 --revolutions 200 --transient-revolutions 50 --plot bif.png\n"
                "  camdyn sweep --speeds 200:1600:29 --param k_s --values 200:20000:21:log --plot map.png\n"
                "  camdyn sweep --speeds 900:1300:5 --param zeta_D --values 0.01,0.1 --netcdf zeta.nc\n"
                "  camdyn sweep --resume zeta.nc --jobs 2       # after Ctrl-C or a crash: only the missing points\n"
                "  camdyn sweep --speeds -1500:-600:10 --revolutions 60 --plot clockwise.png\n\n"
                "One run per point from the static equilibrium (camdyn.sweep.api; the compiled backend by\n"
                "default). With --speeds only: the Poincare section of alpha (once per revolution, after\n"
                "the transient) against speed. With --param k_s: the map of runs with and without impacts\n"
                "over (speed, k_s) with the inverse-kinematics contact-loss curve (Fig. 9); any other rig\n"
                "parameter gives the same map over that parameter. --netcdf saves the labelled results,\n"
                "streaming the finished points to FILE.parts/ while it runs (--out: the same, deprecated);\n"
                "--jobs or --dask run the points in parallel. Every point is checked first: invalid points\n"
                "are listed and nothing runs, unless --skip-invalid. A point that fails is recorded\n"
                "(outcome, message).", cmd_sweep)
    _add_physics(p)
    g = p.add_argument_group("sweep")
    g.add_argument("--speeds", metavar="VALUES",
                   help="cam speeds in rev/min: 'start:stop:count[:log]' or 'v1,v2,...'")
    g.add_argument("--param", metavar="NAME", help="a rig parameter to vary as well (e.g. k_s, e, zeta_D)")
    g.add_argument("--values", metavar="VALUES", help="its values (SI), same syntax as --speeds")
    g.add_argument("--revolutions", type=float, default=60.0, help="run length in revolutions (default: 60)")
    g.add_argument("--transient-revolutions", type=float, default=20.0, dest="transient_revolutions", metavar="N",
                   help="revolutions dropped before the statistics and the section (default: 20)")
    g.add_argument("--samples-per-revolution", type=int, default=64, dest="samples_per_revolution", metavar="N",
                   help="output samples per revolution for the maps (default: 64; the bifurcation uses 1)")
    g.add_argument("--no-stop", action="store_true", dest="no_stop",
                   help="bifurcation: run every point to the end (by default a run stops once its section "
                        "repeats: camdyn.StopWhenPeriodic)")
    g.add_argument("--jobs", type=int, default=1, help="local worker processes (default: 1)")
    g.add_argument("--dask", metavar="ADDRESS", help="run on this dask scheduler (tcp://host:port)")
    _add_solver(g)
    _add_file(g, "--netcdf", "netcdf", "save the sweep as NetCDF (.nc), streaming to FILE.parts/ meanwhile", dest="out")
    _add_file(g, "--out", "netcdf", argparse.SUPPRESS, deprecated_for="--netcdf")
    _add_file(g, "--resume", "netcdf", "continue the interrupted sweep whose --netcdf was FILE, with its own grid, "
                                       "rig, scene and settings (--jobs, --dask, --plot apply; another option must "
                                       "match the sweep's)")
    g.add_argument("--overwrite", action="store_true",
                   help="replace an existing --netcdf FILE (never replaced otherwise)")
    g.add_argument("--skip-invalid", action="store_true", dest="skip_invalid",
                   help="record invalid grid points (outcome INVALID) and run the others; they are left out of "
                        "the plot and of the exit code")
    _add_file(g, "--plot", "plot", "save the bifurcation diagram or contact map (.png, .pdf, .svg...)")

    p = command("continue", "follow a branch of periodic orbits in cam speed or a rig parameter, with its bifurcations",
                "examples:\n"
                "  camdyn continue --start 1650 --end 1850 --netcdf branch.nc --plot branch.png\n"
                "  camdyn continue --start 900 --end 1050 --phase-fraction 0.5     # up to grazing\n"
                "  camdyn continue --param k_s --start 2000 --end 4000 --speed-rpm 1500\n\n"
                "Pseudo-arclength continuation of the fixed points of the stroboscopic map\n"
                "(camdyn.orbits.continuation), from the orbit found by shooting at --start after --warmup\n"
                "revolutions. Prints how each branch ended and the events (fold, branch_point,\n"
                "period_doubling, neimark_sacker, grazing) with their parameter values, as CSV. At a period\n"
                "doubling the doubled branch is continued too. The section is at --phase-fraction of the\n"
                "cam period (0: the sections of 'camdyn sweep'; where the orbit sits on a switching surface\n"
                "there, e.g. in permanent contact at the 0-state, choose another).", cmd_continue)
    _add_physics(p)
    g = p.add_argument_group("continuation")
    g.add_argument("--param", default="speed_rpm", metavar="NAME",
                   help="speed_rpm (rev/min) or a rig parameter (SI), e.g. k_s, e (default: speed_rpm)")
    g.add_argument("--start", type=float, required=True, help="the parameter's start value")
    g.add_argument("--end", type=float, required=True, help="the parameter's end value")
    g.add_argument("--speed-rpm", type=float, dest="speed_rpm", metavar="S",
                   help="the constant cam speed (rev/min) when --param is a rig parameter")
    g.add_argument("--periods", type=int, default=1, help="period of the orbit in cam periods (default: 1)")
    g.add_argument("--phase-fraction", type=float, default=0.0, dest="phase_fraction", metavar="F",
                   help="the section's time after each revolution's start, a fraction of T (default: 0)")
    g.add_argument("--warmup", type=int, default=20, metavar="N",
                   help="revolutions from the static equilibrium before the first orbit's search (default: 20)")
    g.add_argument("--max-points", type=int, default=400, dest="max_points", metavar="N",
                   help="at most this many orbits per branch (default: 400)")
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
    g.add_argument("--switch-depth", type=int, default=1, dest="switch_depth", metavar="N",
                   help="how many period doublings deep to switch branches: 1 follows period 2 from a "
                        "period-1 branch, 2 also period 4 (default: 1)")
    g.add_argument("--jacobian", default="finite_differences", choices=("finite_differences", "variational"),
                   help="dP/dx by finite differences (checked, falling back to the tangent dynamics) or by the "
                        "tangent dynamics (default: finite_differences)")
    _add_solver(g, rtol=_MAP_OPTIONS().rtol, atol=_MAP_OPTIONS().atol)
    _add_file(g, "--netcdf", "netcdf", "save the branches and events as NetCDF (.nc)")
    _add_file(g, "--plot", "plot", "save the branches with their events (.png, .pdf, .svg...)")

    p = command("regenerate", "regenerate the model code from derive/ (needs camdyn[derive])",
                "examples:\n"
                "  camdyn regenerate                  # rewrite camdyn.generated from camdyn.derive\n"
                "  camdyn regenerate --check          # exit 1 if generated/ is out of date\n"
                "  camdyn regenerate --derive my/derive --out my/generated   # an edited copy\n\n"
                "Derives every scene of derive/catalog.py, writes the modules, checks that the folder\n"
                "now matches derive/ exactly (drift check), and imports every module without SymPy.\n"
                "Refuses (exit 2, nothing written) an expression that holds a complex number. For\n"
                "camdyn.generated itself, also writes the neutral value of a new parameter (declared in\n"
                "camdyn/vocabulary/parameters.py) into the shipped rig files that lack it, and says which.\n"
                "See docs/model-editing.md.", cmd_regenerate)
    p.add_argument("--check", action="store_true", help="only check: exit 1 if the folder differs from derive/")
    p.add_argument("--derive", metavar="DIR", help="a derive/ folder to use instead of the installed camdyn.derive")
    p.add_argument("--out", metavar="DIR", help="generated package folder (default: camdyn.generated, or "
                                                "DIR/../generated with --derive)")
    p.add_argument("--jobs", type=int, default=0, help="processes (default: all cores)")

    p = command("reproduce", "reproduce a study of the paper on the reference rig: its figure and numbers",
                "examples:\n  camdyn reproduce --list\n  camdyn reproduce fig10 --fast --out /tmp/repro\n"
                "  camdyn reproduce numbers --json\n\n"
                "Writes the study's figure (<out>/img/repro_<study>.png) and its section of\n"
                "<out>/reproduction.md, the paper's statement beside camdyn's result (camdyn.studies;\n"
                "the same as 'python -m camdyn.studies <study>'). <out> is the checkout's docs/ when camdyn\n"
                "runs from a source checkout (pip install -e .), else ./camdyn-reproduction in the current\n"
                "folder; nothing is ever written inside the installed package.",
                cmd_reproduce)
    p.add_argument("study", nargs="?", help="the study (see --list), or 'all'")
    p.add_argument("--list", action="store_true", help="list the studies")
    p.add_argument("--fast", action="store_true", help="reduced speeds and revolutions (also: CAMDYN_FAST=1)")
    p.add_argument("--out", metavar="DIR", help="folder of reproduction.md and img/ (default: the checkout's "
                                                "docs/, or ./camdyn-reproduction outside a checkout)")
    p.add_argument("--json", action="store_true", help="print the study's numbers as JSON on stdout")
    p.add_argument("--no-docs", action="store_true", dest="no_docs", help="do not update the report")
    p.add_argument("--data-dir", metavar="DIR", dest="data_dir",
                   help="where 'reference-rig' writes the rig presets (default: the checkout's camdyn/model/data, "
                        "or <out>/rigs outside a checkout)")

    p = command("scenes", "list the generated scenes and the shipped rigs",
                "example:\n  camdyn scenes --json", cmd_scenes)
    p.add_argument("--json", action="store_true", help="print scenes, rigs and scene options as JSON")

    p = command("cache", "list or clear the compiled code and derived scenes camdyn keeps for this user",
                "examples:\n  camdyn cache\n  camdyn cache --clear-stale\n\n"
                "The engine and each scene's kernels are compiled on first use and kept per user (never in\n"
                "the installed package), one folder per camdyn version and engine source. A scene outside\n"
                "the catalog is derived on first use (needs SymPy) and kept per derivation source.", cmd_cache)
    g = p.add_mutually_exclusive_group()
    g.add_argument("--clear", action="store_true", help="delete every cache folder (the next run compiles, and derives, again)")
    g.add_argument("--clear-stale", action="store_true", dest="clear_stale",
                   help="delete the folders of other camdyn versions, engines or derivations only")
    for p in sub.choices.values():
        p.set_defaults(flags=_flags(p))
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    show_traceback = "--traceback" in argv
    args = None
    try:
        args = _parser().parse_args(argv)
        args.argv = argv
        with warnings.catch_warnings():
            warnings.showwarning = _show_notice
            code = args.func(args)
        sys.stdout.flush()  # here, so that a closed pipe is handled below, not at exit
        return code
    except KeyboardInterrupt:
        print("camdyn: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # e.g. 'camdyn scenes | head': the reader left; say nothing more
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_BROKEN_PIPE
    except Exception as exc:  # one line, never a traceback (unless asked for)
        if show_traceback:
            import traceback

            traceback.print_exc()
        code, line = _classify(exc, args)
        print(f"camdyn: {line}", file=sys.stderr)
        return code


def _show_notice(message, category, filename, lineno, file=None, line=None):
    """Warnings on the command line as one line, ``camdyn: note: ...`` (not Python's source line):
    the user of the CLI did not write the code the warning points at."""
    print(f"camdyn: note: {message}", file=file or sys.stderr)


def _classify(exc: BaseException, args=None) -> tuple[int, str]:
    """Exit code and the one-line message of an exception (a parameter's name as the command's
    flag when it has one)."""
    from ..errors import ParameterError

    text = " ".join(str(exc).split()) or type(exc).__name__
    if isinstance(exc, ParameterError):
        text = _parameter_line(exc, args) or _in_flags(text, args)
    if isinstance(exc, MissingPart):
        return EXIT_MISSING, f"error: {text}"
    if isinstance(exc, ImportError):
        return EXIT_MISSING, f"error: a module is missing: {text}"
    if isinstance(exc, (CamdynError, ValueError)):
        return EXIT_USAGE, f"error: {text}"
    if isinstance(exc, OSError):
        if exc.filename and exc.strerror:
            return EXIT_USAGE, f"error: {exc.filename}: {exc.strerror}"
        return EXIT_USAGE, f"error: {text}"
    return EXIT_INTERNAL, f"internal error ({type(exc).__name__}: {text}); please report it with --traceback"


if __name__ == "__main__":
    sys.exit(main())
