"""Fig. 1 geometry: the vector loop (Eqs. 1-5) solved for psi_i, psi_j (Eqs. 6-7).

Frames: ``N`` is the fixed frame (e_x, e_y), origin at the cam pivot E; ``B``
is the follower frame, turned by alpha *clockwise*, so that

    u = B.x = (cos alpha, -sin alpha)   along the bar,
    n = B.y = (sin alpha,  cos alpha)   normal to the bar, towards the cam.

Nothing here is transcribed from the paper's final formulas: psi_i and psi_j
are the unknowns of the loop P->O_b = P->E + E->G_c + G_c->O_b (Eq. 1), and
P->E is fixed by the loop at the 0-state (Eq. 5).
"""
from __future__ import annotations

from functools import lru_cache

import sympy as sp
from sympy.physics.vector import ReferenceFrame, Vector

from .profile import h
from .symbols import Theta, alpha, alpha0, chi0, e, r_c, theta0, w_b

N = ReferenceFrame("N")


def follower_frame(angle: sp.Expr) -> ReferenceFrame:
    """The follower frame at a clockwise angle ``angle`` (alpha is clockwise)."""
    return N.orientnew("B", "Axis", (-angle, N.z))


def E_to_Gc(cam_angle: sp.Expr) -> Vector:
    """Eq. 3: Theta is the angle of G_c->E from the horizontal, counter-clockwise."""
    return -e * (sp.cos(cam_angle) * N.x + sp.sin(cam_angle) * N.y)


def P_to_Ob(B: ReferenceFrame, chi: sp.Expr) -> Vector:
    """Eq. 2: the contact point O_b on the follower's cam-side surface."""
    return chi * B.x + w_b / 2 * B.y


def Gc_to_Ob(B: ReferenceFrame, psi_i: sp.Expr) -> Vector:
    """Eq. 4: from the cam centre along -n, a distance r_c plus the gap psi_i."""
    return -(r_c + psi_i) * B.y


@lru_cache(maxsize=None)
def P_to_E() -> Vector:
    """Eq. 5: the constant P->E, from the loop in the 0-state (psi_i = psi_j = 0)."""
    B0 = follower_frame(alpha0)
    return P_to_Ob(B0, chi0) - E_to_Gc(theta0) - Gc_to_Ob(B0, 0)


def P_to_Gc(cam_angle: sp.Expr = Theta) -> Vector:
    return P_to_E() + E_to_Gc(cam_angle)


@lru_cache(maxsize=None)
def loop_solution() -> tuple[sp.Expr, sp.Expr]:
    """Solve the vector loop (Eq. 1) for (psi_i, psi_j) as functions of alpha(t), Theta(t).

    The two scalar equations are the loop's components in the fixed frame;
    they are linear in psi_i, psi_j.  Returns Eqs. 6 and 7 (expanded trig form).
    """
    psi_i, psi_j = sp.symbols("psi_i psi_j", real=True)
    B = follower_frame(alpha)
    residual = P_to_Ob(B, chi0 - psi_j) - (P_to_E() + E_to_Gc(Theta) + Gc_to_Ob(B, psi_i))
    equations = [residual.dot(N.x), residual.dot(N.y)]
    sol = sp.solve(equations, [psi_i, psi_j], dict=True)
    if len(sol) != 1:
        raise RuntimeError(f"vector loop: expected one solution, got {sol}")
    return (sp.simplify(sp.expand_trig(sol[0][psi_i])),
            sp.simplify(sp.expand_trig(sol[0][psi_j])))


def psi_i_conditioned(a: sp.Expr = alpha, cam_angle: sp.Expr = Theta) -> sp.Expr:
    """Eq. 6 in a form without cancellation, used for the gap in generated code.

    psi_i is a difference of terms of size chi0 * alpha that cancel to the
    contact deflection (1e-7 m against 1e-2 m).  Using
    cos(x) - 1 = -2 sin^2(x/2) and sin(a) - sin(b) = 2 cos((a+b)/2) sin((a-b)/2)
    keeps every term proportional to the small differences.
    ``tests/test_derive_equations.py`` (Eqs. 6-7) proves it equals the loop solution.
    """
    d = a - alpha0
    return (chi0 * sp.sin(d) - 2 * (r_c + w_b / 2) * sp.sin(d / 2) ** 2
            + 2 * e * sp.cos(a + (theta0 + cam_angle) / 2) * sp.sin((theta0 - cam_angle) / 2))


def psi_j_conditioned(a: sp.Expr = alpha, cam_angle: sp.Expr = Theta) -> sp.Expr:
    """Eq. 7 in the same cancellation-free form (see :func:`psi_i_conditioned`)."""
    d = a - alpha0
    return (2 * chi0 * sp.sin(d / 2) ** 2 + (r_c + w_b / 2) * sp.sin(d)
            + 2 * e * sp.sin(a + (theta0 + cam_angle) / 2) * sp.sin((theta0 - cam_angle) / 2))


def chi(a: sp.Expr = alpha, cam_angle: sp.Expr = Theta) -> sp.Expr:
    """chi = chi0 - psi_j: moment arm of the normal force about P."""
    return chi0 - psi_j_conditioned(a, cam_angle)


def rigid_contact_angle(cam_angle: sp.Expr = Theta) -> sp.Expr:
    """alpha_i: the follower angle in rigid contact, P->G_c . n = r_c + w_b/2 (Eq. 29).

    With P->G_c = (X, Y), the condition reads X sin(a) + Y cos(a) = R, that is
    rho sin(a + phi) = R with rho = |P->G_c|, phi = atan2(Y, X).  The branch
    whose contact lies on the bar on the cam's side of P (P->G_c . u = chi > 0,
    so cos(a + phi) > 0) is the principal arcsine, continuous with alpha0
    (misprint 10: the printed arccos loses the sign of alpha_i).
    """
    r = P_to_Gc(cam_angle)
    X, Y = r.dot(N.x), r.dot(N.y)
    R = r_c + w_b / 2
    return sp.asin(R / sp.sqrt(X**2 + Y**2)) - sp.atan2(Y, X)


def reach_margin(cam_angle: sp.Expr = Theta) -> sp.Expr:
    """|P->G_c| - (r_c + w_b/2): negative where no follower angle touches the cam."""
    r = P_to_Gc(cam_angle)
    return sp.sqrt(r.dot(N.x) ** 2 + r.dot(N.y) ** 2) - (r_c + w_b / 2)


# --- any convex cam: the loop through the support function (derive.profile) ---------------
def phi_contact(a: sp.Expr = alpha, cam_angle: sp.Expr = Theta) -> sp.Expr:
    """The body angle of the cam's outward normal at the contact: the normal is -n, at the
    fixed angle 3 pi/2 - a, so phi = 3 pi/2 - a - Theta (derive.profile's conventions)."""
    return 3 * sp.pi / 2 - a - cam_angle


def P_to_E_general() -> Vector:
    """Eq. 5 for any cam: in the 0-state the bar's surface touches the cam's support line of
    normal angle phi0 = phi_contact(alpha0, theta0) at chi0, so P->E = P->O_b - E->O_c with
    E->O_c = R(theta0) c(phi0) = h'(phi0) u0 - h(phi0) n0 (u0, n0 the bar's frame there)."""
    B0 = follower_frame(alpha0)
    phi0 = phi_contact(alpha0, theta0)
    return (chi0 - h(phi0, 1)) * B0.x + (w_b / 2 + h(phi0)) * B0.y


def psi_i_general(a: sp.Expr = alpha, cam_angle: sp.Expr = Theta) -> sp.Expr:
    """The gap for any cam: the distance along n from the bar's surface (P.n + w_b/2) to the
    cam's support line of normal -n (E.n - h(phi)), psi_i = P->E . n - w_b/2 - h(phi).

    With d = a - alpha0, P->E . n = (chi0 - h'(phi0)) sin d + (w_b/2 + h(phi0)) cos d; written
    with cos d - 1 = -2 sin^2(d/2) so that no term is of the size of the geometry itself but
    the difference h(phi0) - h(phi).  With the paper's circle it is Eq. 6
    (tests/test_derive_equations.py proves it)."""
    d = a - alpha0
    phi0 = phi_contact(alpha0, theta0)
    return ((chi0 - h(phi0, 1)) * sp.sin(d) - (w_b + 2 * h(phi0)) * sp.sin(d / 2) ** 2
            + h(phi0) - h(phi_contact(a, cam_angle)))


def psi_j_general(a: sp.Expr = alpha, cam_angle: sp.Expr = Theta) -> sp.Expr:
    """psi_j = chi0 - chi for any cam, chi = P->E . u + h'(phi) the contact point's distance
    from P along the bar (the contact point is E + h'(phi) u - h(phi) n); Eq. 7 with the
    paper's circle."""
    d = a - alpha0
    phi0 = phi_contact(alpha0, theta0)
    return (2 * (chi0 - h(phi0, 1)) * sp.sin(d / 2) ** 2 + (w_b / 2 + h(phi0)) * sp.sin(d)
            + h(phi0, 1) - h(phi_contact(a, cam_angle), 1))


def E_to_Oc_general(B: ReferenceFrame, a: sp.Expr = alpha, cam_angle: sp.Expr = Theta) -> Vector:
    """The cam's contact point from E, in the bar's frame: R(Theta) c(phi) = h'(phi) u - h(phi) n."""
    phi = phi_contact(a, cam_angle)
    return h(phi, 1) * B.x - h(phi) * B.y


def curvature_radius(a: sp.Expr = alpha, cam_angle: sp.Expr = Theta) -> sp.Expr:
    """rho = h + h'' at the contact: the Hertz radius of a point contact (Eq. 34 with r_c -> rho)."""
    phi = phi_contact(a, cam_angle)
    return h(phi) + h(phi, 2)
