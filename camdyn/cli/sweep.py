"""``camdyn sweep``: a bifurcation diagram or a contact map (camdyn.sweep.api)."""
from __future__ import annotations

import argparse
import sys

from .common import UsageError, _check_outputs, _parse_values
from .options import _add_file, _add_physics, _add_solver, _backend, _rig, _scene, _solver_options
from .parser import add_command
from .resume import _resume_sweep
from .sweeping import _executor, _sweep_interrupted, _sweep_module, _sweep_progress, _sweep_report


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
    solver = dict(options=_solver_options(args), backend=_backend(args))
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


def add_sweep(sub) -> None:
    """The sweep command and its options."""
    p = add_command(sub, "sweep", "sweep the cam speed (and one rig parameter): bifurcation diagram or contact map",
                    "examples:\n"
                    "  camdyn sweep --speeds 600:1500:91 --revolutions 200 --transient-revolutions 50 --plot bif.png\n"
                    "  camdyn sweep --speeds 200:1600:29 --param k_s --values 200:20000:21:log --plot map.png\n"
                    "  camdyn sweep --speeds 900:1300:5 --param zeta_D --values 0.01,0.1 --netcdf zeta.nc\n"
                    "  camdyn sweep --resume zeta.nc --jobs 2       # after Ctrl-C or a crash: only the missing "
                    "points\n"
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
