"""``camdyn sweep --resume FILE``: the sweep's own grid, rig, scene and settings; the options that
say how to run it apply, any other option typed must match the sweep's."""
from __future__ import annotations

import argparse
from pathlib import Path

from .._checks import is_real
from .common import UsageError, _check_outputs, _flag, _parse_values
from .options import _FileOption, _rig
from .sweeping import _executor, _sweep_interrupted, _sweep_progress, _sweep_report


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
    """The sweep options typed on the command line (dests), not their defaults: the command's words
    read again by its own parser with every default suppressed (the words before the command are
    the flags of ``camdyn`` itself)."""
    command = args.command_parser
    argv = getattr(args, "argv", None)
    if argv is None:   # called without main(): the options that differ from their defaults
        return [a.dest for a in command._actions if a.dest != "help" and getattr(args, a.dest, None) != a.default]
    for action in command._actions:
        action.default = argparse.SUPPRESS
        if isinstance(action, _FileOption):
            action.deprecated_for = None   # said once already
    start = next(i for i, word in enumerate(argv) if not word.startswith("-")) + 1
    typed = command.parse_args(argv[start:])
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
    if is_real(typed) and recorded is not None:
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
