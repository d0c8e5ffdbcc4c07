"""The linearized model of Section 8 (Eqs. 36-38), as the paper builds it, and the exact one.

The paper's procedure (line contact, sliding throughout, Coulomb friction of a
fixed sign mu, a constant damping coefficient c): put alpha = alpha* + d_alpha
in Eq. 10 and keep first-order terms, except that

* the moment arm is frozen at chi* - 0.5 mu w_b (the geometric stiffness
  F_n* d(chi)/d(alpha) is dropped);
* in psi_i the cam term -e sin(alpha + Theta(t)) is kept whole as forcing,
  evaluated at alpha*, and only the rest of psi_i is differentiated in alpha:
  K_l keeps +e cos(alpha* + Theta0) but not the parametric -e cos(alpha* + Theta(t))
  (misprint 9);
* psi_i_dot keeps only d_alpha_dot times that derivative: the cam's
  -e cos(alpha+Theta) Theta_dot term is dropped from the forcing.

The printed F_l (Eq. 38c) uses chi0 where K_l uses chi*; ``forcing_arm``
selects the printed ("printed") or the consistent ("derived") arm.
The exact linearization keeps all of it: the Jacobian of the non-linear
right-hand side along (alpha*, 0, Theta(t)), with time-varying coefficients.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

from . import laws
from . import symbols as S
from .geometry import loop_solution

d_alpha, d_alpha_dot = sp.symbols("delta_alpha delta_alpha_dot", real=True)


@dataclass(frozen=True)
class PaperLinearModel:
    """I_Pb d_alpha_ddot + C_l d_alpha_dot + K_l d_alpha = F_l(t)  (Eq. 37)."""

    K_l: sp.Expr
    C_l: sp.Expr
    F_l: sp.Expr   # a function of Theta(t) (plain symbol S.Theta_s)


@lru_cache(maxsize=None)  # pure; its two simplifications take seconds, and field and jacobian both ask
def paper_linear_model(c_lambda: sp.Expr, mu: sp.Expr, forcing_arm: str = "printed") -> PaperLinearModel:
    """Eqs. 36-38 by the paper's procedure; ``mu`` is the signed friction coefficient."""
    a_star, Th = S.alpha_star, S.Theta_s
    k = laws.contact_stiffness("line", 0)
    # psi_i as the loop gives it (Eq. 6), split into the moving-cam term (forcing)
    # and the rest (differentiated in alpha)
    psi = S.to_plain(loop_solution()[0])
    cam_term = -S.e * sp.sin(S.alpha_s + Th)
    rest = sp.expand(psi - cam_term)
    if rest.has(Th):
        raise RuntimeError("psi_i has a cam term other than -e sin(alpha + Theta)")
    slope = rest.diff(S.alpha_s).subs(S.alpha_s, a_star)
    arm = S.chi_star - mu * S.w_b / 2
    L = laws.spring_compression(S.alpha_s)
    K_l = S.k_s * S.d_x * L.diff(S.alpha_s).subs(S.alpha_s, a_star) + k * arm * slope
    C_l = c_lambda * arm * slope
    forcing_chi = {"printed": S.chi0, "derived": S.chi_star}[forcing_arm]
    psi_at_star = (rest + cam_term).subs(S.alpha_s, a_star)
    F_l = -S.k_s * S.d_x * L.subs(S.alpha_s, a_star) - k * (forcing_chi - mu * S.w_b / 2) * psi_at_star
    return PaperLinearModel(sp.simplify(K_l), sp.simplify(C_l), F_l)


def paper_linear_rhs(model: PaperLinearModel) -> sp.Expr:
    """alpha_ddot of the paper's linear model, with state alpha = alpha* + d_alpha."""
    return (model.F_l - model.C_l * S.alpha_dot - model.K_l * (S.alpha_s - S.alpha_star)) / S.I_Pb


def exact_linear_rhs(alpha_ddot_plain: sp.Expr) -> sp.Expr:
    """First-order Taylor expansion of alpha_ddot(alpha, alpha_dot, t) about (alpha*, 0)."""
    at = {S.alpha_s: S.alpha_star, S.alpha_dot: 0}
    h = alpha_ddot_plain
    return (h.subs(at) + h.diff(S.alpha_s).subs(at) * (S.alpha_s - S.alpha_star)
            + h.diff(S.alpha_dot).subs(at) * S.alpha_dot)
