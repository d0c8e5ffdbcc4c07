"""The README's Python examples run as written."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

README = (Path(__file__).resolve().parent.parent / "README.md").read_text()
BLOCKS = re.findall(r"```python\n(.*?)```", README, flags=re.S)


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_python_block_runs(index, capsys):
    exec(compile(BLOCKS[index], f"README block {index}", "exec"), {})
    printed = capsys.readouterr().out
    for comment in _printed_comments(BLOCKS[index]):
        for shown, cut in re.findall(f"({NUMBER})(\\.\\.\\.)?", comment):
            assert _shown_in(shown, printed, bool(cut)), \
                f"README block {index}: {comment!r} shows {shown}; it printed {printed!r}"


#: a number as the README shows it (its decimals say to what it is rounded)
NUMBER = r"-?\d+(?:\.\d+)?(?:e-?\d+)?"


def _printed_comments(block: str) -> list[str]:
    """The comments that show what the line before printed (a '# ...' line right under a print)."""
    lines = block.splitlines()
    return [b.strip()[2:] for a, b in zip(lines, lines[1:]) if "print(" in a and b.strip().startswith("# ")]


def _shown_in(shown: str, printed: str, cut: bool) -> bool:
    """Whether a number the README shows is one the block printed, to the digits shown: rounded,
    or cut short where it is followed by '...'."""
    decimals = len(shown.split(".")[1]) if "." in shown and "e" not in shown else 0
    value, unit = float(shown), 10.0 ** -decimals
    if cut:
        return any(0 <= abs(float(p)) - abs(value) < unit and float(p) * value >= 0 for p in re.findall(NUMBER, printed))
    return any(abs(float(p) - value) <= 0.5 * unit * (1 + 1e-9) for p in re.findall(NUMBER, printed))


def test_readme_has_the_two_fresh_machine_commands():
    ci = (Path(__file__).resolve().parent.parent / ".ci" / "run").read_text().strip().splitlines()[-1]
    assert ci in README
    assert "examples/quickstart.py" in README


#: what each command the README tells users to run needs installed (a distribution name), or
#: None when camdyn's own dependencies are enough; a README command not listed here fails the test
#: below until it is added, with what it needs
COMMAND_NEEDS = {
    "python examples/quickstart.py": "matplotlib",
    "python -m pytest": "pytest",
    "jupyter lab": "jupyterlab",
    "python -m sphinx": "sphinx",
}


def _extras() -> dict[str, set[str]]:
    """Each extra of pyproject.toml -> the distribution names it installs (camdyn[...] expanded)."""
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib

    table = tomllib.loads((Path(__file__).resolve().parent.parent / "pyproject.toml").read_text())
    raw = table["project"]["optional-dependencies"]

    def names(extra, seen=()):
        out = set()
        for requirement in raw[extra]:
            m = re.match(r"([A-Za-z0-9_.-]+)(?:\[([^\]]+)\])?", requirement)
            if m.group(1) == "camdyn":
                for inner in m.group(2).split(","):
                    if inner not in seen:
                        out |= names(inner.strip(), seen + (extra,))
            else:
                out.add(m.group(1).lower())
        return out

    return {extra: names(extra) for extra in raw}


def test_every_install_and_run_line_of_the_readme_installs_what_it_runs():
    """`pip install -e ".[dev]" && jupyter lab notebooks/` failed with 'jupyter-lab not found'
    (issue 14, C): each `pip install ".[extras]" && command` installs what the command needs."""
    extras = _extras()
    chains = re.findall(r'pip install (?:-e )?"\.\[([a-z,]+)\]"((?:\s*&&\s*[^`\n&]+)+)', README)
    assert len(chains) >= 4, chains
    for names, commands in chains:
        installed = set().union(*(extras[n.strip()] for n in names.split(",")))
        for command in (c.strip() for c in commands.split("&&") if c.strip()):
            need = [v for k, v in COMMAND_NEEDS.items() if command.startswith(k)]
            assert need, f"README runs {command!r}: add what it needs to COMMAND_NEEDS"
            assert need[0] in installed, f'pip install ".[{names}]" does not install {need[0]} for {command!r}'
