"""camdyn.analysis.calibrate: recovers known parameters from their own computed targets; states the
degrees of freedom; rejects ill-posed problems with errors naming the parameter."""
from __future__ import annotations

import dataclasses
import math

import pytest

import camdyn
from camdyn.analysis import calibrate as cal

RIG = camdyn.load_rig("example")
LINE = camdyn.Scene(contact="line", damping="D", friction="coulomb")
DE, SE = camdyn.ConstantSpeed(300.0), camdyn.ConstantSpeed(-300.0)


def measured(targets, truth, extras=None):
    """The targets with their values computed on the true rig (synthetic measurements)."""
    return [dataclasses.replace(t, value=t.compute(t.variant(truth, extras))) for t in targets]


def frequency_targets():
    return [cal.natural_frequency(1.0, LINE, DE, name="f_de"),
            cal.natural_frequency(1.0, LINE, SE, name="f_se"),
            cal.contact_stiffness(1.0, "point", name="k_point"),
            cal.energy_balance_saturation(1.0, name="saturation")]


def test_recovers_known_parameters_of_a_synthetic_rig():
    truth = RIG.replace(I_Pb=0.0081, w_b=0.017, L_us=0.123, alpha0=0.15, theta0=1.2)
    targets = measured(frequency_targets(), truth)
    res = cal.calibrate(RIG, [cal.Unknown("I_Pb", 1e-4, 1.0), cal.Unknown("w_b", 1e-3, 0.05),
                              cal.Unknown("L_us", 0.1, 0.2), cal.Unknown("alpha0", -0.5, 0.5)],
                        targets, fixed={"chi0": "measured on the drawing"},
                        tied={"theta0": lambda p: p["alpha0"] + 1.05})
    for name in ("I_Pb", "w_b", "L_us", "alpha0"):
        assert res.values[name] == pytest.approx(getattr(truth, name), rel=1e-6), name
    assert res.rig.theta0 == pytest.approx(truth.theta0, rel=1e-6)     # tied
    assert all(abs(r.relative) < 1e-9 for r in res.residuals)
    assert res.success and res.all_within
    assert res.dof.targets == 4 and res.dof.unknowns == 4 and res.dof.rank == 4
    assert res.dof.free == 0 and res.dof.redundant == 0
    assert "fixed by assumption: chi0 (measured on the drawing)" in res.dof.statement()
    assert "Tied to others: theta0" in res.dof.statement()
    # the frequencies fix I_Pb (sensitivity -1/2 of a frequency to log I_Pb)
    assert res.sensitivity[0, 0] == pytest.approx(-0.5, abs=1e-3)
    text = res.report()
    assert "| I_Pb |" in text and "| f_de |" in text


def test_extra_unknown_of_a_rig_variant_and_a_user_callable():
    """The experiment's spring is a parameter of a variant only (settings), fitted with the rest;
    any callable of the rig is a target."""
    truth = RIG.replace(I_Pb=0.0079)
    extras = {"k_exp": 40.0}
    targets = measured([
        cal.contact_loss_speed(1.0, settings={"k_s": "k_exp", "l_lambda": 0.016}, name="loss"),
        cal.Target("undamped_Hz", 1.0, lambda rig: camdyn.static_equilibrium(rig).frequency_Hz, unit="Hz"),
    ], truth, extras)
    res = cal.calibrate(RIG, [cal.Unknown("I_Pb", 1e-4, 1.0), cal.Unknown("k_exp", 1.0, 2000.0, initial=45.0)],
                        targets)
    assert res.extras["k_exp"] == pytest.approx(40.0, rel=1e-6)
    assert res.rig.I_Pb == pytest.approx(0.0079, rel=1e-6)
    assert res.rig.k_s == RIG.k_s                       # the base rig keeps its spring
    variant = res.variant("loss")
    assert variant.k_s == pytest.approx(40.0, rel=1e-6) and variant.l_lambda == 0.016


def test_redundant_target_and_underdetermined_fit_are_stated():
    truth = RIG.replace(I_Pb=0.008)
    f = cal.natural_frequency(1.0, LINE, DE, name="f_de")
    targets = measured([f, dataclasses.replace(f, name="f_de_again")], truth)
    res = cal.calibrate(RIG, [cal.Unknown("I_Pb", 1e-4, 1.0)], targets)
    assert res.dof.rank == 1 and res.dof.redundant == 1
    assert "redundant" in res.dof.statement()
    # two unknowns, one frequency: only I_Pb / chi*^2 is determined
    one = measured([f], truth)
    with pytest.raises(cal.CalibrationError, match=r"2 unknowns \(I_Pb, chi0\) but only 1 target"):
        cal.calibrate(RIG, [cal.Unknown("I_Pb", 1e-4, 1.0), cal.Unknown("chi0", 0.05, 0.2)], one)
    res = cal.calibrate(RIG, [cal.Unknown("I_Pb", 1e-4, 1.0), cal.Unknown("chi0", 0.05, 0.2)], one,
                        allow_underdetermined=True)
    assert res.dof.free >= 1 and "undetermined" in res.dof.statement()
    assert abs(res.residuals[0].relative) < 1e-8


def test_rounding_sigma_and_scales():
    assert cal.rounding_sigma(2182.0, 4) == pytest.approx(0.5)
    assert cal.rounding_sigma(34.2e6, 3) == pytest.approx(0.05e6)
    assert cal.rounding_sigma(1.36, 3) == pytest.approx(0.005)
    t = cal.natural_frequency(2182.0, LINE, DE, digits=4)
    assert t.uncertainty == pytest.approx(0.5)
    assert cal.Unknown("k_s", 1.0, 1e4).log and not cal.Unknown("L_us", 0.1, 0.2).log
    assert not cal.Unknown("k_s", 1.0, 1e4, scale="linear").log
    u = cal.Unknown("I_Pb", 1e-4, 1.0)
    assert u.from_internal(u.to_internal(0.0123)) == pytest.approx(0.0123)


@pytest.mark.parametrize("make, match", [
    (lambda: cal.calibrate(RIG, [cal.Unknown("I_pb", 1e-4, 1.0)], frequency_targets()[:1]),
     r"unknown 'I_pb' is not a rig parameter \(did you mean 'I_Pb'\?\)"),
    (lambda: cal.calibrate(RIG, [cal.Unknown("I_Pb", 1e-4, 1.0)] * 2, frequency_targets()[:2]),
     "listed twice: I_Pb"),
    (lambda: cal.Unknown("I_Pb", 1.0, 1e-4), "lower = 1.0 must be < upper"),
    (lambda: cal.Unknown("alpha0", -1.0, 1.0, scale="log"), "log scale needs lower > 0"),
    (lambda: cal.calibrate(RIG, [cal.Unknown("I_Pb", 0.1, 1.0)], frequency_targets()[:1]),
     r"unknown 'I_Pb': initial value 0.0073 is outside its bounds"),
    (lambda: cal.calibrate(RIG, [cal.Unknown("I_Pb", 1e-4, 1.0)], frequency_targets()[:1],
                           fixed={"I_Pb": "measured"}), "both an unknown and fixed"),
    (lambda: cal.calibrate(RIG, [cal.Unknown("I_Pb", 1e-4, 1.0)], frequency_targets()[:1],
                           fixed={"chi_0": "measured"}), r"fixed parameter 'chi_0' is not a rig parameter"),
    (lambda: cal.calibrate(RIG, [cal.Unknown("I_Pb", 1e-4, 1.0)], frequency_targets()[:1],
                           fixed={"chi0": ""}), "give the assumption"),
    (lambda: cal.calibrate(RIG, [cal.Unknown("I_Pb", 1e-4, 1.0)],
                           [cal.contact_loss_speed(130.0, settings={"k_s": "k_exp"})]),
     r"refer to 'k_exp', which is not among the unknowns"),
    (lambda: cal.contact_loss_speed(130.0, settings={"ks": 10.0}), r"setting 'ks' is not a rig parameter"),
    (lambda: cal.natural_frequency(math.nan, LINE, DE), "value = nan must be a finite number"),
    (lambda: cal.natural_frequency(2182.0, LINE, DE, sigma=0.0), "sigma = 0.0 must be"),
    (lambda: cal.natural_frequency(2182.0, LINE, DE, sigma=1.0, digits=4), "sigma or digits, not both"),
    (lambda: cal.calibrate(RIG, [], frequency_targets()), "no unknowns"),
    (lambda: cal.calibrate(RIG, [cal.Unknown("I_Pb", 1e-4, 1.0)], []), "no targets"),
    (lambda: cal.calibrate(RIG, [cal.Unknown("beta_X", 1.0, 2.0, initial=1.5)], frequency_targets()[:1]),
     "not a rig parameter"),
])
def test_ill_posed_problems_raise_errors_naming_the_parameter(make, match):
    with pytest.raises(cal.CalibrationError, match=match):
        make()


def test_a_target_that_cannot_be_computed_is_named():
    rig = RIG.replace(l_lambda=None)
    with pytest.raises(cal.CalibrationError, match=r"target 'k_line' cannot be computed.*l_lambda"):
        cal.calibrate(rig, [cal.Unknown("I_Pb", 1e-4, 1.0)], [cal.contact_stiffness(138e6, "line")])


def test_calibration_error_is_a_camdyn_value_error():
    assert issubclass(cal.CalibrationError, camdyn.errors.CamdynError)
    assert issubclass(cal.CalibrationError, ValueError)
