"""Symbols of the model, by the paper's notation, with units and meaning.

Every symbol used by the derivation is declared here once, with SymPy
assumptions that reflect its physical range (positive lengths, real angles).
The state and the cam motion are functions of time (``dynamicsymbols``);
:func:`to_plain` swaps them for plain symbols before code generation.

Units are SI: metres, radians, seconds, newtons, pascals.
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from sympy.physics.vector import dynamicsymbols

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


def _param(name: str, unit: str, meaning: str, **assumptions) -> Param:
    return Param(sp.Symbol(name, real=True, **assumptions), unit, meaning)


# --- rig parameters (Section 3, Fig. 1) --------------------------------------------
_RIG = [
    _param("r_c", "m", "cam radius", positive=True),
    _param("e", "m", "cam eccentricity |E G_c|", nonnegative=True),
    _param("w_b", "m", "follower bar width", positive=True),
    _param("chi0", "m", "P to contact along the bar in the 0-state", positive=True),
    _param("alpha0", "rad", "follower angle in the 0-state"),
    _param("theta0", "rad", "cam angle in the 0-state (Theta(0))"),
    _param("d_x", "m", "horizontal distance from P to the follower spring", positive=True),
    _param("d_y", "m", "height of the pivot P above ground"),
    _param("L_us", "m", "free length of the follower spring", positive=True),
    _param("k_s", "N/m", "follower spring stiffness", positive=True),
    _param("I_Pb", "kg m^2", "follower moment of inertia about P", positive=True),
    _param("Y_c", "Pa", "Young's modulus of the cam", positive=True),
    _param("Y_b", "Pa", "Young's modulus of the follower", positive=True),
    _param("nu_c", "1", "Poisson's ratio of the cam", nonnegative=True),
    _param("nu_b", "1", "Poisson's ratio of the follower", nonnegative=True),
    _param("l_lambda", "m", "line-contact length (Eq. 13)", positive=True),
    _param("mu_m", "1", "friction coefficient (models I and II)", nonnegative=True),
    _param("s", "s/m", "smoothing factor of friction model II", positive=True),
    _param("zeta_A", "1", "viscous damping ratio, model A (Eq. 24)", nonnegative=True),
    _param("beta_B", "s/m", "impact damping factor, model B (Eq. 25)", nonnegative=True),
    _param("beta_C", "N s/m^1.25", "impact damping factor, model C (Eq. 26)", nonnegative=True),
    _param("zeta_D", "1", "viscous damping ratio, model D (Eq. 27b)", nonnegative=True),
    _param("beta_D", "s/m", "impact damping factor, model D (Eq. 27a)", nonnegative=True),
    _param("zeta_E", "1", "viscous damping ratio, model E (Eq. 28b)", nonnegative=True),
    _param("beta_E", "N s/m^1.25", "impact damping factor, model E (Eq. 28a)", nonnegative=True),
]

# --- quantities the runtime computes from the rig before a run ----------------------
_DERIVED = [
    _param("alpha_star", "rad", "static equilibrium angle alpha* (Eqs. 16-18)"),
    _param("chi_star", "m", "chi* = chi0 - psi_j* at static equilibrium", positive=True),
    _param("vartheta", "rad/s", "undamped linearized natural frequency (Eq. 23, misprint 4)",
           positive=True),
]

# --- cam-motion constants ----------------------------------------------------------
_CAM = [
    _param("Omega_c", "rad/s", "constant cam speed (>0 counter-clockwise, de-energizing)"),
    _param("Theta_p", "rad", "peak-to-peak cam angle of the oscillating cam (Section 7.2)"),
    _param("omega_c", "rad/s", "frequency of the oscillating cam (Section 7.2)"),
]

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
alpha_star = PARAMS["alpha_star"].symbol
chi_star = PARAMS["chi_star"].symbol
vartheta = PARAMS["vartheta"].symbol
Omega_c = PARAMS["Omega_c"].symbol
Theta_p = PARAMS["Theta_p"].symbol
omega_c = PARAMS["omega_c"].symbol

# --- time functions: the generalized coordinate and the motion input ----------------
alpha, Theta = dynamicsymbols("alpha Theta", real=True)

# --- plain symbols that stand for the state and the cam in generated code -----------
t_s = sp.Symbol("t", real=True)  # plain, real time (dynamicsymbols._t has no assumptions)
alpha_s = sp.Symbol("alpha", real=True)
alpha_dot = sp.Symbol("alpha_dot", real=True)
Theta_s = sp.Symbol("Theta", real=True)
Theta_dot = sp.Symbol("Theta_dot", real=True)
Theta_ddot = sp.Symbol("Theta_ddot", real=True)


def to_plain(expr: sp.Expr) -> sp.Expr:
    """Replace alpha(t), Theta(t) and their derivatives by plain symbols.

    Higher derivatives first, so that d/dt alpha(t) is not mangled into
    d/dt alpha_s.  alpha_ddot never appears: the equations of motion are
    solved for it.
    """
    return sp.sympify(expr).subs(
        {
            Theta.diff(t, 2): Theta_ddot,
            Theta.diff(t): Theta_dot,
            alpha.diff(t): alpha_dot,
        }
    ).subs({Theta: Theta_s, alpha: alpha_s}).subs(t, t_s)
