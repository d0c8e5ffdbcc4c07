"""Code generation: a scene's kernels (:class:`derive.scenes.SceneModule`) -> plain-Python text.

A scene gets two modules (:func:`sources`): ``scene_<slug>``, everything a run needs (the
automaton's data, ``pack()``, the fields, surfaces, Jacobian and outputs), and its companion
``variational_<slug>``, the kernels only the tangent dynamics and the continuation use
(``surface_gradient``, ``field_sensitivity``), so that a run neither imports nor compiles
them.  Both read the same parameter vector: PARAMS and ``pack()`` cover the kernels of both.

Each generated function dispatches on its mode (or surface and mode) and computes, in the
branch of a mode, the named quantities of :mod:`derive.fields` once each, in the order of the
derivation (``psi_i = ...``, ``F_n = ...``, ``alpha_ddot = ...``).  Modes that compute the same
quantities share one branch (a *family*); where their laws differ (the damping law, the
friction direction) the quantity has one ``if``/``elif``/``else`` line per law.

Deterministic by construction: parameters are read in one canonical order, common
subexpressions are numbered x0, x1, ... in the order ``sympy.cse`` returns them (canonical
ordering), families and modes come in the automaton's order, and the header carries a hash
of the symbolic inputs and the SymPy version.  Sines and cosines are economised first
(:mod:`derive.trig`): their parameter-only parts become constants of ``pack()``.
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
from . import profile as H
from . import symbols as S
from . import trig
from .profile_code import PROFILE_BLOCK, evaluator_source
from .automaton import Automaton
from .fields import Kernel
from .scenes import Case, Function, SceneModule, build
from camdyn.vocabulary import (ECCENTRIC, CONTINUATION_PARAMETERS, OUTPUTS, SURFACES, TRANSITION, SceneSpec, outputs_of,
                               state_names)

#: Canonical order of everything a kernel may read from the parameter vector p.
PARAM_ORDER = S.RIG_NAMES + tuple(sym.name for sym in laws.CONSTANTS) + S.DERIVED_NAMES + S.CAM_NAMES
UNITS = {**{name: p.unit for name, p in S.PARAMS.items()}, "Y_e": "Pa",
         PROFILE_BLOCK: "m and rad: the profile's data (derive.profile_code)"}
ARGS = {"m": "mode index: a position in MODES (MODE_<NAME> constants)",
        "j": "reset index: a position in RESETS (RESET_<NAME> constants)",
        "s": "surface index: a position in SURFACES (SURFACE_<NAME> constants)",
        "t": "time (s)", "alpha": "follower angle alpha (rad, clockwise)",
        "alpha_dot": "follower angular velocity (rad/s)", "Theta": "cam angle (rad)",
        "y": "the translating follower's face: its distance from the cam's centre E along the guide (m)",
        "y_dot": "the translating follower's velocity along its guide (m/s)",
        "p": "parameter vector, laid out as PARAMS (SI units); build it with pack()",
        "cam": "(Theta, Theta_dot, Theta_ddot) of the user's cam motion at t (rad, rad/s, rad/s^2)",
        "out": "a float64 array the results are written into (length: the number of results)"}
RESULT_UNITS = {"alpha_ddot": "rad/s^2", "dalpha_ddot_dalpha": "1/s^2", "dalpha_ddot_dalpha_dot": "1/s",
                "value": "m, m/s or m/s^2", "rate": "the value's unit per s",
                "dh_dalpha": "surface unit/rad", "dh_dalpha_dot": "surface unit s/rad", "dh_dt": "surface unit/s", "Theta": "rad", "Theta_dot": "rad/s", "Theta_ddot": "rad/s^2",
                "M": "N m", "dM_dalpha": "N m/rad", "psi_i": "m", "psi_j": "m", "k_lambda": "N/m",
                "reach_margin": "m", "alpha_i": "rad", "dalpha_i_dTheta": "1", "d2alpha_i_dTheta2": "1/rad",
                "spring_moment": "N m", "V_s": "J", "V_s_printed": "J",
                "dq_dq": "1", "dq_dq_dot": "s", "dq_dot_dq": "1/s", "dq_dot_dq_dot": "1", "dq_dt": "q/s",
                "dq_dot_dt": "q/s^2",
                "alpha": "rad", "alpha_dot": "rad/s", "y": "m", "y_dot": "m/s", "y_ddot": "m/s^2", "dy_ddot_dy": "1/s^2", "dy_ddot_dy_dot": "1/s", "dh_dy": "surface unit/m",
                "dh_dy_dot": "surface unit s/m", "F": "N", "dF_dy": "N/m", "y_i": "m", "dy_i_dTheta": "m/rad",
                "d2y_i_dTheta2": "m/rad^2", "spring_force": "N",
                **{name: unit for f in S.COORDINATES for name, (unit, _) in outputs_of(f).items()},
                **{f"d{q.name}_ddot_d{n}": f"{q.unit}/s^2 per {UNITS[n]}" for n in CONTINUATION_PARAMETERS
                   for q in S.COORDINATES.values()}}
#: the infix of field_sensitivity's result names d<q>_ddot_d<parameter> (the parameter's name follows)
SENSITIVITY_INFIX = "_ddot_d"
_STATE = {"t": S.t_s, "alpha": S.alpha_s, "alpha_dot": S.alpha_dot, "y": S.y_s, "y_dot": S.y_dot, "Theta": S.Theta_s}


def sensitivity_parameter(result: str) -> str:
    """The continuation parameter of a field_sensitivity result name d<q>_ddot_d<parameter>."""
    return result.split(SENSITIVITY_INFIX, 1)[1]


class _Scalar(PythonCodePrinter):
    def __init__(self):
        super().__init__({"fully_qualified_modules": False, "standard": "python3"})

    def _print_Abs(self, expr):
        return f"abs({self._print(expr.args[0])})"

    def _print_SignedPow32(self, expr):
        x = self._print(expr.args[0])
        return f"({x})*sqrt(abs({x}))"

    def _print_SupportFunction(self, expr):
        """h^(n)(phi): the scene's profile evaluator, reading the profile's data at the end of p."""
        return f"profile({expr.order}, {self._print(expr.args[1])}, p, PROFILE_OFFSET)"


    def _print_JunctionFunction(self, expr):
        """The arcs' junction indicator (derive.profile.JunctionFunction), from the profile's data."""
        return f"junction_indicator({expr.order}, {self._print(expr.args[1])}, p, PROFILE_OFFSET)"


class _PackScalar(_Scalar):
    """pack()'s printer: the evaluator reads the profile's data from the mapping's block."""

    def _print_SupportFunction(self, expr):
        return f"profile({expr.order}, {self._print(expr.args[1])}, {_BLOCK_LOCAL}, 0)"


#: pack()'s local name of the profile's data block
_BLOCK_LOCAL = "profile_block"


class _Vector(NumPyPrinter):
    def __init__(self):
        super().__init__({"fully_qualified_modules": True})


def _is_constant(name: str) -> bool:
    """A constant pack() computes: a trigonometric one of derive.trig (sin_<angle>, cos_<angle>),
    or the cam's support function at a parameter-only angle (h<n>_at_<angle>)."""
    return name.startswith(("sin_", "cos_")) or (name[:1] == "h" and name[2:6] == "_at_")


def _constant_unit(name: str) -> str:
    """The unit of a constant of pack(): 1 for a sine or cosine, m/rad^n for h^(n)."""
    if name.startswith(("sin_", "cos_")):
        return "1"
    return "m" if name[1] == "0" else f"m/rad^{name[1]}"


def _profile_constants(exprs: tuple[sp.Expr, ...]) -> tuple[tuple[sp.Expr, ...], dict]:
    """The calls h^(n)(c) of a parameter-only angle c (the 0-state's, Eq. 5) as constants of
    pack(): {symbol h<n>_at_<c>: the call}, and the expressions with the symbols."""
    constant = {call: sp.Symbol(f"h{call.order}_at_{trig._slug(call.args[1])}", real=True)
                for x in exprs for call in H.calls(x) if H.is_constant_call(call)}
    if not constant:
        return exprs, {}
    return tuple(sp.sympify(x).xreplace(constant) for x in exprs), {sym: call for call, sym in constant.items()}


def _param_names(exprs) -> list[str]:
    """The parameters the expressions read, in PARAM_ORDER, then the trigonometric constants."""
    names = {s.name for e in exprs for s in sp.sympify(e).free_symbols}
    return [n for n in PARAM_ORDER if n in names] + sorted(n for n in names if _is_constant(n))


def constant_name(kind: str, name: str) -> str:
    """MODE_CONTACT_LOADING_FWD, SURFACE_GAP, OUT_PSI_I: the index constants of the module."""
    return f"{kind}_{name.upper()}"


# --- one family: the modes that compute the same named quantities -----------------------
@dataclass
class _Variant:
    symbol: sp.Symbol
    expr: sp.Expr
    note: str
    keys: list


@dataclass
class _Family:
    """Cases computing the same quantities; their definitions by name, with one variant per
    distinct expression; economised and common-subexpression-eliminated."""

    keys: list
    order: list          # quantity names in computation order
    variants: dict       # name -> [_Variant]
    results: tuple       # result expressions (the same for every case of the family)
    replacements: list = None   # [(x_k, expr)] from sympy.cse
    constants: dict = None      # trigonometric constants used {symbol: definition}

    @classmethod
    def of(cls, cases: list[Case]) -> "_Family":
        order, variants = [], {}
        for case in cases:
            for d in case.kernel.definitions:
                if d.name not in variants:
                    order.append(d.name)
                    variants[d.name] = []
                same = next((v for v in variants[d.name] if v.expr == d.expr), None)
                if same is None:
                    variants[d.name].append(_Variant(d.symbol, d.expr, d.note, [case.key]))
                else:
                    same.keys.append(case.key)
        fam = cls([c.key for c in cases], order, variants, cases[0].kernel.results)
        fam._reduce()
        return fam

    def _all(self) -> list[_Variant]:
        return [v for name in self.order for v in self.variants[name]]

    def _reduce(self):
        """derive.trig's economy of sines and cosines, then common subexpressions."""
        items = self._all()
        exprs = [sp.sympify(v.expr) for v in items] + [sp.sympify(r) for r in self.results]
        exprs, constants = _economised(tuple(exprs))
        replacements, reduced = sp.cse(list(exprs), symbols=sp.numbered_symbols("x"), order="canonical")
        for v, e in zip(items, reduced):
            v.expr = e
        self.results = tuple(reduced[len(items):])
        self.replacements = list(replacements)
        self.constants = constants

    def expressions(self) -> list[sp.Expr]:
        return [e for _, e in self.replacements] + [v.expr for v in self._all()] + list(self.results)


@lru_cache(maxsize=None)
def _economised(exprs: tuple[sp.Expr, ...]) -> tuple[tuple[sp.Expr, ...], dict]:
    exprs, profile_constants = _profile_constants(exprs)
    out, constants = trig.economise(list(exprs))
    return tuple(out), dict(sorted({**constants, **profile_constants}.items(), key=lambda kv: kv[0].name))


def _families(cases: tuple[Case, ...]) -> list[_Family]:
    """Cases grouped by the names they define and their results, in order of first appearance."""
    groups: dict = {}
    for case in cases:
        signature = (tuple(d.name for d in case.kernel.definitions), tuple(sp.srepr(r) for r in case.kernel.results))
        groups.setdefault(signature, []).append(case)
    return [_Family.of(group) for group in groups.values()]


def _separate_families(f: Function) -> list[list[_Family]]:
    """Style "separate": per result, the families of the cases reduced to that result and the
    definitions it needs (so its common subexpressions, and arithmetic, are those of a function
    returning it alone)."""
    return [_families(tuple(Case(c.key, Kernel(c.kernel.definitions, (c.kernel.results[r],)).pruned())
                            for c in f.cases)) for r in range(len(f.results))]


# --- printing -----------------------------------------------------------------------------
class _Writer:
    """Prints one function: guards from dispatch keys, families, variants, results."""

    def __init__(self, f: Function, automaton: Automaton, params: list[str]):
        self.f, self.automaton, self.params = f, automaton, params
        self.printer = _Vector() if f.style == "numpy" else _Scalar()

    def _value_name(self, arg: str, value: int) -> str:
        if arg == "m":
            return constant_name("MODE", self.automaton.modes[value].name)
        if arg == "j":
            return constant_name("RESET", self.automaton.resets[value])
        return constant_name("SURFACE", self.automaton.surfaces[value])

    def guard(self, keys, context) -> str:
        """A condition on the dispatch arguments that holds for ``keys`` among ``context``."""
        dispatch = self.f.dispatch
        varying = [i for i in range(len(dispatch)) if len({k[i] for k in context}) > 1]
        if not varying:
            return "True"
        if len(varying) == 2:  # (m, s): by surface, then the modes where it is not all of them
            m_all = {k[0] for k in context}
            terms = []
            for s in sorted({k[1] for k in keys}):
                ms = sorted(k[0] for k in keys if k[1] == s)
                term = f"s == {self._value_name('s', s)}"
                if set(ms) != m_all:
                    term += " and (" + " or ".join(f"m == {self._value_name('m', m)}" for m in ms) + ")"
                terms.append(term)
            return terms[0] if len(terms) == 1 else " or ".join(f"({t})" if " and " in t else t for t in terms)
        i = varying[0]
        arg = dispatch[i]
        return " or ".join(f"{arg} == {self._value_name(arg, v)}" for v in sorted({k[i] for k in keys}))

    def family_lines(self, fam: _Family, bare: bool = False) -> list[str]:
        """The family's code; ``bare``: up to its results, without returning or storing them."""
        lines = [f"{n} = p[{self.params.index(n)}]" for n in _param_names(fam.expressions())]
        rep = dict(fam.replacements)
        index = {sym: i for i, (sym, _) in enumerate(fam.replacements)}
        keys_of = self._replacement_keys(fam, index)
        done: set = set()

        def deps(expr) -> list:
            """Replacements an expression needs, transitively, not yet printed, in CSE order."""
            found, stack = set(), [expr]
            while stack:
                for s in sp.sympify(stack.pop()).free_symbols:
                    if s in rep and s not in found and s not in done:
                        found.add(s)
                        stack.append(rep[s])
            return sorted(found, key=index.get)

        def emit(syms, out):
            for s in syms:
                out.append(f"{s} = {self.printer.doprint(rep[s])}")
                done.add(s)

        for name in fam.order:
            variants = fam.variants[name]
            if len(variants) == 1:
                emit(deps(variants[0].expr), lines)
                lines += self._definition(variants[0])
                continue
            shared = [s for v in variants for s in deps(v.expr) if not set(keys_of[s]) <= set(v.keys)]
            emit(sorted(set(shared), key=index.get), lines)
            for k, v in enumerate(variants):
                head = "else:" if k == len(variants) - 1 else \
                    f"{'if' if k == 0 else 'elif'} {self.guard(v.keys, fam.keys)}:"
                body: list[str] = []
                emit(deps(v.expr), body)
                lines += [head] + ["    " + x for x in body + self._definition(v)]
        for r in fam.results:
            emit(deps(r), lines)
        return lines if bare else lines + self._results(fam.results)

    def _replacement_keys(self, fam: _Family, index) -> dict:
        """The cases that use each replacement (directly or through later ones)."""
        keys = {sym: set() for sym, _ in fam.replacements}
        users = [(v.expr, set(v.keys)) for v in fam._all()] + [(r, set(fam.keys)) for r in fam.results]
        for expr, ks in users:
            for s in sp.sympify(expr).free_symbols:
                if s in keys:
                    keys[s] |= ks
        for sym, expr in reversed(fam.replacements):
            for s in sp.sympify(expr).free_symbols:
                if s in keys:
                    keys[s] |= keys[sym]
        return keys

    def _definition(self, v: _Variant) -> list[str]:
        note = f"  # {v.note}" if v.note else ""
        return [f"{v.symbol} = {self.printer.doprint(v.expr)}{note}"]

    def _results(self, results) -> list[str]:
        style = self.f.style
        code = [self.printer.doprint(r) for r in results]
        if style == "return":
            return [f"return {code[0]}"]
        if style == "fill":
            target = [constant_name("OUT", n) if self.f.name == "outputs" else
                      constant_name("SENS", sensitivity_parameter(n)) if self.f.name == "field_sensitivity"
                      else str(i) for i, n in enumerate(self.f.results)]
            return [f"out[{t}] = {c}" for t, c in zip(target, code)] + ["return"]
        if style == "numpy":
            arrays = ", ".join(a for a in self.f.args if a in _STATE)
            return [f"_zero = numpy.zeros(numpy.broadcast({arrays}).shape)",
                    "return (" + ", ".join(f"{c} + _zero" for c in code) + ")"]
        return ["return (" + ", ".join(code) + ")" if len(code) > 1 else f"return {code[0]}"]

    def _missing(self) -> list[str]:
        return ["out[:] = nan", "return"] if self.f.style in ("fill", "separate") else ["return nan"]

    def source(self, families: list[_Family], universe: set) -> str:
        return self._source([(fam.keys, self.family_lines(fam)) for fam in families], universe)

    def separate_source(self, parts: list[list[_Family]], universe: set) -> str:
        """Style "separate": per case, each result's family code in turn, each stored in out."""
        groups: dict = {}  # (family of each result, by position) -> the keys they compute together
        for key in [k for fam in parts[0] for k in fam.keys]:
            groups.setdefault(tuple(next(i for i, f in enumerate(fams) if key in f.keys) for fams in parts),
                              []).append(key)
        blocks = []
        for which, keys in groups.items():
            body = []
            for r, (fams, i) in enumerate(zip(parts, which)):
                body += self.family_lines(fams[i], bare=True) + [f"out[{r}] = {self.printer.doprint(fams[i].results[0])}"]
            blocks.append((keys, body + ["return"]))
        return self._source(blocks, universe)

    def _source(self, blocks: list[tuple[list, list[str]]], universe: set) -> str:
        """The function: docstring, then each block of code under a guard on its keys."""
        f = self.f
        text = [f.doc, "", "Arguments: " + ", ".join(f.args) + " (see the module docstring)."]
        text.append("Returns " + ("(written to out): " if f.style in ("fill", "separate") else ": ") + ", ".join(
            f"{n} ({RESULT_UNITS[n]})" for n in f.results) + ".")
        lines = [f"def {f.name}({', '.join(f.args)}):", textwrap.indent('"""' + "\n".join(text) + '\n"""', "    ")]
        if "cam" in f.args:
            lines.append("    Theta, Theta_dot, Theta_ddot = cam")
        remaining = set(universe)
        for k, (keys, body) in enumerate(blocks):
            covers = set(keys) == remaining
            if covers and k == len(blocks) - 1:
                lines += ["    " + x for x in body]
            else:
                lines += [f"    if {self.guard(keys, remaining)}:"] + ["        " + x for x in body]
            remaining -= set(keys)
        if remaining:
            lines += ["    " + x for x in self._missing()]
        return "\n".join(lines)


def _universe(f: Function, automaton: Automaton) -> set:
    if f.dispatch == ("m",):
        return {(m,) for m in range(len(automaton.modes))}
    if f.dispatch == ("j",):
        return {(j,) for j in range(len(automaton.resets))}
    if f.dispatch == ("m", "s"):
        return {(m, s) for m in range(len(automaton.modes)) for s in range(len(automaton.surfaces))}
    return {()}


# --- the real-arithmetic guard ---------------------------------------------------------------
class ComplexExpressionError(ValueError):
    """An expression to be written holds a complex number: generated code computes in float64,
    and a compiled kernel cannot even store a complex value in its real output."""


def _complex_numbers(expr: sp.Expr) -> set:
    """The complex numbers in ``expr``: SymPy's I (a complex Float is written with it too), or
    a number that is not an extended real (complex infinity)."""
    return {a for a in sp.sympify(expr).atoms() if a is sp.I or (a.is_number and a.is_extended_real is False)}


def _shorter(text: str, width: int) -> str:
    return text if len(text) <= width else text[:width - 3] + "..."


def refuse_complex(scene: str, kernel: str, name: str, expr: sp.Expr) -> None:
    """Raise :class:`ComplexExpressionError` naming the scene, the kernel and the expression
    (``name = expr``) if ``expr`` holds a complex number; return otherwise."""
    numbers = _complex_numbers(expr)
    if not numbers:
        return
    expr = sp.sympify(expr)
    terms = sorted((str(m) for m in expr.atoms(sp.Mul) if numbers & set(m.args)), key=len)
    where = f" in the term {_shorter(terms[0], 120)}" if terms else ""
    raise ComplexExpressionError(
        f"scene {scene}, kernel {kernel}: {name} = {_shorter(str(expr), 160)} holds the complex number "
        f"{', '.join(sorted(map(str, numbers)))}{where}; generated code computes in real arithmetic: "
        "make the law real for real arguments (docs/model-editing.md, 'Things to know')")


def _refuse_complex_kernels(mod: SceneModule, families: dict) -> None:
    """:func:`refuse_complex` on every expression a scene's kernels write: first the named
    quantities of each case (the clearest message), then what common subexpressions and the
    trigonometric economy made of them (the x_k and the constants pack() computes)."""
    slug, A = mod.spec.slug, mod.automaton
    for f in mod.functions + mod.variational:
        for case in f.cases:
            mode = f" (mode {A.modes[case.key[0]].name})" if f.dispatch[:1] == ("m",) else ""
            for d in case.kernel.definitions:
                refuse_complex(slug, f.name + mode, d.name, d.expr)
            for name, r in zip(f.results, case.kernel.results):
                refuse_complex(slug, f.name + mode, name, r)
        fams = families[f.name]
        for fam in (x for group in fams for x in group) if f.style == "separate" else fams:
            for expr in fam.expressions() + list(fam.constants.values()):
                refuse_complex(slug, f.name, "a common subexpression", expr)


# --- the module -----------------------------------------------------------------------------
def _hash(mod: SceneModule) -> str:
    h = hashlib.sha256(repr(sorted(mod.spec.derived_options().items())).encode())
    h.update(repr(mod.automaton).encode())
    for f in mod.functions + mod.variational:
        h.update(f"{f.name}{f.args}{f.results}{f.style}".encode())
        for case in f.cases:
            h.update(repr(case.key).encode())
            for d in case.kernel.definitions:
                h.update((d.name + sp.srepr(d.expr)).encode())
            for r in case.kernel.results:
                h.update(sp.srepr(r).encode())
    return h.hexdigest()[:16]


def _pack_code(params: list[str], constants: dict, profile: bool) -> tuple[str, list[str]]:
    derived = {**laws.CONSTANTS, **constants}
    inputs = [n for n in PARAM_ORDER if n in params and n not in {s.name for s in laws.CONSTANTS}]
    for sym, definition in derived.items():
        if sym.name in params:
            inputs += [n for n in _param_names([definition]) if n not in inputs]
    inputs = [n for n in PARAM_ORDER if n in inputs] + ([PROFILE_BLOCK] if profile else [])
    printer = _PackScalar()
    lines = ["def pack(values):",
             '    """Parameter vector p (laid out as PARAMS) from a mapping of the INPUTS names, SI units.',
             "",
             "    Computes the laws' constants (Y_e, Eq. 14) and the sines and cosines of parameter-only",
             "    angles (sin_<angle>, cos_<angle>: derive.trig) once, here, not in every kernel call."]
    if profile:
        lines += [f"    The cam's profile data (values[{PROFILE_BLOCK!r}], a flat array: see profile()) follows",
                  "    the named parameters, from p[PROFILE_OFFSET] on; the support function at the 0-state's",
                  "    angle (h<n>_at_<angle>, Eq. 5) is computed here once."]
    lines += ['    """']
    lines += [f"    {n} = float(values[{n!r}])" for n in inputs if n != PROFILE_BLOCK]
    if profile:
        lines.append(f"    {_BLOCK_LOCAL} = numpy.ascontiguousarray(values[{PROFILE_BLOCK!r}], dtype=float)")
    for sym, definition in derived.items():
        if sym.name in params:
            lines.append(f"    {sym.name} = {printer.doprint(definition)}")
    named = f"numpy.array([{', '.join(params)}], dtype=float)"
    lines.append(f"    return numpy.concatenate(({named}, {_BLOCK_LOCAL}))" if profile else f"    return {named}")
    return "\n".join(lines), inputs


def _index_constants(kind: str, names) -> list[str]:
    return [f"{constant_name(kind, n)} = {i}" for i, n in enumerate(names)]


def _named(table: str, kind: str, names) -> list[str]:
    """A table of names and its index constants (``MODES`` and ``MODE_<NAME> = i``)."""
    return [f"{table} = {tuple(names)!r}"] + _index_constants(kind, names)


def _automaton_code(A: Automaton) -> list[str]:
    mode = {m.name: constant_name("MODE", m.name) for m in A.modes}
    surf = {s: constant_name("SURFACE", s) for s in A.surfaces}

    def targets(ts) -> str:
        items = [f"({mode[t.mode]}, (" + "".join(f"({surf[c.surface]}, {c.sign}), " for c in t.conditions) + "))"
                 for t in ts]
        return "(" + ", ".join(items) + ",)"

    lines = ["# --- the hybrid automaton (derive.automaton) ---"] + _named("MODES", "MODE", [m.name for m in A.modes])
    lines += ["#: per mode: the follower touches the cam (Eq. 10) or flies (Eq. 15)",
              "CONTACT_OF_MODE = " + repr(tuple(m.contact for m in A.modes)),
              "#: per mode: the damping law of models D, E ('impact' t_a..t_b, 'viscous' after), or None",
              "PHASE_OF_MODE = " + repr(tuple(m.phase for m in A.modes)),
              "#: per mode: Coulomb friction, sliding forward ('fwd', v_r > 0), backward, or 'stick', or None",
              "SLIP_OF_MODE = " + repr(tuple(m.slip for m in A.modes))]
    if any(m.terminal for m in A.modes):  # (a module without it has none: camdyn.engine.tables)
        lines += ["#: per mode: the run ends on entering it (Outcome.OFF_FACE: the contact beyond the face's end)",
                  "TERMINAL_OF_MODE = " + repr(tuple(m.terminal for m in A.modes))]
    lines += _named("SURFACES", "SURFACE", A.surfaces)
    if A.timed:  # (a module without it has none: camdyn.engine.tables)
        lines += ["#: the surfaces of time alone (the cam angle's): the engine steps to their crossings",
                  "TIMED_SURFACES = (" + "".join(f"{surf[s]}, " for s in A.timed) + ")"]
    rate = [surf[A.rates[s]] if s in A.rates else "-1" for s in A.surfaces]
    lines += ["#: per surface: the surface that is its time derivative (-1: none); an excursion across",
              "#: zero and back inside one step is found where the derivative changes sign",
              "RATE_OF_SURFACE = (" + "".join(f"{r}, " for r in rate) + ")",
              "RESETS = " + repr(A.resets)] + _index_constants("RESET", A.resets)
    lines += ["#: the initial mode: the first candidate (mode, conditions) whose conditions (surface, sign)",
              "#: hold, i.e. sign * value >= 0 (looked ahead along the motion where a value is exactly 0)",
              "INITIAL = " + targets(A.initial),
              "#: (source mode, surface, direction, candidate targets, reset): leave the source where the",
              "#: surface's value crosses zero upward (+1: from < 0 to >= 0) or downward (-1), for the first",
              "#: target whose conditions hold",
              "TRANSITIONS = ("]
    lines += ["    (" + ", ".join(_transition_cells(tr, mode, surf, targets)) + ")," for tr in A.transitions]
    lines += [")"]
    if A.chatter is not None:
        lines += ["#: the rigid law's chatter end, a row like TRANSITIONS': where the impacts through the transition of",
                  "#: the same source, surface and direction converge geometrically, the engine takes this row's",
                  "#: targets and reset instead (camdyn.engine.rules.chatter_ends)",
                  "CHATTER = (" + ", ".join(_transition_cells(A.chatter, mode, surf, targets)) + ")"]
    return lines


def _transition_cells(tr, mode: dict, surf: dict, targets) -> list[str]:
    """One TRANSITIONS row's cells, in the vocabulary's TRANSITION order."""
    cells = {"source": mode[tr.source], "surface": surf[tr.surface], "direction": f"{tr.direction:+d}",
             "targets": targets(tr.targets), "reset": constant_name("RESET", tr.reset)}
    return [cells[column] for column in TRANSITION]


def module_name(spec: SceneSpec) -> str:
    """The scene's generated module: the kernels a run needs."""
    return "scene_" + spec.slug


def variational_name(spec: SceneSpec) -> str:
    """The scene's companion module: its variational kernels (``SceneModule.variational``)."""
    return "variational_" + spec.slug


def _arguments_doc(spec: SceneSpec, p: str) -> list[str]:
    args = {**ARGS, "p": p}
    return ["Arguments of every kernel, in this order where it takes them:"] + [
        f"    {a}: {args[a]}" for a in ("m", "s", "t", *state_names(spec.follower), "p", "cam", "out")
        if a != "cam" or spec.motion == "user"]


def _paragraph(text: str) -> list[str]:
    return textwrap.wrap(text, 95, break_long_words=False, break_on_hyphens=False) + [""]


def _module_doc(spec: SceneSpec, A: Automaton, companion: str | None) -> list[str]:
    variational = (f"The variational kernels (surface_gradient, field_sensitivity) are in the companion module "
                   f"{companion} (VARIATIONAL), which only the tangent dynamics and the continuation import."
                   if companion else "The scene has no variational kernels (VARIATIONAL is None).")
    return [f'"""Generated kernels of the scene {spec.slug!r}.', "",
            "Scene: " + ", ".join(f"{k}={v!r}" for k, v in spec.derived_options().items()) + ".", "",
            "The hybrid automaton is data (MODES, SURFACES, INITIAL, TRANSITIONS, RESETS; the rules that",
            "read it are camdyn.derive.automaton's docstring) and the kernels compute, per mode, the",
            "named quantities of the derivation once each.", ""] + _paragraph(variational) + _arguments_doc(
            spec, ARGS["p"]) + [
            "Surfaces: " + "; ".join(f"{s} ({SURFACES[s][0]})" for s in A.surfaces) + "." if A.surfaces else
            "No switching surfaces (sliding contact throughout).", '"""']


def _variational_doc(spec: SceneSpec) -> list[str]:
    scene = module_name(spec)
    text = (f"The kernels of the scene that only the tangent dynamics (saltation matrices) and the parameter "
            f"continuation use, apart from the scene's module {scene}, which a run imports alone. They read "
            "that module's parameter vector and take the indices of its modes and surfaces: PARAMS, MODES and "
            "SURFACES here are copies of its own.")
    return [f'"""Generated variational kernels of the scene {spec.slug!r}.', ""] + _paragraph(text) + _arguments_doc(
        spec, "parameter vector, laid out as PARAMS (SI units); build it with the scene module's pack()") + ['"""']


def _flat(families: dict, functions) -> list[list[_Family]]:
    """The family lists of every function, a "separate" one's per result."""
    return [fams for f in functions
            for fams in (families[f.name] if f.style == "separate" else [families[f.name]])]


@dataclass
class _Layout:
    """What a scene's two modules share: the kernels' families, and the parameter vector p (its
    names, and the trigonometric constants pack() computes) that covers both modules' kernels."""

    mod: SceneModule
    families: dict       # function name -> [_Family] (style "separate": per result, [[_Family]])
    params: list
    constants: dict

    @classmethod
    def of(cls, spec: SceneSpec) -> "_Layout":
        mod = build(spec)
        functions = mod.functions + mod.variational
        families = {f.name: _separate_families(f) if f.style == "separate" else _families(f.cases)
                    for f in functions}
        constants: dict = {}
        exprs: list = []
        for fams in _flat(families, functions):
            for fam in fams:
                constants.update(fam.constants)
                exprs += fam.expressions()
        _refuse_complex_kernels(mod, families)
        constants = dict(sorted(constants.items(), key=lambda kv: kv[0].name))
        return cls(mod, families, _param_names(exprs), constants)

    def header(self) -> str:
        return "\n".join(["# Generated by camdyn.derive -- DO NOT EDIT. Regenerate with: python -m camdyn.derive",
                          f"# scene: {self.mod.spec.slug}", f"# symbolic-input hash: {_hash(self.mod)}",
                          f"# sympy: {sp.__version__}"])

    def kernels(self, functions) -> list[str]:
        A = self.mod.automaton
        return [_Writer(f, A, self.params).separate_source(self.families[f.name], _universe(f, A))
                if f.style == "separate" else _Writer(f, A, self.params).source(self.families[f.name], _universe(f, A))
                for f in functions]


def _module_text(header: str, doc: list[str], imports: list[str], data: list[str], code: list[str]) -> str:
    parts = [header, "\n".join(doc), "\n".join(imports)]
    return "\n\n\n".join(parts) + "\n\n" + "\n".join(data) + "\n\n\n" + "\n\n\n".join(code) + "\n"


_MATH = "from math import *  # noqa: F401,F403  (sin, cos, sqrt, ... on floats)"


def _profile_parts(L: "_Layout") -> tuple[list[str], list[str], list[str]]:
    """A scene on a cam other than the circle: the imports, data and code its modules add for
    the profile evaluator (derive.profile_code); nothing for the paper's circle."""
    family = L.mod.spec.profile
    if family == ECCENTRIC:
        return [], [], []
    data = ["# --- the cam's profile (derive.profile_code): its data follows PARAMS in p ---",
            f"PROFILE = {family!r}", f"PROFILE_OFFSET = {len(L.params)}"]
    return ["import numba"], data, [evaluator_source(family)]


def _scene_source(L: _Layout) -> str:
    """The text of a scene's module (``scene_<slug>``)."""
    spec, A = L.mod.spec, L.mod.automaton
    companion = variational_name(spec) if L.mod.variational else None
    pack, inputs = _pack_code(L.params, L.constants, spec.profile != ECCENTRIC)
    extra_imports, extra_data, extra_code = _profile_parts(L)
    data = ["SCENE = " + repr(spec.derived_options()), f"SLUG = {spec.slug!r}",
            "#: the companion module of the variational kernels, beside this one (None: the scene has none)",
            f"VARIATIONAL = {companion!r}", "PARAMS = " + repr(tuple(L.params)), "INPUTS = " + repr(tuple(inputs)),
            "UNITS = " + repr({n: UNITS.get(n, _constant_unit(n) if _is_constant(n) else None)
                               for n in L.params + [i for i in inputs if i not in L.params]})]
    data += _automaton_code(A)
    outputs = tuple(outputs_of(spec.follower))
    data += ["# --- output quantities (camdyn.vocabulary.OUTPUTS) ---", "OUTPUTS = " + repr(outputs)]
    data += _index_constants("OUT", outputs) + extra_data
    return _module_text(L.header(), _module_doc(spec, A, companion), [_MATH, "", "import numpy"] + extra_imports,
                        data, extra_code + [pack] + L.kernels(L.mod.functions))


def _variational_source(L: _Layout) -> str:
    """The text of a scene's companion module (``variational_<slug>``)."""
    spec, A = L.mod.spec, L.mod.automaton
    data = [f"SLUG = {spec.slug!r}", "PARAMS = " + repr(tuple(L.params))]
    data += _named("MODES", "MODE", [m.name for m in A.modes]) + _named("SURFACES", "SURFACE", A.surfaces)
    if len(A.resets) > 1:  # reset_jacobian dispatches on them
        data += _named("RESETS", "RESET", A.resets)
    sensitivity = next((f.results for f in L.mod.variational if f.name == "field_sensitivity"), None)
    if sensitivity is not None:
        names = tuple(sensitivity_parameter(n) for n in sensitivity)
        data += ["# --- continuation parameters of field_sensitivity (vocabulary.CONTINUATION_PARAMETERS) ---",
                 "SENSITIVITY = " + repr(names)] + _index_constants("SENS", names)
    extra_imports, extra_data, extra_code = _profile_parts(L)
    imports = [_MATH, ""] + extra_imports if extra_imports else [_MATH]
    return _module_text(L.header(), _variational_doc(spec), imports, data + extra_data,
                        extra_code + L.kernels(L.mod.variational))


def sources(spec: SceneSpec) -> dict[str, str]:
    """File name -> text of a scene's generated modules: ``scene_<slug>.py`` and, for a scene
    with variational kernels, its companion ``variational_<slug>.py``."""
    L = _Layout.of(spec)
    files = {module_name(spec) + ".py": _scene_source(L)}
    if L.mod.variational:
        files[variational_name(spec) + ".py"] = _variational_source(L)
    return files


def module_source(spec: SceneSpec) -> str:
    """The complete text of a scene's generated module (without its companion: :func:`sources`)."""
    return sources(spec)[module_name(spec) + ".py"]
