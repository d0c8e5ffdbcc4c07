"""Running and reporting a sweep from the command line (camdyn.sweep.api): the executor, what a
sweep found, its plot, and how to go on after an interrupt."""
from __future__ import annotations

import contextlib
import importlib
import sys

from .common import EXIT_INCOMPLETE, EXIT_OK, MissingPart, UsageError, _plot_modules, _save_figure


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


def _sweep_progress(args) -> bool:
    return not args.no_progress and sys.stderr.isatty()


def _resume_command(args, out) -> str:
    """The command that resumes ``out`` with the options of this one that say how to run it."""
    import shlex

    words = ["camdyn"] + (["--no-progress"] if args.no_progress else []) + ["sweep", "--resume", str(out)]
    words += (["--jobs", str(args.jobs)] if args.jobs > 1 else []) + (["--dask", args.dask] if args.dask else [])
    words += ["--plot", args.plot] if args.plot else []
    return shlex.join(words)


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

    if "attractor" in ds:          # a basin map (camdyn basins), resumed
        return basins_report(ds, args)
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


def basins_report(ds, args) -> int:
    """Print the attractor table, plot the map; exit 3 if a start's run did not succeed."""
    from ..sweep.attractors import NO_RUN, attractor_table

    print(f"basin map of {ds.attrs['scene']} on rig {ds.attrs['rig']!r}: {ds.attrs['points']} starts, "
          f"{ds.attrs['attractors']} attractors (told apart to {ds.attrs['attractor_tol']:g} rad)")
    for row in attractor_table(ds):
        if isinstance(row["id"], int):
            where = "".join(f", {k} {row[k]:g}" for k in ("speed_rpm",) if k in row)
            check = (f", shooting: {row['orbit']}, |mu| max {row['multiplier']:.3g}"
                     f"{'' if row['confirmed'] else ' (NOT confirmed)'}" if "confirmed" in row else "")
            print(f"  attractor {row['id']}: P{row['period']}{where}, section alpha {row['alpha']:.6g} rad, "
                  f"alpha_dot {row['alpha_dot']:.6g} rad/s; {row['points']} starts{check}")
        else:
            print(f"  {row['id'].replace('_', ' ')}: {row['points']} starts")
    if getattr(args, "plot", None):
        speeds = ds["speed_rpm"].values if "speed_rpm" in ds.dims else [None]
        if len(speeds) > 1:
            print("  the plot shows the first speed of the map", file=sys.stderr)
        _save_figure(_plot_modules().basin_map(ds, speed_rpm=speeds[0]), args.plot)
    return EXIT_INCOMPLETE if (ds["attractor"].values == NO_RUN).any() else EXIT_OK
