"""Named quantities: a kernel as an ordered list of definitions, the way the paper writes it.

A :class:`Definition` names one physical quantity (``psi_i``, ``F_n``, ``alpha_ddot``...) with
an expression in the state (t, alpha, alpha_dot), the parameters, and quantities defined
before it.  Generated code keeps those names, so a kernel reads like Eqs. 6-12 one after the
other, and each quantity is computed once.

:func:`flatten` substitutes every definition into an expression (the fully expanded form the
symbolic tests and the lambdify oracle compare against); :func:`derivatives` differentiates
through the definitions by the chain rule (forward mode), giving named derivatives such as
``dF_n_dalpha`` for the Jacobians.
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp


@dataclass(frozen=True)
class Definition:
    """``symbol = expr``; ``note`` says what it is (with the paper's equation number)."""

    symbol: sp.Symbol
    expr: sp.Expr
    note: str = ""

    @property
    def name(self) -> str:
        return self.symbol.name


def quantity(name: str) -> sp.Symbol:
    """The symbol of a named quantity (real, as every quantity of the model)."""
    return sp.Symbol(name, real=True)


def substitutions(definitions: tuple[Definition, ...]) -> dict[sp.Symbol, sp.Expr]:
    """{symbol: flattened expression} for every definition, in order."""
    flat: dict[sp.Symbol, sp.Expr] = {}
    for d in definitions:
        flat[d.symbol] = sp.sympify(d.expr).xreplace(flat)
    return flat


def flatten(expr: sp.Expr, definitions: tuple[Definition, ...]) -> sp.Expr:
    """``expr`` with every named quantity replaced by its definition, recursively."""
    return sp.sympify(expr).xreplace(substitutions(definitions))


def derivatives(definitions: tuple[Definition, ...], wrt: sp.Symbol) -> tuple[Definition, ...]:
    """Named total derivatives d<q>/d<wrt> of the definitions (chain rule through earlier
    quantities); identically zero ones are left out and count as 0 where they are used."""
    out: list[Definition] = []
    known: dict[sp.Symbol, sp.Symbol] = {}
    for d in definitions:
        expr = sp.sympify(d.expr)
        total = expr.diff(wrt)
        for q, dq in known.items():
            if expr.has(q):
                total += expr.diff(q) * dq
        if total != 0:
            symbol = quantity(f"d{d.name}_d{wrt.name}")
            known[d.symbol] = symbol
            out.append(Definition(symbol, total, f"d({d.name})/d({wrt.name})"))
    return tuple(out)


def derivative_symbol(name: str, wrt: sp.Symbol, derived: tuple[Definition, ...]) -> sp.Expr:
    """The symbol of d<name>/d<wrt> among ``derived``, or 0 where it vanishes."""
    target = f"d{name}_d{wrt.name}"
    return next((d.symbol for d in derived if d.name == target), sp.Integer(0))


def used(definitions: tuple[Definition, ...], results: tuple[sp.Expr, ...]) -> tuple[Definition, ...]:
    """The definitions the results need, directly or through other definitions, in order."""
    needed = set().union(*(sp.sympify(r).free_symbols for r in results)) if results else set()
    keep = []
    for d in reversed(definitions):
        if d.symbol in needed:
            keep.append(d)
            needed |= sp.sympify(d.expr).free_symbols
    return tuple(reversed(keep))
