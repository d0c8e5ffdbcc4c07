"""``camdyn chart``: the jump chart, the jump (grazing) speed against a rig parameter beside the
inverse-kinematics contact-loss speed (camdyn.orbits.continuation.jump_chart)."""
from __future__ import annotations

from .common import EXIT_INCOMPLETE, EXIT_OK, _built, _busy, _check_outputs, _in_flags, _plot_modules, _save_figure
from .options import (_MAP_OPTIONS, _add_arclength, _add_file, _add_physics, _add_solver, _backend,
                      _continuation_settings, _rig, _scene, _solver_options)
from .parser import add_command


def cmd_chart(args) -> int:
    from ..orbits.continuation import GrazingOutcome, GrazingSettings, jump_chart

    rig, scene = _rig(args), _scene(args)
    _check_outputs(args, "netcdf", "plot")
    settings = _built(GrazingSettings, {"gap_tol": "gap_tol"}, args,
                      continuation=_continuation_settings(args, switch_depth=0), gap_tol=args.gap_tol)
    with _busy(f"the jump speed against {args.param}", args):
        ds = jump_chart(rig, scene, args.param, args.start, args.end, search=args.search,
                        phase_fraction=args.phase_fraction, warmup_revolutions=args.warmup, settings=settings,
                        options=_solver_options(args), backend=_backend(args))
    unit = ds.attrs["parameter_units"]
    print(f"jump chart of {scene.slug} on rig {rig.name!r} against {args.param} ({unit}): {ds.sizes['point']} "
          f"grazing orbits; {_in_flags(ds.attrs['outcome_message'], args)}")
    print(f"{args.param} ({unit}),jump_speed (rev/min),contact_loss_speed (rev/min),relative_difference,"
          "compliance_shift")
    for k, s, loss, shift in zip(ds[args.param].values, ds["speed_rpm"].values, ds["contact_loss_rpm"].values,
                                 ds["compliance_shift"].values):
        print(f"{k:.8g},{s:.10g},{loss:.10g},{s / loss - 1:.4e},{shift:.4e}")
    kinds = ds.attrs["codim2_kinds"].split()
    for kind, k, s in zip(ds["codim2_kind"].values, ds[f"codim2_{args.param}"].values, ds["codim2_speed_rpm"].values):
        print(f"{kinds[int(kind)]} at {args.param} = {k:.8g}, {s:.10g} rev/min")
    if args.netcdf:
        ds.to_netcdf(args.netcdf, engine="scipy")
        print(f"  wrote {args.netcdf}")
    if args.plot and ds.sizes["point"]:
        _save_figure(_plot_modules().jump_chart(ds), args.plot)
    return EXIT_OK if ds.attrs["outcome"] == GrazingOutcome.END_REACHED.name else EXIT_INCOMPLETE


def add_chart(sub) -> None:
    """The chart command and its options."""
    p = add_command(sub, "chart", "the jump chart: the jump (grazing) speed against a rig parameter, and its "
                                  "quasi-static limit",
                    "examples:\n"
                    "  camdyn chart --param k_s --start 2000 --end 4000 --netcdf jump.nc --plot jump.png\n"
                    "  camdyn chart --rig reference-experiment --param k_s --start 8.4 --end 84\n\n"
                    "Continues the grazing orbit (the follower first leaving the cam) in the cam speed and\n"
                    "--param together (camdyn.orbits.continuation.continue_grazing), from the grazing that a\n"
                    "continuation in speed finds over --search at --start. Prints, as CSV, the jump speed at\n"
                    "each grazing orbit beside the contact-loss speed by inverse kinematics and the\n"
                    "first-order shift between them by the contact's compliance, then the codimension-2\n"
                    "points (a Floquet multiplier at grazing through -1 or +1). Exit code 3 when the curve\n"
                    "ends before --end (its outcome says why).", cmd_chart)
    _add_physics(p)
    g = p.add_argument_group("chart")
    g.add_argument("--param", required=True, metavar="NAME", help="the rig parameter (SI), e.g. k_s, L_us, e")
    g.add_argument("--start", type=float, required=True, help="the parameter's start value")
    g.add_argument("--end", type=float, required=True, help="the parameter's end value")
    g.add_argument("--search", type=float, nargs=2, metavar=("LOW", "HIGH"),
                   help="the speeds (rev/min) the first grazing is searched between (default: 0.9 and 1.05 times "
                        "the contact-loss speed at --start)")
    g.add_argument("--phase-fraction", type=float, default=None, dest="phase_fraction", metavar="F",
                   help="the section's time in the cam period, away from the gap's maximum (default: half a period "
                        "from where the inverse kinematics lose contact)")
    g.add_argument("--warmup", type=int, default=20, metavar="N",
                   help="revolutions from the static equilibrium before the first orbit's search (default: 20)")
    g.add_argument("--gap-tol", type=float, default=1e-6, dest="gap_tol", metavar="TOL",
                   help="the gap's tolerance, a fraction of the largest deflection (default: 1e-6)")
    _add_arclength(g)
    _add_solver(g, rtol=_MAP_OPTIONS().rtol, atol=_MAP_OPTIONS().atol)
    _add_file(g, "--netcdf", "netcdf", "save the chart as NetCDF (.nc)")
    _add_file(g, "--plot", "plot", "save the chart (.png, .pdf, .svg...)")
