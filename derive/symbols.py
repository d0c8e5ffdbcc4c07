"""Symbols of the model, by the paper's notation, with units and meaning.

The constants are declared once, in :mod:`camdyn.vocabulary.parameters` (name, unit, meaning,
valid range, shared with the runtime's :class:`camdyn.Rig`); here each becomes a SymPy
symbol with the assumptions its range gives (positive lengths, real angles), and a
module-level name so that the derivation reads like the paper.
The state and the cam motion are functions of time (``dynamicsymbols``);
:func:`to_plain` swaps them for plain symbols before code generation.

Units are SI: metres, radians, seconds, newtons, pascals.
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from sympy.physics.vector import dynamicsymbols

from camdyn.vocabulary import names as declared_names, parameters as declared

t = dynamicsymbols._t  # the time symbol dynamicsymbols differentiate with


@dataclass(frozen=True)
class Param:
    """One model constant: its symbol, unit and meaning (paper section)."""

    symbol: sp.Symbol
    unit: str
    meaning: str

    @property
    def name(self) -> str:
        return self.symbol.name


def _param(row) -> Param:
    """The symbol of a declared constant (:mod:`camdyn.vocabulary.parameters`), real, with the
    sign its declaration gives."""
    assumptions = {row.sign: True} if row.sign else {}
    return Param(sp.Symbol(row.name, real=True, **assumptions), row.unit, row.description)


# --- rig parameters (Section 3, Fig. 1), equilibrium results, cam-motion constants ------
_RIG = [_param(row) for row in declared.RIG_PARAMETERS]
_DERIVED = [_param(row) for row in declared.EQUILIBRIUM_QUANTITIES]
_CAM = [_param(row) for row in declared.CAM_CONSTANTS]

PARAMS: dict[str, Param] = {p.name: p for p in _RIG + _DERIVED + _CAM}
RIG_NAMES = tuple(p.name for p in _RIG)
DERIVED_NAMES = tuple(p.name for p in _DERIVED)
CAM_NAMES = tuple(p.name for p in _CAM)

# module-level names, so the derivation reads like the paper
r_c = PARAMS["r_c"].symbol
e = PARAMS["e"].symbol
w_b = PARAMS["w_b"].symbol
chi0 = PARAMS["chi0"].symbol
alpha0 = PARAMS["alpha0"].symbol
theta0 = PARAMS["theta0"].symbol
d_x = PARAMS["d_x"].symbol
d_y = PARAMS["d_y"].symbol
L_us = PARAMS["L_us"].symbol
k_s = PARAMS["k_s"].symbol
I_Pb = PARAMS["I_Pb"].symbol
Y_c = PARAMS["Y_c"].symbol
Y_b = PARAMS["Y_b"].symbol
nu_c = PARAMS["nu_c"].symbol
nu_b = PARAMS["nu_b"].symbol
l_lambda = PARAMS["l_lambda"].symbol
mu_m = PARAMS["mu_m"].symbol
s = PARAMS["s"].symbol
zeta_A = PARAMS["zeta_A"].symbol
beta_B = PARAMS["beta_B"].symbol
beta_C = PARAMS["beta_C"].symbol
zeta_D = PARAMS["zeta_D"].symbol
beta_D = PARAMS["beta_D"].symbol
zeta_E = PARAMS["zeta_E"].symbol
beta_E = PARAMS["beta_E"].symbol
m_f = PARAMS["m_f"].symbol
gamma = PARAMS["gamma"].symbol
offset = PARAMS["offset"].symbol
F_p = PARAMS["F_p"].symbol
xi = PARAMS["xi"].symbol
face_start = PARAMS["face_start"].symbol
face_end = PARAMS["face_end"].symbol
alpha_star = PARAMS["alpha_star"].symbol
y_star = PARAMS["y_star"].symbol
chi_star = PARAMS["chi_star"].symbol
vartheta = PARAMS["vartheta"].symbol
Omega_c = PARAMS["Omega_c"].symbol
Theta_p = PARAMS["Theta_p"].symbol
omega_c = PARAMS["omega_c"].symbol

# --- time functions: the generalized coordinate and the motion input ----------------
alpha, Theta = dynamicsymbols("alpha Theta", real=True)
#: the translating follower's coordinate: its face's distance from E along the guide (derive.translating)
y = dynamicsymbols("y", real=True)

# --- plain symbols that stand for the state and the cam in generated code -----------
t_s = sp.Symbol("t", real=True)  # plain, real time (dynamicsymbols._t has no assumptions)
alpha_s = sp.Symbol("alpha", real=True)
alpha_dot = sp.Symbol("alpha_dot", real=True)
Theta_s = sp.Symbol("Theta", real=True)
Theta_dot = sp.Symbol("Theta_dot", real=True)
Theta_ddot = sp.Symbol("Theta_ddot", real=True)
y_s = sp.Symbol("y", real=True)
y_dot = sp.Symbol("y_dot", real=True)


@dataclass(frozen=True)
class Coordinate:
    """A follower's generalized coordinate: its name and unit (camdyn.vocabulary.COORDINATES),
    its function of time in the derivation, and the plain symbols of it and its rate in generated
    code (the kernels' arguments); ``acceleration`` is the named quantity the field computes."""

    name: str
    unit: str
    function: sp.Expr
    plain: sp.Symbol
    rate: sp.Symbol

    @property
    def acceleration(self) -> sp.Symbol:
        return sp.Symbol(f"{self.name}_ddot", real=True)


#: the coordinate of each follower type (the scene option ``follower``; its name and unit are the
#: vocabulary's, camdyn.vocabulary.COORDINATES)
_TIME_FUNCTIONS = {"alpha": (alpha, alpha_s, alpha_dot), "y": (y, y_s, y_dot)}
COORDINATES = {follower: Coordinate(name, unit, *_TIME_FUNCTIONS[name])
               for follower, (name, unit, _) in declared_names.COORDINATES.items()}


def to_plain(expr: sp.Expr) -> sp.Expr:
    """Replace alpha(t) (or the translating follower's y(t)), Theta(t) and their derivatives by plain
    symbols.

    Higher derivatives first, so that d/dt alpha(t) is not mangled into
    d/dt alpha_s.  alpha_ddot never appears: the equations of motion are
    solved for it.
    """
    return sp.sympify(expr).subs(
        {
            Theta.diff(t, 2): Theta_ddot,
            Theta.diff(t): Theta_dot,
            alpha.diff(t): alpha_dot,
            y.diff(t): y_dot,
        }
    ).subs({Theta: Theta_s, alpha: alpha_s, y: y_s}).subs(t, t_s)
