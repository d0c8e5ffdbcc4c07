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
    # a checkout as installed: camdyn/ with derive/ and generated/ inside it
    runtime = package_dir("camdyn")
    pkg = tmp_path / "src" / "camdyn"
    shutil.copytree(runtime, pkg, ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "derive", "generated"))
    derive = copy_tree(package_dir("camdyn.derive"), pkg / "derive")
    copy_tree(package_dir("camdyn.generated"), pkg / "generated")
    before = {p.relative_to(pkg): p.read_bytes() for p in pkg.rglob("*.py")
              if p.relative_to(pkg).parts[0] not in ("derive", "generated")}

    # the edit: a new friction law "atan" (derive/laws.py) and one scene that uses it (derive/catalog.py)
    edit(derive / "vocabulary.py", 'FRICTION_MODELS = ("none", "coulomb", "tanh")',
         'FRICTION_MODELS = ("none", "coulomb", "tanh", "atan")')
    edit(derive / "laws.py", TANH, TANH + '\n    if model == "atan":\n        ' + ATAN)
    one_scene_catalog(derive, 'damping="D", friction="atan"', 'damping="D", friction="tanh"')

    env = {**os.environ, "PYTHONPATH": str(tmp_path / "src")}

    def camdyn_cli(*args):
        return subprocess.run([sys.executable, "-m", "camdyn.cli", "--no-progress", *args], cwd=tmp_path,
                              env=env, capture_output=True, text=True, timeout=600)

    regen = camdyn_cli("regenerate", "--jobs", "2")  # the one command, as in the user's checkout
    assert regen.returncode == 0, regen.stderr
    assert "drift check: 3 files in sync" in regen.stdout and "2 of 2 scene modules" in regen.stdout

    run = camdyn_cli("simulate", "--friction", "atan", "--speed-rpm", "1100", "--revolutions", "1",
                     "--csv", "atan.csv")
    assert run.returncode == 0, run.stderr
    assert "scene line_d_atan_constant_nonlinear: SUCCESS" in run.stdout
    rows = list(csv.DictReader((tmp_path / "atan.csv").open()))
    F_f, F_n, v_r = (np.array([float(r[k]) for r in rows]) for k in ("F_f", "F_n", "v_r"))
    rig = camdyn.example_rig()
    assert friction_ratio_matches(F_f, F_n, v_r, rig.mu_m, rig.s, atan_law)

    from_python = subprocess.run(
        [sys.executable, "-c", "import camdyn; s = camdyn.Scene(friction='atan'); "
                               "print(s.kernels().__file__)"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert from_python.returncode == 0, from_python.stderr
    assert from_python.stdout.startswith(str(pkg / "generated"))

    after = {p.relative_to(pkg): p.read_bytes() for p in pkg.rglob("*.py")
             if p.relative_to(pkg).parts[0] not in ("derive", "generated")}
    assert after == before  # no file of the runtime changed


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
