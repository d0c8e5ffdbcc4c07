"""The paper's PRINTED equations, transcribed by hand (Sundar, Dreyer & Singh, JSV 332 (2013) 4280-4295).

This is the only place in the test suite where printed formulas live.  They are
transcribed from the printed paper (restated in ``docs/equations.md``), *including*
their misprints, so the tests can show where the derivation (``camdyn.derive``)
agrees with the paper and where it departs from it on purpose (the numbered
misprints of ``docs/misprints.md``).  Nothing here is
imported from the derivation except its symbols, so a transcription error cannot
hide a derivation error.

Conventions: Eqs. 5-12, 15 and the printed v_r use the time functions
``S.alpha(t)``, ``S.Theta(t)``; the static and linearized equations (16-18, 36-38)
use the plain symbols ``S.alpha_star``, ``S.Theta_s``, ``S.chi_star``.
"""
from __future__ import annotations

import sympy as sp

from camdyn.derive import symbols as S

a, Th, t = S.alpha, S.Theta, S.t
a_dot, Th_dot = a.diff(t), Th.diff(t)
R = S.r_c + S.w_b / 2            # the paper's recurring (r_c + w_b/2) = (r_c + 0.5 w_b)

#: The equivalent modulus as the laws use it: the same SymPy symbol as camdyn.derive.laws.Y_e
#: (name and assumptions), declared here so that this file depends on the symbols only.
Y_e = sp.Symbol("Y_e", positive=True)

#: Constant symbols of Section 8: the constant damping coefficient and the SIGNED friction coefficient.
c_lambda = sp.Symbol("c_lambda", real=True)
mu = sp.Symbol("mu", real=True)

#: psi_i*, psi_j* as unknowns of Eqs. 16-18.
psi_i_star, psi_j_star = sp.symbols("psi_i_star psi_j_star", real=True)


# --- Section 3.1: geometry -----------------------------------------------------------------

# Eq. 5: the constant vector P->E, components along e_x and e_y
PE_x = S.chi0 * sp.cos(S.alpha0) + R * sp.sin(S.alpha0) + S.e * sp.cos(S.theta0)     # Eq. 5, e_x
PE_y = -S.chi0 * sp.sin(S.alpha0) + R * sp.cos(S.alpha0) + S.e * sp.sin(S.theta0)    # Eq. 5, e_y

# Eq. 6: psi_i(t)
psi_i = (S.chi0 * sp.sin(a - S.alpha0) + R * (sp.cos(a - S.alpha0) - 1)
         + S.e * (sp.sin(a + S.theta0) - sp.sin(a + Th)))

# Eq. 7: psi_j(t)
psi_j = (S.chi0 * (1 - sp.cos(a - S.alpha0)) + R * sp.sin(a - S.alpha0)
         - S.e * (sp.cos(a + S.theta0) - sp.cos(a + Th)))

# Eq. 8: psi_i_dot(t)
psi_i_dot = (S.chi0 * sp.cos(a - S.alpha0) * a_dot - R * sp.sin(a - S.alpha0) * a_dot
             + S.e * (sp.cos(a + S.theta0) * a_dot - sp.cos(a + Th) * (a_dot + Th_dot)))

# Eq. 9: psi_j_dot(t)
psi_j_dot = (S.chi0 * sp.sin(a - S.alpha0) * a_dot + R * sp.cos(a - S.alpha0) * a_dot
             + S.e * (sp.sin(a + S.theta0) * a_dot - sp.sin(a + Th) * (a_dot + Th_dot)))

# chi(t) = chi0 - psi_j(t)   (text after Eq. 4)
chi = S.chi0 - psi_j


# --- Section 3.2: forces and equations of motion --------------------------------------------

def eq10_moment(F_s, F_n, F_f, chi_):
    """Eq. 10, right-hand side: I_Pb alpha_ddot = -F_s d_x + F_n chi - 0.5 F_f w_b."""
    return -F_s * S.d_x + F_n * chi_ - sp.Rational(1, 2) * F_f * S.w_b


def eq11_spring_force(angle=a):
    """Eq. 11: F_s = k_s [L_us - d_y + d_x tan(alpha) - 0.5 w_b sec(alpha)]."""
    return S.k_s * (S.L_us - S.d_y + S.d_x * sp.tan(angle) - sp.Rational(1, 2) * S.w_b * sp.sec(angle))


def eq12_normal_force(k_lambda, c_lam, psi, psi_dot):
    """Eq. 12: F_n = -k_lambda(psi_i) psi_i - c_lambda(psi_i) psi_i_dot."""
    return -k_lambda * psi - c_lam * psi_dot


def eq13_line_stiffness(Y=Y_e):
    """Eq. 13: k_lambda = (pi/4) Y_e l_lambda (line contact)."""
    return sp.pi / 4 * Y * S.l_lambda


# Eq. 14: Y_e = [(1 - nu_c^2)/Y_c + (1 - nu_b^2)/Y_b]^-1
Y_e_eq14 = ((1 - S.nu_c**2) / S.Y_c + (1 - S.nu_b**2) / S.Y_b) ** -1


def eq15_moment(F_s):
    """Eq. 15 (no contact), right-hand side: I_Pb alpha_ddot = -F_s d_x (misprint 3: the spring stays)."""
    return -F_s * S.d_x


def v_r_printed():
    """Section 3.4 text: v_r = psi_j_dot - (r_c + e sin(alpha + Theta)) (alpha_dot + Theta_dot) (misprint 8)."""
    return psi_j_dot - (S.r_c + S.e * sp.sin(a + Th)) * (a_dot + Th_dot)


def eq34_point_stiffness(psi, Y=Y_e):
    """Eq. 34: k_lambda = (4/3) Y_e (r_c |psi_i|)^0.5 (point contact)."""
    return sp.Rational(4, 3) * Y * sp.sqrt(S.r_c * sp.Abs(psi))


def eq35_bearing_force(F_f, F_n, angle=a):
    """Eq. 35: N_x = F_f cos(alpha) + F_n sin(alpha)."""
    return F_f * sp.cos(angle) + F_n * sp.sin(angle)


# --- Section 3.3: static equilibrium ---------------------------------------------------------
As = S.alpha_star

# Eq. 16 (left-hand side, = 0)
eq16 = S.chi0 * sp.sin(As - S.alpha0) + R * sp.cos(As - S.alpha0) - R - psi_i_star
# Eq. 17 (left-hand side, = 0)
eq17 = S.chi0 * (1 - sp.cos(As - S.alpha0)) + R * sp.sin(As - S.alpha0) - psi_j_star
# Eq. 18 (left-hand side, = 0), AS PRINTED: the contact term has a + sign (misprint 1)
eq18 = (-S.k_s * S.d_x * (S.L_us - S.d_y + S.d_x * sp.tan(As) - sp.Rational(1, 2) * S.w_b * sp.sec(As))
        + sp.pi / 4 * Y_e * S.l_lambda * psi_i_star * (S.chi0 - psi_j_star))


def eq23_vartheta(J: sp.Matrix):
    """Eq. 23 AS PRINTED: vartheta = |Im(Eig[J])|^0.5 (misprint 4), for each eigenvalue of J."""
    return [sp.Abs(sp.im(lam)) ** sp.Rational(1, 2) for lam in J.eigenvals(multiple=True)]


# --- Section 3.4: damping ------------------------------------------------------------------

def eq24_viscous(zeta):
    """Eqs. 24, 27b, 28b: c = 2 zeta vartheta I_Pb / chi*^2."""
    return 2 * zeta * S.vartheta * S.I_Pb / S.chi_star**2


def eq25_impact_k(beta, k_lambda, psi):
    """Eqs. 25, 27a AS PRINTED: c = beta k_lambda psi_i (negative in contact: misprint 2)."""
    return beta * k_lambda * psi


def eq26_impact_power(beta, psi):
    """Eqs. 26, 28a: c = beta |psi_i|^0.25."""
    return beta * sp.Abs(psi) ** sp.Rational(1, 4)


# --- Section 4-5: rigid contact angle, energy balance ----------------------------------------

def eq29_alpha_i(X, Y):
    """Eq. 29 AS PRINTED, X, Y the components of P->G_c (misprint 10: arccos loses the sign).

    alpha_i = arccos( ([X^4 + X^2 Y^2 - X^2 (r_c + 0.5 w_b)^2]^0.5 + Y (r_c + 0.5 w_b)) / (X^2 + Y^2) )
    """
    return sp.acos((sp.sqrt(X**4 + X**2 * Y**2 - X**2 * R**2) + Y * R) / (X**2 + Y**2))


def eq32_kinetic(xi):
    """Eqs. 31-32: T_b = 0.5 I_Pb ((1 + xi) e Omega_c / chi*)^2."""
    return sp.Rational(1, 2) * S.I_Pb * ((1 + xi) * S.e * S.Omega_c / S.chi_star) ** 2


def eq33_integrand(angle):
    """Eq. 33, the integrand of Delta V:
    k_s [L_us - d_y + d_x tan - 0.5 w_b sec] [d_x sec^2 - 0.5 w_b sec tan]."""
    return (S.k_s * (S.L_us - S.d_y + S.d_x * sp.tan(angle) - sp.Rational(1, 2) * S.w_b * sp.sec(angle))
            * (S.d_x * sp.sec(angle) ** 2 - sp.Rational(1, 2) * S.w_b * sp.sec(angle) * sp.tan(angle)))


# --- Section 8: the linearized model, Eqs. 37-38 AS PRINTED -----------------------------------
_k_line = eq13_line_stiffness()
_arm_star = S.chi_star - sp.Rational(1, 2) * mu * S.w_b
_slope = (S.chi0 * sp.cos(As - S.alpha0) - (S.r_c + sp.Rational(1, 2) * S.w_b) * sp.sin(As - S.alpha0)
          + S.e * sp.cos(As + S.theta0))

# Eq. 38a: C_l = c_lambda (chi* - 0.5 mu w_b) [chi0 cos(a*-a0) - (r_c + 0.5 w_b) sin(a*-a0) + e cos(a*+Theta0)]
C_l = c_lambda * _arm_star * _slope

# Eq. 38b: K_l = k_s d_x [2 d_x - w_b sin a*] / (1 + cos 2a*)
#               + k_lambda (chi* - 0.5 mu w_b) [chi0 cos(a*-a0) + e cos(a*+Theta0) - (r_c + 0.5 w_b) sin(a*-a0)]
K_l = (S.k_s * S.d_x * (2 * S.d_x - S.w_b * sp.sin(As)) / (1 + sp.cos(2 * As))
       + _k_line * _arm_star * (S.chi0 * sp.cos(As - S.alpha0) + S.e * sp.cos(As + S.theta0)
                                - (S.r_c + sp.Rational(1, 2) * S.w_b) * sp.sin(As - S.alpha0)))


def F_l(arm_chi=S.chi0):
    """Eq. 38c: F_l(t), AS PRINTED with ``arm_chi = chi0`` (misprint 9: K_l and C_l use chi*).

    F_l = -k_s d_x [L_us - d_y + (d_x sin 2a* - w_b cos a*) / (1 + cos 2a*)]
          - k_lambda (chi0 - 0.5 mu w_b) [(r_c + 0.5 w_b)(cos(a*-a0) - 1) + chi0 sin(a*-a0)
                                          + e (sin(a*+Theta0) - sin(a*+Theta(t)))]
    The extracted text shows "e sin(a*+Theta0) - sin(a*+Theta(t))" across a line break inside a
    large parenthesis; the factor e on both sines is required by units and is printed so in Eq. 36.
    Only the moment arm (chi0 - 0.5 mu w_b) is parametrized; chi0 inside the bracket stays chi0.
    """
    spring = S.L_us - S.d_y + (S.d_x * sp.sin(2 * As) - S.w_b * sp.cos(As)) / (1 + sp.cos(2 * As))
    bracket = ((S.r_c + sp.Rational(1, 2) * S.w_b) * (sp.cos(As - S.alpha0) - 1)
               + S.chi0 * sp.sin(As - S.alpha0)
               + S.e * (sp.sin(As + S.theta0) - sp.sin(As + S.Theta_s)))
    return -S.k_s * S.d_x * spring - _k_line * (arm_chi - sp.Rational(1, 2) * mu * S.w_b) * bracket
