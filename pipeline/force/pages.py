"""Report pages for blocked force, eccentricity and grasping (paper Figs. 7A, 7B and 8B).

:func:`figures` reads the files of a *force directory* (written by ``python -m pipeline force``;
each is optional, a page is made for each file present):

=========================  =====================================================================
file                       written by / page
=========================  =====================================================================
force_summary.csv          ``force aggregate``: Fig. 7A force (N) against pressure (kPa), mean
                           +- sd shading per material; eccentricity against pressure
eccentricity_summary.csv   ``force aggregate``: Fig. 7B table of e at the maximum pressure and a
                           representative photo per material with the fitted ellipse drawn
grasp_summary.csv          ``force grasp``: Fig. 8B heaviest mass held (g) against pressure (kPa)
=========================  =====================================================================
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from pipeline.force.grasp import grasp_figure

FORCE_SUMMARY = "force_summary.csv"
ECCENTRICITY_SUMMARY = "eccentricity_summary.csv"
GRASP_SUMMARY = "grasp_summary.csv"

A4_PORTRAIT = (8.27, 11.69)


def figures(force_dir: Path) -> list[Figure]:
    """Report pages for the files present in ``force_dir`` (see module docstring).

    Parameters
    ----------
    force_dir : Path
        Folder written by ``python -m pipeline force aggregate/grasp``.

    Returns
    -------
    list of matplotlib.figure.Figure
        Empty when the folder holds none of the files.
    """
    force_dir = Path(force_dir)
    out: list[Figure] = []
    if (force_dir / FORCE_SUMMARY).is_file():
        out.append(force_figure(pd.read_csv(force_dir / FORCE_SUMMARY)))
    if (force_dir / ECCENTRICITY_SUMMARY).is_file():
        summary = pd.read_csv(force_dir / ECCENTRICITY_SUMMARY)
        if len(summary):
            out.append(eccentricity_figure(summary, base=force_dir))
    if (force_dir / GRASP_SUMMARY).is_file():
        out.append(grasp_figure(pd.read_csv(force_dir / GRASP_SUMMARY)))
    return out


def force_figure(summary: pd.DataFrame) -> Figure:
    """Fig. 7A-style page: blocked force (N) against pressure (kPa), mean +- 1 sd per material,
    and below it the mean eccentricity against pressure where measured."""
    fig = Figure(figsize=A4_PORTRAIT)
    has_e = "eccentricity_mean" in summary.columns and summary["eccentricity_mean"].notna().any()
    ax = fig.add_subplot(2, 1, 1) if has_e else fig.add_subplot(1, 1, 1)
    for j, (material, m) in enumerate(summary.groupby("material", sort=True)):
        for direction, d in m.groupby("direction", sort=True):
            d = d.sort_values("pressure_kpa")
            p = d["pressure_kpa"].to_numpy(float)
            f = d["force_mean_n"].to_numpy(float)
            sd = np.nan_to_num(d["force_sd_n"].to_numpy(float))
            style = "-" if direction == "up" else "--"
            label = str(material) if direction == "up" else f"{material} ({direction})"
            ax.plot(p, f, style, marker="o", ms=3, color=f"C{j}", label=label)
            ax.fill_between(p, f - sd, f + sd, color=f"C{j}", alpha=0.25 if direction == "up" else 0.12, lw=0)
    ax.set_xlabel("pressure (kPa)")
    ax.set_ylabel("blocked force F (N)")
    ax.set_title("Blocked force against pressure (mean, shading: one standard deviation; cf. Fig. 7A)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    if has_e:
        ax2 = fig.add_subplot(2, 1, 2)
        for j, (material, m) in enumerate(summary.groupby("material", sort=True)):
            d = m[m["eccentricity_mean"].notna()].sort_values("pressure_kpa")
            d = d[d["direction"] == "up"] if (d["direction"] == "up").any() else d
            e = d["eccentricity_mean"].to_numpy(float)
            sd = np.nan_to_num(d["eccentricity_sd"].to_numpy(float))
            ax2.errorbar(d["pressure_kpa"], e, yerr=sd, fmt="o-", ms=3, capsize=2, color=f"C{j}", label=str(material))
        ax2.set_xlabel("pressure (kPa)")
        ax2.set_ylabel("eccentricity e (-)")
        ax2.set_ylim(0, 1)
        ax2.set_title("Eccentricity of the blocked inextensible layer (ok photos; bars: one sd)", fontsize=10)
        ax2.grid(alpha=0.3)
        ax2.legend(fontsize=8)
    fig.tight_layout()
    return fig


def eccentricity_figure(summary: pd.DataFrame, *, base: Path | None = None) -> Figure:
    """Fig. 7B-style page: table of e at the maximum pressure per material and, when the photo
    is reachable, a representative photo with the fitted ellipse (yellow dashed) drawn on it."""
    fig = Figure(figsize=A4_PORTRAIT)
    n = len(summary)
    cols = 2
    rows = int(np.ceil(n / cols))
    grid = fig.add_gridspec(rows + 1, cols, height_ratios=[0.55] + [1.0] * rows)
    tab = fig.add_subplot(grid[0, :])
    tab.set_axis_off()
    cells = [
        [
            str(r["material"]),
            f"{r['pressure_kpa']:g}",
            f"{r['eccentricity_mean']:.3f}" if np.isfinite(r["eccentricity_mean"]) else "-",
            f"{r['eccentricity_sd']:.3f}" if np.isfinite(r["eccentricity_sd"]) else "-",
            f"{int(r['n'])}",
            f"{int(r['n_excluded'])}",
            f"{r['force_mean_n']:.2f}" if np.isfinite(r["force_mean_n"]) else "-",
        ]
        for _, r in summary.iterrows()
    ]
    table = tab.table(
        cellText=cells,
        colLabels=["material", "max pressure (kPa)", "e mean (-)", "e sd (-)", "n ok", "n excluded", "force (N)"],
        loc="center",
    )
    table.auto_set_font_size(False)
    table.set_fontsize(8)
    tab.set_title("Eccentricity at the maximum pressure (cf. Fig. 7B)", fontsize=10)
    for k, (_, r) in enumerate(summary.iterrows()):
        ax = fig.add_subplot(grid[1 + k // cols, k % cols])
        _draw_photo(ax, r, base)
    fig.tight_layout()
    return fig


def _draw_photo(ax: Axes, r: pd.Series, base: Path | None) -> None:
    import cv2

    title = f"{r['material']} at {r['pressure_kpa']:g} kPa"
    path = r.get("image_path")
    image = None
    if isinstance(path, str) and path:
        p = Path(path)
        if not p.is_absolute() and base is not None:
            p = base / p
        if p.is_file():
            image = cv2.imread(str(p), cv2.IMREAD_COLOR)
    if image is None:
        ax.text(0.5, 0.5, f"{title}\n(photo not available)", ha="center", va="center", transform=ax.transAxes, fontsize=8)
        ax.set_axis_off()
        return
    ax.imshow(cv2.cvtColor(image, cv2.COLOR_BGR2RGB))
    keys = ("centre_x_px", "centre_y_px", "semi_major_px", "semi_minor_px", "angle_deg")
    if all(k in r.index and np.isfinite(r[k]) for k in keys):
        t = np.linspace(0.0, 2.0 * np.pi, 300)
        th = np.deg2rad(r["angle_deg"])
        a, b = r["semi_major_px"], r["semi_minor_px"]
        x = r["centre_x_px"] + a * np.cos(t) * np.cos(th) - b * np.sin(t) * np.sin(th)
        y = r["centre_y_px"] + a * np.cos(t) * np.sin(th) + b * np.sin(t) * np.cos(th)
        ax.plot(x, y, "--", color="yellow", lw=1.5)
        title += f": e = {r['image_eccentricity']:.2f}"
    ax.set_title(title, fontsize=8)
    ax.set_axis_off()
