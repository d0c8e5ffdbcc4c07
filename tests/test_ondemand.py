"""Scenes outside the catalog, derived on first use into the per-user cache (camdyn.ondemand)."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import camdyn
from camdyn import ondemand
from camdyn.cli import main
from camdyn.errors import SceneError

#: a valid scene that derive/catalog.py does not list (and a small one: quick to derive)
OPTIONS = dict(contact="point", damping="C", friction="none")


@pytest.fixture
def user_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("CAMDYN_CACHE_DIR", str(tmp_path))
    return tmp_path


def test_the_scene_is_not_in_the_catalog():
    assert camdyn.derive.vocabulary.SceneSpec(**OPTIONS).slug not in camdyn.Scene.available()


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
    # byte for byte what `python -m camdyn.derive` writes for the scene (writer.render maps module_source)
    assert path.read_text(encoding="utf-8") == codegen.module_source(scene)
    assert kernels.SLUG == scene.slug

    with warnings.catch_warnings():
        warnings.simplefilter("error", camdyn.CompileNotice)  # cached: not derived again
        again = camdyn.Scene(**OPTIONS).kernels()
    assert again is kernels

    rig = camdyn.example_rig()
    result = camdyn.simulate(rig, scene, speed_rpm=300, t_end=0.005, backend="python")
    assert result.ok, result.outcome.message
    assert np.all(np.isfinite(result.alpha)) and np.all(np.isfinite(result.F_n))

    capsys.readouterr()
    assert main(["cache"]) == 0
    out = capsys.readouterr().out
    assert scene.slug in out and "current" in out
    assert main(["cache", "--clear-stale"]) == 0
    assert path.is_file()  # the current derivation is kept
    assert main(["cache", "--clear"]) == 0
    assert not path.exists()
