"""The notebooks' code runs top to bottom (cells executed in order in one namespace).

Executing them in a real Jupyter kernel (nbclient) is the notebooks issue's job; this
checks the code itself, with IPython's display() standing in for the front end.
"""
from __future__ import annotations

import json
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parent.parent / "notebooks").glob("*.ipynb"))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_code_runs(path, capsys):
    pytest.importorskip("sympy")
    pytest.importorskip("IPython")
    cells = json.loads(path.read_text())["cells"]
    namespace: dict = {}
    for i, cell in enumerate(cells):
        if cell["cell_type"] == "code":
            exec(compile("".join(cell["source"]), f"{path.name} cell {i}", "exec"), namespace)
    out = capsys.readouterr().out
    assert "False" not in out, out  # every printed check in the notebook reads True
