"""The example at the top of camdyn.analysis.calibrate's documentation runs as written (it had
gone stale: an import path from before the subpackages, and two targets of one default name)."""
from __future__ import annotations

import textwrap

from camdyn.analysis import calibrate as cal


def test_the_module_example_runs_and_fits_its_two_frequencies():
    doc = cal.__doc__
    code = textwrap.dedent(doc.split("::\n", 1)[1].split("\nEach target", 1)[0])
    assert "from camdyn.analysis import calibrate as cal" in code
    space: dict = {}
    exec(compile(code.replace("print(result.report())", "report = result.report()"), "example", "exec"), space)
    result = space["result"]
    assert result.success and result.all_within          # both frequencies to their printed rounding
    assert result.dof.rank == 2 and set(result.values) == {"I_Pb", "w_b"}
    assert space["fitted"] is result.rig and "chi0 (measured on the drawing)" in space["report"]
