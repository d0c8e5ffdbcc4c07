"""Sections of docs/performance.md written by benchmark scripts other than performance.py (the
jump chart, the rigid scene beside Siconos, the basin map): each between its own markers, replaced
by its script's ``--report`` and kept, in order, when performance.py regenerates the rest."""
from __future__ import annotations

import re
from pathlib import Path

#: the performance report these sections go into
REPORT = Path(__file__).resolve().parent.parent.parent / "docs" / "performance.md"


def _markers(name: str) -> tuple[str, str]:
    return f"<!-- section:{name} begin -->", f"<!-- section:{name} end -->"


def write_section(name: str, markdown: str, path: Path = REPORT) -> Path:
    """Put ``markdown`` between the section's markers in the report at ``path`` (replacing what was
    there, or appended at the end); the script that ran is named in the markdown itself."""
    begin, end = _markers(name)
    block = f"{begin}\n{markdown.strip()}\n{end}"
    text = path.read_text(encoding="utf-8") if path.exists() else ""
    pattern = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.S)
    text = pattern.sub(lambda _: block, text) if pattern.search(text) else text.rstrip() + "\n\n" + block + "\n"
    path.write_text(text, encoding="utf-8")
    return path


def kept_sections(text: str) -> str:
    """Every script's section in ``text`` (an earlier report), in order, markers included."""
    found = re.finditer(r"<!-- section:(\S+) begin -->.*?<!-- section:\1 end -->", text, re.S)
    return "\n\n".join(m.group(0) for m in found)
