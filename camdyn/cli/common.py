"""What every command shares: exit codes and errors, the library's messages in the command's
flags, progress, value lists, plots, and output checks before any work."""
from __future__ import annotations

import contextlib
import os
import re
import sys
import threading
import time
from pathlib import Path

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
               "friction='tanh'": ("friction", "{flag} tanh"), "response='dynamic'": ("response", "{flag} dynamic"), "another start value": ("start", "another {flag}")}


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


def _flag(args, name: str) -> str:
    return (getattr(args, "flags", None) or {}).get(name, "--" + name.replace("_", "-"))


# --------------------------------------------------------------------------- progress
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


# --------------------------------------------------------------------------- values, plots, outputs
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
