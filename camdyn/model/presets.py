"""Named rigs shipped with camdyn (TOML files in camdyn/model/data).

A model edit that adds a parameter with a neutral value (``neutral=`` in
``camdyn.vocabulary.parameters``: the value that gives the paper's law back) would leave every shipped
rig without it, and the scenes that read it would refuse them. ``camdyn regenerate`` writes that
value into the shipped files that lack it (:func:`add_neutral_values`) and says which;
``camdyn regenerate --check`` fails while one lacks it (:func:`lacking_neutral_values`). A rig file
of your own is never changed: the scenes refuse it with a message that names the value.
"""
from __future__ import annotations

import re
from importlib import resources
from pathlib import Path

from .._version import __version__
from ..errors import ParameterError, RigFileError
from .rig import NEUTRAL, PARAMETERS, Rig, tomllib

_BY_NAME = {p.name: p for p in PARAMETERS}
_TABLE = re.compile(r"^\s*\[")          # a TOML table header
_KEY = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*=")


def available() -> list[str]:
    """The names of the shipped rigs (the TOML files of camdyn/model/data)."""
    return sorted(p.name[:-5] for p in resources.files("camdyn.model.data").iterdir() if p.name.endswith(".toml"))


def load_rig(name: str) -> Rig:
    """A shipped rig by name (see :func:`available`), or a TOML file path."""
    if name in available():
        with resources.as_file(resources.files("camdyn.model.data") / f"{name}.toml") as path:
            rig = Rig.from_toml(path)
        return rig.replace(origin=f"camdyn preset {name!r} (camdyn {__version__})")
    if str(name).endswith(".toml"):
        return Rig.from_toml(name)
    raise ParameterError("name", name, f"one of {available()} or a path to a .toml rig file")


def example_rig() -> Rig:
    """The illustrative rig of the README (not the paper's identified rig)."""
    return load_rig("example")


def cam_example_rig(theta0: float | None = None) -> Rig:
    """The example rig's follower on a cycloidal rise-dwell-return cam: 0.05 rad of follower lift,
    rise and return over 100 degrees, dwells of 80, base circle 25 mm, its pivot where the example
    rig has it (docs/model-editing.md, "A new cam"); the 0-state at the cam angle ``theta0`` (rad,
    default the example rig's).  Use it with ``Scene(profile="spline")``."""
    import math

    from .followers import follower_of_rig, rig_on_cam
    from .motion_laws import rise_dwell_return
    from .synthesis import cam_from_law

    rig, deg = example_rig(), math.pi / 180
    law = rise_dwell_return(0.05, (100 * deg, 80 * deg, 100 * deg, 80 * deg), law="cycloidal")
    return rig_on_cam(rig, cam_from_law(law, follower_of_rig(rig), r_b=0.025), theta0=theta0)


def translating_example_rig() -> Rig:
    """An illustrative translating flat-faced follower on an eccentric circle (its lift is harmonic);
    use it with ``Scene(follower="translating")``."""
    return load_rig("translating-example")


def translating_cam_example_rig() -> Rig:
    """:func:`translating_example_rig`'s follower on a cycloidal rise-dwell-return cam: 10 mm of lift,
    rise and return over 100 degrees, dwells of 80, base circle 15 mm (the 0-state on it, in the low
    dwell at theta0 = 320 degrees, as the eccentric rig's); use it with ``Scene(follower="translating", profile="spline")``."""
    import math

    from .followers import TranslatingFollower
    from .motion_laws import rise_dwell_return
    from .synthesis import cam_from_law

    rig, deg = translating_example_rig(), math.pi / 180
    law = rise_dwell_return(0.01, (100 * deg, 80 * deg, 100 * deg, 80 * deg), law="cycloidal")
    cam = cam_from_law(law, TranslatingFollower(rig.gamma, rig.offset), r_b=0.015)
    return rig.replace(profile=cam, theta0=320 * deg, name="translating-cam-example")  # 320 deg: the low dwell


def second_rig() -> Rig:
    """The flat-faced translating follower on the cam of six circular arcs of the second published rig
    (docs/second-rig.md: Alzate et al. 2007, Osorio et al. 2008; every number from the Siconos
    CamFollower example, marked there reported / inferred): mass 1.221 kg, spring 1430.8 N/m pressing
    with 143.08 N on the base circle (radius 0.40 m; the spring free 0.3 m from the cam's centre),
    restitution 0.8.  The cam's axis is its body x axis; the 0-state is on the base circle.  Use it with
    ``Scene(follower="translating", contact="rigid", damping="none", friction="none", profile="arcs")``."""
    import math

    import numpy as np

    from .profiles import ArcProfile

    deg = math.pi / 180
    c_flank, c_nose, rho_nose = 0.45, 0.40393320723821, 0.15
    # where the flank and the nose meet: the normal parallel to the line of their centres
    flank_nose = -math.pi / 2 + (math.pi - math.atan2(c_nose * math.sin(110 * deg), c_nose * math.cos(110 * deg)
                                                      - c_flank))
    angles = np.array([-90 * deg, flank_nose, -20 * deg, 20 * deg, -flank_nose, 90 * deg, 270 * deg])
    rho = np.array([0.85, rho_nose, c_nose + rho_nose, rho_nose, 0.85, 0.40])
    cx = np.array([0.0, c_nose * math.cos(20 * deg), 0.0, c_nose * math.cos(20 * deg), 0.0, 0.0])
    cy = np.array([c_flank, -c_nose * math.sin(20 * deg), 0.0, c_nose * math.sin(20 * deg), -c_flank, 0.0])
    cam = ArcProfile(angles, rho, cx, cy)
    return Rig(r_c=0.40, e=0.0, theta0=-math.pi / 2, k_s=1430.8, Y_c=200e9, Y_b=200e9, nu_c=0.3, nu_b=0.3,
               m_f=1.221, gamma=math.pi / 2, offset=0.0, F_p=1430.8 * (0.40 - 0.3), xi=0.8, follower="translating",
               profile=cam, name="second-rig", description="the second published rig's arc cam and flat-faced "
               "follower, as the Siconos CamFollower example gives it (docs/second-rig.md)",
               origin=f"camdyn preset 'second-rig' (camdyn {__version__})")


def preset_files() -> list[Path]:
    """The shipped rig files, as files on disk (the package's data folder)."""
    folder = Path(str(resources.files("camdyn.model.data")))
    return [folder / f"{name}.toml" for name in available()]


def _parameter_lines(lines: list[str]) -> dict[str, int]:
    """Parameter name -> line index, for the keys of the [parameters] table of a rig file."""
    found, inside = {}, False
    for i, line in enumerate(lines):
        if _TABLE.match(line):
            inside = line.strip() == "[parameters]"
        elif inside and _KEY.match(line):
            found[_KEY.match(line).group(1)] = i
    return found


def lacking_neutral_values() -> dict[Path, list[str]]:
    """The shipped rig files that do not give a parameter declared with a neutral value, and those
    parameters (empty when every file gives them all)."""
    lacking = {}
    for path in preset_files():
        given = _parameter_lines(path.read_text(encoding="utf-8").splitlines())
        names = [n for n in NEUTRAL if n not in given]
        if names:
            lacking[path] = names
    return lacking


def _with_line(lines: list[str], name: str) -> list[str]:
    """``lines`` with the neutral value of ``name`` added to the [parameters] table: after the
    parameter declared just before it that the file gives (the order of camdyn.model.rig.PARAMETERS,
    the order Rig.to_toml writes), else first in the table."""
    given = _parameter_lines(lines)
    order = [p.name for p in PARAMETERS]
    before = [given[n] for n in order[:order.index(name)] if n in given]
    at = max(before) + 1 if before else next(i for i, line in enumerate(lines) if line.strip() == "[parameters]") + 1
    return lines[:at] + [_BY_NAME[name].toml_line(NEUTRAL[name])] + lines[at:]


def add_neutral_values() -> dict[Path, list[str]]:
    """Write the neutral value of each parameter declared with one into the shipped rig files
    that lack it; return the files changed and the parameters added to each."""
    lacking = lacking_neutral_values()
    for path, names in lacking.items():
        text = path.read_text(encoding="utf-8")
        lines = text.splitlines()
        for name in names:
            lines = _with_line(lines, name)
        new = "\n".join(lines) + ("\n" if text.endswith("\n") else "")
        given = tomllib.loads(new).get("parameters", {})
        if any(given.get(n) != NEUTRAL[n] for n in names):  # the line landed outside [parameters]
            raise RigFileError(str(path), f"could not add {', '.join(names)} to its [parameters] table; add "
                               + ", ".join(f"'{n} = {NEUTRAL[n]!r}'" for n in names) + " by hand")
        path.write_text(new, encoding="utf-8")
    return lacking
