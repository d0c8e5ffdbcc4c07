"""``camdyn equilibrium``, ``contact-loss``, ``lyapunov`` and ``continue``: the analyses of a rig
beyond one run."""
from __future__ import annotations

import json

from .common import (EXIT_INCOMPLETE, EXIT_OK, UsageError, _busy, _check_outputs, _in_flags, _parse_values,
                     _plot_modules, _save_figure)
from .options import (_MAP_OPTIONS, _add_arclength, _add_cam, _add_file, _add_physics, _add_solver, _backend, _cam,
                      _continuation_settings, _rig, _scene, _solver_options)
from .parser import add_command


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
        L = lyapunov_exponents(rig, scene, cam, settings=settings, options=options, backend=_backend(args))
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


def cmd_continue(args) -> int:
    from ..orbits.continuation import SPEED, ContinuationOutcome, continue_orbit, events_table

    rig, scene = _rig(args), _scene(args)
    if args.param != SPEED and args.speed_rpm is None:
        raise UsageError(f"--param {args.param} is continued at a constant cam speed: give --speed-rpm")
    if args.param == SPEED and args.speed_rpm is not None:
        raise UsageError("--speed-rpm is for a rig parameter's continuation; the speed itself runs from --start "
                         "to --end")
    _check_outputs(args, "netcdf", "plot")
    settings = _continuation_settings(args, switch_depth=args.switch_depth)
    kwargs = dict(speed_rpm=args.speed_rpm, periods=args.periods, phase_fraction=args.phase_fraction,
                  warmup_revolutions=args.warmup, settings=settings, options=_solver_options(args),
                  backend=_backend(args))
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


def add_equilibrium(sub) -> None:
    """The equilibrium command and its options."""
    p = add_command(sub, "equilibrium", "static equilibrium and linearized natural frequency (Eqs. 16-23), as JSON",
                    "example:\n  camdyn equilibrium --contact point --speed-rpm 300\n\n"
                    "The cam speed (default: at rest) sets the direction of Coulomb friction, which is why\n"
                    "de- and self-energizing rigs differ (Section 7.1).", cmd_equilibrium,
                    aliases=["natural-frequency"])
    _add_physics(p, full=False)
    p.add_argument("--speed-rpm", type=float, default=0.0, dest="speed_rpm",
                   help="cam speed setting the friction direction (default: 0, at rest)")


def add_contact_loss(sub) -> None:
    """The contact-loss command and its options."""
    p = add_command(sub, "contact-loss", "cam speed (rev/min) above which the follower leaves the cam",
                    "examples:\n  camdyn contact-loss --rig my_rig.toml\n"
                    "  camdyn contact-loss --k-s 100:10000:5:log\n\n"
                    "By inverse kinematics (Section 6): the speed at which rigid contact would need a\n"
                    "pulling contact force. With --k-s, one line per spring stiffness (CSV).", cmd_contact_loss)
    p.add_argument("--rig", default="example", help="shipped rig name or a .toml rig file (default: example)")
    p.add_argument("--k-s", dest="k_s", metavar="VALUES",
                   help="spring stiffnesses in N/m: 'start:stop:count[:log]' or 'v1,v2,...'")


def add_lyapunov(sub) -> None:
    """The lyapunov command and its options."""
    p = add_command(sub, "lyapunov", "Lyapunov exponents of a run (tangent dynamics with saltation matrices)",
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


def add_continue(sub) -> None:
    """The continue command and its options."""
    p = add_command(sub, "continue",
                    "follow a branch of periodic orbits in cam speed or a rig parameter, with its bifurcations",
                    "examples:\n"
                    "  camdyn continue --start 1650 --end 1850 --netcdf branch.nc --plot branch.png\n"
                    "  camdyn continue --start 900 --end 1050 --phase-fraction 0.5     # up to grazing\n"
                    "  camdyn continue --param k_s --start 2000 --end 4000 --speed-rpm 1500\n\n"
                    "Pseudo-arclength continuation of the fixed points of the stroboscopic map\n"
                    "(camdyn.orbits.continuation), from the orbit found by shooting at --start after --warmup\n"
                    "revolutions. Prints how each branch ended and the events (fold, branch_point,\n"
                    "period_doubling, neimark_sacker, grazing, corner_impact) with their parameter values, as\n"
                    "CSV. At a period doubling the doubled branch is continued too. The section is at\n"
                    "--phase-fraction of the cam period (0: the sections of 'camdyn sweep'; where the orbit sits\n"
                    "on a switching surface there, e.g. in permanent contact at the 0-state, choose another).",
                    cmd_continue)
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
    _add_arclength(g)
    g.add_argument("--switch-depth", type=int, default=1, dest="switch_depth", metavar="N",
                   help="how many period doublings deep to switch branches: 1 follows period 2 from a "
                        "period-1 branch, 2 also period 4 (default: 1)")
    g.add_argument("--jacobian", default="finite_differences", choices=("finite_differences", "variational"),
                   help="dP/dx by finite differences (checked, falling back to the tangent dynamics) or by the "
                        "tangent dynamics (default: finite_differences)")
    _add_solver(g, rtol=_MAP_OPTIONS().rtol, atol=_MAP_OPTIONS().atol)
    _add_file(g, "--netcdf", "netcdf", "save the branches and events as NetCDF (.nc)")
    _add_file(g, "--plot", "plot", "save the branches with their events (.png, .pdf, .svg...)")
