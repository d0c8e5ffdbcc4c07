"""The model-edit workflow of docs/model-editing.md, run on temporary copies of the repository.

1. Change a law in a scratch copy of derive/, regenerate it into a scratch folder with one
   command (generated, drift-checked, import-checked), load the module and simulate it: the
   run follows the edited law.
2. Add a new law option and a scene for it in a full copy of the package: after
   ``camdyn regenerate`` the new scene runs from Python and from the command line, and no
   file of the runtime (camdyn/) was touched.
3. The drift check catches a hand edit of a generated file.

Each copy regenerates only the scenes it needs (a one-line catalog), to stay quick; the
recipe is the same with the full catalog.
"""
from __future__ import annotations

import csv
import importlib
import importlib.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import camdyn
from camdyn.cli import main

pytest.importorskip("sympy")

TANH = "return S.mu_m * sp.tanh(S.s * v_r)"
ATAN = "return S.mu_m * 2 / sp.pi * sp.atan(S.s * v_r)"


def package_dir(name: str) -> Path:
    return Path(importlib.util.find_spec(name).submodule_search_locations[0])


def copy_tree(src: Path, dst: Path) -> Path:
    shutil.copytree(src, dst, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    return dst


def edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, f"{path.name} no longer contains {old!r}: update this test and docs/model-editing.md"
    path.write_text(text.replace(old, new, 1))


def one_scene_catalog(derive: Path, *specs: str) -> None:
    (derive / "catalog.py").write_text(
        "from .vocabulary import SceneSpec\n\nCATALOG = (\n" + "".join(f"    SceneSpec({s}),\n" for s in specs) + ")\n")


def load_generated(folder: Path, name: str):
    """Import a generated package from a folder under a name of our choice."""
    spec = importlib.util.spec_from_file_location(name, folder / "__init__.py",
                                                  submodule_search_locations=[str(folder)])
    package = importlib.util.module_from_spec(spec)
    sys.modules[name] = package
    spec.loader.exec_module(package)
    return package


def full_copy(tmp_path: Path) -> Path:
    """A checkout as installed, under tmp_path/src: camdyn/ with derive/ and generated/ inside it."""
    pkg = tmp_path / "src" / "camdyn"
    shutil.copytree(package_dir("camdyn"), pkg,
                    ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "derive", "generated"))
    copy_tree(package_dir("camdyn.derive"), pkg / "derive")
    copy_tree(package_dir("camdyn.generated"), pkg / "generated")
    return pkg


def runtime_files(pkg: Path) -> dict[Path, bytes]:
    """The runtime's files of a copy (all but derive/ and generated/), to show none changed."""
    return {p.relative_to(pkg): p.read_bytes() for p in pkg.rglob("*.py")
            if p.relative_to(pkg).parts[0] not in ("derive", "generated")}


def scratch_cli(tmp_path: Path):
    """``camdyn ...`` run in a fresh process on the copy of :func:`full_copy`."""
    env = {**os.environ, "PYTHONPATH": str(tmp_path / "src")}

    def camdyn_cli(*args):
        return subprocess.run([sys.executable, "-m", "camdyn.cli", "--no-progress", *args], cwd=tmp_path,
                              env=env, capture_output=True, text=True, timeout=600)
    return camdyn_cli


def csv_columns(path: Path) -> dict[str, np.ndarray]:
    """The numeric columns of a ``camdyn simulate --csv`` file by quantity name (``alpha (rad)`` -> ``alpha``)."""
    from camdyn.metadata import parse_column_header
    rows = list(csv.reader(path.open()))
    names = [parse_column_header(h) for h in rows[0]]
    return {n: np.array([float(r[i]) for r in rows[1:]]) for i, n in enumerate(names) if n != "regime"}


def trapezoid_cumulative(t: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum((y[1:] + y[:-1]) / 2 * np.diff(t))])


def friction_ratio_matches(F_f, F_n, v_r, mu_m, s, law) -> bool:
    contact = np.abs(F_n) > 1e-6 * np.max(np.abs(F_n))
    return np.allclose(F_f[contact] / F_n[contact], mu_m * law(s * v_r[contact]), rtol=1e-9, atol=1e-12)


def atan_law(x):
    return 2 / np.pi * np.arctan(x)


@pytest.mark.slow  # notebook 04 runs the same steps in the default run
def test_edit_a_law_in_a_scratch_copy_regenerate_import_and_simulate(tmp_path, capfd):
    derive = copy_tree(package_dir("camdyn.derive"), tmp_path / "derive")
    edit(derive / "laws.py", TANH, ATAN)  # friction model II: tanh -> arctan smoothing
    one_scene_catalog(derive, 'damping="D", friction="tanh"')
    out = tmp_path / "generated"

    assert main(["regenerate", "--derive", str(derive), "--out", str(out), "--jobs", "1"]) == 0
    text = capfd.readouterr().out
    assert "drift check: 2 files in sync" in text and "1 of 1 scene modules import without SymPy" in text
    assert "atan(" in (out / "scene_line_d_tanh_constant_nonlinear.py").read_text()

    edited = load_generated(out, "edited_generated").SCENES["line_d_tanh_constant_nonlinear"]
    kernels = importlib.import_module(f"edited_generated.{edited}")

    class EditedScene(camdyn.Scene):
        def kernels(self):
            return kernels

    rig = camdyn.example_rig()
    runs = {}
    for name, scene in {"edited": EditedScene(friction="tanh"), "shipped": camdyn.Scene(friction="tanh")}.items():
        runs[name] = camdyn.simulate(rig, scene, speed_rpm=1100, revolutions=1, sample_rate_Hz=20_000)
        assert runs[name].ok
    r = runs["edited"]
    assert friction_ratio_matches(r.F_f, r.F_n, r.v_r, rig.mu_m, rig.s, atan_law)
    s = runs["shipped"]
    assert friction_ratio_matches(s.F_f, s.F_n, s.v_r, rig.mu_m, rig.s, np.tanh)
    assert not np.allclose(r.alpha, s.alpha, rtol=0, atol=1e-9)  # the edit changes the motion


@pytest.mark.slow
def test_drift_check_catches_a_hand_edit_of_generated_code(tmp_path, capfd):
    derive = copy_tree(package_dir("camdyn.derive"), tmp_path / "derive")
    one_scene_catalog(derive, 'damping="none", friction="none"')
    out = tmp_path / "generated"
    assert main(["regenerate", "--derive", str(derive), "--out", str(out), "--jobs", "1"]) == 0
    assert main(["regenerate", "--derive", str(derive), "--out", str(out), "--check", "--jobs", "1"]) == 0
    module = out / "scene_line_none_none_constant_nonlinear.py"
    module.write_text(module.read_text().replace("def rhs(", "def rhs(  ", 1))
    capfd.readouterr()
    assert main(["regenerate", "--derive", str(derive), "--out", str(out), "--check", "--jobs", "1"]) == 1
    captured = capfd.readouterr()
    assert "scene_line_none_none_constant_nonlinear.py: differs" in captured.err
    assert "1 differ" in captured.out


@pytest.mark.slow
def test_a_new_law_option_and_scene_need_no_edit_in_the_runtime(tmp_path):
    pkg = full_copy(tmp_path)
    derive = pkg / "derive"
    before = runtime_files(pkg)

    # the edit: a new friction law "atan" (derive/laws.py) and one scene that uses it (derive/catalog.py)
    edit(derive / "vocabulary.py", 'FRICTION_MODELS = ("none", "coulomb", "tanh")',
         'FRICTION_MODELS = ("none", "coulomb", "tanh", "atan")')
    edit(derive / "laws.py", TANH, TANH + '\n    if model == "atan":\n        ' + ATAN)
    one_scene_catalog(derive, 'damping="D", friction="atan"', 'damping="D", friction="tanh"')

    camdyn_cli = scratch_cli(tmp_path)
    env = {**os.environ, "PYTHONPATH": str(tmp_path / "src")}
    regen = camdyn_cli("regenerate", "--jobs", "2")  # the one command, as in the user's checkout
    assert regen.returncode == 0, regen.stderr
    assert "drift check: 3 files in sync" in regen.stdout and "2 of 2 scene modules" in regen.stdout

    run = camdyn_cli("simulate", "--friction", "atan", "--speed-rpm", "1100", "--revolutions", "1",
                     "--csv", "atan.csv")
    assert run.returncode == 0, run.stderr
    assert "scene line_d_atan_constant_nonlinear: SUCCESS" in run.stdout
    columns = csv_columns(tmp_path / "atan.csv")
    F_f, F_n, v_r = (columns[k] for k in ("F_f", "F_n", "v_r"))
    rig = camdyn.example_rig()
    assert friction_ratio_matches(F_f, F_n, v_r, rig.mu_m, rig.s, atan_law)

    from_python = subprocess.run(
        [sys.executable, "-c", "import camdyn; s = camdyn.Scene(friction='atan'); "
                               "print(s.kernels().__file__)"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert from_python.returncode == 0, from_python.stderr
    assert from_python.stdout.startswith(str(pkg / "generated"))

    assert runtime_files(pkg) == before  # no file of the runtime changed


def test_regenerate_refuses_a_folder_that_is_not_derive(tmp_path, capsys):
    (tmp_path / "derive").mkdir()
    assert main(["regenerate", "--derive", str(tmp_path / "derive")]) == 2
    assert "not a camdyn derive/ folder" in capsys.readouterr().err


def test_the_documented_law_texts_still_exist():
    """docs/model-editing.md and notebook 04 edit these lines of derive/laws.py and vocabulary.py."""
    laws = (package_dir("camdyn.derive") / "laws.py").read_text()
    vocabulary = (package_dir("camdyn.derive") / "vocabulary.py").read_text()
    assert TANH in laws and 'FRICTION_MODELS = ("none", "coulomb", "tanh")' in vocabulary
    doc = (Path(__file__).resolve().parent.parent / "docs" / "model-editing.md").read_text()
    assert TANH in doc and ATAN in doc


K_S_ROW = 'RigParameter("k_s", "N/m", "follower spring stiffness", True, "Eq. 11", (_POSITIVE,)),'
K_S3_ROW = ('\n    RigParameter("k_s3", "N/m^3", "cubic stiffness of the follower spring", False, "a model edit",'
            ' (_NON_NEGATIVE,)),')
LINEAR_SPRING = "return S.k_s * spring_compression(a)"
CUBIC_SPRING = "L = spring_compression(a)\n    return S.k_s * L + S.k_s3 * L**3"


def test_a_new_parameter_needs_no_edit_in_the_runtime(tmp_path):
    """docs/model-editing.md, "A law with a new parameter": a cubic spring term with its own
    constant k_s3, declared once in derive/parameters.py, reaches the rig's validation, its
    TOML reading and the simulation through the command line, with camdyn/ untouched.

    Runs in the default suite: one scene is regenerated, and the runs use the interpreted
    engine loop (no compile in the scratch package)."""
    pkg = full_copy(tmp_path)
    before = runtime_files(pkg)
    derive = pkg / "derive"
    edit(derive / "parameters.py", K_S_ROW, K_S_ROW + K_S3_ROW)
    edit(derive / "symbols.py", 'k_s = PARAMS["k_s"].symbol', 'k_s = PARAMS["k_s"].symbol\nk_s3 = PARAMS["k_s3"].symbol')
    edit(derive / "laws.py", LINEAR_SPRING, CUBIC_SPRING)
    one_scene_catalog(derive, 'damping="D", friction="coulomb"')
    cli = scratch_cli(tmp_path)
    regen = cli("regenerate", "--jobs", "1")
    assert regen.returncode == 0, regen.stderr
    assert "k_s3" in (pkg / "generated" / "scene_line_d_coulomb_constant_nonlinear.py").read_text()

    example = (package_dir("camdyn") / "data" / "example.toml").read_text()
    runs = {}
    for k_s3 in (0.0, 2e9):  # N/m^3: at the example rig's ~1 mm compression, k_s3 L^2 ~ k_s
        rig = tmp_path / f"cubic_{k_s3:g}.toml"
        rig.write_text(example.replace("[parameters]", f"[parameters]\nk_s3 = {k_s3!r}"))
        run = cli("simulate", "--rig", str(rig), "--speed-rpm", "300", "--t-end", "0.01", "--backend", "python",
                  "--csv", f"cubic_{k_s3:g}.csv")
        assert run.returncode == 0, run.stderr
        runs[k_s3] = csv_columns(tmp_path / f"cubic_{k_s3:g}.csv")
    shipped = camdyn.simulate(camdyn.example_rig(), camdyn.Scene(damping="D", friction="coulomb"),
                              speed_rpm=300, t_end=0.01, sample_rate_Hz=20_000)
    # k_s3 = 0: the shipped model; the expressions differ (an added 0 * L^3), so agreement to
    # the solver's tolerance (rtol 1e-8 on alpha ~ 0.2 rad), not bit for bit
    assert np.allclose(runs[0.0]["alpha"], shipped.alpha, rtol=0, atol=1e-8)
    assert np.allclose(runs[0.0]["F_s"], shipped.F_s, rtol=1e-6)
    # k_s3 > 0: a stiffer spring, so a larger spring force at the new static equilibrium
    cubic = runs[2e9]
    assert cubic["F_s"][0] > runs[0.0]["F_s"][0] * 1.01
    # the edited spring's potential (derived by integrating its moment) keeps the energy balance
    # E(t) - E(0) = int (P_in - D_c - D_f) dt of Sec. 5; the bound is the trapezoid rule's own
    # error on these samples, estimated from the same integral at half the sample rate
    assert np.all(np.isfinite(cubic["energy"]))
    power = cubic["P_in"] - cubic["D_c"] - cubic["D_f"]
    fine = trapezoid_cumulative(cubic["t"], power)
    coarse = trapezoid_cumulative(cubic["t"][::2], power[::2])
    quadrature_error = np.max(np.abs(fine[::2] - coarse)) / 3
    drift = np.abs(cubic["energy"][::2] - cubic["energy"][0] - fine[::2])
    assert np.max(drift) < 10 * quadrature_error + 1e-9 * np.max(np.abs(cubic["energy"]))

    bad = tmp_path / "bad.toml"
    bad.write_text(example.replace("[parameters]", "[parameters]\nk_s3 = -1.0"))
    refused = cli("simulate", "--rig", str(bad), "--speed-rpm", "300", "--t-end", "0.001", "--backend", "python")
    assert refused.returncode == 2
    assert "k_s3" in refused.stderr and ">= 0" in refused.stderr and "N/m^3" in refused.stderr
    missing = cli("simulate", "--speed-rpm", "300", "--t-end", "0.001", "--backend", "python")  # the example rig has no k_s3
    assert missing.returncode == 2 and "k_s3" in missing.stderr
    assert runtime_files(pkg) == before  # no file of the runtime changed
