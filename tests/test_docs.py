"""The documentation (issue 14, B and L): it builds with warnings as errors, its API reference
covers the public API, and every link of the README and docs/ stays inside the repository."""
from __future__ import annotations

import importlib
import inspect
import re
import subprocess
import sys
from pathlib import Path

import pytest

import camdyn

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
#: the public modules the reference must cover (the engine's modules join after its rewrite)
MODULES = [
    "model.rig",
    "model.cam",
    "model.scene",
    "model.model",
    "model.presets",
    "model.ondemand",
    "model.profiles",
    "model.motion_laws",
    "model.followers",
    "model.synthesis",
    "model.cam_files",
    "model.cam_tables",
    "runs.simulation",
    "runs.request",
    "runs.result",
    "runs.stopping",
    "runs.quasistatic",
    "runs.pieces",
    "orbits.section_map",
    "orbits.derivatives",
    "orbits.shooting",
    "orbits.tangent",
    "orbits.lyapunov",
    "orbits.continuation",
    "orbits.continuation.charts",
    "orbits.continuation.codim1",
    "orbits.continuation.grazing",
    "orbits.continuation.grazing_curve",
    "orbits.continuation.grazing_dataset",
    "analysis.statics",
    "analysis.calibrate",
    "analysis.chaos01",
    "analysis.signal",
    "sweep.api",
    "sweep.attractors",
    "io.files",
    "io.metadata",
    "io.plots",
    "vocabulary.scenes",
    "vocabulary.names",
    "vocabulary.parameters",
    "outcome",
    "errors",
]


@pytest.fixture(scope="module")
def html(tmp_path_factory):
    """The HTML documentation, built once: ``python -m sphinx -W`` (a warning fails the build)."""
    pytest.importorskip("sphinx")
    pytest.importorskip("myst_nb")
    out = tmp_path_factory.mktemp("docs")
    proc = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                           "-d", str(out / "doctrees"), str(DOCS), str(out / "html")],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[-4000:]
    return out / "html"


def test_docs_build_without_warnings(html):
    for page in ("index", "guide", "equations", "misprints", "model-editing", "_generated/derivation",
                 "api/index"):
        assert (html / f"{page}.html").is_file(), page


def test_the_derivation_notebook_is_rendered(html):
    text = (html / "_generated" / "derivation.html").read_text()
    assert "The derivation" in text and "loop_solution" in text  # a code cell, as committed


def _public(module) -> list[str]:
    names = getattr(module, "__all__", None)
    if names is None:
        names = [n for n, v in vars(module).items() if not n.startswith("_")
                 and (inspect.isclass(v) or inspect.isfunction(v)) and v.__module__ == module.__name__]
    return list(names)


@pytest.mark.parametrize("name", MODULES)
def test_the_reference_documents_every_public_name_of_each_module(html, name):
    module = importlib.import_module(f"camdyn.{name}")
    text = (html / "api" / f"{name}.html").read_text()
    missing = [n for n in _public(module) if f'id="camdyn.{name}.{n}"' not in text]
    assert not missing, f"camdyn.{name}: not in the reference: {missing}"


def test_the_reference_covers_every_top_level_name(html):
    text = (html / "api" / "camdyn.html").read_text()
    missing = [n for n in camdyn.__all__ if n != "__version__"
               and f'id="camdyn.{n}"' not in text and f"camdyn.{n}</span>" not in text]
    assert not missing, missing


# ------------------------------------------------------------------ links stay in the repository (B)
LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")


def _markdown_files():
    return [ROOT / "README.md"] + sorted(DOCS.glob("*.md"))


@pytest.mark.parametrize("path", _markdown_files(), ids=lambda p: p.name)
def test_every_relative_link_points_to_a_file_of_the_repository(path):
    bad = []
    for target in LINK.findall(path.read_text(encoding="utf-8")):
        if re.match(r"[a-z]+://|mailto:", target):
            continue
        resolved = (path.parent / target).resolve()
        if ROOT not in resolved.parents or not resolved.exists():
            bad.append(target)
    assert not bad, f"{path.name}: links outside the repository or to nothing: {bad}"


def test_nothing_cites_files_a_user_of_the_repository_does_not_have():
    """The paper's equations and misprints are docs/equations.md and docs/misprints.md, not a
    folder beside the checkout (the README cited a file in a 'shared' folder next to it)."""
    tracked = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True)
    if tracked.returncode != 0:
        pytest.skip("not a git checkout")
    offenders = []
    for rel in tracked.stdout.split():
        path = ROOT / rel
        if path == Path(__file__).resolve():
            continue  # this test names the pattern
        if path.suffix in {".py", ".md", ".ipynb", ".toml", ".txt", ""} and path.is_file():
            text = path.read_text(encoding="utf-8", errors="ignore")
            if re.search(r"(\.\./|/work/)shared/", text):
                offenders.append(rel)
    assert not offenders, offenders


def test_the_misprint_page_lists_all_twelve_and_the_equations_page_cites_the_paper():
    misprints = (DOCS / "misprints.md").read_text()
    for k in range(1, 13):
        assert re.search(rf"^\| {k} \|", misprints, flags=re.M), k
        assert re.search(rf"^{k}\. \*\*", misprints, flags=re.M), k
    equations = (DOCS / "equations.md").read_text()
    for eq in ("Eq. 6", "Eq. 10", "Eq. 12", "Eq. 23", "Eq. 29", "Eq. 33", "Eqs. 36–38"):
        assert eq in equations, eq
