"""Code generation: SymPy functions of a scene -> a plain-Python module.

Deterministic by construction: parameters are unpacked in one canonical
order, common subexpressions are numbered x0, x1, ... in the order
``sympy.cse`` returns them, and the header carries a hash of the symbolic
inputs (the scene and every expression's ``srepr``) and the SymPy version.

Two flavours of each kernel: scalar code on Python floats with ``math``
(measured ~5x faster per call than NumPy-printed code for a 1-DOF RHS), and a
``_v`` NumPy flavour on arrays, for outputs over many samples.
"""
from __future__ import annotations

import hashlib
import textwrap
from dataclasses import dataclass
from functools import lru_cache

import sympy as sp
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.pycode import PythonCodePrinter

from . import laws
from . import symbols as S
from . import trig
from .scenes import FLAG_SURFACES, OUTPUTS, Function, SceneSpec, build, regimes

#: Canonical order of everything a kernel may read from the parameter vector p.
PARAM_ORDER = S.RIG_NAMES + tuple(sym.name for sym in laws.CONSTANTS) + S.DERIVED_NAMES + S.CAM_NAMES
UNITS = {**{name: p.unit for name, p in S.PARAMS.items()}, "Y_e": "Pa"}
STATE_ARGS = {"t": "time (s)", "alpha": "follower angle alpha (rad, clockwise)",
              "alpha_dot": "follower angular velocity (rad/s)", "Theta": "cam angle (rad)",
              "p": "parameter vector, laid out as PARAMS (SI units); build it with pack()",
              "cam": "(Theta, Theta_dot, Theta_ddot) of the user's cam motion at t (rad, rad/s, rad/s^2)"}
OUTPUT_UNITS = {"alpha_ddot": "rad/s^2", "dalpha_ddot_dalpha": "1/s^2", "dalpha_ddot_dalpha_dot": "1/s",
                "psi_i": "m", "psi_j": "m", "psi_i_dot": "m/s", "F_s": "N", "F_n": "N", "F_f": "N",
                "v_r": "m/s", "N_x": "N", "alpha_i": "rad", "energy": "J", "P_in": "W", "D_c": "W",
                "D_f": "W", "Theta": "rad", "Theta_dot": "rad/s", "Theta_ddot": "rad/s^2", "M": "N m",
                "dM_dalpha": "N m/rad", "k_lambda": "N/m", "dalpha_i_dTheta": "1", "d2alpha_i_dTheta2": "1/rad",
                "spring_moment": "N m", "reach_margin": "m", "dv_r_dt": "m/s^2", "dv_r_dalpha": "m/s/rad", "dv_r_dalpha_dot": "m/rad", "V_s": "J", "V_s_printed": "J",
                "surface": "m or m/s", "auxiliary": "m/s, m/s^2, m/s/rad or m/rad", "power": "W"}


class _Scalar(PythonCodePrinter):
    def __init__(self):
        super().__init__({"fully_qualified_modules": False, "standard": "python3"})

    def _print_Abs(self, expr):
        return f"abs({self._print(expr.args[0])})"

    def _print_SignedPow32(self, expr):
        x = self._print(expr.args[0])
        return f"({x})*sqrt(abs({x}))"


class _Vector(NumPyPrinter):
    def __init__(self):
        super().__init__({"fully_qualified_modules": True})

    def _print_SignedPow32(self, expr):
        x = self._print(expr.args[0])
        return f"({x})*numpy.sqrt(numpy.abs({x}))"


def _param_names(exprs) -> list[str]:
    """The parameters the expressions read, in PARAM_ORDER, then the trigonometric
    constants (derive.trig) by name."""
    names = {s.name for e in exprs for s in sp.sympify(e).free_symbols}
    return [n for n in PARAM_ORDER if n in names] + sorted(n for n in names if _is_constant(n))


def _is_constant(name: str) -> bool:
    return name.startswith(("sin_", "cos_"))


@lru_cache(maxsize=None)
def _economised(exprs: tuple[sp.Expr, ...]) -> tuple[tuple[sp.Expr, ...], tuple[tuple[sp.Symbol, sp.Expr], ...]]:
    """derive.trig.economise of a function's expressions (as emitted), and its constants."""
    out, constants = trig.economise(list(exprs))
    return tuple(out), tuple(sorted(constants.items(), key=lambda kv: kv[0].name))


@dataclass
class _Module:
    """A scene's functions as derived (hashed) and the index kernels' branches; the
    parameters and trigonometric constants (derive.trig) of the code emitted for both."""
    spec: SceneSpec
    functions: tuple[Function, ...]

    def __post_init__(self):
        self.families = _index_families(self.spec, self.functions)
        emitted = list(self.functions) + [f for fam in self.families for _, f in fam[2]]
        self.constants = dict(sorted({kv for f in emitted for kv in _economised(f.exprs)[1]}, key=lambda kv: kv[0].name))
        self.params = _param_names([x for f in emitted for x in _economised(f.exprs)[0]])

    def source_hash(self) -> str:
        h = hashlib.sha256(repr(sorted(self.spec.as_dict().items())).encode())
        for f in self.functions:
            h.update(f"{f.name}{f.args}{f.outputs}".encode())
            for x in f.exprs:
                h.update(sp.srepr(x).encode())
        return h.hexdigest()[:16]


def _function_code(f: Function, params: list[str]) -> str:
    lines = [f"def {f.name}({', '.join(f.args)}):"]
    doc = [f.doc, "", "Arguments:"]
    doc += [f"    {a}: {STATE_ARGS[a]}" for a in f.args]
    doc += ["Returns" + (" (a tuple):" if len(f.outputs) > 1 else ":")]
    doc += [f"    {o} ({OUTPUT_UNITS[o]})" for o in f.outputs]
    lines.append(textwrap.indent('"""' + "\n".join(doc) + '\n"""', "    "))
    return "\n".join(lines + _body_lines(f, params))


def _body_lines(f: Function, params: list[str]) -> list[str]:
    """The statements of a function (parameter unpacking, CSE, return), indented once."""
    printer = _Vector() if f.vectorised else _Scalar()
    exprs = list(_economised(f.exprs)[0])
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("x"), order="canonical")
    used = _param_names(exprs)
    lines = []
    if "cam" in f.args:
        lines.append("    Theta, Theta_dot, Theta_ddot = cam")
    lines += [f"    {n} = p[{params.index(n)}]" for n in used]
    lines += [f"    {sym} = {printer.doprint(val)}" for sym, val in replacements]
    if f.vectorised:
        arrays = ", ".join(a for a in f.args if a in ("t", "alpha", "alpha_dot", "Theta"))
        lines.append(f"    _zero = numpy.zeros(numpy.broadcast({arrays}).shape)")
        values = [f"{printer.doprint(r)} + _zero" for r in reduced]
    else:
        values = [printer.doprint(r) for r in reduced]
    lines.append("    return " + (values[0] if len(values) == 1 else "(" + ", ".join(values) + ")"))
    return lines


#: Index-dispatched kernels for compiled engines (numba): one self-contained function
#: per family, selecting a branch by an integer, with no call to another kernel.
INDEX_ARGS = {"r": "regime index, position in REGIME_NAMES", "k": "flag index, position in FLAGS",
              "j": "auxiliary index: 0 gap rate; 1, 2, 3 the partials of v_r (Coulomb scenes)",
              "c": "3 r + i: regime r = REGIME_NAMES[c // 3], flow i = (P_in, D_c, D_f)[c % 3]"}


def _index_function_code(name: str, selector: str, branches: list[tuple[str, Function]], doc: str,
                         output: str, params: list[str]) -> str:
    """``name(selector, t, alpha, alpha_dot, p)``: the scalar body of ``branches[i]`` where
    ``selector == i``; NaN for an index out of range.  Plain ``math``, so numba can compile it
    (e.g. as a ``cfunc``) with the parameter vector passed as an array."""
    args = (selector, "t", "alpha", "alpha_dot", "p")
    lines = [f"def {name}({', '.join(args)}):"]
    text = [doc, "", "Arguments:", f"    {selector}: {INDEX_ARGS[selector]}"]
    text += [f"    {a}: {STATE_ARGS[a]}" for a in args[1:]]
    text += ["Branches:"] + [f"    {i}: {label}" for i, (label, _) in enumerate(branches)]
    text += ["Returns:", f"    {output} ({OUTPUT_UNITS[output]}); nan for an index out of range"]
    lines.append(textwrap.indent('"""' + "\n".join(text) + '\n"""', "    "))
    for i, (_, f) in enumerate(branches):
        lines.append(f"    {'if' if i == 0 else 'elif'} {selector} == {i}:")
        lines += ["    " + line for line in _body_lines(f, params)]
    lines.append("    return nan")
    return "\n".join(lines)


def _index_families(spec: SceneSpec, functions: tuple[Function, ...]) -> list[tuple]:
    """The index-dispatched kernels of a compiled engine, as (name, selector, branches, doc,
    output) for _index_function_code:

    - ``rhs_index`` over the regimes;
    - with flags, ``surface_index`` over the flags' surfaces;
    - in non-linear scenes, ``aux_index``: the gap rate (micro-hops hidden inside a step)
      and, with Coulomb friction, the partials of v_r (the Filippov stick mode);
    - ``power_index`` over (regime, flow): the energy ledger's P_in, D_c, D_f (OUTPUTS[10:13]).
    """
    if spec.motion == "user":  # its kernels need the user's Python callables: not compilable
        return []
    by_name = {f.name: f for f in functions}
    names = [r.name for r in regimes(spec)]
    out = [("rhs_index", "r", [(n, by_name[f"rhs_{n}"]) for n in names],
            "Angular acceleration (rad/s^2) of regime REGIME_NAMES[r]: rhs_<regime> by index.", "alpha_ddot")]
    if spec.flags:
        surfaces = [(f"{flag}: {FLAG_SURFACES[flag][0]}", by_name[FLAG_SURFACES[flag][0]]) for flag in spec.flags]
        out.append(("surface_index", "k", surfaces,
                    "Switching surface of flag FLAGS[k] (FLAG_SURFACES): gap, gap_rate or slip by index.", "surface"))
    if "gap_rate" in by_name:
        aux = [("psi_i_dot", by_name["gap_rate"])] + _single_outputs(by_name.get("slip_partials"))
        out.append(("aux_index", "j", aux, "Auxiliary scalars of the hybrid loop by index: the gap rate and, "
                    "with Coulomb friction, the partials of v_r.", "auxiliary"))
    flows = [pair for n in names for pair in _single_outputs(by_name[f"out_{n}"], OUTPUTS[10:13], f"{n}: ")]
    out.append(("power_index", "c", flows, "Power flows of the energy ledger by index: P_in (cam drive), D_c "
                "(contact damping), D_f (friction) of each regime.", "power"))
    return out


def _single_outputs(f: Function | None, outputs: tuple[str, ...] | None = None,
                    prefix: str = "") -> list[tuple[str, Function]]:
    """One single-output Function per output of ``f`` (those named in ``outputs``, or all)."""
    if f is None:
        return []
    wanted = f.outputs if outputs is None else outputs
    return [(prefix + o, Function(f"{f.name}_{o}", f.args, (o,), (f.exprs[f.outputs.index(o)],), f.doc))
            for o in wanted]


def _pack_code(params: list[str], constants: dict[sp.Symbol, sp.Expr]) -> tuple[str, list[str]]:
    derived = {**laws.CONSTANTS, **constants}
    inputs = [n for n in PARAM_ORDER if n in params and n not in {s.name for s in laws.CONSTANTS}]
    for sym, definition in derived.items():
        if sym.name in params:
            inputs += [n for n in _param_names([definition]) if n not in inputs]
    inputs = [n for n in PARAM_ORDER if n in inputs]
    printer = _Scalar()
    lines = ["def pack(values):",
             '    """Parameter vector p (laid out as PARAMS) from a mapping of the INPUTS names, SI units.',
             "",
             "    Computes the laws' constants (Y_e, Eq. 14) and the sines and cosines of parameter-only",
             "    angles (sin_<angle>, cos_<angle>: derive.trig) once, here, not in every kernel call.",
             '    """']
    lines += [f"    {n} = float(values[{n!r}])" for n in inputs]
    for sym, definition in derived.items():
        if sym.name in params:
            lines.append(f"    {sym.name} = {printer.doprint(definition)}")
    lines.append(f"    return numpy.array([{', '.join(params)}], dtype=float)")
    return "\n".join(lines), inputs


def module_source(spec: SceneSpec) -> str:
    """The complete text of a scene's generated module."""
    mod = _Module(spec, build(spec))
    params = mod.params
    pack, inputs = _pack_code(params, mod.constants)
    regime_table = {r.key: r.name for r in regimes(spec)}
    flags = spec.flags
    header = [
        "# Generated by camdyn.derive -- DO NOT EDIT. Regenerate with: python -m camdyn.derive",
        f"# scene: {spec.slug}",
        f"# symbolic-input hash: {mod.source_hash()}",
        f"# sympy: {sp.__version__}",
    ]
    doc = [
        f'"""Generated kernels of the scene {spec.slug!r}.',
        "",
        "Scene: " + ", ".join(f"{k}={v!r}" for k, v in spec.as_dict().items()) + ".",
        "",
        "Every kernel takes the parameter vector p laid out as PARAMS; build it with",
        "pack(values), values a mapping of the INPUTS names to SI floats.",
        "State kernels take (t, alpha, alpha_dot, p" + (", cam" if spec.motion == "user" else "") + ").",
        "",
        "Regimes: REGIMES maps the discrete state (one value per name in FLAGS, None where",
        "a flag does not apply) to a regime name; rhs_<regime>, jac_<regime>, out_<regime>",
        "and out_<regime>_v are its kernels.  FLAG_SURFACES gives, per flag, the surface",
        "function whose sign sets it and the sign where the flag is True.",
        '"""',
    ]
    data = [
        "SCENE = " + repr(spec.as_dict()),
        f"SLUG = {spec.slug!r}",
        "PARAMS = " + repr(tuple(params)),
        "INPUTS = " + repr(tuple(inputs)),
        "UNITS = " + repr({n: UNITS.get(n, "1" if _is_constant(n) else None)
                           for n in params + [i for i in inputs if i not in params]}),
        "FLAGS = " + repr(flags),
        "FLAG_SURFACES = " + repr({f: FLAG_SURFACES[f] for f in flags}),
        "REGIMES = " + repr(regime_table),
        "OUTPUTS = " + repr(OUTPUTS),
        "REGIME_NAMES = " + repr(tuple(regime_table.values())),
    ]
    body = [_function_code(f, params) for f in mod.functions]
    body += [_index_function_code(*family, params) for family in mod.families]
    imports = ["from math import *  # noqa: F401,F403  (sin, cos, sqrt, ... on floats)", "", "import numpy"]
    parts = ["\n".join(header), "\n".join(doc), "\n".join(imports), "\n".join(data), pack] + body
    return "\n\n\n".join(parts[:3]) + "\n\n" + parts[3] + "\n\n\n" + "\n\n\n".join(parts[4:]) + "\n"
