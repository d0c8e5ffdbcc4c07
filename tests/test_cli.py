"""The camdyn command: outputs, one-line errors, exit codes."""
from __future__ import annotations

import csv
import json

from camdyn.cli import main


def test_simulate_writes_csv(tmp_path, capsys):
    out = tmp_path / "run.csv"
    assert main(["simulate", "--speed-rpm", "300", "--revolutions", "0.2", "--sample-rate-Hz", "2000",
                 "--csv", str(out)]) == 0
    rows = list(csv.reader(out.open()))
    assert rows[0][:3] == ["t", "alpha", "alpha_dot"] and rows[0][-1] == "regime"
    assert len(rows) == 1 + 81  # 0.2 rev at 300 rev/min = 0.04 s at 2 kHz: 80 intervals, both ends
    assert "alpha_r: rms" in capsys.readouterr().out


def test_equilibrium_prints_json(capsys):
    assert main(["equilibrium", "--damping", "none", "--friction", "none"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["psi_i_star_m"] < 0 and data["natural_frequency_Hz"] > 0


def test_errors_are_one_line_with_exit_code_2(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("name = 'x'\n[parameters]\nr_c = -1\n")
    assert main(["contact-loss", "--rig", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("camdyn: error:")
    assert main(["simulate", "--speed-rpm", "nan", "--revolutions", "1"]) == 2
    assert "speed_rpm" in capsys.readouterr().err
