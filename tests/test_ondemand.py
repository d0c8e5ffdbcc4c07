"""Scenes outside the catalog, derived on first use into the per-user cache (camdyn.model.ondemand)."""
from __future__ import annotations

import sys
import types
import warnings
from pathlib import Path

import numpy as np
import pytest

import camdyn
from camdyn.model import ondemand
from camdyn.cli import main
from camdyn.errors import SceneError
from camdyn.model.model import Model
from camdyn.model.scene import variational_kernels

#: a valid scene that derive/catalog.py does not list (and a small one: quick to derive)
OPTIONS = dict(contact="point", damping="C", friction="none")


@pytest.fixture
def user_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("CAMDYN_CACHE_DIR", str(tmp_path))
    return tmp_path


def test_the_scene_is_not_in_the_catalog():
    assert camdyn.vocabulary.SceneSpec(**OPTIONS).slug not in camdyn.Scene.available()


def test_without_sympy_the_error_names_the_derive_extra(user_cache, monkeypatch):
    monkeypatch.setattr(ondemand, "sympy_version", lambda: None)
    with pytest.raises(SceneError, match=r'pip install "camdyn\[derive\]"') as info:
        camdyn.Scene(**OPTIONS)
    assert "point_c_none_constant_nonlinear" in str(info.value)
    assert camdyn.Scene(friction="tanh").in_catalog  # catalogued scenes need no SymPy


def test_a_scene_outside_the_catalog_is_derived_once_cached_listed_and_cleared(user_cache, capsys):
    codegen = pytest.importorskip("camdyn.derive.codegen")
    scene = camdyn.Scene(**OPTIONS)
    assert not scene.in_catalog
    with pytest.warns(camdyn.CompileNotice, match="derives the scene"):
        kernels = scene.kernels()
    path = ondemand.module_path(scene)
    assert path.is_relative_to(user_cache)
    # byte for byte what `python -m camdyn.derive` writes for the scene and its companion of
    # variational kernels (writer.render maps codegen.sources)
    companion = path.with_name(kernels.VARIATIONAL + ".py")
    assert {f.name: f.read_text(encoding="utf-8") for f in (path, companion)} == codegen.sources(scene)
    assert kernels.SLUG == scene.slug

    with warnings.catch_warnings():
        warnings.simplefilter("error", camdyn.CompileNotice)  # cached: not derived again
        again = camdyn.Scene(**OPTIONS).kernels()
    assert again is kernels

    rig = camdyn.example_rig()
    result = camdyn.simulate(rig, scene, speed_rpm=300, t_end=0.005, backend="python")
    assert result.ok, result.outcome.message
    assert np.all(np.isfinite(result.alpha)) and np.all(np.isfinite(result.F_n))
    assert not [m for m in sys.modules if kernels.VARIATIONAL in m]  # a run does not import the companion

    model = Model(rig, scene, camdyn.ConstantSpeed(300))
    gap = model.surface_gradient(model.mode("free"), kernels.SURFACES.index("gap"), 0.0, model.equilibrium.alpha, 0.0)
    assert np.all(np.isfinite(gap)) and model.variational.SLUG == scene.slug
    companion.rename(companion.with_suffix(".moved"))  # a companion gone from the cache: a clear error
    with pytest.raises(SceneError, match=f"variational kernels of scene '{scene.slug}' are missing"):
        Model(rig, scene, camdyn.ConstantSpeed(300)).surface_gradient(1, 0, 0.0, 0.0, 0.0)
    companion.with_suffix(".moved").rename(companion)

    capsys.readouterr()
    assert main(["cache"]) == 0
    out = capsys.readouterr().out
    assert scene.slug in out and "current" in out
    assert main(["cache", "--clear-stale"]) == 0
    assert path.is_file()  # the current derivation is kept
    assert main(["cache", "--clear"]) == 0
    assert not path.exists()


def test_a_missing_or_foreign_companion_is_a_scene_error_naming_the_scene(tmp_path):
    """A scene module whose companion is not beside it, or belongs to another scene, gives a
    SceneError that names the scene (not an AttributeError or wrong numbers)."""
    from camdyn.generated import scene_line_d_coulomb_constant_nonlinear as shipped
    fake = types.ModuleType("fake_scene")
    fake.__file__ = str(tmp_path / "scene_fake.py")
    for name in ("SLUG", "PARAMS", "MODES", "SURFACES", "VARIATIONAL"):
        setattr(fake, name, getattr(shipped, name))
    with pytest.raises(SceneError, match=f"variational kernels of scene '{shipped.SLUG}' are missing"):
        variational_kernels(fake)
    (tmp_path / (fake.VARIATIONAL + ".py")).write_text(
        Path(shipped.__file__).with_name(fake.VARIATIONAL + ".py").read_text())
    fake.PARAMS = fake.PARAMS[1:]
    with pytest.raises(SceneError, match="differ in PARAMS"):
        variational_kernels(fake)
    fake.VARIATIONAL = None  # a scene without variational kernels (the linear models)
    assert variational_kernels(fake) is None
