"""Every number the paper reports, with camdyn's value on the reference rig and the
relative difference; the paper's qualitative statements with camdyn's finding.

Static numbers (stiffnesses, natural frequencies, contact-loss speed, saturation) are
computed here; results of the dynamic studies are read from what those studies recorded
in the report (run them first; missing ones are listed as not run)."""
from __future__ import annotations

import math

import camdyn
from camdyn.analysis.statics import contact_loss_speed, natural_frequency, static_equilibrium

from .common import PAPER, Context, StudyOutput, experiment_rig, fmt, md_table, recorded_numbers, reference_rig, rel

NAME, TITLE = "numbers", "Every reported number: paper and camdyn"


def run(ctx: Context) -> StudyOutput:
    rec = recorded_numbers(ctx.out / "reproduction.md")
    entries = _static_entries(reference_rig(), experiment_rig()) + _spectrum_entries(rec.get("fig10", {}))
    qual = _chaos_statements(rec.get("fig4-5")) + _other_statements(rec)
    rows = [[e["quantity"], e["where"], f"{e['paper']:.6g} {e['unit']}",
             "–" if e["camdyn"] is None else f"{e['camdyn']:.6g} {e['unit']}",
             "–" if e["relative_difference"] is None else f"{e['relative_difference']:+.2e}", e["how"],
             f"`{e['command']}`"] for e in entries]
    md = "\n\n".join([
        "Each number the paper prints about its results, camdyn's value on the reference rig, and the "
        "relative difference (camdyn − paper) / paper. The rig was identified from the first seven "
        "(see [reference-rig.md](reference-rig.md)), so those agree by construction, to the paper's "
        "rounding; the spectral peaks are an independent check of the Jacobian values. The measured "
        "contact-loss speed (125 rev/min, Alzate et al.) is a measurement, not a model number: not "
        "reproduced. `python -m camdyn.studies numbers` also prints this list as JSON.",
        md_table(["quantity", "where", "paper", "camdyn", "relative difference", "how", "command"], rows),
        "The paper's qualitative statements:",
        md_table(["where", "the paper", "camdyn", "study"], qual),
    ])
    numbers = {"numbers": entries, "statements": [{"where": q[0], "paper": q[1], "camdyn": q[2], "study": q[3]}
                                                  for q in qual]}
    return StudyOutput(NAME, TITLE, md, numbers, [])


def _static_entries(ref, exp) -> list[dict]:
    """The seven static numbers, computed here on the reference rig and its experiment variant."""
    line = camdyn.Scene(contact="line", damping="D", friction="coulomb")
    point = camdyn.Scene(contact="point", damping="D", friction="coulomb")
    values = {
        "k_line": (static_equilibrium(ref, "line").contact_stiffness, "Eq. 13 at equilibrium", "numbers"),
        "k_point": (static_equilibrium(ref, "point").contact_stiffness, "Eq. 34 secant at equilibrium", "numbers"),
        "f_line_de": (natural_frequency(ref, line, camdyn.ConstantSpeed(300)).Hz, "Eq. 23, Jacobian", "numbers"),
        "f_line_se": (natural_frequency(ref, line, camdyn.ConstantSpeed(-300)).Hz, "Eq. 23, Jacobian", "numbers"),
        "f_point_de": (natural_frequency(ref, point, camdyn.ConstantSpeed(300)).Hz, "Eq. 23, Jacobian", "numbers"),
        "contact_loss": (contact_loss_speed(exp), "inverse kinematics, reference-experiment", "numbers"),
        "alpha_rp_saturation": (math.pi / 2 - static_equilibrium(exp).alpha, "energy balance limit π/2 − α*",
                                "numbers"),
    }
    entries = []
    for key, (v, how, study) in values.items():
        p = PAPER[key]
        entries.append({"quantity": key, "statement": p["text"], "where": p["where"], "unit": p["unit"],
                        "paper": p["value"], "camdyn": v, "relative_difference": rel(v, p["value"]),
                        "how": how, "command": f"python -m camdyn.studies {study}"})
    return entries


def _spectrum_entries(f10: dict) -> list[dict]:
    """The three natural frequencies again, as the peaks of fig10's spectra (None: fig10 not run)."""
    entries = []
    for key, pkey in (("line_de", "f_line_de"), ("line_se", "f_line_se"), ("point_de", "f_point_de")):
        p = PAPER[pkey]
        v = f10.get(key, {}).get("spectrum_peak_Hz")
        entries.append({"quantity": f"{pkey}_spectrum", "statement": p["text"] + " (peak of the α spectrum, Fig. 10)",
                        "where": p["where"], "unit": "Hz", "paper": p["value"], "camdyn": v,
                        "relative_difference": rel(v, p["value"]),
                        "how": "spectral peak of a simulation" if v is not None else "not run: run fig10 first",
                        "command": "python -m camdyn.studies fig10"})
    return entries


def _chaos_statements(f45: dict | None) -> list[list[str]]:
    """Section 4's chaos onsets against what fig4-5 recorded."""
    if not f45:
        return [["Sec. 4", "chaos onsets for damping A–E", "not run: run fig4-5 first", "fig4-5"]]
    fa = f45.get("first_aperiodic_rpm", {})
    at = f45.get("class_at_155", {})

    def first(model):
        speed = fa.get(model)
        return "none (periodic at every speed of the study)" if speed is None else f"{fmt(speed)} rev/min"
    return [
        ["Sec. 4", "chaos beyond about 155 rev/min for damping B and D",
         f"first aperiodic speed: B {first('B')}, D {first('D')}", "fig4-5"],
        ["Sec. 4", "damping E chaotic even before 155 rev/min", f"E: first aperiodic {first('E')}", "fig4-5"],
        ["Sec. 4", "damping A and C still periodic at 155 rev/min", f"A: {at.get('A')}, C: {at.get('C')}", "fig4-5"],
    ]


def _other_statements(rec: dict) -> list[list[str]]:
    """Sections 5, 7.1, 8 and 7.2 against what fig7-8, fig11, fig16 and fig12-15 recorded (those run)."""
    qual = []
    f78 = rec.get("fig7-8")
    if f78:
        under = ", ".join(fmt(v) for v in f78.get("below_xi005_rpm", [])) or "none"
        over = ", ".join(fmt(v) for v in f78.get("above_xi005_rpm", [])) or "none"
        qual.append(["Sec. 5", "ξ < 0.05 needed below 160 rev/min",
                     f"contact-model α_rp below the ξ = 0.05 energy balance at {under} rev/min, above it at {over}",
                     "fig7-8"])
    f11 = rec.get("fig11")
    if f11:
        qual.append(["Sec. 7.1", "self-energizing has the higher mean F_n",
                     f"mean F_n {f11['se']['mean_F_n']:.4g} N (self) vs {f11['de']['mean_F_n']:.4g} N (de)", "fig11"])
    f16 = rec.get("fig16")
    if f16:
        qual.append(["Sec. 8", "linear model: only the fundamental of Ω_c; non-linear: super-harmonics",
                     f"2nd harmonic / fundamental: linear (printed) {f16['linear_paper']['harmonics_over_fundamental'][0]:.2g}, "
                     f"non-linear {f16['nonlinear']['harmonics_over_fundamental'][0]:.2g}", "fig16"])
    f12 = rec.get("fig12-15")
    if f12:
        qual.append(["Sec. 7.2", "v_r changes sign twice per revolution at e = 0.7 r_c, 50 rev/min",
                     "sign changes per revolution (model II): printed v_r "
                     f"{f12['constant/printed/tanh']['v_r_sign_changes'] / f12['constant/printed/tanh'].get('periods', 1):g}"
                     f", kinematic v_r {f12['constant/kinematic/tanh']['v_r_sign_changes'] / f12['constant/kinematic/tanh'].get('periods', 1):g}",
                     "fig12-15"])
    return qual
