"""``camdyn basins``: the attractor each start (alpha, alpha_dot) reaches (camdyn.sweep.attractors)."""
from __future__ import annotations

from .common import _check_outputs, _parse_values
from .options import _add_file, _add_physics, _add_solver, _backend, _rig, _scene, _solver_options
from .parser import add_command
from .sweeping import _executor, _sweep_interrupted, _sweep_module, _sweep_progress, basins_report


def cmd_basins(args) -> int:
    sweeps = _sweep_module()
    from ..sweep import attractors as B

    rig, scene = _rig(args), _scene(args)
    speeds = _parse_values(args.speeds, "--speed-rpm")
    alpha = _parse_values(args.alpha, "--alpha")
    alpha_dot = _parse_values(args.alpha_dot, "--alpha-dot")
    if args.from_equilibrium:
        from ..analysis.statics import static_equilibrium

        alpha_star = static_equilibrium(rig, scene.contact).alpha
        alpha = [alpha_star + a for a in alpha]
    _check_outputs(args, "out", "plot")
    solver = dict(options=_solver_options(args), backend=_backend(args))
    with _executor(args, sweeps) as executor, _sweep_interrupted(args, args.out):
        ds = B.basins(rig, scene, alpha=alpha, alpha_dot=alpha_dot, speed_rpm=speeds[0] if len(speeds) == 1 else speeds,
                      revolutions=args.revolutions, tol=args.tol, confirm=not args.no_confirm,
                      lyapunov_revolutions=args.lyapunov_revolutions, executor=executor,
                      progress=_sweep_progress(args), out=args.out, overwrite=args.overwrite, **solver)
    if args.out:
        print(f"  wrote {args.out}")
    return basins_report(ds, args)


def add_basins(sub) -> None:
    """The basins command and its options."""
    p = add_command(sub, "basins", "map starts (alpha, alpha_dot) to the attractors they reach: basins of attraction",
                    "examples:\n"
                    "  camdyn basins --rig reference-experiment --speed-rpm 125 --from-equilibrium \\\n"
                    "      --alpha 0:0.5:50 --alpha-dot -3:3:50 --jobs 2 --netcdf basins.nc --plot basins.png\n"
                    "  camdyn sweep --resume basins.nc --jobs 2       # after Ctrl-C or a crash\n\n"
                    "One run per start at t = 0 (camdyn.sweep.attractors), sampled at the section t = k T and stopped\n"
                    "once periodic (camdyn.StopWhenPeriodic): each start reaches a periodic attractor (its minimal\n"
                    "period and section points, told apart to --tol), or is chaotic (with --lyapunov-revolutions:\n"
                    "lambda_1 > 3 standard errors), not settled, or a run that did not succeed. The attractors\n"
                    "are confirmed by shooting (camdyn.periodic_orbit) unless --no-confirm.", cmd_basins)
    _add_physics(p)
    g = p.add_argument_group("basins")
    g.add_argument("--speed-rpm", required=True, dest="speeds", metavar="VALUES",
                   help="cam speed(s) in rev/min: one value, or 'start:stop:count' / 'v1,v2,...' for a map per speed")
    g.add_argument("--alpha", required=True, metavar="VALUES", help="start angles alpha in rad, as --speed-rpm")
    g.add_argument("--alpha-dot", required=True, dest="alpha_dot", metavar="VALUES",
                   help="start rates alpha_dot in rad/s, as --speed-rpm")
    g.add_argument("--from-equilibrium", action="store_true", dest="from_equilibrium",
                   help="--alpha values are offsets from the static equilibrium alpha*")
    g.add_argument("--revolutions", type=int, default=200, help="longest run in revolutions (default: 200)")
    g.add_argument("--tol", type=float, default=1e-6,
                   help="attractors closer than this (rad; alpha_dot: tol x cam speed in rad/s) are one "
                        "(default: 1e-6)")
    g.add_argument("--lyapunov-revolutions", type=int, default=0, dest="lyapunov_revolutions", metavar="N",
                   help="judge starts that do not settle by lambda_1 over N revolutions (default: 0, not judged)")
    g.add_argument("--no-confirm", action="store_true", dest="no_confirm",
                   help="do not confirm each attractor by shooting")
    g.add_argument("--jobs", type=int, default=1, help="local worker processes (default: 1)")
    g.add_argument("--dask", metavar="ADDRESS", help="run on this dask scheduler (tcp://host:port)")
    _add_solver(g)
    _add_file(g, "--netcdf", "netcdf", "save the map as NetCDF (.nc), streaming to FILE.parts/ meanwhile", dest="out")
    g.add_argument("--overwrite", action="store_true", help="replace an existing --netcdf FILE")
    _add_file(g, "--plot", "plot", "save the basin map (.png, .pdf, .svg...)")
