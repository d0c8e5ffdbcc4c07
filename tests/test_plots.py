"""camdyn.io.plots: each figure is drawn from real runs, has the axes a reader needs, and saves;
matplotlib stays optional."""
from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

import camdyn
from camdyn.io import plots

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def impacting():
    """1100 rev/min on the example rig: above contact loss, impacts every revolution.
    The sample rate is a whole multiple of the cam frequency (Poincare samples are exact)."""
    rig = camdyn.example_rig()
    return camdyn.simulate(rig, camdyn.Scene(), speed_rpm=1100, revolutions=6, sample_rate_Hz=1100 / 60 * 400)


@pytest.fixture(autouse=True)
def _close():
    yield
    plt.close("all")


def saves(fig, tmp_path, name="fig.png"):
    path = tmp_path / name
    fig.savefig(path)
    assert path.read_bytes()[:8] == PNG
    return path


def test_time_history_is_over_cam_revolutions(impacting, tmp_path):
    fig = plots.time_history(impacting, "alpha_r", mark_impacts=True, shade_free=True)
    ax = fig.axes[0]
    assert "t/T" in ax.get_xlabel() and r"\alpha_r" in ax.get_ylabel()
    x = ax.lines[0].get_xdata()
    assert x[0] == 0 and math.isclose(x[-1], 6, rel_tol=1e-9)  # six revolutions
    assert "mrad" in ax.get_ylabel()  # alpha_r of a few mrad gets the milli prefix
    assert ax.patches  # free flight shaded
    saves(fig, tmp_path)


def test_time_history_overlays_labelled_runs_in_a_window(impacting):
    other = impacting.after(impacting.t[0])
    fig = plots.time_history({"D": impacting, "D again": other}, "F_n", revolutions=(1, 2))
    ax = fig.axes[0]
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["D", "D again"]
    assert ax.get_xlim() == (1, 2)
    assert np.all((ax.lines[0].get_xdata() >= 1) & (ax.lines[0].get_xdata() <= 2))


def test_overview_has_alpha_r_force_and_sliding_velocity(impacting, tmp_path):
    fig = plots.overview(impacting)
    labels = [a.get_ylabel() for a in fig.axes]
    assert len(labels) == 3 and "alpha_r" in labels[0] and "F_n" in labels[1] and "v_r" in labels[2]
    # the physics in words, not the generated module's slug (line_d_coulomb_constant_nonlinear)
    assert fig.axes[0].get_title() == "line contact, damping D, Coulomb friction, 1100 rev/min, rig example"
    saves(fig, tmp_path)


def test_spectrum_marks_the_harmonics_of_the_cam(impacting, tmp_path):
    f0 = 1100 / 60
    fig = plots.spectrum(impacting, "alpha", bands=[(0, 8 * f0), (1500, 3000)], mark_Hz={"vartheta": 2200.0},
                         transient_revolutions=1)
    low, high = fig.axes
    marks = sorted(line.get_xdata()[0] for line in low.lines if line.get_linestyle() == ":")
    assert np.allclose(marks, f0 * np.arange(1, 9))
    assert [t.get_text() for t in low.texts] == [str(k) for k in range(1, 9)]
    assert any("vartheta = 2200 Hz" in t.get_text() for t in high.get_legend().get_texts())
    assert any("too dense" in t.get_text() for t in high.get_legend().get_texts())  # 80 harmonics in 1.5 kHz
    assert low.get_yscale() == "log" and "frequency (Hz)" in low.get_xlabel()
    saves(fig, tmp_path)


def test_spectrum_of_whole_periods_puts_harmonics_on_bins(impacting):
    t = impacting.t
    keep = plots.whole_period_samples(t, impacting.period)
    duration = keep.sum() * (t[1] - t[0])
    assert math.isclose(duration / impacting.period, 6, rel_tol=1e-9)


def test_poincare_section_samples_once_per_revolution(impacting, tmp_path):
    sec = plots.poincare_section(impacting, transient_revolutions=2)
    assert np.allclose(np.diff(sec["t"]), impacting.period)
    assert np.isclose(sec["t"][0], 2 * impacting.period)
    i = np.searchsorted(impacting.t, sec["t"][-1])
    assert sec["alpha"][-1] == pytest.approx(impacting.alpha[i], abs=1e-12)  # a sample, not interpolated
    fig = plots.poincare(impacting, transient_revolutions=2)
    assert "5 points" in fig.axes[0].get_legend().get_texts()[0].get_text()  # revolutions 2..6
    saves(fig, tmp_path)


def test_poincare_section_needs_a_period(impacting):
    no_period = impacting.after(impacting.t[0])
    no_period.period = math.inf
    with pytest.raises(ValueError, match="periodic cam"):
        plots.poincare_section(no_period)


def test_bifurcation_accepts_ragged_and_2d_points(tmp_path):
    fig = plots.bifurcation([100, 200, 300], [[0.1], [0.1, 0.2], [np.nan, 0.3, 0.1, 0.2]], relative_to=0.0)
    xs = fig.axes[0].lines[1].get_xdata()
    assert sorted(xs) == [100, 200, 200, 300, 300, 300]
    assert "rev/min" in fig.axes[0].get_xlabel()
    fig = plots.bifurcation([1, 2], np.ones((2, 3)) * 1e-3)
    assert "mrad" in fig.axes[0].get_ylabel()
    with pytest.raises(ValueError, match="2 speeds but 3 columns"):
        plots.bifurcation([1, 2], [[1], [2], [3]])
    saves(fig, tmp_path)


def test_contact_map_codes_names_and_loss_curve(tmp_path):
    speeds, ks = np.array([100.0, 200.0, 300.0]), np.array([1e3, 1e4])
    regime = np.array([["sliding", "impacting", "impacting"], ["sliding", "sliding", "failed"]])
    fig = plots.contact_map(speeds, ks, regime, loss_curve=([150, 250], [1e3, 1e4]))
    ax = fig.axes[0]
    assert ax.get_yscale() == "log"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "sliding", "impacting", "failed", "contact loss (inverse kinematics)"]
    with pytest.raises(ValueError, match="expected"):
        plots.contact_map(speeds, ks, np.zeros((3, 2)))
    saves(fig, tmp_path)


def test_contact_map_leaves_skipped_points_out():
    """A column of skipped points (a speed out of range, skipped by the sweep) is not on the axes;
    a skipped point among others is drawn as skipped, not failed; the curve stays on the map."""
    speeds, ks = np.array([100.0, 200.0, 1e6]), np.array([1e3, 1e4, 1e7])
    regime = np.array([["sliding", "impacting", "skipped"], ["skipped", "sliding", "skipped"],
                       ["skipped", "skipped", "skipped"]])
    fig = plots.contact_map(speeds, ks, regime, loss_curve=([150, 250, 300], [1e3, 1e4, 1e7]))
    ax = fig.axes[0]
    assert ax.get_xlim()[1] < 1e3 and ax.get_ylim()[1] < 1e6
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "sliding", "impacting", "skipped", "contact loss (inverse kinematics)"]
    with pytest.raises(ValueError, match="every point of the map is skipped"):
        plots.contact_map(speeds[:1], ks[:1], [["skipped"]])


def test_work_precision_is_log_log_with_tolerances(tmp_path):
    records = [{"label": "DOP853", "error": e, "seconds": s, "rtol": r}
               for e, s, r in [(1e-6, 1.0, 1e-6), (1e-9, 2.0, 1e-9)]]
    fig = plots.work_precision(records + [{"label": "RK45", "error": 1e-6, "seconds": 3.0}])
    ax = fig.axes[0]
    assert ax.get_xscale() == ax.get_yscale() == "log"
    assert sorted(t.get_text() for t in ax.texts) == ["1e-06", "1e-09"]
    saves(fig, tmp_path)


def test_unknown_quantity_is_a_clear_error(impacting):
    with pytest.raises(ValueError, match="quantity 'alpha_rr' is not one of"):
        plots.time_history(impacting, "alpha_rr")


def test_import_does_not_need_matplotlib_and_calls_say_how_to_install():
    code = ("import sys; sys.modules['matplotlib'] = None; sys.modules['matplotlib.pyplot'] = None\n"
            "import camdyn.io.plots as p\n"
            "try:\n    p.time_history(None)\nexcept ImportError as e:\n    print(e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert 'pip install "camdyn[plot]"' in out


# ------------------------------------------------------------------ issue 14 (K)
def test_spectrum_panels_share_one_unit_and_mark_the_noise_floor(impacting):
    """The band around the contact mode holds only noise: it is drawn in the unit of the whole
    figure (not prad) with the median level marked, so it does not read as a signal."""
    fig = plots.spectrum(impacting, "alpha", bands=[(0, 200), (1800, 2600)], transient_revolutions=1)
    low, high = fig.axes
    assert low.get_ylabel() == high.get_ylabel() and "(mrad)" in low.get_ylabel()
    for ax in (low, high):
        floors = [t.get_text() for t in ax.get_legend().get_texts() if t.get_text().startswith("noise floor")]
        assert len(floors) == 1 and "mrad" in floors[0]
    assert "1100 rev/min" in low.get_title() and "_" not in low.get_title()


def test_bifurcation_marks_the_contact_loss_speed():
    speeds = [800.0, 1000.0, 1200.0]
    fig = plots.bifurcation(speeds, np.zeros((3, 2)), contact_loss_rpm=997.9)
    ax = fig.axes[0]
    assert [line.get_xdata()[0] for line in ax.lines if line.get_linestyle() == "--"] == [997.9]
    assert "contact loss" in ax.get_legend().get_texts()[0].get_text()
    fig = plots.bifurcation(speeds, np.zeros((3, 2)), contact_loss_rpm=2000.0)  # out of range: not drawn
    assert fig.axes[0].get_legend() is None


def test_no_text_in_any_figure_is_smaller_than_the_minimum(impacting):
    """Legends, harmonic numbers, annotations: every text at least MIN_FONT_PT (8.5 pt: at the
    saved 150 dpi about 18 px, readable in a report), which the 6.5-7.5 pt labels were not."""
    from matplotlib.text import Text

    records = [{"label": "DOP853", "error": 1e-6, "seconds": 1.0, "rtol": 1e-6},
               {"label": "DOP853", "error": 1e-9, "seconds": 2.0, "rtol": 1e-9}]
    figures = [plots.overview(impacting), plots.time_history(impacting, mark_impacts=True),
               plots.spectrum(impacting, "alpha", bands=[(0, 200)], transient_revolutions=1),
               plots.poincare(impacting), plots.bifurcation([1, 2], np.ones((2, 2)), contact_loss_rpm=1.5),
               plots.contact_map([1.0, 2.0], [1.0, 10.0], np.array([[0, 1], [1, 2]]), loss_curve=([1, 2], [1, 10])),
               plots.work_precision(records)]
    for fig in figures:
        fig.canvas.draw()
        sizes = [t.get_fontsize() for t in fig.findobj(Text) if t.get_text().strip() and t.get_visible()]
        assert sizes and min(sizes) >= plots.MIN_FONT_PT, fig


def test_every_continuation_event_has_its_marker():
    from camdyn.io.plots import EVENT_MARKERS
    from camdyn.orbits.continuation import EVENTS
    assert set(EVENT_MARKERS) == set(EVENTS)
