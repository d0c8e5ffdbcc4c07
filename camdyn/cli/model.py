"""``camdyn regenerate``, ``scenes`` and ``cache``: the model's code, the scenes and rigs there are,
and what camdyn keeps for this user."""
from __future__ import annotations

import importlib
import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

from .common import EXIT_CHECK_FAILED, EXIT_INTERNAL, EXIT_MISSING, EXIT_OK, EXIT_USAGE, UsageError
from .options import _options
from .parser import add_command


_REGENERATE = r'''
import importlib, sys
from pathlib import Path
derive_dir, out, check_only, jobs = sys.argv[1], Path(sys.argv[2]), sys.argv[3] == "1", int(sys.argv[4])
if derive_dir:
    sys.path.insert(0, str(Path(derive_dir).resolve().parent))
    package = Path(derive_dir).resolve().name
else:
    package = "camdyn.derive"
try:
    import sympy  # noqa: F401
except ImportError:
    print("camdyn: error: regenerate needs SymPy: pip install \"camdyn[derive]\"", file=sys.stderr)
    sys.exit(4)
writer = importlib.import_module(package + ".writer")
catalog = importlib.import_module(package + ".catalog")
codegen = importlib.import_module(package + ".codegen")
from tqdm import tqdm
specs = tuple(sorted(set(catalog.CATALOG), key=lambda s: s.slug))
bar = dict(total=len(specs), desc="deriving scenes", unit="scene", file=sys.stderr, disable=None)
try:
    files = writer.render(specs, jobs=jobs, progress=lambda done: tqdm(done, **bar))
except codegen.ComplexExpressionError as exc:  # the edit made a law complex: nothing is written
    print(f"camdyn: error: {exc}", file=sys.stderr)
    sys.exit(2)
if not check_only:
    changed = writer.write(files, out)
    print(f"{len(files)} files generated in {out}; changed: {', '.join(changed) or 'none'}")
problems = writer.check(files, out)
for p in problems:
    print(p, file=sys.stderr)
print(f"drift check: {len(files)} files " + ("in sync with derive/" if not problems else f"-- {len(problems)} differ"))
sys.exit(1 if problems else 0)
'''


_IMPORT_CHECK = r'''
import importlib.util, sys
from pathlib import Path
out = Path(sys.argv[1])
name = "camdyn_regenerated_check"
spec = importlib.util.spec_from_file_location(name, out / "__init__.py", submodule_search_locations=[str(out)])
pkg = importlib.util.module_from_spec(spec); sys.modules[name] = pkg; spec.loader.exec_module(pkg)
bad = []
for slug, module in sorted(pkg.SCENES.items()):
    try:
        m = importlib.import_module(name + "." + module)
        assert m.SLUG == slug, f"{module}.SLUG is {m.SLUG!r}"
        if m.VARIATIONAL is not None:
            v = importlib.import_module(name + "." + m.VARIATIONAL)
            assert v.SLUG == slug and v.PARAMS == m.PARAMS, f"{m.VARIATIONAL} is not {module}'s companion"
    except Exception as exc:
        bad.append(f"{module}: {type(exc).__name__}: {exc}")
if "sympy" in sys.modules:
    bad.append("the generated code imports SymPy")
for b in bad:
    print(b, file=sys.stderr)
print(f"import check: {len(pkg.SCENES) - len(bad)} of {len(pkg.SCENES)} scene modules import without SymPy")
sys.exit(1 if bad else 0)
'''


def _default_generated() -> Path:
    from .. import generated

    return Path(generated.__file__).resolve().parent


def cmd_regenerate(args) -> int:
    if args.derive:
        derive_dir = Path(args.derive)
        if not (derive_dir / "writer.py").is_file() or not (derive_dir / "catalog.py").is_file():
            raise UsageError(f"--derive {args.derive}: not a camdyn derive/ folder (no writer.py and catalog.py)")
        out = Path(args.out) if args.out else derive_dir.resolve().parent / "generated"
    else:
        out = Path(args.out) if args.out else _default_generated()
    if args.check and not out.is_dir():
        raise UsageError(f"{out}: no generated package to check")
    jobs = args.jobs or (os.cpu_count() or 1)
    code = subprocess.call([sys.executable, "-c", _REGENERATE, str(args.derive or ""), str(out),
                            "1" if args.check else "0", str(jobs)])
    if code != 0:
        return {4: EXIT_MISSING, 1: EXIT_CHECK_FAILED, 2: EXIT_USAGE}.get(code, EXIT_INTERNAL)
    code = subprocess.call([sys.executable, "-c", _IMPORT_CHECK, str(out)])
    if code != 0:
        return EXIT_CHECK_FAILED
    if not _regenerates_own_package(args, out):
        if not args.check:
            print(f"  the scenes in {out} are not camdyn.generated; see docs/model-editing.md to use them")
        return EXIT_OK
    return _neutral_values_in_presets(args.check)


def _regenerates_own_package(args, out: Path) -> bool:
    """Whether this regenerate derives camdyn.derive into camdyn.generated (not a copy)."""
    own_derive = Path(importlib.util.find_spec("camdyn.derive").submodule_search_locations[0]).resolve()
    return out.resolve() == _default_generated() and (not args.derive or Path(args.derive).resolve() == own_derive)


def _neutral_values_in_presets(check: bool) -> int:
    """The shipped rig files give every parameter declared with a neutral value (the value that
    gives the paper's law, camdyn.vocabulary.parameters): write the missing ones and say so, or,
    with --check, fail while one is missing."""
    from ..model import presets

    if check:
        lacking = presets.lacking_neutral_values()
        for path, names in lacking.items():
            print(f"{path.name}: does not give {', '.join(names)} (declared with a neutral value in "
                  "camdyn/vocabulary/parameters.py): run camdyn regenerate", file=sys.stderr)
        print(f"presets check: {len(presets.preset_files()) - len(lacking)} of {len(presets.preset_files())} "
              "shipped rig files give every parameter declared with a neutral value")
        return EXIT_CHECK_FAILED if lacking else EXIT_OK
    for path, names in presets.add_neutral_values().items():
        values = ", ".join(f"{n} = {presets.NEUTRAL[n]!r}" for n in names)
        print(f"updated the shipped rig {path}: added {values}, the neutral value declared in "
              "camdyn/vocabulary/parameters.py (the paper's law), so the scenes that read it run this rig as before")
    return EXIT_OK


def cmd_scenes(args) -> int:
    from .. import generated
    from ..model import presets

    if args.json:
        print(json.dumps({"scenes": sorted(generated.SCENES), "rigs": presets.available(),
                          "options": {k: list(v) for k, v in _options().items()}}, indent=2))
        return EXIT_OK
    print("generated scenes (contact_damping_friction_motion_model[_vrprinted][_printedsign][_memoryless]):")
    for slug in sorted(generated.SCENES):
        print(f"  {slug}")
    print("shipped rigs: " + ", ".join(presets.available()) + "  (or a path to a .toml rig file)")
    return EXIT_OK


def cmd_cache(args) -> int:
    """List camdyn's caches of this user (compiled code, scenes derived on demand), or clear them."""
    from ..model import ondemand
    from .. import engine

    if args.clear or args.clear_stale:
        removed = engine.clear_cache(stale_only=args.clear_stale)
        removed += ondemand.clear(stale_only=args.clear_stale)
        print(f"removed {len(removed)} cache folder(s)" + "".join(f"\n  {d}" for d in removed))
        return EXIT_OK
    entries = engine.cache_entries()
    print(f"camdyn's compiled code for this user: {engine.user_cache_root()} (set {engine.CACHE_ENV} to move it)")
    if not entries:
        print("  empty: the first run compiles the engine")
    for folder, size, current in entries:
        print(f"  {folder.name}  {size / 1e6:.1f} MB  {'current' if current else 'stale (another camdyn or engine)'}")
    scenes = ondemand.entries()
    print(f"scenes derived on demand: {ondemand.scenes_root()}")
    if not scenes:
        print("  none: a scene outside the catalog is derived on first use")
    for folder, slugs, current in scenes:
        state = "current" if current else "stale (another derivation or SymPy)"
        print(f"  {folder.name}  {state}: {', '.join(slugs) or 'no scenes'}")
    return EXIT_OK


def add_regenerate(sub) -> None:
    """The regenerate command and its options."""
    p = add_command(sub, "regenerate", "regenerate the model code from derive/ (needs camdyn[derive])",
                    "examples:\n"
                    "  camdyn regenerate                  # rewrite camdyn.generated from camdyn.derive\n"
                    "  camdyn regenerate --check          # exit 1 if generated/ is out of date\n"
                    "  camdyn regenerate --derive my/derive --out my/generated   # an edited copy\n\n"
                    "Derives every scene of derive/catalog.py, writes the modules, checks that the folder\n"
                    "now matches derive/ exactly (drift check), and imports every module without SymPy.\n"
                    "Refuses (exit 2, nothing written) an expression that holds a complex number. For\n"
                    "camdyn.generated itself, also writes the neutral value of a new parameter (declared in\n"
                    "camdyn/vocabulary/parameters.py) into the shipped rig files that lack it, and says which.\n"
                    "See docs/model-editing.md.", cmd_regenerate)
    p.add_argument("--check", action="store_true", help="only check: exit 1 if the folder differs from derive/")
    p.add_argument("--derive", metavar="DIR", help="a derive/ folder to use instead of the installed camdyn.derive")
    p.add_argument("--out", metavar="DIR", help="generated package folder (default: camdyn.generated, or "
                                                "DIR/../generated with --derive)")
    p.add_argument("--jobs", type=int, default=0, help="processes (default: all cores)")


def add_scenes(sub) -> None:
    """The scenes command and its options."""
    p = add_command(sub, "scenes", "list the generated scenes and the shipped rigs",
                    "example:\n  camdyn scenes --json", cmd_scenes)
    p.add_argument("--json", action="store_true", help="print scenes, rigs and scene options as JSON")


def add_cache(sub) -> None:
    """The cache command and its options."""
    p = add_command(sub, "cache", "list or clear the compiled code and derived scenes camdyn keeps for this user",
                    "examples:\n  camdyn cache\n  camdyn cache --clear-stale\n\n"
                    "The engine and each scene's kernels are compiled on first use and kept per user (never in\n"
                    "the installed package), one folder per camdyn version and engine source. A scene outside\n"
                    "the catalog is derived on first use (needs SymPy) and kept per derivation source.", cmd_cache)
    g = p.add_mutually_exclusive_group()
    g.add_argument("--clear", action="store_true", help="delete every cache folder (the next run compiles, and derives, again)")
    g.add_argument("--clear-stale", action="store_true", dest="clear_stale",
                   help="delete the folders of other camdyn versions, engines or derivations only")
