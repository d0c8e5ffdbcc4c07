"""Shared machinery of the studies: settings, runs, figures, the report.

Every study is a function ``run(ctx) -> Outcome``; :func:`camdyn.studies.run` builds
the context (fast mode, output folder) and writes the study's section of
``docs/reproduction.md``.
"""
from __future__ import annotations

import json
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import camdyn
from camdyn.errors import CamdynError

#: environment variable that switches every study to its fast mode ("1") for tests
FAST_ENV = "CAMDYN_FAST"
#: environment variable that caps the number of worker processes of the studies (default 2)
WORKERS_ENV = "CAMDYN_WORKERS"

#: the reported numbers of the paper (Sundar, Dreyer & Singh 2013), with where they are stated
PAPER = {
    "k_line": dict(value=138e6, unit="N/m", digits=3, where="Sec. 6",
                   text="linearized contact stiffness at equilibrium, line contact l = 1.6 mm: 138 MN/m"),
    "k_point": dict(value=34.2e6, unit="N/m", digits=3, where="Sec. 6",
                    text="linearized contact stiffness at equilibrium, point contact: 34.2 MN/m"),
    "f_line_de": dict(value=2182.0, unit="Hz", digits=4, where="Sec. 6-7, Fig. 10",
                      text="natural frequency, line contact, de-energizing (+300 rev/min): 2182 Hz"),
    "f_line_se": dict(value=2125.0, unit="Hz", digits=4, where="Sec. 7.1, Fig. 10",
                      text="natural frequency, line contact, self-energizing (-300 rev/min): 2125 Hz"),
    "f_point_de": dict(value=1331.0, unit="Hz", digits=4, where="Sec. 6, Fig. 10",
                       text="natural frequency, point contact (+300 rev/min): 1331 Hz"),
    "contact_loss": dict(value=130.0, unit="rev/min", digits=3, where="Sec. 4",
                         text="contact loss by inverse kinematics on the experiment's settings: 130 rev/min "
                              "(measured 125 rev/min by Alzate et al.)"),
    "alpha_rp_saturation": dict(value=1.36, unit="rad", digits=3, where="Sec. 5, Fig. 8",
                                text="alpha_rp rises and saturates at 1.36 rad, alpha reaching 90 degrees"),
}

#: the experiment's speeds (Section 4), rev/min
EXPERIMENT_SPEEDS = (110.0, 135.0, 143.0, 148.0, 150.0, 155.0, 159.0)


def fast_default() -> bool:
    return os.environ.get(FAST_ENV, "0").strip().lower() not in ("", "0", "false", "no")


#: the folder (in the working directory) the studies write to when camdyn is not a source checkout
DEFAULT_OUT = "camdyn-reproduction"


def checkout_root(package_dir: Path | None = None) -> Path | None:
    """The source checkout camdyn runs from (an editable install: ``pip install -e .``), or None
    when camdyn is an installed copy (site-packages), which the studies never write into."""
    package = Path(package_dir) if package_dir is not None else Path(camdyn.__file__).resolve().parent
    root = package.parent
    pyproject = root / "pyproject.toml"
    try:
        text = pyproject.read_text(encoding="utf-8")
    except OSError:
        return None
    if re.search(r'^name\s*=\s*"camdyn"', text, flags=re.M) and (root / "docs").is_dir():
        return root
    return None


def default_out() -> Path:
    """Where a study writes when not told: the checkout's ``docs/``, else ``./camdyn-reproduction``."""
    root = checkout_root()
    return root / "docs" if root is not None else Path.cwd() / DEFAULT_OUT


def default_data_dir(out: Path) -> Path:
    """Where ``reference-rig`` writes the rig presets when not told: the checkout's ``camdyn/model/data``
    (they are shipped from there), else ``<out>/rigs`` -- never inside an installed package."""
    root = checkout_root()
    return root / "camdyn" / "model" / "data" if root is not None else Path(out) / "rigs"


@dataclass
class Context:
    """Where a study writes, and how thoroughly it computes."""

    fast: bool
    out: Path                 # the folder holding reproduction.md and img/
    write_docs: bool = True   # update reproduction.md / reference-rig.md
    data_dir: Path | None = None  # where reference-rig writes the presets (None: default_data_dir(out))
    log: Any = print
    reuse: bool = False       # reuse the stages a study recorded in the report (chaos-scan's stage 1)

    @property
    def img(self) -> Path:
        p = self.out / "img"
        p.mkdir(parents=True, exist_ok=True)
        return p

    def png(self, name: str) -> Path:
        return self.img / f"repro_{name}.png"


@dataclass
class StudyOutput:
    """What a study produced: its section of the report, numbers (JSON-able), figure files."""

    name: str
    title: str
    markdown: str
    numbers: dict = field(default_factory=dict)
    figures: list[Path] = field(default_factory=list)


# ----------------------------------------------------------------------------- rigs


def reference_rig() -> camdyn.Rig:
    """The reference rig (Sections 6-8 settings): the shipped ``reference`` preset."""
    return _preset("reference")


def experiment_rig() -> camdyn.Rig:
    """The reference rig on the experiment's settings (Sections 4-5): ``reference-experiment``."""
    return _preset("reference-experiment")


def _preset(name: str) -> camdyn.Rig:
    from camdyn.model.presets import available, load_rig
    if name not in available():
        raise CamdynError(f"the preset {name!r} does not exist yet: run 'python -m camdyn.studies reference-rig'")
    return load_rig(name)


# ----------------------------------------------------------------------------- simulation


def simulate(rig, scene, cam=None, **kw):
    """camdyn.simulate on the default (compiled) engine; the backend is recorded in
    ``result.meta["backend"]``.  A run that stops early is reported as it ended: no rerun."""
    result = camdyn.simulate(rig, scene, cam, **kw)
    result.meta["backend"] = result.stats.get("backend")
    return result


def poincare(result, transient_revolutions: float, phase: float = 0.0):
    """(alpha_r, alpha_dot) sampled once per cam revolution after the transient."""
    T = result.period
    n = int(math.floor((result.t[-1] - result.t[0]) / T + 1e-9))
    k = np.arange(int(math.ceil(transient_revolutions)), n + 1)
    ts = result.t[0] + (k + phase) * T
    ts = ts[ts <= result.t[-1]]
    return np.interp(ts, result.t, result.alpha_r), np.interp(ts, result.t, result.alpha_dot)


def classify(points: np.ndarray, scale: float, max_period: int = 8, rtol: float = 2e-3) -> str:
    """"P1".."P8" if the Poincare sequence repeats with that period (to rtol of ``scale``),
    else "aperiodic"; "too short" without enough points."""
    x = np.asarray(points, dtype=float)
    if x.size < 2 * max_period + 2:
        return "too short"
    tol = max(rtol * scale, 1e-9)
    for p in range(1, max_period + 1):
        if np.all(np.abs(x[p:] - x[:-p]) <= tol):
            return f"P{p}"
    return "aperiodic"


# ----------------------------------------------------------------------------- figures and text


def figure(nrows=1, ncols=1, **kw):
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    kw.setdefault("figsize", (7.5, 3.2 * nrows))
    kw.setdefault("constrained_layout", True)
    return plt.subplots(nrows, ncols, **kw)


def save(fig, path: Path) -> Path:
    import matplotlib.pyplot as plt
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def spectrum_panels(ax, low_title: str, band_title: str) -> None:
    """Titles, labels, legends and grids of the two spectrum panels (fig10, fig16): the low
    frequencies (harmonics of the cam) left, the band around the resonance right."""
    ax[0].set_title(low_title)
    ax[0].set_xlabel("frequency (Hz)")
    ax[0].set_ylabel("|α| (rad)")
    ax[0].legend(fontsize=7)
    ax[0].grid(alpha=0.3)
    ax[1].set_title(band_title)
    ax[1].set_xlabel("frequency (Hz)")
    ax[1].legend(fontsize=7)
    ax[1].grid(alpha=0.3)


def md_table(header: list[str], rows: list[list[Any]]) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(out)


def fmt(x, digits: int = 4) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–" if x is None else str(x)
    return f"{x:.{digits}g}"


def rel(a, b) -> float | None:
    if a is None or b is None or not b:
        return None
    return (a - b) / b


# ----------------------------------------------------------------------------- the report

REPORT_HEADER = """# The paper's results, reproduced

Sundar, Dreyer & Singh, *J. Sound Vib.* 332 (2013) 4280–4295, reproduced with camdyn on the
reference rig (`camdyn/model/data/reference.toml`, Sections 6–8 settings) and its experiment variant
(`reference-experiment.toml`, Sections 4–5); see [reference-rig.md](reference-rig.md) for how
that rig was identified. Each section below is written by one command,
`python -m camdyn.studies <name>`, and says what the paper states beside what camdyn computes.
The paper compares several results with measurements of Alzate et al. (2007); those
measurements are not available here, so no section plots them and none is invented.
"""

ORDER = ["reference-rig", "fig4-5", "chaos-scan", "fig6", "fig7-8", "fig9", "fig10", "fig11", "fig12-15", "fig16", "numbers",
         "second-rig", "jump-chart"]


def _markers(name):
    return f"<!-- study:{name} begin -->", f"<!-- study:{name} end -->"


def update_report(path: Path, output: StudyOutput, command: str) -> None:
    """Replace (or insert, in study order) the study's section of the report at ``path``."""
    text = path.read_text(encoding="utf-8") if path.exists() else REPORT_HEADER
    begin, end = _markers(output.name)
    numbers = json.dumps(output.numbers, sort_keys=True, default=_json_default)
    body = (f"{begin}\n## {output.title}\n\n*Made by `{command}`.*\n\n{output.markdown.strip()}\n\n"
            f"<!-- numbers:{output.name} {numbers} -->\n{end}")
    pattern = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.S)
    if pattern.search(text):
        text = pattern.sub(lambda _: body, text)
    else:
        # insert before the first later study already present
        later = ORDER[ORDER.index(output.name) + 1:] if output.name in ORDER else []
        positions = [text.find(_markers(n)[0]) for n in later if _markers(n)[0] in text]
        if positions:
            i = min(positions)
            text = text[:i] + body + "\n\n" + text[i:]
        else:
            text = text.rstrip() + "\n\n" + body + "\n"
    path.write_text(text, encoding="utf-8")


def recorded_numbers(path: Path) -> dict[str, dict]:
    """The numbers each study recorded in the report at ``path`` ({study: numbers})."""
    if not path.exists():
        return {}
    out = {}
    for m in re.finditer(r"<!-- numbers:(\S+) (\{.*?\}) -->", path.read_text(encoding="utf-8")):
        try:
            out[m.group(1)] = json.loads(m.group(2))
        except json.JSONDecodeError:  # pragma: no cover - a hand-edited report
            pass
    return out


def _json_default(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serializable: {type(o).__name__}")


def to_json(obj) -> str:
    return json.dumps(obj, indent=2, sort_keys=False, default=_json_default, allow_nan=True)


def parallel_map(fn, jobs, fast: bool, workers: int | None = None):
    """Map ``fn`` over ``jobs`` (in order); on 2 processes unless fast or a single job.

    The environment variable ``CAMDYN_WORKERS`` (e.g. ``1`` on a shared machine) overrides the
    number of processes. ``fn`` must be a module-level function (picklable)."""
    jobs = list(jobs)
    env = os.environ.get(WORKERS_ENV, "").strip()
    if workers is None and env:
        workers = max(1, int(env))
    workers = workers if workers is not None else (1 if fast else min(2, os.cpu_count() or 1))
    if workers <= 1 or len(jobs) <= 1:
        return [fn(j) for j in jobs]
    from concurrent.futures import ProcessPoolExecutor
    with ProcessPoolExecutor(workers) as ex:
        return list(ex.map(fn, jobs))


def impact_run(rig, damping: str, speed_rpm: float, revolutions: float, transient: float,
               sample_rate_Hz: float = 4000.0, keep_history: float = 0.0, y0=None, t_start: float = 0.0,
               max_revolutions: float | None = None) -> dict:
    """One run of the experiment's impacting rig: residual statistics and the Poincare section.

    Returns a JSON-able dict; ``keep_history`` revolutions of (t, alpha_r) at the end are kept.
    The run starts from the static equilibrium, or from ``y0 = (alpha, alpha_dot)`` at time
    ``t_start`` (e.g. the end state of a run at a neighbouring speed: ``out["end_state"]``).

    Statistics and the class are taken over the last ``revolutions - transient`` revolutions
    (the *window*). With ``max_revolutions``, a run whose window is aperiodic is continued, one
    window at a time, from its end state, up to ``max_revolutions`` in all, and classed on its
    last window: a motion that wanders between coexisting attractors for a few hundred
    revolutions before it settles is then classed by where it settles, not as aperiodic.
    ``out["revolutions"]`` is the number of revolutions run in all.
    """
    scene = camdyn.Scene(contact="line", damping=damping, friction="coulomb")
    window = revolutions - transient
    out = {"damping": damping, "speed_rpm": speed_rpm, "revolutions": revolutions, "transient": transient}
    r = simulate(rig, scene, speed_rpm=speed_rpm, revolutions=revolutions, sample_rate_Hz=sample_rate_Hz,
                 y0=y0, t_start=t_start)
    skip, total = transient, revolutions
    while True:
        out.update(_window_stats(r, skip))
        if (out["class"] != "aperiodic" or not max_revolutions or window <= 0
                or total + window > max_revolutions + 1e-9):
            break
        r = simulate(rig, scene, speed_rpm=speed_rpm, revolutions=window, sample_rate_Hz=sample_rate_Hz,
                     y0=(float(r.alpha[-1]), float(r.alpha_dot[-1])), t_start=float(r.t[-1]))
        skip, total = 0.0, total + window
    out.update(outcome=r.outcome.name, backend=r.meta.get("backend"), revolutions=total)
    if r.t.size:
        out["end_state"] = [float(r.alpha[-1]), float(r.alpha_dot[-1]), float(r.t[-1])]
    if keep_history and r.t.size:
        T = r.period
        keep = r.t >= r.t[-1] - keep_history * T
        out["t"] = ((r.t[keep] - r.t[keep][0]) / T).tolist()
        out["alpha_r"] = r.alpha_r[keep].tolist()
    return out


#: a largest Lyapunov exponent is told from zero when it is this many standard errors of its
#: batch means away from it (about 99.7 % for independent, normally distributed batch means)
CONFIDENCE_SE = 3.0


def chaos_by_lyapunov(rig, damping: str, speed_rpm: float, transient: int, revolutions: int, batches: int) -> dict:
    """The largest Lyapunov exponent (camdyn.orbits.lyapunov) of the impacting rig's run from the
    static equilibrium, over ``revolutions`` after ``transient`` (the window of
    :func:`impact_run`'s class), and the verdict it gives: *chaotic* where it is positive by
    CONFIDENCE_SE standard errors, *regular* where it is negative by as many, else *undecided*.
    From the tangent dynamics where they can be integrated (``method`` "variational"); where they
    cannot (damping C and E: their impact law's Jacobian is unbounded at first contact,
    camdyn.orbits.tangent), from two neighbouring runs (``method`` "differences",
    camdyn.orbits.lyapunov.largest_by_differences), whose distance's effect on the exponent must
    then not change the verdict (:func:`camdyn.orbits.lyapunov.largest_exponent`)."""
    from camdyn.model.model import Model
    from camdyn.orbits.lyapunov import LyapunovSettings, largest_exponent

    scene = camdyn.Scene(contact="line", damping=damping, friction="coulomb")
    settings = LyapunovSettings(revolutions=revolutions, transient=transient, batches=batches)
    e = largest_exponent(Model(rig, scene, camdyn.ConstantSpeed(speed_rpm)), settings)
    return {"lyapunov": e.largest, "lyapunov_se": e.standard_error, "lyapunov_per_rev": e.largest * e.period,
            "chaos": e.verdict(CONFIDENCE_SE), "lyapunov_method": e.method}


def continuation_start(end_state, from_rpm: float, to_rpm: float) -> tuple[list[float], float]:
    """(y0, t_start) that continue a run ended in ``end_state`` (alpha, alpha_dot, t) at
    ``from_rpm`` at the speed ``to_rpm``, at the same cam angle (Theta = Theta0 + Omega_c t):
    the second initial condition of a slow speed sweep."""
    alpha, alpha_dot, t = end_state
    w_from, w_to = from_rpm * 2 * math.pi / 60.0, to_rpm * 2 * math.pi / 60.0
    phase = math.fmod(w_from * t, 2 * math.pi)
    return [alpha, alpha_dot], phase / w_to


def _window_stats(r, transient: float) -> dict:
    """rms, peak-to-peak, max, impacts per revolution, Poincare section and class of a run
    after ``transient`` revolutions (the class's tolerance is relative to the window's own
    peak-to-peak of alpha_r)."""
    out = {}
    T = r.period
    t_end = r.t[-1] if r.t.size else 0.0
    steady = r.after(r.t[0] + transient * T) if r.t.size else r
    if steady.t.size > 10:
        ar = steady.alpha_r
        out.update(rms=float(np.sqrt(np.mean((ar - ar.mean()) ** 2))), p2p=float(np.ptp(ar)),
                   max=float(ar.max()), impacts_per_rev=float(len(steady.impacts()) / max((t_end - steady.t[0]) / T, 1e-9)))
        section, _ = poincare(r, transient)
        out["section"] = section.tolist()
        scale = max(float(np.ptp(ar)), 1e-6)
        out["class"] = classify(section, scale) if r.ok else f"stopped ({r.outcome.name})"
    else:
        out.update(rms=None, p2p=None, max=None, impacts_per_rev=None, section=[])
        out["class"] = f"stopped ({r.outcome.name})"
    return out
