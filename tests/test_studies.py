"""The paper's studies: each runs in fast mode and produces its figure and its report section;
the shipped reference rig reproduces the paper's numbers to the paper's rounding."""
from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

import camdyn
from camdyn import studies
from camdyn.analysis.statics import contact_loss_speed, natural_frequency, static_equilibrium
from camdyn.studies import common, rig_fit

pytest.importorskip("matplotlib")

FIGURES = {
    "fig4-5": ["repro_fig4-5.png"], "fig6": ["repro_fig6.png"], "fig7-8": ["repro_fig7-8.png"],
    "fig9": ["repro_fig9.png"], "fig10": ["repro_fig10.png"], "fig11": ["repro_fig11.png"],
    "fig12-15": ["repro_fig12-13.png", "repro_fig14-15.png"], "fig16": ["repro_fig16.png"],
    "second-rig": ["repro_second-rig.png"], "jump-chart": ["repro_jump-chart.png"],
}


@pytest.fixture(scope="module")
def report_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("repro")


# ---------------------------------------------------------------- the reference rig

REF = camdyn.load_rig("reference")
EXP = camdyn.load_rig("reference-experiment")
LINE = camdyn.Scene(contact="line", damping="D", friction="coulomb")
POINT = camdyn.Scene(contact="point", damping="D", friction="coulomb")

TARGETS = {  # computed on the shipped presets; tolerance: the paper's rounding (half a unit of the last digit)
    "k_line": lambda: static_equilibrium(REF, "line").contact_stiffness,
    "k_point": lambda: static_equilibrium(REF, "point").contact_stiffness,
    "f_line_de": lambda: natural_frequency(REF, LINE, camdyn.ConstantSpeed(300)).Hz,
    "f_line_se": lambda: natural_frequency(REF, LINE, camdyn.ConstantSpeed(-300)).Hz,
    "f_point_de": lambda: natural_frequency(REF, POINT, camdyn.ConstantSpeed(300)).Hz,
    "contact_loss": lambda: contact_loss_speed(EXP),
    "alpha_rp_saturation": lambda: math.pi / 2 - static_equilibrium(EXP).alpha,
}


@pytest.mark.parametrize("key", TARGETS)
def test_reference_rig_reproduces_the_reported_number_to_the_papers_rounding(key):
    paper = common.PAPER[key]
    sigma = camdyn.analysis.calibrate.rounding_sigma(paper["value"], paper["digits"])
    assert abs(TARGETS[key]() - paper["value"]) <= sigma * (1 + 1e-9), (key, TARGETS[key](), paper["value"])


def test_reference_rig_settings_are_the_papers():
    """Sections 6-8: k_s = 2000 N/m, e = 0.1 r_c, line 1.6 mm, zeta_D = 0.01; the experiment variant
    differs only in k_s, l_lambda and zeta_D; sliding contact at 300 rev/min and at e = 0.7 r_c, 50 rev/min."""
    assert REF.k_s == 2000.0 and REF.l_lambda == 0.0016 and REF.zeta_D == 0.01 and REF.beta_D == 4.25
    assert REF.e == pytest.approx(0.1 * REF.r_c)
    assert EXP.l_lambda == 0.016 and EXP.zeta_D == 0.119
    diff = {k for k, v in REF.to_dict().items() if EXP.to_dict()[k] != v}
    assert diff == {"k_s", "l_lambda", "zeta_D", "name", "description"}
    assert contact_loss_speed(REF) > 300.0
    assert contact_loss_speed(REF.replace(e=0.7 * REF.r_c)) > 50.0


def test_reference_rig_study_regenerates_the_shipped_presets(tmp_path):
    """The calibration, started from the shipped values, lands on them (the presets are its output)."""
    out = studies.run("reference-rig", fast=True, out=tmp_path, data_dir=tmp_path / "data", log=lambda *a: None)
    fitted = camdyn.Rig.from_toml(tmp_path / "data" / "reference.toml")
    for name in ("I_Pb", "w_b", "L_us", "alpha0", "theta0"):
        assert getattr(fitted, name) == pytest.approx(getattr(REF, name), rel=1e-6, abs=1e-9), name
    exp = camdyn.Rig.from_toml(tmp_path / "data" / "reference-experiment.toml")
    assert exp.k_s == pytest.approx(EXP.k_s, rel=1e-6)
    assert all(v["within_rounding"] for k, v in out.numbers.items() if isinstance(v, dict) and "within_rounding" in v)
    doc = (tmp_path / "reference-rig.md").read_text()
    for word in ("reported", "inferred", "assumed", "Degrees of freedom", "residual / σ"):
        assert word in doc
    for name in ("r_c", "chi0", "d_x", "d_y", "theta0", "I_Pb", "w_b", "L_us", "alpha0", "k_s"):
        assert f"| {name} |" in doc


# ---------------------------------------------------------------- each study, fast

@pytest.mark.parametrize("name", list(FIGURES))
def test_study_runs_fast_and_writes_its_figure_and_section(name, report_dir):
    out = studies.run(name, fast=True, out=report_dir, log=lambda *a: None)
    for png in FIGURES[name]:
        path = report_dir / "img" / png
        assert path.exists() and path.stat().st_size > 10_000, png
        assert path in out.figures
    text = (report_dir / "reproduction.md").read_text()
    begin, end = common._markers(name)
    assert text.count(begin) == 1 and text.count(end) == 1
    section = text[text.index(begin):text.index(end)]
    assert f"python -m camdyn.studies {name} --fast" in section
    assert "The paper" in section or "the paper" in section
    if name == "second-rig":   # its corner impact, located on the continued branch (checked against a run in
        from camdyn.studies.second_rig import CORNER_RANGE      # tests/test_corner_impact.py)
        found = [c["speed_rpm"] for c in out.numbers["corner_impacts"]]
        assert len(found) == 1 and CORNER_RANGE[0] < found[0] < CORNER_RANGE[1] and f"{found[0]:.6f}" in section
    json.dumps(out.numbers, default=common._json_default)      # the numbers are JSON-able
    assert common.recorded_numbers(report_dir / "reproduction.md")[name] is not None


def test_numbers_study_lists_every_reported_number(report_dir):
    out = studies.run("numbers", fast=True, out=report_dir, log=lambda *a: None)
    entries = {e["quantity"]: e for e in out.numbers["numbers"]}
    for key, paper in common.PAPER.items():
        e = entries[key]
        assert e["paper"] == paper["value"] and e["camdyn"] is not None
        assert abs(e["relative_difference"]) < 2e-3
    assert "f_line_de_spectrum" in entries


def test_report_sections_are_replaced_in_place_and_kept_in_order(tmp_path):
    path = tmp_path / "reproduction.md"
    common.update_report(path, common.StudyOutput("fig9", "Nine", "first", {"a": 1}), "cmd9")
    common.update_report(path, common.StudyOutput("fig6", "Six", "six", {}), "cmd6")
    common.update_report(path, common.StudyOutput("fig9", "Nine", "second", {"a": 2}), "cmd9")
    text = path.read_text()
    assert "first" not in text and "second" in text
    assert text.index("## Six") < text.index("## Nine")
    assert text.startswith("# The paper's results, reproduced")
    assert common.recorded_numbers(path)["fig9"] == {"a": 2}


def test_poincare_classification():
    assert common.classify([1.0, 2.0] * 20, scale=1.0) == "P2"
    assert common.classify([0.5] * 30, scale=1.0) == "P1"
    assert common.classify([math.sin(k * k) for k in range(40)], scale=1.0) == "aperiodic"
    assert common.classify([1.0] * 5, scale=1.0) == "too short"


def test_command_line(tmp_path):
    run = [sys.executable, "-m", "camdyn.studies"]
    listed = subprocess.run(run + ["list"], capture_output=True, text=True, check=True).stdout
    assert all(name in listed for name in studies.STUDIES)
    bad = subprocess.run(run + ["fig99"], capture_output=True, text=True)
    assert bad.returncode == 2 and "no study 'fig99'" in bad.stderr
    out = subprocess.run(run + ["numbers", "--fast", "--out", str(tmp_path)], capture_output=True, text=True,
                         check=True).stdout
    entries = json.loads(out)["numbers"]
    assert {e["quantity"] for e in entries} >= set(common.PAPER)


def test_unknown_study_name_suggests():
    with pytest.raises(KeyError, match="did you mean 'fig10'"):
        studies.run("fig_10", fast=True)


# ---------------------------------------------------------------- periodicity runs and the geometry scan

def test_continuation_start_keeps_the_cam_angle():
    """The up-sweep's second start: the state at the end of a run at one speed, at the same cam angle
    at the next speed (Theta = Theta0 + Omega_c t)."""
    end = [0.3, -1.2, 25.71425]
    y0, t_start = common.continuation_start(end, 140.0, 143.0)
    assert y0 == [0.3, -1.2]
    w = lambda rpm: rpm * 2 * math.pi / 60
    d = (w(143.0) * t_start - w(140.0) * end[2]) % (2 * math.pi)
    assert min(d, 2 * math.pi - d) == pytest.approx(0.0, abs=1e-9)
    assert 0.0 <= t_start < 60 / 143.0


def test_impact_run_continues_from_its_end_state():
    """A run continued from its end state ends where the uninterrupted run ends; a periodic run is not
    extended by max_revolutions."""
    fs = 4400.0  # 2400 samples per revolution at 110 rev/min: the last sample is at the end of the run
    one = common.impact_run(EXP, "D", 110.0, 30, 10, sample_rate_Hz=fs, max_revolutions=60)
    assert one["class"] == "P1" and one["revolutions"] == 30
    y0, t = one["end_state"][:2], one["end_state"][2]
    assert t == pytest.approx(30 * 60 / 110.0, abs=1e-9)
    two = common.impact_run(EXP, "D", 110.0, 30, 0, sample_rate_Hz=fs, y0=y0, t_start=t)
    whole = common.impact_run(EXP, "D", 110.0, 60, 10, sample_rate_Hz=fs)
    assert two["end_state"][2] == pytest.approx(whole["end_state"][2], abs=1e-9)
    assert two["end_state"][0] == pytest.approx(whole["end_state"][0], abs=1e-7)


def test_reference_rig_geometry_override_refits_every_printed_number():
    """identify(geometry=...) keeps every printed number within rounding for another assumed geometry."""
    res = rig_fit.identify(geometry=dict(d_x=0.05, theta0_offset=math.pi))
    assert res.all_within
    assert res.rig.d_x == 0.05
    assert res.rig.theta0 == pytest.approx(rig_fit.theta0_for(res.rig.alpha0) + math.pi)
    with pytest.raises(KeyError, match="not one of"):
        rig_fit.identify(geometry=dict(e=0.1))


def _study_imports() -> dict[str, set[str]]:
    """module -> the modules of camdyn.studies it imports (at the top or inside a function)."""
    import ast
    folder = Path(studies.__file__).parent
    graph = {}
    for path in folder.glob("*.py"):
        names = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.level == 1:
                names |= {node.module} if node.module else {a.name for a in node.names}
        graph[path.stem] = names & {p.stem for p in folder.glob("*.py")}
    return graph


def test_the_studies_import_no_circle():
    """The reference-rig fit lives in rig_fit, which both reference_rig and chaos_scan import (they
    imported each other, inside functions)."""
    graph = _study_imports()
    assert graph["chaos_scan"] >= {"rig_fit"} and "reference_rig" not in graph["chaos_scan"]

    def on_a_circle(start: str) -> bool:
        todo, seen = list(graph[start]), set()
        while todo:
            module = todo.pop()
            if module == start:
                return True
            if module not in seen:
                seen.add(module)
                todo.extend(graph[module])
        return False

    circles = [m for m in graph if on_a_circle(m)]
    assert not circles, circles


def test_chaos_scan_writes_its_section_to_both_documents(tmp_path):
    """chaos-scan (fast) writes its section to reproduction.md and to reference-rig.md, and the
    reference-rig study keeps that section when it rewrites its page."""
    quiet = dict(fast=True, out=tmp_path, data_dir=tmp_path / "data", log=lambda *a: None)
    studies.run("reference-rig", **quiet)
    assert "Not run yet" in (tmp_path / "reference-rig.md").read_text()
    out = studies.run("chaos-scan", **quiet)
    assert len(out.numbers["stage1"]) == 2 and out.numbers["stage2"][-1]["shipped"]
    doc = (tmp_path / "reference-rig.md").read_text()
    assert doc.count("## Chaos onsets: geometry scan") == 1 and "Not run yet" not in doc
    assert "python -m camdyn.studies chaos-scan --fast" in (tmp_path / "reproduction.md").read_text()
    studies.run("reference-rig", **quiet)
    again = (tmp_path / "reference-rig.md").read_text()
    assert again.count("## Chaos onsets: geometry scan") == 1 and "Not run yet" not in again
    # --reuse takes stage 1 from the report only when its settings are the same
    from camdyn.studies import chaos_scan
    ctx = common.Context(fast=True, out=tmp_path, reuse=True)
    s = chaos_scan.settings(True)
    assert chaos_scan._recorded_stage1(ctx, s) == out.numbers["stage1"]
    assert chaos_scan._recorded_stage1(ctx, {**s, "revolutions": s["revolutions"] + 1}) is None
    assert chaos_scan._recorded_stage1(common.Context(fast=True, out=tmp_path / "empty"), s) is None


# ---------------------------------------------------------------- where the studies write (issue 14, I)

def test_checkout_is_told_from_an_installed_copy(tmp_path):
    checkout = tmp_path / "src"
    (checkout / "camdyn").mkdir(parents=True)
    (checkout / "docs").mkdir()
    (checkout / "pyproject.toml").write_text('[project]\nname = "camdyn"\n')
    assert common.checkout_root(checkout / "camdyn") == checkout
    site = tmp_path / "lib" / "site-packages"
    (site / "camdyn").mkdir(parents=True)
    assert common.checkout_root(site / "camdyn") is None
    other = tmp_path / "other"
    (other / "camdyn").mkdir(parents=True)
    (other / "docs").mkdir()
    (other / "pyproject.toml").write_text('[project]\nname = "something-else"\n')
    assert common.checkout_root(other / "camdyn") is None


def _files_under(folder):
    return {p: p.stat().st_mtime_ns for p in folder.rglob("*") if p.is_file() and "__pycache__" not in p.parts}


def test_an_installed_camdyn_writes_to_the_working_folder_never_into_the_package(tmp_path, monkeypatch, capsys):
    from camdyn.cli import main

    package = Path(camdyn.__file__).resolve().parent
    before = _files_under(package)
    monkeypatch.setattr(common, "checkout_root", lambda package_dir=None: None)  # as if pip-installed
    monkeypatch.chdir(tmp_path)
    assert main(["reproduce", "numbers", "--fast"]) == 0
    report = tmp_path / common.DEFAULT_OUT / "reproduction.md"
    assert report.exists()
    err = capsys.readouterr().err
    assert "not running from a source checkout" in err and str(tmp_path / common.DEFAULT_OUT) in err
    assert common.default_data_dir(tmp_path / common.DEFAULT_OUT) == tmp_path / common.DEFAULT_OUT / "rigs"
    assert _files_under(package) == before
    assert not (tmp_path / "docs").exists()  # the old fallback made ./docs here


def test_a_checkout_writes_its_docs_and_presets():
    root = common.checkout_root()
    if root is None:
        pytest.skip("camdyn is not running from a source checkout")
    assert common.default_out() == root / "docs"
    assert common.default_data_dir(root / "docs") == root / "camdyn" / "model" / "data"
