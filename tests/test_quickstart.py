"""examples/quickstart.py, the README's first command (issue 14, J): what it says about the run is
computed from the run, and its figure goes to the current folder (or --out), said where."""
from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
pytest.importorskip("matplotlib")


def _quickstart():
    spec = importlib.util.spec_from_file_location("quickstart", ROOT / "examples" / "quickstart.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_quickstart_reports_impacts_from_the_run_and_writes_to_the_current_folder(tmp_path, monkeypatch, capsys):
    quickstart = _quickstart()
    monkeypatch.chdir(tmp_path)
    written = quickstart.main([])
    out = capsys.readouterr().out
    assert written == tmp_path / "quickstart.png" and written.read_bytes()[:4] == b"\x89PNG"
    assert f"saved {written}" in out  # the absolute path, so the user can find it
    # the sentence about each speed agrees with that run's own count of impacts
    counts = [int(n) for n in re.findall(r"(\d+) impacts, ", out)]
    assert len(counts) == 2 and counts[0] == 0 and counts[1] > 0
    assert "stays on the cam (no impacts)" in out
    assert f"hits it {counts[1]} times in {quickstart.REVOLUTIONS} revolutions" in out


def test_quickstart_claims_nothing_the_run_does_not_show():
    text = (ROOT / "examples" / "quickstart.py").read_text()
    assert "once per revolution" not in text  # the run shows 8 impacts a revolution at 1100 rev/min


def test_the_readme_quickstart_figure_is_not_committed_by_accident():
    ignored = (ROOT / ".gitignore").read_text().split()
    assert "/quickstart.png" in ignored  # the README runs it from the checkout's root
