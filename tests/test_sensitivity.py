"""Parameter derivatives of the field (issue 13, item 2): the generated ``field_sensitivity``
against central differences of ``rhs`` over models rebuilt with the parameter perturbed (the
static equilibrium, alpha*, chi*, vartheta, solved again: total derivatives)."""
from __future__ import annotations

import pytest

import camdyn
from camdyn.model.cam import RPM
from camdyn.vocabulary import CONTINUATION_PARAMETERS
from camdyn.model.model import Model

RIG = camdyn.example_rig()
SPEED = 1100.0
#: relative step of the central differences: truncation ~H^2 = 1e-10, rounding ~eps / H =
#: 2e-11 of the field, and the equilibrium solve (brentq to 4 eps) divided by H: 1e-10
H = 1e-5


def _model(scene, speed=SPEED, **rig):
    return Model(RIG.replace(**rig) if rig else RIG, scene, camdyn.ConstantSpeed(speed))


def _difference(scene, name, m, state):
    if name == "Omega_c":
        h = H * SPEED
        lo, hi = _model(scene, SPEED - h), _model(scene, SPEED + h)
        step = 2 * h * RPM
    else:
        value = getattr(RIG, name)
        lo, hi = _model(scene, **{name: value * (1 - H)}), _model(scene, **{name: value * (1 + H)})
        step = 2 * H * value
    return (hi.rhs(m, *state) - lo.rhs(m, *state)) / step


@pytest.mark.parametrize("damping", ["D", "E", "A"])
def test_field_sensitivity_matches_central_differences(damping):
    scene = camdyn.Scene(contact="line", damping=damping, friction="coulomb")
    model = _model(scene)
    names = model.variational.SENSITIVITY
    assert names == tuple(n for n in CONTINUATION_PARAMETERS if n in names)     # the vocabulary's order
    assert names[:3] == ("Omega_c", "k_s", "e")
    a = model.equilibrium.alpha - 2e-5                       # pressed into the cam: in contact
    checked = 0
    for m, mode in enumerate(model.kernels.MODES):
        state = (0.0137, a if mode != "free" else a + 0.01, 0.3)
        got = model.field_sensitivity(m, *state)
        for name in names:
            expected = _difference(scene, name, m, state)
            scale = max(abs(expected), 1e-6 * abs(model.rhs(m, *state)) / abs(getattr(RIG, name, 1.0) or 1.0))
            # 1e-6 relative: the differences' error (H above) is ~1e-10 of the field, over
            # derivatives that can be 1e-4 of it
            assert got[name] == pytest.approx(expected, rel=1e-6, abs=1e-6 * scale), (mode, name)
            checked += 1
    assert checked == len(model.kernels.MODES) * len(names)


def test_k_s_acts_through_the_equilibrium_in_the_viscous_law():
    """In damping D's viscous phase c = 2 zeta_D I_Pb vartheta / chi*^2: the total d/dk_s differs
    from the partial at fixed chi*, vartheta (p's k_s alone perturbed) by far more than the 1e-6
    the test above resolves, so that test checks the equilibrium's part too."""
    scene = camdyn.Scene(contact="line", damping="D", friction="coulomb")
    model = _model(scene)
    m = model.mode("contact_unloading_fwd")
    state = (0.0137, model.equilibrium.alpha - 2e-5, 0.3)
    total = model.field_sensitivity(m, *state)["k_s"]
    k = model.kernels.PARAMS.index("k_s")
    p_lo, p_hi = model.p.copy(), model.p.copy()
    p_lo[k], p_hi[k] = RIG.k_s * (1 - H), RIG.k_s * (1 + H)
    partial = (model.kernels.rhs(m, *state, p_hi) - model.kernels.rhs(m, *state, p_lo)) / (2 * H * RIG.k_s)
    assert abs(total - partial) > 10 * 1e-6 * abs(total)      # measured 2e-5 relative


def test_linear_models_have_no_parameter_derivatives():
    model = Model(RIG, camdyn.Scene(damping="D", friction="coulomb", model="linear_exact"), camdyn.ConstantSpeed(300))
    with pytest.raises(camdyn.SceneError, match="non-linear"):
        model.field_sensitivity(0, 0.0, 0.0, 0.0)
