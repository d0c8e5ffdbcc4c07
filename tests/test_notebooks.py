"""Every notebook in notebooks/ runs top to bottom in a real Jupyter kernel (nbclient).

The notebooks run on their small workload: ``CAMDYN_FAST=1`` is set for the kernel, and each
notebook reads it to shorten its runs.  A test fails on any error in any cell, and on any
printed check that reads False (the notebooks print their checks as ``<what>: True``).

A notebook whose small workload still takes long can say so in its metadata,
``{"camdyn": {"test": "slow"}}``; it is then marked slow (run with ``-m slow``).
"""
from __future__ import annotations

import json
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parent.parent / "notebooks").glob("*.ipynb"))


def _is_slow(path: Path) -> bool:
    return json.loads(path.read_text()).get("metadata", {}).get("camdyn", {}).get("test") == "slow"


def _params():
    return [pytest.param(p, id=p.name, marks=[pytest.mark.slow] if _is_slow(p) else []) for p in NOTEBOOKS]


def test_the_notebooks_are_there():
    names = [p.name for p in NOTEBOOKS]
    for prefix in ("01-", "03-", "04-", "05-"):
        assert any(n.startswith(prefix) for n in names), names


@pytest.mark.parametrize("path", _params())
def test_notebook_runs_in_a_kernel(path, monkeypatch):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    if "camdyn.derive" in path.read_text():
        pytest.importorskip("sympy")  # the derivation notebooks need camdyn[derive]
    monkeypatch.setenv("CAMDYN_FAST", "1")
    nb = nbformat.read(path, as_version=4)
    kernel = nb.metadata.get("kernelspec", {}).get("name", "python3")
    client = nbclient.NotebookClient(nb, timeout=600, kernel_name=kernel,
                                     resources={"metadata": {"path": str(path.parent)}})
    client.execute()  # raises CellExecutionError, with the cell and its traceback, on any error
    failed = []
    for index, cell in enumerate(nb.cells):
        for output in cell.get("outputs", []) if cell.cell_type == "code" else []:
            if output.get("output_type") == "stream":
                failed += [f"cell {index}: {line}" for line in output["text"].splitlines()
                           if line.rstrip().endswith(": False")]
    assert not failed, "\n".join(failed)
