"""Chaos onsets of Section 4 against the reference rig's assumed geometry.

The reference rig fixes four geometry values by assumption (r_c, chi0, d_x and Theta0; d_y
is only a datum), and nothing the paper prints determines them. Section 4 states where the
experiment's motion becomes chaotic (B and D above about 155 rev/min, E earlier, A and C
still periodic at 155). This study asks whether some assumed geometry reproduces those
onsets: for every geometry of a grid it refits the other unknowns with
:func:`camdyn.studies.rig_fit.identify` (so every printed number is reproduced again),
builds the experiment's variant, and classes the motion (Poincare section once per cam
revolution) at the speeds that decide the paper's statements (stage 1); the geometries that
meet most statements, and the shipped geometry, are then run for all five damping models
on a denser speed grid (stage 2).

Its section is written to ``docs/reproduction.md`` and, as "Chaos onsets: geometry scan",
to ``docs/reference-rig.md`` (which :mod:`.reference_rig` renders from the numbers this
study records in the report).
"""
from __future__ import annotations

import json
import math
import time

from camdyn.analysis.statics import contact_loss_speed
from camdyn.model.presets import load_rig

from .common import (Context, StudyOutput, chaos_by_lyapunov, fmt, impact_run, md_table, parallel_map,
                     recorded_numbers, to_json)
from .rig_fit import INITIAL, experiment_variant, identify, preset_start, unknowns

NAME, TITLE = "chaos-scan", "Chaos onsets: geometry scan"

#: the runs that decide the paper's statements (model, speed in rev/min)
STAGE1_RUNS = (("B", 150.0), ("B", 155.0), ("B", 159.0), ("D", 150.0), ("D", 155.0), ("D", 159.0),
               ("E", 148.0), ("E", 150.0), ("A", 155.0), ("C", 148.0), ("C", 150.0), ("C", 155.0))

#: the statements of Sec. 4 as checks on the stage-1 runs: name -> (text, predicate on {run: class})
def _p(c):
    return str(c).startswith("P")


def _ap(c):
    return c == "aperiodic"


CHECKS = {
    "BD150": ("B and D periodic at 150", lambda k: _p(k["B150"]) and _p(k["D150"])),
    "B155": ("B aperiodic at 155 or 159", lambda k: _ap(k["B155"]) or _ap(k["B159"])),
    "D155": ("D aperiodic at 155 or 159", lambda k: _ap(k["D155"]) or _ap(k["D159"])),
    "E": ("E aperiodic at 148 or 150 (earlier than B, D)", lambda k: _ap(k["E148"]) or _ap(k["E150"])),
    "AC155": ("A and C periodic at 155", lambda k: _p(k["A155"]) and _p(k["C155"])),
    "C150": ("C periodic at 148 and 150 (periodic below 150)", lambda k: _p(k["C148"]) and _p(k["C150"])),
}

MODELS = "ABCDE"


def settings(fast: bool) -> dict:
    if fast:
        return dict(grid=dict(r_c=[0.025], chi0=[0.10], dx_ratio=[1.0, 0.5], theta0_offset=[0.0]),
                    stage1=(("D", 155.0), ("E", 150.0)), dense=[150.0, 155.0], stage2=1,
                    revolutions=6, transient=3, max_revolutions=6, batches=3)
    return dict(grid=dict(r_c=[0.025, 0.020, 0.015], chi0=[0.07, 0.10, 0.14, 0.20],
                          dx_ratio=[0.3, 0.4, 0.5, 0.6, 1.0], theta0_offset=[0.0, math.pi]),
                stage1=STAGE1_RUNS, dense=[140.0, 143.0, 145.0, 148.0, 150.0, 152.0, 155.0, 157.0, 159.0, 162.0],
                stage2=3, revolutions=200, transient=100, max_revolutions=500, batches=10)


def geometries(grid: dict) -> list[dict]:
    out = []
    for r_c in grid["r_c"]:
        for chi0 in grid["chi0"]:
            for ratio in grid["dx_ratio"]:
                for off in grid["theta0_offset"]:
                    out.append(dict(r_c=r_c, chi0=chi0, dx_ratio=ratio, theta0_offset=off))
    return out


def _fit(g: dict):
    # start from the shipped preset, scaled to the lever: the frequencies fix I_Pb / chi*^2 and w_b / chi*
    start = preset_start()
    s = g["chi0"] / load_rig("reference").chi0
    start.update(I_Pb=start["I_Pb"] * s * s, w_b=start["w_b"] * s)
    geometry = dict(r_c=g["r_c"], chi0=g["chi0"], d_x=g["dx_ratio"] * g["chi0"], theta0_offset=g["theta0_offset"])
    res = identify(start, geometry)
    return res, experiment_variant(res)


def _fit_summary(res) -> dict:
    return {"within_rounding": bool(res.all_within),
            "max_abs_residual_sigma": max(abs(r.normalized) for r in res.residuals),
            "fitted": {k: float(v) for k, v in res.values.items()},
            "contact_loss_e07_rpm": contact_loss_speed(res.rig.replace(e=0.7 * res.rig.r_c))}


def _stage1(args) -> dict:
    g, runs, s = args
    t0 = time.time()
    res, exp = _fit(g)
    out = {"geometry": g, **_fit_summary(res), "classes": {}}
    for d, sp in runs:
        r = impact_run(exp, d, sp, s["revolutions"], s["transient"], max_revolutions=s["max_revolutions"])
        out["classes"][f"{d}{sp:g}"] = r["class"]
    if all(k in out["classes"] for d, sp in STAGE1_RUNS for k in [f"{d}{sp:g}"]):
        out["checks"] = {name: bool(pred(out["classes"])) for name, (_, pred) in CHECKS.items()}
    else:
        out["checks"] = {}
    out["met"] = sum(out["checks"].values())
    out["seconds"] = time.time() - t0
    return out


def _stage2(args) -> dict:
    g, speeds, s = args
    res, exp = _fit(g)
    out = {"geometry": g, **_fit_summary(res), "classes": {}, "lyapunov": {}}
    for d in MODELS:
        for sp in speeds:
            r = impact_run(exp, d, sp, s["revolutions"], s["transient"], max_revolutions=s["max_revolutions"])
            out["classes"][f"{d}{sp:g}"] = r["class"]
            ly = chaos_by_lyapunov(exp, d, sp, s["transient"], s["revolutions"] - s["transient"], s["batches"])
            out["lyapunov"][f"{d}{sp:g}"] = {k: ly[k] for k in ("chaos", "lyapunov", "lyapunov_se")}
    out["onsets"] = onsets(out["classes"], speeds)
    out["onsets_lyapunov"] = {d: next((sp for sp in speeds if out["lyapunov"][f"{d}{sp:g}"]["chaos"] == "chaotic"),
                                      None) for d in MODELS}
    out["verdict"] = verdict(judged(out), speeds)
    return out


def judged(r: dict) -> dict:
    """Each stage-2 run's class as the verdicts read it: by the largest Lyapunov exponent where
    there is one (chaotic: aperiodic; regular: periodic, its periodicity class if that is
    periodic, else "P (λ1 < 0)"; undecided: neither), by the periodicity class where there is
    none (an older result without one: damping C and E had no exponent before the two-run estimate)."""
    out = {}
    for key, c in r["classes"].items():
        ly = r.get("lyapunov", {}).get(key, {}).get("chaos", "n/a")
        out[key] = {"chaotic": "aperiodic", "regular": c if str(c).startswith("P") else "P (λ1 < 0)",
                    "undecided": "undecided"}.get(ly, c)
    return out


def onsets(classes: dict, speeds) -> dict:
    """The first aperiodic speed per model (None: none aperiodic)."""
    first = {}
    for d in MODELS:
        ap = [sp for sp in speeds if classes.get(f"{d}{sp:g}") == "aperiodic"]
        first[d] = min(ap) if ap else None
    return first


def verdict(classes: dict, speeds) -> dict:
    """The paper's statements on the dense grid: A-D periodic below 150 (E may be chaotic earlier);
    B and D first aperiodic at 152 or above and aperiodic somewhere in 155-159; E first aperiodic
    before B and D; A and C periodic at 155."""
    first = onsets(classes, speeds)
    low = [sp for sp in speeds if sp < 150.0]
    band = [sp for sp in speeds if 155.0 <= sp <= 159.0]
    bd = [first[d] for d in "BD"]
    return {
        "A–D periodic below 150": all(str(classes.get(f"{d}{sp:g}", "")).startswith("P") for d in "ABCD" for sp in low),
        "B, D onset 152-159": all(f is not None and f >= 152.0 for f in bd)
        and all(any(classes.get(f"{d}{sp:g}") == "aperiodic" for sp in band) for d in "BD"),
        "E earlier than B, D": first["E"] is not None and all(f is None or first["E"] < f for f in bd),
        "A, C periodic at 155": all(str(classes.get(f"{d}155")).startswith("P") for d in "AC"),
    }


def _geo_text(g: dict) -> str:
    off = g["theta0_offset"]
    off_s = "0" if off == 0 else ("π" if abs(off - math.pi) < 1e-12 else f"{off:.3g}")
    return (f"r_c {1000 * g['r_c']:g} mm, χ0 {1000 * g['chi0']:g} mm, d_x {g['dx_ratio']:g} χ0, "
            f"Θ0 + π/2 + α0 = {off_s}")


def _misfits(st1: list[dict]) -> str:
    """Which geometries do not reproduce the printed numbers, and which fitted unknown sits at a bound."""
    bad = [r for r in st1 if not r["within_rounding"]]
    if not bad:
        return ""
    bounds = {u.name: (u.lower, u.upper) for u in unknowns(INITIAL)}
    at = sorted({f"{k} at its {'upper' if abs(v - bounds[k][1]) <= 1e-6 * abs(bounds[k][1]) else 'lower'} bound "
                 f"{bounds[k][1] if abs(v - bounds[k][1]) <= 1e-6 * abs(bounds[k][1]) else bounds[k][0]:g}"
                 for r in bad for k, v in r["fitted"].items()
                 if k in bounds and min(abs(v - b) for b in bounds[k]) <= 1e-6 * max(abs(b) for b in bounds[k])})
    geos = sorted({(r["geometry"]["r_c"], r["geometry"]["dx_ratio"]) for r in bad})
    return (" (the other " + str(len(bad)) + ": r_c, d_x / χ0 = "
            + ", ".join(f"{1000 * a:g} mm, {b:g}" for a, b in geos)
            + (f"; the fit ends with {', '.join(at)}" if at else "") + "; they are kept in the table)")


def _short(c: str) -> str:
    return "ap" if c == "aperiodic" else ("stop" if str(c).startswith("stopped") else str(c))


def section(numbers: dict) -> str:
    """The markdown of the scan (for reproduction.md and reference-rig.md) from its recorded numbers."""
    s = numbers["settings"]
    st1, st2 = numbers["stage1"], numbers["stage2"]
    runs = [f"{d}{sp:g}" for d, sp in s["stage1"]]
    lines = _intro(s, st1, numbers.get("stage1_reused", False)) + _stage1_lines(st1, runs) + _stage2_lines(st2, s["dense"])
    lines += _conclusion(st2, s["dense"])
    return "\n".join(lines)


def _intro(s: dict, st1: list[dict], reused: bool) -> list[str]:
    """The grid, the refit and the classifier."""
    g = s["grid"]
    return [
        f"Does any assumed geometry reproduce the chaos onsets of Section 4 (B and D chaotic above about "
        f"155 rev/min, E earlier, A and C still periodic at 155)? Grid: r_c ∈ {{{', '.join(f'{1000 * v:g}' for v in g['r_c'])}}} mm "
        f"(the bound of Sec. 7.2 allows up to about 25 mm), χ0 ∈ {{{', '.join(f'{1000 * v:g}' for v in g['chi0'])}}} mm, "
        f"d_x / χ0 ∈ {{{', '.join(f'{v:g}' for v in g['dx_ratio'])}}}, Θ0 = −π/2 − α0 + "
        f"{{{', '.join('0' if v == 0 else ('π' if abs(v - math.pi) < 1e-12 else f'{v:.3g}') for v in g['theta0_offset'])}}}; "
        f"d_y = 100 mm (a datum: only L_us − d_y enters). {len(st1)} geometries; for each, I_Pb, w_b, L_us, α0 and "
        f"the experiment's k_s are refitted (`reference_rig.identify(start, geometry)`), and "
        f"{sum(1 for r in st1 if r['within_rounding'])} of {len(st1)} reproduce every printed number to its "
        f"rounding{_misfits(st1)}.",
        "",
        f"Classifier: the motion is started from the static equilibrium (as in Sec. 4) and run "
        f"{s['revolutions']} revolutions; the first {s['transient']} are dropped; the Poincaré section (α_r once per "
        f"revolution) of the last {s['revolutions'] - s['transient']} is *periodic (Pn)* when it repeats with "
        f"period n ≤ 8 to 0.2 % of the window's peak-to-peak α_r. A window classed aperiodic is continued from "
        f"its end state, one window at a time, up to {s['max_revolutions']} revolutions, and classed by its last "
        f"window: a motion wandering between coexisting attractors before it settles is classed by where it "
        f"settles. *ap* = still aperiodic after {s['max_revolutions']} revolutions "
        f"(chaotic or a very long transient; no Lyapunov exponent is computed).",
        "",
        "**Stage 1**: every geometry at the speeds that decide the paper's statements"
        + (" (recorded by an earlier run with the same settings, reused: `--reuse`)" if reused else "")
        + ". Checks: " + "; ".join(f"({i + 1}) {CHECKS[k][0]}" for i, k in enumerate(CHECKS)) + ".",
        "",
    ]


def _stage1_lines(st1: list[dict], runs: list[str]) -> list[str]:
    """Every geometry at the deciding speeds, with the checks it meets."""
    lines = []
    rows = []
    for r in sorted(st1, key=lambda r: -r["met"]):
        ok = "".join("✓" if r["checks"].get(k) else "✗" for k in CHECKS) if r["checks"] else "–"
        rows.append([_geo_text(r["geometry"]), "yes" if r["within_rounding"] else "**no**"]
                    + [_short(r["classes"].get(k, "–")) for k in runs] + [f"{r['met']} {ok}"])
    lines.append(md_table(["geometry", "printed numbers"] + runs + ["checks met"], rows))
    lines.append("")
    if st1 and st1[0]["checks"]:
        counts = {k: sum(1 for r in st1 if r["classes"].get(k) == "aperiodic") for k in runs}
        lines.append("Aperiodic runs per column over the grid: "
                     + ", ".join(f"{k} {counts[k]}/{len(st1)}" for k in runs) + ".")
        per_check = {k: sum(1 for r in st1 if r["checks"].get(k)) for k in CHECKS}
        lines.append("")
        lines.append("Geometries meeting each check: " + ", ".join(f"({i + 1}) {per_check[k]}/{len(st1)}"
                                                                  for i, k in enumerate(CHECKS)) + "; all "
                     f"{len(CHECKS)}: {sum(1 for r in st1 if r['met'] == len(CHECKS))}.")
        lines.append("")
    return lines


_LY_SHORT = {"chaotic": "ch", "regular": "reg", "undecided": "?", "n/a": "n/a"}


def _stage2_lines(st2: list[dict], speeds) -> list[str]:
    """The best geometries and the shipped one on the dense speed grid."""
    lines = []
    lines.append(f"**Stage 2**: the {len(st2) - 1} geometries meeting most checks, and the shipped geometry "
                 f"(last), for all five models at {', '.join(f'{v:g}' for v in speeds)} rev/min.")
    lines.append("")
    for r in st2:
        lines.append(f"*{_geo_text(r['geometry'])}*" + (" (the shipped reference rig)" if r.get("shipped") else "")
                     + f": printed numbers within rounding: {'yes' if r['within_rounding'] else '**no**'}")
        lines.append("")
        rows = [[f"model {d}"] + [_short(r["classes"][f"{d}{sp:g}"]) for sp in speeds]
                + [fmt(r["onsets"][d]) if r["onsets"][d] else "none"] for d in MODELS]
        lines.append(md_table(["Ω_c (rev/min)"] + [f"{v:g}" for v in speeds] + ["first aperiodic"], rows))
        if r.get("lyapunov"):
            lines.append("")
            lines.append("The same runs judged by the largest Lyapunov exponent (as in fig4-5: *ch* chaotic, *reg* "
                         "regular, *?* undecided at 3 standard errors; for C and E λ1 by two neighbouring runs):")
            lines.append("")
            ly_rows = [[f"model {d}"] + [_LY_SHORT.get(r["lyapunov"][f"{d}{sp:g}"]["chaos"], "?") for sp in speeds]
                       + [fmt(r["onsets_lyapunov"][d]) if r["onsets_lyapunov"][d] else "none"] for d in MODELS]
            lines.append(md_table(["Ω_c (rev/min)"] + [f"{v:g}" for v in speeds] + ["first chaotic (λ1)"], ly_rows))
        lines.append("")
        lines.append("Paper's statements on this grid (chaos judged by λ1 where there is one, by periodicity "
                     "where it is n/a): " + "; ".join(
                         f"{k}: {'yes' if v else '**no**'}" for k, v in verdict(judged(r), speeds).items()) + ".")
        lines.append("")
    return lines


def _conclusion(st2: list[dict], speeds) -> list[str]:
    """Whether any geometry reproduces the onsets; otherwise the closest one and why not."""
    lines = []
    classes = [judged(r) for r in st2]          # chaos by lambda_1 where there is one
    first = [onsets(c, speeds) for c in classes]
    found = [r for r, c in zip(st2, classes) if all(verdict(c, speeds).values())]
    # a periodic range ending in a chaotic one, or periodic again above an aperiodic speed?
    rows_ap = [(i, d) for i in range(len(st2)) for d in MODELS if first[i][d] is not None]
    again = [(i, d) for i, d in rows_ap
             if any(str(classes[i][f"{d}{sp:g}"]).startswith("P") for sp in speeds if sp > first[i][d])]
    if rows_ap:
        lines.append(f"In stage 2 (chaos by λ1 where there is one, by periodicity where it is n/a), {len(rows_ap)} of "
                     f"{len(st2) * len(MODELS)} model rows have a chaotic speed; in {len(again)} of them a higher "
                     "speed is periodic again.")
        lines.append("")
    if not found and st2:
        fails = [(sum(not v for v in verdict(c, speeds).values()), i) for i, c in enumerate(classes)]
        k, i = min(fails)
        r, c = st2[i], classes[i]
        v = verdict(c, speeds)
        low = [f"{d} {sp:g}" for d in "ABCD" for sp in speeds if sp < 150.0 and not str(c[f"{d}{sp:g}"]).startswith("P")]
        back = []
        for d in "BD":
            on = first[i][d]
            later = [sp for sp in speeds if on is not None and sp > on and str(c[f"{d}{sp:g}"]).startswith("P")]
            if later:
                back.append(f"{d} (" + ", ".join(f"{sp:g} {c[f'{d}{sp:g}']}" for sp in later) + ")")
        lines.append(f"Closest: *{_geo_text(r['geometry'])}*, which fails {k} of {len(v)} statements ("
                     + ", ".join(name for name, ok in v.items() if not ok) + ")"
                     + (f"; not periodic below 150 rev/min: {', '.join(low)}" if low else "")
                     + (f"; periodic again above the onset: {', '.join(back)}" if back else "") + ".")
        lines.append("")
    if found:
        lines.append("**Reproduced** by: " + "; ".join(_geo_text(r["geometry"]) for r in found) + ".")
    else:
        lines.append(
            "**Not reproduced.** No scanned geometry reproduces the chaos onsets of Section 4 on the dense speed "
            "grid, so the assumed geometry of the shipped rig is kept. Likely reasons (hypotheses, not tested "
            "here): the onsets depend on the damping laws' constants, which the paper identified on Alzate et "
            "al.'s rig and camdyn keeps as printed, and on that rig's inertia and spring beyond what the printed "
            "numbers fix; and the paper does not say how it classed a motion as chaotic (its Figs. 4–6 show time "
            "histories and spectra of a few revolutions), so which of camdyn's periodic windows, long transients "
            "or coexisting motions would count as chaotic there is not known.")
    return lines


def run(ctx: Context) -> StudyOutput:
    s = settings(ctx.fast)
    geos = geometries(s["grid"])
    st1 = _recorded_stage1(ctx, s) if ctx.reuse else None
    reused = st1 is not None
    if not reused:
        ctx.log(f"{NAME}: stage 1, {len(geos)} geometries x {len(s['stage1'])} runs")
        st1 = parallel_map(_stage1, [(g, s["stage1"], s) for g in geos], ctx.fast)
    else:
        ctx.log(f"{NAME}: stage 1 reused from {ctx.out / 'reproduction.md'} ({len(st1)} geometries)")
    # stage 2: the geometries meeting most checks among those reproducing every printed number
    best = sorted(range(len(st1)), key=lambda i: (not st1[i]["within_rounding"], -st1[i]["met"], i))[: s["stage2"]]
    shipped = dict(r_c=0.025, chi0=0.10, dx_ratio=1.0, theta0_offset=0.0)
    cand = [st1[i]["geometry"] for i in best]
    ctx.log(f"{NAME}: stage 2, {len(cand) + 1} geometries x {len(MODELS) * len(s['dense'])} runs")
    st2 = parallel_map(_stage2, [(g, s["dense"], s) for g in cand + [shipped]], ctx.fast)
    st2[-1]["shipped"] = True
    numbers = {"settings": _as_recorded(s), "stage1_reused": reused,
               "stage1": [{k: v for k, v in r.items() if k != "seconds"} for r in st1], "stage2": st2,
               "reproduced": [r["geometry"] for r in st2 if all(r["verdict"].values())]}
    md = section(numbers)
    if ctx.write_docs:
        _update_reference_rig_doc(ctx, md)
    return StudyOutput(NAME, TITLE, md, numbers, [])


#: the settings stage 1's results depend on: a recorded stage 1 is reused only when they agree
STAGE1_SETTINGS = ("grid", "stage1", "revolutions", "transient", "max_revolutions")


def _as_recorded(s: dict) -> dict:
    """The settings as the report records them (the stage-1 runs as lists)."""
    return {**s, "stage1": [list(x) for x in s["stage1"]]}


def _recorded_stage1(ctx: Context, s: dict) -> list[dict] | None:
    """Stage 1 as recorded in the report by an earlier run with the same stage-1 settings, or None
    (then it is run again)."""
    rec = recorded_numbers(ctx.out / "reproduction.md").get(NAME)
    if not rec:
        return None
    now = json.loads(to_json(_as_recorded(s)))
    same = all(rec["settings"].get(k) == now[k] for k in STAGE1_SETTINGS)
    return rec["stage1"] if same and len(rec["stage1"]) == len(geometries(s["grid"])) else None


MARK_BEGIN, MARK_END = "<!-- chaos-scan begin -->", "<!-- chaos-scan end -->"


def reference_rig_block(md: str | None) -> str:
    """The "Chaos onsets: geometry scan" section of reference-rig.md (``md``: this study's markdown)."""
    body = md if md else ("Not run yet: `python -m camdyn.studies chaos-scan` scans the assumed geometry for the "
                          "chaos onsets of Section 4 and writes its result here.")
    return (f"{MARK_BEGIN}\n## Chaos onsets: geometry scan\n\n*Made by `python -m camdyn.studies chaos-scan`.*\n\n"
            f"{body.strip()}\n{MARK_END}")


def _update_reference_rig_doc(ctx: Context, md: str) -> None:
    path = ctx.out / "reference-rig.md"
    if not path.exists():
        return
    text = path.read_text(encoding="utf-8")
    block = reference_rig_block(md)
    if MARK_BEGIN in text and MARK_END in text:
        i, j = text.index(MARK_BEGIN), text.index(MARK_END) + len(MARK_END)
        text = text[:i] + block + text[j:]
    else:
        text = text.rstrip() + "\n\n" + block + "\n"
    path.write_text(text, encoding="utf-8")
    ctx.log(f"updated {path} (section chaos onsets)")
