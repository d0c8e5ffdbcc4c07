"""The figures of docs/performance.md (docs/img/perf_*.png)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _save(plt, fig, path: Path) -> None:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_case(result: dict, path: Path):
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for label, pts in result["curves"].items():
        pts = [(s, e) for _, s, e in sorted(pts, reverse=True) if math.isfinite(e) and e > 0]
        if pts:  # joined in tolerance order, loosest first: the solver's curve as rtol tightens
            s, e = zip(*pts)
            ax.loglog(e, s, "-o" if label.startswith("camdyn") else ":^", label=label, ms=4)
    ax.axvline(result["agreement"], color="0.6", lw=0.8, ls="--", label="error floor (RK45 vs DOP853)")
    ax.set_xlabel("error (rad; impacting, camdyn: max of alpha error and 10 x impact-time error in s)")
    ax.set_ylabel("wall time (s)")
    ax.set_title(result["case"].title, fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    _save(plt, fig, path)


def plot_floor(fs: dict, path: Path):
    plt = _pyplot()
    rep = fs["floor"]
    labels = list(rep.variants) + [f"diagnostic: {k}" for k in fs["pieces"]]
    values = [rep.us_per_step(k) for k in rep.variants] + list(fs["pieces"].values())
    fig, ax = plt.subplots(figsize=(7.5, 4.4))
    colors = ["C0" if k.startswith("engine") else "C1" if k.startswith("floor") else "0.6" for k in labels]
    ax.barh(range(len(labels)), values, color=colors)
    ax.set_yticks(range(len(labels)), labels, fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel("wall time per accepted step (us), best of interleaved rounds")
    ax.set_title(f"sliding run, mode {rep.mode}, rtol {rep.run.rtol:.0e}: engine / floor = {rep.ratio_median:.2f} "
                 f"(same work), {rep.default_ratio:.2f} (as it runs)", fontsize=9)
    _save(plt, fig, path)


def plot_sweeps(sw: dict, img: Path):
    """The bifurcation diagram and the contact-loss map of the sweep section."""
    plt = _pyplot()
    bif, cmap = sw["bif"], sw["cmap"]
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for v, row in zip(bif["speed_rpm"].values, bif["alpha_section"].values):
        ax.plot(np.full(row.size, v), row, ",k")
    ax.axvline(sw["loss"], color="r", lw=0.8, label="contact loss (inverse kinematics)")
    ax.set(xlabel="cam speed (rev/min)", ylabel="alpha once per revolution (rad)")
    ax.set_title("bifurcation diagram, line 16 mm, D, Coulomb (Poincare section)", fontsize=9)
    ax.legend(fontsize=7)
    _save(plt, fig, img / "perf_bifurcation.png")
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.pcolormesh(cmap["speed_rpm"], cmap["k_s"], cmap["impacts_per_rev"], shading="nearest", cmap="viridis")
    ax.plot(cmap["loss_speed_predicted"], cmap["k_s"], "r-", label="contact loss, inverse kinematics")
    ax.set(xlabel="cam speed Omega_c (rev/min)", ylabel="k_s (N/m)")
    ax.set_title("contact-loss map: impacts per revolution after 3 revolutions (cf. Fig. 9)", fontsize=9)
    ax.legend(fontsize=7)
    _save(plt, fig, img / "perf_contact_loss.png")
