"""The layout is the architecture (issue 26): the rooms stand in layers, each imports only from
the layers below it, nothing imports in a circle, and the engine is entered by its public face.

Read from the code's imports (module level and inside functions), as a reader of the tree would."""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CAMDYN = ROOT / "camdyn"

#: the layers, lowest first: a module may import from its own layer and the ones below
LAYERS = [
    {"errors", "outcome", "_lazy", "_checks", "_version", "vocabulary"},
    {"engine"},
    {"model"},
    {"runs"},
    {"orbits", "analysis"},
    {"sweep", "io"},
    {"studies", "cli", "__init__"},
]
LAYER = {room: level for level, rooms in enumerate(LAYERS) for room in rooms}


def _modules() -> dict[str, Path]:
    out = {}
    for path in CAMDYN.rglob("*.py"):
        rel = path.relative_to(CAMDYN).with_suffix("")
        parts = ["camdyn", *rel.parts]
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def _imports(module: str, path: Path) -> set[str]:
    """The camdyn modules ``module`` imports (relative imports resolved; a name imported from a
    package counts as the package, or as its submodule when it is one)."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not target.startswith("camdyn"):
                continue
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                if sub.startswith(("camdyn.generated", "camdyn.derive")):
                    continue                      # the generated code and its generator: not rooms of the runtime
                found.add(sub if sub in MODULES else target)
        elif isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.startswith("camdyn")}
    return {m for m in found if m in MODULES and m != module}


def _room(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


GRAPH = {m: _imports(m, p) for m, p in MODULES.items() if not m.startswith(("camdyn.derive", "camdyn.generated"))}


def test_no_room_imports_a_higher_one():
    upward = [(m, t) for m, targets in GRAPH.items() for t in targets
              if _room(m) in LAYER and _room(t) in LAYER and LAYER[_room(t)] > LAYER[_room(m)]]
    assert not upward, upward


def test_every_room_has_a_layer():
    rooms = {_room(m) for m in GRAPH}
    assert rooms <= set(LAYER), rooms - set(LAYER)


def test_no_import_circle():
    """Tarjan's strongly connected components of the module graph: each a single module."""
    index, low, stack, on, circles, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in GRAPH.get(v, ()):
            if w not in GRAPH:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                circles.append(sorted(component))
    for v in GRAPH:
        if v not in index:
            visit(v)
    assert not circles, circles


def test_the_engine_is_entered_by_its_public_face():
    """Outside camdyn/engine/ nothing imports an engine module, only the package."""
    inside = [(m, t) for m, targets in GRAPH.items() if _room(m) != "engine"
              for t in targets if t.startswith("camdyn.engine.")]
    assert not inside, inside


def test_the_public_face_of_the_engine_resolves():
    import camdyn.engine as engine
    for name in engine.__all__:
        assert getattr(engine, name) is not None, name


@pytest.mark.parametrize("module", sorted(m for m in GRAPH if m.count(".") <= 1 and MODULES[m].name != "__init__.py"))
def test_few_top_level_modules(module):
    """At most ~12 modules at camdyn's top level; each listed here is one of them."""
    top = [m for m in GRAPH if m.count(".") == 1 and MODULES[m].name != "__init__.py"]
    assert len(top) <= 12, top
