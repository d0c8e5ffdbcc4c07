"""The paper's studies, reproduced on the reference rig, one command each.

``python -m camdyn.studies <name>`` runs one study: it writes its figure
(``<out>/img/repro_<name>.png``), its numbers, and its section of
``<out>/reproduction.md`` (the paper's statement beside camdyn's result).  ``<out>`` is the
checkout's ``docs/`` when camdyn runs from a source checkout (an editable install), else
``./camdyn-reproduction`` in the working directory: nothing is written inside an installed
package.
``python -m camdyn.studies list`` lists them; ``--fast`` (or the environment variable
``CAMDYN_FAST=1``) runs a reduced version (fewer revolutions and speeds) for tests.

From Python::

    from camdyn import studies
    out = studies.run("fig10", fast=True, out="/tmp/repro")   # -> StudyOutput
    out.numbers, out.figures, out.markdown

Studies: reference-rig (identify the reference rig; writes the presets reference*.toml into the
checkout's camdyn/model/data, or ``<out>/rigs`` for an installed camdyn, and ``<out>/reference-rig.md``), fig4-5, chaos-scan, fig6, fig7-8, fig9, fig10, fig11, fig12-15, fig16, numbers, second-rig, jump-chart.
"""
from __future__ import annotations

import importlib
from pathlib import Path

from .common import DEFAULT_OUT, FAST_ENV, ORDER, Context, StudyOutput, default_out, fast_default, update_report

__all__ = ["STUDIES", "run", "Context", "StudyOutput", "FAST_ENV", "DEFAULT_OUT", "report_path"]

#: study name -> (module, one-line description)
STUDIES = {
    "reference-rig": ("reference_rig", "identify the reference rig (presets + reference-rig.md)"),
    "fig4-5": ("fig04_05", "alpha_r rms and peak-to-peak vs speed, damping A-E; time histories at 155 rev/min"),
    "chaos-scan": ("chaos_scan", "the chaos onsets of Sec. 4 against the assumed geometry (also in reference-rig.md)"),
    "fig6": ("fig06", "alpha_r in time and frequency at 155 rev/min, damping D"),
    "fig7-8": ("fig07_08", "alpha_rp vs speed: contact model and energy balance, low and broad range"),
    "fig9": ("fig09", "the k_s - Omega_c map of sliding and impacting regimes"),
    "fig10": ("fig10", "alpha spectra: line vs point, de- vs self-energizing"),
    "fig11": ("fig11", "F_n(t) for the two directions of rotation"),
    "fig12-15": ("fig12_15", "v_r, F_f, N_x: Coulomb vs smoothed friction, printed and kinematic v_r"),
    "fig16": ("fig16", "alpha spectra: linearized vs non-linear model"),
    "numbers": ("numbers_report", "every reported number: paper, camdyn, relative difference"),
    "second-rig": ("second_rig", "the second published rig (issue 28): detachment, bifurcation diagram, corners"),
    "jump-chart": ("jump_chart", "the jump speed against k_s on the reference experiment rig (two-parameter continuation)"),
}
assert list(STUDIES) == ORDER


def report_path(out: str | Path | None = None) -> Path:
    return (Path(out) if out is not None else default_out()) / "reproduction.md"


def run(name: str, *, fast: bool | None = None, out: str | Path | None = None, write_docs: bool = True,
        data_dir: str | Path | None = None, log=print, reuse: bool = False) -> StudyOutput:
    """Run one study; write its figure(s) and its section of ``<out>/reproduction.md``.

    ``fast`` (default: the environment variable CAMDYN_FAST) reduces speeds and revolutions.
    ``out`` is the folder of the report (default: the checkout's ``docs/`` when camdyn runs
    from a source checkout, else ``./camdyn-reproduction``); figures go to ``<out>/img``.
    ``data_dir`` is where ``reference-rig`` writes the presets (default: the checkout's
    ``camdyn/model/data``, else ``<out>/rigs``).  ``reuse`` lets a study take the results of an
    expensive stage from the numbers it recorded in ``<out>/reproduction.md`` when they were made
    with the same settings (chaos-scan's stage 1); the section then says so.  Nothing is written
    inside an installed package.
    """
    if name not in STUDIES:
        import difflib
        close = difflib.get_close_matches(name, list(STUDIES), n=1)
        raise KeyError(f"no study {name!r}" + (f" (did you mean {close[0]!r}?)" if close else "")
                       + f"; studies: {', '.join(STUDIES)}")
    fast = fast_default() if fast is None else bool(fast)
    out_dir = Path(out) if out is not None else default_out()
    if out is None and out_dir.name == DEFAULT_OUT:
        log(f"camdyn is not running from a source checkout: writing to {out_dir} (choose with --out DIR)")
    out_dir.mkdir(parents=True, exist_ok=True)
    ctx = Context(fast=fast, out=out_dir, write_docs=write_docs,
                  data_dir=Path(data_dir) if data_dir is not None else None, log=log, reuse=reuse)
    module = importlib.import_module(f"{__name__}.{STUDIES[name][0]}")
    output = module.run(ctx)
    if write_docs:
        command = f"python -m camdyn.studies {name}" + (" --fast" if fast else "") + (" --reuse" if reuse else "")
        update_report(out_dir / "reproduction.md", output, command)
        log(f"updated {out_dir / 'reproduction.md'} (section {name})")
    return output
