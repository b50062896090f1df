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

Every page is A4 in the report's style; each material has the same colour as on the report's
own pages (:func:`pipeline.layout.style.material_colors`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.transforms import offset_copy

from pipeline.fileio import read_table
from pipeline.layout.style import FOOTER_PT, MARGIN_PT, Color, material_colors, page, report_style
from pipeline.layout.typeset import Column, Flow, Table, fmt, table_height_pt

FORCE_SUMMARY = "force_summary.csv"
ECCENTRICITY_SUMMARY = "eccentricity_summary.csv"
GRASP_SUMMARY = "grasp_summary.csv"
#: the files :func:`figures` reads
FILES: tuple[str, ...] = (FORCE_SUMMARY, ECCENTRICITY_SUMMARY, GRASP_SUMMARY)
#: widest photo drawn on the eccentricity page (px): about its printed width at 150 dpi
PHOTO_MAX_WIDTH_PX = 400
P_LABEL = "pressure (kPa)"
PAGE_W_PT = 595.0


def _read(force_dir: Path, name: str) -> pd.DataFrame | None:
    path = force_dir / name
    return (
        read_table(path, f"the {name} written by 'python -m pipeline force'")
        if path.is_file()
        else None
    )


def figures(
    force_dir: Path,
    colors: Mapping[str, Color] | None = None,
    *,
    synthetic: Sequence[str] = (),
    grasp_example: bool = False,
) -> list[Figure]:
    """Report pages for the files present in ``force_dir`` (see module docstring).

    Parameters
    ----------
    force_dir : Path
        Folder written by ``python -m pipeline force aggregate/grasp``.
    colors : mapping, optional
        Colour of each material (the report passes its own); others get
        :func:`~pipeline.layout.style.material_colors`.
    synthetic : sequence of str
        Materials whose blocked-force photos were rendered, not taken: the force and
        eccentricity pages say so.
    grasp_example : bool
        The grasp log is the paper's example (the shipped ``grasp_example.csv``): its page says so.

    Returns
    -------
    list of matplotlib.figure.Figure
        Empty when the folder holds none of the files.
    """
    force_dir = Path(force_dir)
    tables = {name: _read(force_dir, name) for name in FILES}
    found = sorted(
        {
            str(m)
            for t in tables.values()
            if t is not None and "material" in t
            for m in t["material"]
        }
    )
    palette = {**material_colors(sorted(set(found) | set(colors or {}))), **dict(colors or {})}
    out: list[Figure] = []
    note = synthetic_note(synthetic)
    if tables[FORCE_SUMMARY] is not None:
        out.append(force_figure(tables[FORCE_SUMMARY], palette, note=note))
    summary = tables[ECCENTRICITY_SUMMARY]
    if summary is not None and len(summary):
        out.append(eccentricity_figure(summary, palette, base=force_dir, note=note))
    if tables[GRASP_SUMMARY] is not None:
        out.append(grasp_figure(tables[GRASP_SUMMARY], palette, example=grasp_example))
    return out


def synthetic_note(materials: Sequence[str]) -> str:
    """The line a force page carries when some of its materials' photos were rendered.

    >>> synthetic_note(["SS40", "DS20"])
    'synthetic (rendered by the virtual rig, not measured): DS20, SS40'
    >>> synthetic_note([])
    ''
    """
    return (
        f"synthetic (rendered by the virtual rig, not measured): {', '.join(sorted(materials))}"
        if materials
        else ""
    )


@report_style()
def force_figure(summary: pd.DataFrame, colors: Mapping[str, Color], note: str = "") -> Figure:
    """Fig. 7A-style page: blocked force (N) against pressure (kPa), mean +- 1 sd per material,
    and below it the mean eccentricity against pressure where measured."""
    fig = page(label="force")
    has_e = "eccentricity_mean" in summary.columns and summary["eccentricity_mean"].notna().any()
    axes = fig.subplots(2 if has_e else 1, 1, squeeze=False)[:, 0]
    ax = axes[0]
    for material, m in summary.groupby("material", sort=True):
        c = colors[str(material)]
        for direction, d in m.groupby("direction", sort=True):
            d = d.sort_values("pressure_kpa")
            p = d["pressure_kpa"].to_numpy(float)
            f = d["force_mean_n"].to_numpy(float)
            sd = np.nan_to_num(d["force_sd_n"].to_numpy(float))
            label = str(material) if direction == "up" else f"{material} (decreasing P)"
            ax.plot(
                p, f, "-" if direction == "up" else "--", marker="o", ms=3, color=c, label=label
            )
            ax.fill_between(
                p, f - sd, f + sd, color=c, alpha=0.25 if direction == "up" else 0.12, lw=0
            )
    sd_max = (
        float(np.nanmax(summary["force_sd_n"].to_numpy(float))) if len(summary) else float("nan")
    )
    n = int(summary["n"].max()) if "n" in summary and len(summary) else 0
    ax.set_xlabel(P_LABEL)
    ax.set_ylabel("blocked force F (N)")
    span = float(np.nanmax(summary["force_mean_n"].to_numpy(float))) if len(summary) else 0.0
    hidden = span > 0 and 2 * sd_max < 0.02 * span
    ax.set_title(
        f"Blocked force against pressure (cf. Fig. 7A)\nmean of {n} ramp(s) per level, ± 1 sd "
        "shaded; "
        f"largest sd {fmt(sd_max, 3)} N"
        + (", so the shading hides behind the lines" if hidden else "")
        + (f"\n{note}" if note else "")
    )
    ax.legend(loc="upper left", frameon=False)
    if has_e:
        ax2 = axes[1]
        for material, m in summary.groupby("material", sort=True):
            d = m[m["eccentricity_mean"].notna()].sort_values("pressure_kpa")
            d = d[d["direction"] == "up"] if (d["direction"] == "up").any() else d
            e = d["eccentricity_mean"].to_numpy(float)
            sd = np.nan_to_num(d["eccentricity_sd"].to_numpy(float))
            ax2.errorbar(
                d["pressure_kpa"],
                e,
                yerr=sd,
                fmt="o-",
                ms=3,
                capsize=2,
                color=colors[str(material)],
                label=str(material),
            )
        ax2.set_xlabel(P_LABEL)
        ax2.set_ylabel("eccentricity e (-)")
        ax2.set_ylim(0, 1)
        ax2.set_title(
            "Eccentricity of the blocked inextensible layer, increasing P (ok photos; bars: ± 1 sd)"
        )
        ax2.legend(loc="upper left", frameon=False)
    return fig


def eccentricity_table(summary: pd.DataFrame, note: str = "") -> Table:
    """e at the maximum pressure per material, typeset."""
    rows = tuple(
        (
            str(r["material"]),
            fmt(r["pressure_kpa"], 0),
            fmt(r["eccentricity_mean"], 3),
            fmt(r["eccentricity_sd"], 3),
            fmt(r["n"], 0),
            fmt(r["n_excluded"], 0),
            fmt(r["force_mean_n"], 2),
        )
        for _, r in summary.iterrows()
    )
    return Table(
        columns=(
            Column("material", "left"),
            Column("max pressure (kPa)"),
            Column("e mean (-)"),
            Column("e sd (-)"),
            Column("photos ok"),
            Column("excluded"),
            Column("force (N)"),
        ),
        rows=rows,
        title="Eccentricity at the maximum pressure (cf. Fig. 7B)" + (f"; {note}" if note else ""),
        size=8.0,
    )


@report_style()
def eccentricity_figure(summary: pd.DataFrame, colors: Mapping[str, Color] | None = None, *,
                        base: Path | None = None, note: str = "") -> Figure:
    """Fig. 7B-style page: table of e at the maximum pressure per material and, when the photo
    is reachable, a representative photo with the fitted ellipse (yellow dashed) drawn on it."""
    palette = {**material_colors(sorted(summary["material"].astype(str))), **dict(colors or {})}
    table = eccentricity_table(summary, note)
    width = PAGE_W_PT - 2 * MARGIN_PT
    top = 36.0 + table_height_pt(table, width) + 10.0
    fig = page(label="eccentricity", top_pt=top)
    Flow(fig, top_pt=36.0).table(table)
    n = len(summary)
    cols = 2 if n > 1 else 1
    axes = list(fig.subplots(int(np.ceil(n / cols)), cols, squeeze=False).flat)
    for ax, (_, r) in zip(axes, summary.iterrows(), strict=False):
        _draw_photo(ax, r, base, palette.get(str(r["material"]), (0.0, 0.0, 0.0)))
    for ax in axes[n:]:
        ax.set_axis_off()
    return fig


def _draw_photo(ax: Axes, r: pd.Series, base: Path | None, color: Color) -> None:
    title = f"{r['material']} at {r['pressure_kpa']:g} kPa"
    path = r.get("image_path")
    image = None
    if isinstance(path, str) and path:
        p = Path(path)
        if not p.is_absolute() and not p.is_file() and base is not None:
            p = base / p
        if p.is_file():
            image = cv2.imread(str(p), cv2.IMREAD_COLOR)
    ax.set_axis_off()
    if image is None:
        ax.text(
            0.5,
            0.5,
            f"{title}\n(photo not available)",
            ha="center",
            va="center",
            transform=ax.transAxes,
        )
        return
    f = min(1.0, PHOTO_MAX_WIDTH_PX / image.shape[1])
    small = cv2.resize(image, None, fx=f, fy=f, interpolation=cv2.INTER_AREA) if f < 1 else image
    ax.imshow(
        cv2.cvtColor(small, cv2.COLOR_BGR2RGB),
        extent=(-0.5, image.shape[1] - 0.5, image.shape[0] - 0.5, -0.5),
        interpolation="none",
    )
    keys = ("centre_x_px", "centre_y_px", "semi_major_px", "semi_minor_px", "angle_deg")
    if all(k in r.index and np.isfinite(r[k]) for k in keys):
        t = np.linspace(0.0, 2.0 * np.pi, 300)
        th = np.deg2rad(r["angle_deg"])
        a, b = r["semi_major_px"], r["semi_minor_px"]
        x = r["centre_x_px"] + a * np.cos(t) * np.cos(th) - b * np.sin(t) * np.sin(th)
        y = r["centre_y_px"] + a * np.cos(t) * np.sin(th) + b * np.sin(t) * np.cos(th)
        ax.plot(x, y, "--", color="yellow", lw=1.5)
        title += f": e = {r['image_eccentricity']:.2f} (fitted ellipse dashed)"
    ax.set_title(title, color=color, fontweight="bold")


def grasp_table(summary: pd.DataFrame) -> Table:
    """The grasp-log summary, one row per material, side and object: mass held at each pressure."""
    rows = []
    for (material, side, diameter), g in summary.groupby(
        ["material", "side", "diameter_mm"], sort=True
    ):
        cells = [f"{fmt(r.pressure_kpa, 0)}: " + ("not held" if not np.isfinite(r.max_mass_held_g)
                                                  else fmt(r.max_mass_held_g, 0))
                 for r in g.sort_values("pressure_kpa").itertuples()]
        rows.append((str(material), str(side), fmt(diameter, 0), ", ".join(cells),
                     f"{int(g['n_held'].sum())} of {int(g['n_attempts'].sum())}"))
    return Table(
        columns=(
            Column("material", "left"),
            Column("side", "left"),
            Column("object diameter (mm)"),
            Column("pressure (kPa): heaviest mass held (g)", "left", wrap_pt=260.0),
            Column("attempts held"),
        ),
        rows=tuple(rows),
        title="Grasp log summary",
        size=7.5,
        notes=(
            (
                "not held: no attempt at that pressure held the object (a red x on the zero line "
                "above)."
            ),
        ),
    )


@report_style()
def grasp_figure(
    summary: pd.DataFrame, colors: Mapping[str, Color] | None = None, *, example: bool = False
) -> Figure:
    """Fig. 8B-style page: heaviest mass held (g) against pressure (kPa), one line per material.

    One panel per (side, object diameter), all on the same axes ranges so panels compare at a
    glance; pressures where nothing was held are drawn as a red cross on the zero line and
    labelled; the whole log summary is in a table below.

    Parameters
    ----------
    summary : pandas.DataFrame
        Output of :func:`pipeline.force.grasp.heaviest_held`.
    colors : mapping, optional
        Colour of each material.
    example : bool
        The log is the paper's example: the title says so.

    Returns
    -------
    matplotlib.figure.Figure
    """
    palette = {
        **material_colors(sorted(summary["material"].astype(str).unique())),
        **dict(colors or {}),
    }
    groups = list(summary.groupby(["side", "diameter_mm"], sort=True))
    table = grasp_table(summary)
    width = PAGE_W_PT - 2 * MARGIN_PT
    table_h = table_height_pt(table, width) + 10.0
    fig = page(label="grasp", bottom_pt=table_h)
    fig.suptitle(
        "Grasp log: heaviest mass held against pressure (cf. Fig. 8B)"
        + (
            "\nthe paper's example, transcribed from its text (config force.grasp_log: your own)"
            if example
            else ""
        )
    )
    if not groups:
        ax = fig.subplots()
        ax.text(0.5, 0.5, "grasp log has no rows", ha="center", va="center", transform=ax.transAxes)
        ax.set_axis_off()
        return fig
    cols = 2 if len(groups) > 1 else 1
    axes = fig.subplots(
        int(np.ceil(len(groups) / cols)), cols, squeeze=False, sharex=True, sharey=True
    )
    p_max = float(summary["pressure_kpa"].max())
    m_max = float(np.nanmax(np.append(summary["max_mass_held_g"].to_numpy(float), 1.0)))
    for ax, ((side, diameter), g) in zip(axes.flat, groups, strict=False):
        for j, (material, m) in enumerate(g.groupby("material", sort=True)):
            m = m.sort_values("pressure_kpa")
            ok = m["max_mass_held_g"].notna()
            # shrinking markers drawn on top of each other: materials with equal values stay visible
            # as rings
            ax.plot(
                m.loc[ok, "pressure_kpa"],
                m.loc[ok, "max_mass_held_g"],
                "o-",
                color=palette[str(material)],
                label=str(material),
                ms=max(10.0 - 1.7 * j, 5.0),
                mec="white",
                mew=0.6,
                lw=1.2,
                zorder=2 + j,
            )
            if (~ok).any():
                ax.plot(
                    m.loc[~ok, "pressure_kpa"],
                    np.zeros(int((~ok).sum())),
                    "x",
                    color="#b00000",
                    ms=8,
                    mew=2,
                    clip_on=False,
                    zorder=5,
                )
                for p in m.loc[~ok, "pressure_kpa"]:
                    ax.text(
                        p,
                        0.0,
                        f"{material} not held",
                        ha="center",
                        fontsize=7.0,
                        color="#b00000",
                        transform=offset_copy(ax.transData, fig=fig, y=8.0, units="points"),
                    )
        ax.set_title(f"{side} an object of {diameter:g} mm diameter")
        ax.set_xlim(-0.04 * p_max - 1.0, 1.08 * p_max + 1.0)
        ax.set_ylim(0.0, 1.15 * m_max)
        ax.grid(alpha=0.3)
        ax.legend(loc="best", frameon=False)
    for ax in axes[-1, :]:
        ax.set_xlabel(P_LABEL)
    for ax in axes[:, 0]:
        ax.set_ylabel("heaviest mass held (g)")
    for ax in list(axes.flat)[len(groups):]:
        ax.set_axis_off()
    Flow(fig, top_pt=72.0 * fig.get_figheight() - FOOTER_PT - table_h + 4.0).table(table)
    return fig
