"""Tests of camdyn.model.rig (the Rig parameter set) and camdyn.errors."""

import dataclasses
import importlib
import math
import os
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from camdyn.errors import CamdynError, ParameterError, RigFileError
from camdyn.model.rig import PARAMETERS, Rig

DATA = Path(__file__).parent / "data"
REPO = Path(__file__).resolve().parents[1]

VALID = dict(
    r_c=0.05, e=0.005, w_b=0.02, chi0=0.1, alpha0=0.0, theta0=-1.5707963267948966,
    d_x=0.1, d_y=0.3, L_us=0.25, k_s=2000.0, I_Pb=0.0075, Y_c=2e11, Y_b=2e11,
    nu_c=0.3, nu_b=0.3, l_lambda=0.0016, mu_m=0.3, s=10.0, zeta_D=0.01, beta_D=4.25,
)
#: the parameters an oscillating rig (the default follower) must give: of every rig, or of its follower type
REQUIRED = ["r_c", "e", "w_b", "chi0", "alpha0", "theta0", "d_x", "d_y", "L_us",
            "k_s", "I_Pb", "Y_c", "Y_b", "nu_c", "nu_b"]
#: the translating follower's own parameters, required of its rigs (and refused by the others)
TRANSLATING = ["m_f", "gamma", "offset", "F_p"]
OSCILLATING_ONLY = ["w_b", "chi0", "alpha0", "d_x", "d_y", "L_us", "I_Pb"]
OPTIONAL = ["face_start", "face_end", "l_lambda", "xi", "mu_m", "s", "zeta_A", "beta_B", "beta_C", "zeta_D", "beta_D",
            "zeta_E", "beta_E"]


@pytest.fixture
def rig():
    return Rig(**VALID)


def test_valid_construction(rig):
    for key, value in VALID.items():
        assert getattr(rig, key) == value
    assert rig.zeta_A is None and rig.beta_E is None
    assert rig.name == "unnamed" and rig.description == ""
    with pytest.raises(dataclasses.FrozenInstanceError):
        rig.k_s = 1.0


def test_ints_and_numpy_scalars_stored_as_float():
    r = Rig(**{**VALID, "k_s": 2000, "I_Pb": np.float32(0.0075), "d_y": np.int64(0), "r_c": np.float64(0.05)})
    for key in ("k_s", "I_Pb", "d_y", "r_c"):
        assert type(getattr(r, key)) is float
    assert r.k_s == 2000.0 and r.d_y == 0.0


def test_table_matches_dataclass_fields():
    fields = {f.name: f for f in dataclasses.fields(Rig)}
    assert [p.name for p in PARAMETERS] == REQUIRED + TRANSLATING + OPTIONAL
    assert list(fields) == REQUIRED + TRANSLATING + OPTIONAL + ["name", "description", "follower", "origin", "profile",
                                                                "profile_data"]
    for p in PARAMETERS:
        has_default = fields[p.name].default is not dataclasses.MISSING
        assert (p.required and not p.follower) is not has_default  # a follower's own: checked in __post_init__
        if has_default:
            assert fields[p.name].default is None
    assert {p.name for p in PARAMETERS if p.follower == "oscillating"} == set(OSCILLATING_ONLY)
    assert {p.name for p in PARAMETERS if p.follower == "translating"} == set(TRANSLATING)


@pytest.mark.parametrize("name", REQUIRED)
def test_missing_required_parameter_named(name):
    d = {k: v for k, v in VALID.items() if k != name}
    with pytest.raises(RigFileError, match=rf"missing required parameter\(s\): {name}$"):
        Rig.from_dict(d)
    with pytest.raises(ParameterError if name in OSCILLATING_ONLY else TypeError, match=rf"{name}"):
        Rig(**d)
    with pytest.raises(ParameterError, match=rf"^{name} is not given: required"):
        Rig(**{**d, name: None})


def test_all_missing_parameters_listed():
    with pytest.raises(RigFileError) as info:
        Rig.from_dict({"k_s": 1.0, "name": "x"})
    for name in REQUIRED:
        if name != "k_s":
            assert name in str(info.value)


@pytest.mark.parametrize("name, value, valid, meaning", [
    ("k_s", -5.0, "> 0", "follower spring stiffness, N/m"),
    ("k_s", 0.0, "> 0", "N/m"),
    ("r_c", 0.0, "> 0", "cam radius, m"),
    ("w_b", -0.02, "> 0", "m"),
    ("chi0", 0, "> 0", "m"),
    ("d_x", -0.1, "> 0", "m"),
    ("L_us", 0.0, "> 0", "m"),
    ("I_Pb", -1e-3, "> 0", "kg m^2"),
    ("Y_c", -2e11, "> 0", "Pa"),
    ("Y_b", 0.0, "> 0", "Pa"),
    ("e", -0.001, ">= 0", "m"),
    ("nu_c", -0.1, ">= 0", "dimensionless"),
    ("nu_b", 0.5, "< 0.5", "dimensionless"),
    ("alpha0", 1.53, "pi/2 - 0.05", "rad"),
    ("alpha0", -1.53, "pi/2 - 0.05", "rad"),
    ("l_lambda", 0.0, "> 0", "m"),
    ("mu_m", -0.3, ">= 0", "dimensionless"),
    ("s", 0.0, "> 0", "s/m"),
    ("zeta_A", -0.1, ">= 0", "dimensionless"),
    ("beta_B", -1.0, ">= 0", "s/m"),
    ("beta_C", -1.0, ">= 0", "N s/m^1.25"),
])
def test_out_of_range(name, value, valid, meaning):
    with pytest.raises(ParameterError) as info:
        Rig(**{**VALID, name: value})
    message = str(info.value)
    assert message.startswith(f"{name} = {value} is out of range: must be ")
    assert valid in message and meaning in message
    assert (info.value.name, info.value.value) == (name, value)


def test_example_message_exact():
    with pytest.raises(ParameterError) as info:
        Rig(**{**VALID, "k_s": -5.0})
    assert str(info.value) == "k_s = -5.0 is out of range: must be > 0 (follower spring stiffness, N/m)"
    assert info.value.valid == "> 0"


@pytest.mark.parametrize("name", REQUIRED + OPTIONAL)
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf, 10**400, True, False, np.bool_(True),
                                 "0.05", [0.05], np.array([0.05])])
def test_non_finite_or_not_a_number(name, bad):
    with pytest.raises(ParameterError) as info:
        Rig(**{**VALID, name: bad})
    message = str(info.value)
    assert message.startswith(f"{name} = ")
    assert "must be a finite real number" in message
    if isinstance(bad, (bool, np.bool_, str, list, np.ndarray)):
        assert f"is not a real number ({type(bad).__name__})" in message


@pytest.mark.parametrize("name", OPTIONAL)
def test_optional_none_accepted(name):
    assert getattr(Rig(**{**VALID, name: None}), name) is None


@pytest.mark.parametrize("name, value, hint", [
    ("r_c", 50.0, "given in mm"),
    ("w_b", 20, "given in mm"),
    ("chi0", 100.0, "given in mm"),
    ("d_x", 100.0, "given in mm"),
    ("d_y", -300.0, "given in mm"),
    ("L_us", 250.0, "given in mm"),
    ("l_lambda", 16.0, "given in mm"),
    ("Y_c", 200.0, "given in GPa"),
    ("Y_b", 2e5, "given in GPa or MPa"),
    ("alpha0", 30.0, "given in degrees"),
    ("alpha0", -1.6, "given in degrees"),
    ("theta0", -90.0, "given in degrees"),
])
def test_wrong_unit_rejected_with_hint(name, value, hint):
    d = {**VALID, name: value}
    if name == "r_c":
        d["e"] = 5.0  # so that only r_c is implausible
    with pytest.raises(ParameterError, match=rf"^{name} = .*{hint}"):
        Rig(**d)


def test_plausible_extremes_accepted():
    Rig(**{**VALID, "r_c": 10.0, "Y_c": 1e6, "alpha0": 1.52, "theta0": 2 * math.pi, "d_y": -10.0})


def test_alpha0_near_90_degrees_is_not_called_a_unit_error():
    with pytest.raises(ParameterError) as info:
        Rig(**{**VALID, "alpha0": 1.55})
    assert "degrees?" not in str(info.value) and "tan and sec" in str(info.value)


@pytest.mark.parametrize("e", [0.05, 0.06])
def test_pivot_outside_cam_rejected(e):
    with pytest.raises(ParameterError, match=r"^e = .* must be < r_c .*inside the cam disk"):
        Rig(**{**VALID, "e": e})
    assert Rig(**{**VALID, "e": 0.0499}).e == 0.0499


def test_text_fields_must_be_strings():
    with pytest.raises(ParameterError, match="^name = 3 .*a string"):
        Rig(**{**VALID, "name": 3})


def test_from_dict_unknown_key_suggests():
    with pytest.raises(RigFileError) as info:
        Rig.from_dict({**VALID, "k_S": 1.0, "alpha_0": 0.0, "zzz": 1}, source="mine")
    message = str(info.value)
    assert message.startswith("mine: unknown parameter 'k_S' (did you mean 'k_s'?)")
    assert "'alpha_0' (did you mean 'alpha0'?)" in message
    assert "'zzz'" in message and "'zzz' (did" not in message
    assert info.value.key == "k_S"


@pytest.mark.parametrize("bad", ["2000", [2000.0], {"v": 1}])
def test_from_dict_wrong_type_names_key_and_type(bad):
    with pytest.raises(RigFileError) as info:
        Rig.from_dict({**VALID, "k_s": bad}, source="x.toml")
    message = str(info.value)
    assert message.startswith("x.toml: k_s = ") and type(bad).__name__ in message
    assert isinstance(info.value.__cause__, ParameterError)


def test_from_dict_rejects_non_mapping():
    with pytest.raises(RigFileError, match="expected a table"):
        Rig.from_dict([("k_s", 1.0)])


def test_dict_round_trip(rig):
    d = rig.to_dict()
    assert d["k_s"] == 2000.0 and d["zeta_A"] is None and d["name"] == "unnamed"
    assert Rig.from_dict(d) == rig


def test_read_hand_written_file():
    rig = Rig.from_toml(DATA / "rig_valid.toml")
    assert rig == Rig(**VALID, name="steel line contact", description=rig.description)
    assert rig.description.startswith("Parameter set used by")
    assert type(rig.k_s) is float and type(rig.alpha0) is float


def write(tmp_path, text, name="rig.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_toml_unknown_key_suggests(tmp_path):
    text = (DATA / "rig_valid.toml").read_text().replace("k_s = 2000", "ks = 2000")
    path = write(tmp_path, text)
    with pytest.raises(RigFileError) as info:
        Rig.from_toml(path)
    assert str(info.value) == f"{path}: unknown parameter 'ks' (did you mean 'k_s'?)"


def test_toml_misplaced_keys(tmp_path):
    path = write(tmp_path, "r_c = 0.05\n[parameters]\n")
    with pytest.raises(RigFileError, match=r"'r_c' must be inside the \[parameters\] table"):
        Rig.from_toml(path)
    path = write(tmp_path, 'name = "x"\n[parameter]\nr_c = 0.05\n')
    with pytest.raises(RigFileError, match=r"unknown top-level key 'parameter' \(did you mean 'parameters'\?\)"):
        Rig.from_toml(path)
    path = write(tmp_path, 'name = "x"\n')
    with pytest.raises(RigFileError, match=r"missing \[parameters\] table"):
        Rig.from_toml(path)


def test_toml_bad_value_names_file_and_key(tmp_path):
    text = (DATA / "rig_valid.toml").read_text().replace("k_s = 2000", 'k_s = "2000"')
    path = write(tmp_path, text)
    with pytest.raises(RigFileError, match=r"rig\.toml: k_s = '2000' is not a real number \(str\)"):
        Rig.from_toml(path)


def test_toml_syntax_error_names_file(tmp_path):
    path = write(tmp_path, "[parameters]\nr_c = 0.05\nk_s = = 2000\n", name="broken.toml")
    with pytest.raises(RigFileError) as info:
        Rig.from_toml(path)
    assert str(info.value).startswith(f"{path}: not valid TOML")
    assert info.value.source == str(path)


def test_toml_unreadable_file(tmp_path):
    with pytest.raises(RigFileError, match="cannot read rig file"):
        Rig.from_toml(tmp_path / "absent.toml")


def test_toml_round_trip_exact(tmp_path, rig):
    awkward = rig.replace(
        name='quote " backslash \\ tab \t',
        description="line one\nline two: µ, ∞, 😀, DEL \x7f, NUL \x00",
        chi0=0.1 + 0.2, d_y=-1e-300, theta0=-0.0, I_Pb=1 / 3, Y_b=123456789012.34567,
        l_lambda=None, beta_C=3.25e5,
    )
    for original in (rig, awkward):
        path = tmp_path / "out.toml"
        original.to_toml(path)
        loaded = Rig.from_toml(path)
        assert loaded == original
        assert repr(loaded.to_dict()) == repr(original.to_dict())  # bit-exact, keeps -0.0


def test_replace_validates(rig):
    changed = rig.replace(k_s=3000, name="stiffer")
    assert changed.k_s == 3000.0 and changed.name == "stiffer" and rig.k_s == 2000.0
    with pytest.raises(ParameterError, match=r"^k_s = -1 is out of range"):
        rig.replace(k_s=-1)
    with pytest.raises(ParameterError, match=r"^e = 0\.2 .* < r_c"):
        rig.replace(e=0.2)
    with pytest.raises(RigFileError, match=r"unknown parameter 'K_s' \(did you mean 'k_s'\?\)"):
        rig.replace(K_s=1.0)


def test_equivalent_modulus_steel_on_steel(rig):
    expected = 200e9 / (2 * (1 - 0.09))  # two equal halves of (1 - nu^2) / Y
    assert rig.Y_e == pytest.approx(expected, rel=1e-14)
    assert rig.Y_e == pytest.approx(1.0989e11, rel=1e-4)


def test_equivalent_modulus_rigid_follower_limit(rig):
    r = rig.replace(Y_b=1e30, Y_c=7e10, nu_c=0.33)
    assert r.Y_e == pytest.approx(7e10 / (1 - 0.33**2), rel=1e-12)


def test_require(rig):
    assert rig.require("beta_D", "zeta_D", "l_lambda", why="damping model D") is None
    with pytest.raises(ParameterError) as info:
        rig.require("beta_B", "zeta_A", why="damping model B")
    assert str(info.value).startswith("beta_B is not given: required by damping model B (")
    assert "also not given: zeta_A" in str(info.value)
    assert info.value.name == "beta_B" and info.value.value is None
    with pytest.raises(ParameterError, match=r"^zeta_E is not given: required \("):
        rig.require("zeta_E")
    with pytest.raises(RigFileError, match="did you mean 'beta_D'"):
        rig.require("beta_d")


def test_error_hierarchy_and_pickling():
    errors = [ParameterError("k_s", -5.0, "> 0", reason="r"), RigFileError("f.toml", "bad", key="k")]
    for err in errors:
        assert isinstance(err, CamdynError) and isinstance(err, ValueError)
        copy = pickle.loads(pickle.dumps(err))
        assert type(copy) is type(err) and str(copy) == str(err) and copy.__dict__ == err.__dict__


def test_import_does_not_import_sympy():
    code = "import sys, camdyn.model.rig; sys.exit(any(m.split('.')[0] == 'sympy' for m in sys.modules))"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")]))}
    assert subprocess.run([sys.executable, "-c", code], env=env).returncode == 0


def test_shipped_rig_files_state_each_parameters_meaning_and_unit():
    """Issue 14 (R): every parameter line of a shipped TOML rig ends with the meaning and SI unit
    of camdyn.model.rig.PARAMETERS (as Rig.to_toml writes them), so a user editing a file sees units."""
    import re
    from importlib.resources import files

    from camdyn.model.rig import PARAMETERS

    by_name = {p.name: p for p in PARAMETERS}
    for path in files("camdyn.model.data").iterdir():
        if not path.name.endswith(".toml"):
            continue
        lines = path.read_text(encoding="utf-8").split("[parameters]", 1)[1].splitlines()
        params = [re.match(r"^(\w+)\s*=\s*[^#]*#\s*(.*)$", line) for line in lines if re.match(r"^\w+\s*=", line)]
        assert params and all(params), path.name
        for m in params:
            assert m.group(2) == by_name[m.group(1)].meaning, (path.name, m.group(1))


def test_rig_reads_the_one_declaration_in_derive():
    """camdyn.Rig's fields, units and ranges are derive/parameters.py's rows, not a second list,
    and every constant a generated scene reads is either a rig parameter, an equilibrium
    result, a cam constant or a constant of the laws computed from them."""
    from camdyn import generated
    from camdyn.vocabulary import parameters as declared
    assert [p.name for p in PARAMETERS] == list(declared.RIG_NAMES)
    for p, row in zip(PARAMETERS, declared.RIG_PARAMETERS):
        assert (p.required, p.rules, p.description) == (row.required, row.rules, row.description)
    profile_data = {"profile"}  # a cam profile's data block (derive.profile_code), given by the rig's profile
    known = set(declared.RIG_NAMES) | set(declared.EQUILIBRIUM_NAMES) | set(declared.CAM_NAMES) | profile_data
    for module in generated.SCENES.values():
        kernels = importlib.import_module(f"camdyn.generated.{module}")
        assert set(kernels.INPUTS) <= known, module


def test_origin_records_where_the_values_came_from(tmp_path):
    """Rig.origin: a file's path, a preset's name, and the parameters replace() changed;
    it takes no part in equality and is not a value of to_dict()."""
    import camdyn
    example = camdyn.example_rig()
    assert example.origin.startswith("camdyn preset 'example' (camdyn ")
    changed = example.replace(k_s=2500.0, zeta_D=0.02)
    assert changed.origin == example.origin + "; changed k_s, zeta_D"
    assert example.replace(name="renamed").origin == example.origin  # no parameter changed
    path = tmp_path / "mine.toml"
    changed.to_toml(path)
    loaded = Rig.from_toml(path)
    assert loaded.origin == f"file {path.resolve()}"
    assert loaded == changed and "origin" not in loaded.to_dict()
    assert Rig(**VALID).origin == ""
    with pytest.raises(ParameterError, match="origin"):
        Rig(**VALID, origin=3)
