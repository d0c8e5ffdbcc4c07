"""``camdyn simulate`` and ``camdyn spectrum``: one run from the command line, its outputs and its
spectrum."""
from __future__ import annotations

import csv
import math
import sys
from typing import NamedTuple

from ..errors import CamdynError
from .common import (EXIT_INCOMPLETE, EXIT_OK, UsageError, _busy, _check_outputs, _in_flags, _plot_modules,
                     _save_figure)
from .options import _add_cam, _add_file, _add_physics, _add_run, _backend, _cam, _rig, _scene, _solver_options, _span
from .parser import add_command


class _Run(NamedTuple):
    result: object
    rig: object
    settings: dict


def _simulate(args) -> _Run:
    """One run from the command-line options (cam, scene, run length, solver), with the rig and
    the settings that made it (for the saved run's attributes)."""
    from ..io.metadata import describe_cam, describe_scene
    from ..runs.request import loose_keywords
    from ..runs.simulation import simulate

    cam = _cam(args)
    scene = _scene(args, cam.kind)
    request = {"backend": _backend(args), "span": _span(args, cam), "options": _solver_options(args)}
    rig = _rig(args)
    with _busy(f"simulating {describe_scene(scene)}, {describe_cam(cam)}", args) as share:
        result = simulate(rig, scene, cam, progress=share, **request)
    return _Run(result, rig, loose_keywords(request))


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
        q, unit = result.meta.get("coordinate", "alpha"), "m" if result.meta.get("coordinate") == "y" else "rad"
        print(f"  {q}_r: rms {stats.rms:.6g} {unit}, peak-to-peak {stats.peak_to_peak:.6g} {unit}"
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

    _check_outputs(args, "csv", "plot")
    source, period, natural, status = _spectrum_source(args)
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
    _print_peaks(args, f, amp, f0)
    if args.csv:
        _write_spectrum(args, f, amp)
    if args.plot:
        plots = _plot_modules()
        bands = [tuple(b) for b in args.band] if args.band else None
        marks = {r"$\vartheta$ (Eq. 23)": natural} if natural else None
        fig = plots.spectrum(source, args.quantity, bands=bands, fmax=args.fmax, mark_Hz=marks)
        _save_figure(fig, args.plot)
    return status


def _spectrum_source(args):
    """(the series to transform, its cam period, the linearized natural frequency in Hz or None,
    the exit status so far): a saved run (--input), or a run of the options."""
    if args.input:
        from ..io.files import read_series

        t, x, period = read_series(args.input, args.quantity)
        return _Series(t, period, **{args.quantity: x}), period, None, EXIT_OK
    result = _simulate(args).result
    print(result.summary())
    status = EXIT_OK
    if not result.ok:
        print(f"camdyn: the run stopped early: {result.outcome.message}", file=sys.stderr)
        status = EXIT_INCOMPLETE
    natural = None
    if args.speed_rpm is not None:  # the linearization about the static equilibrium (Eq. 23)
        from ..analysis.statics import natural_frequency
        from ..model.cam import ConstantSpeed

        try:
            natural = natural_frequency(_rig(args), _scene(args), ConstantSpeed(args.speed_rpm)).Hz
        except CamdynError:
            natural = None
    return result, result.period, natural, status


def _print_peaks(args, f, amp, f0: float) -> None:
    """The --peaks strongest peaks up to --fmax, by frequency, as multiples of the cam frequency f0."""
    import numpy as np

    from ..analysis import signal
    from ..io.metadata import units

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


def _write_spectrum(args, f, amp) -> None:
    """--csv: the frequency (Hz) and amplitude of each bin."""
    from ..io.metadata import units

    unit = units(args.quantity)
    with open(args.csv, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["f (Hz)", f"amplitude of {args.quantity}" + (f" ({unit})" if unit else "")])
        for fi, ai in zip(f, amp):
            writer.writerow([repr(float(fi)), repr(float(ai))])
    print(f"  wrote {args.csv}")


def add_simulate(sub) -> None:
    """The simulate command and its options."""
    p = add_command(sub, "simulate", "simulate a run and save its time histories and a plot",
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


def add_spectrum(sub) -> None:
    """The spectrum command and its options."""
    p = add_command(sub, "spectrum", "amplitude spectrum of a run, with the harmonics of the cam speed",
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
