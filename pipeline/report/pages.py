"""The report's own pages, each a function returning matplotlib Figures (call inside report_style())."""

from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.layout_engine import ConstrainedLayoutEngine

from pipeline.aggregate import status_counts
from pipeline.report.calibration import calibration_lines
from pipeline.report.data import ReportData, fmt, rms_row
from pipeline.report.strip import Strip, build_strip
from pipeline.report.style import LANDSCAPE_SIZE_IN, PAGE_SIZE_IN, lighter, material_colors

PSI_LABEL = "Bending angle ψ (deg)"
P_LABEL = "Input pressure P (kPa)"
#: characters per line of wrapped text on a portrait page at 9 pt
WRAP_CHARS = 100
#: text lines per summary page
LINES_PER_PAGE = 62


#: share of the page height kept free at the bottom for the footer
FOOTER_BAND = 0.022


def page(size_in: tuple[float, float] = PAGE_SIZE_IN) -> Figure:
    """A new page laid out by constrained layout, leaving the footer band free."""
    return Figure(figsize=size_in, layout=ConstrainedLayoutEngine(rect=(0.0, FOOTER_BAND, 1.0, 1.0 - FOOTER_BAND)))


# ------------------------------------------------------------------------------------------
# summary (text) pages


def summary_lines(data: ReportData, version: str, config_digest: str | None, warnings: Sequence[str],
                  infos: Sequence[str]) -> list[tuple[str, str]]:
    """The summary as (style, text) lines; style is ``"h"`` (heading), ``"b"`` (body) or ``"w"`` (warning)."""
    lines: list[tuple[str, str]] = []

    def body(text: str, indent: str = "") -> None:
        for part in textwrap.wrap(text, WRAP_CHARS - len(indent), subsequent_indent="    ") or [""]:
            lines.append(("b", indent + part))

    lines.append(("h", "Software and configuration"))
    body(f"pipeline version {version}")
    if data.inputs.config is not None:
        body(f"config {data.inputs.config}: sha256 {config_digest}")
    else:
        body("config: none given (--config); the digest cannot be reported")
    lines.append(("h", "Datasets"))
    counts = status_counts(data.angles)
    for d in data.inputs.datasets:
        c = counts[counts["dataset"] == d.name]
        body(f"{d.name}: {d.angles_csv} (sha256 {data.digests[str(d.angles_csv)][:16]} without the seconds column)")
        body(f"photos {d.photoset_dir or 'not given'}; overlays {d.overlays_dir or 'not given'}", "    ")
        for r in c.itertuples():
            body(f"{r.material}: {r.images} images, {r.ok} ok, {r.flagged} flagged, {r.failed} failed", "    ")
            if r.reasons:
                body(f"reasons: {r.reasons}", "        ")
    tot = counts[["images", "ok", "flagged", "failed"]].sum()
    body(f"total: {int(tot['images'])} images, {int(tot['ok'])} ok, {int(tot['flagged'])} flagged, "
         f"{int(tot['failed'])} failed (flagged and failed are left out of the curves and fits)")
    lines += calibration_lines(data.angles, [d.name for d in data.inputs.datasets])  # issue 17
    lines.append(("h", "Other inputs"))
    for path, digest in data.digests.items():
        if path not in {str(d.angles_csv) for d in data.inputs.datasets}:
            body(f"{path}: sha256 {digest[:16]}")
    for note in list(data.notes) + list(infos):
        body(note)
    lines.append(("h", "Materials"))
    for m in data.materials:
        h = data.hysteresis[data.hysteresis["material"] == m]
        dirs = ", ".join(d for d in ("up", "down") if (h["direction"] == d).any())
        body(f"{m}: {len(h)} pressure levels ({dirs}), up to {fmt(h['pressure_kpa'].max(), 0)} kPa, "
             f"{int(h['n_actuators'].max()) if len(h) else 0} actuator(s)")
    lines.append(("h", "Warnings"))
    if warnings:
        for w in warnings:
            for part in textwrap.wrap("WARNING: " + w, WRAP_CHARS, subsequent_indent="    "):
                lines.append(("w", part))
    else:
        body("none")
    return lines


def text_pages(title: str, lines: Sequence[tuple[str, str]]) -> list[Figure]:
    """Lay (style, text) lines out on as many portrait pages as needed."""
    pages: list[Figure] = []
    chunks = [lines[i:i + LINES_PER_PAGE] for i in range(0, max(len(lines), 1), LINES_PER_PAGE)]
    for k, chunk in enumerate(chunks):
        fig = Figure(figsize=PAGE_SIZE_IN)
        fig.text(0.08, 0.955, title + ("" if k == 0 else " (continued)"), fontsize=14, weight="bold", va="top")
        y, step = 0.91, 0.0135
        for style, text in chunk:
            if style == "h":
                y -= step * 0.5
                fig.text(0.08, y, text, fontsize=10.5, weight="bold", va="top")
            else:
                fig.text(0.08, y, text, fontsize=8.5, va="top", family="DejaVu Sans Mono",
                         color="#b00000" if style == "w" else "black")
            y -= step
        pages.append(fig)
    return pages


# ------------------------------------------------------------------------------------------
# hysteresis plots


#: line styles of successive model curves of one material (one per l0)
CURVE_STYLES: tuple[object, ...] = ("--", ":", "-.", (0, (5, 1, 1, 1)))


def model_lines(data: ReportData, material: str, p_max_kpa: float) -> list[tuple[str, np.ndarray, np.ndarray, object]]:
    """Model curves of ``material`` to draw: ``(label, pressure, psi, linestyle)``, psi order.

    The curves ``compare`` used (``curve`` column: one per l0, labelled with it) when present,
    else the plain model curve.  Pressures outside [0, ``p_max_kpa``] are NaN (not drawn).
    """
    c = data.model_curves[data.model_curves["material"].astype(str) == material]
    if "curve" in c.columns and c["curve"].notna().any():
        groups = [(g, f"model, l0 {float(g['l0_mm'].iloc[0]):g} mm")
                  for _, g in c[c["curve"].notna()].groupby("curve", sort=False)]
    else:
        groups = [(c, "analytical model")] if len(c) else []
    out = []
    for i, (g, label) in enumerate(groups):
        g = g.sort_values("psi_deg", ascending=False, kind="stable")
        p = pd.to_numeric(g["pressure_kpa"], errors="coerce").to_numpy(float)
        s = pd.to_numeric(g["psi_deg"], errors="coerce").to_numpy(float)
        p = np.where((p >= 0) & (p <= p_max_kpa), p, np.nan)
        if np.isfinite(p).any():
            out.append((label, p, s, CURVE_STYLES[i % len(CURVE_STYLES)]))
    return out


def plot_hysteresis(ax: Axes, data: ReportData, material: str, color: tuple[float, float, float],
                    *, legend: bool = True, title: str | None = None) -> None:
    """Fig. 6 style: mean +- 1 sd shaded (darker increasing, lighter decreasing), model dashed."""
    h = data.hysteresis[data.hysteresis["material"] == material]
    p_max = float(h["pressure_kpa"].max()) if len(h) else 1.0
    styles = {"up": (color, 0.35, "increasing P"), "down": (lighter(color), 0.35, "decreasing P")}
    for direction in ("up", "down"):
        b = h[h["direction"] == direction].sort_values("pressure_kpa")
        if b.empty:
            continue
        col, alpha, label = styles[direction]
        p = b["pressure_kpa"].to_numpy(float)
        m = b["psi_mean_deg"].to_numpy(float)
        sd = np.nan_to_num(b["psi_sd_deg"].to_numpy(float))
        ax.fill_between(p, m - sd, m + sd, color=col, alpha=alpha, linewidth=0, label=f"± 1 sd, {label}")
        ax.plot(p, m, color=col, marker="o", markersize=2.5, label=f"mean, {label}")
    for label, mp, ms, style in model_lines(data, material, p_max * 1.02):
        ax.plot(mp, ms, linestyle=style, color="0.15", linewidth=1.2, label=label)
    ax.axhline(0.0, color="0.5", linewidth=0.6, zorder=0)
    ax.set_xlim(left=0.0, right=max(p_max, 1.0) * 1.03)
    ax.set_xlabel(P_LABEL)
    ax.set_ylabel(PSI_LABEL)
    ax.set_title(material if title is None else title)
    if legend:
        ax.legend(loc="best", frameon=False)


def overview_page(data: ReportData) -> Figure:
    """All materials side by side, as the paper's Fig. 6."""
    materials = data.materials
    colors = material_colors(materials)
    n = max(len(materials), 1)
    ncols = 1 if n == 1 else 2
    nrows = math.ceil(n / ncols)
    fig = page()
    fig.suptitle("Bending angle versus input pressure (as Fig. 6 of the paper)")
    axes = fig.subplots(nrows, ncols, squeeze=False)
    for ax, m in zip(axes.flat, materials, strict=False):
        plot_hysteresis(ax, data, m, colors[m], legend=(m == materials[0]))
    for ax in list(axes.flat)[len(materials):]:
        ax.set_axis_off()
    fig.supxlabel("Shaded: mean ± 1 standard deviation over actuators and trials; darker = increasing,\n"
                  "lighter = decreasing pressure; dashed: analytical model (loading branch).\n", fontsize=7.5)
    return fig


def _metric_rows(row: dict[str, float]) -> list[tuple[str, str, str]]:
    g = row.get
    k_ci = f"{fmt(g('k_p_fit'), 2)} [{fmt(g('k_p_ci_low'), 2)}, {fmt(g('k_p_ci_high'), 2)}]"
    return [
        ("RMS model error, both directions (deg)", fmt(g("rms_deg"), 1), fmt(g("paper_rms_deg"), 1)),
        ("RMS, increasing / decreasing P (deg)", f"{fmt(g('rms_up_deg'), 1)} / {fmt(g('rms_down_deg'), 1)}", "n/a"),
        ("P at ψ = 0, increasing / decreasing (kPa)",
         f"{fmt(g('p_zero_up_kpa'), 0)} / {fmt(g('p_zero_down_kpa'), 0)}", fmt(g("paper_p_zero_kpa"), 0)),
        ("P at ψ = -ψ0, increasing / decreasing (kPa)",
         f"{fmt(g('p_minus_psi0_up_kpa'), 0)} / {fmt(g('p_minus_psi0_down_kpa'), 0)}", "n/a"),
        ("Range of motion (deg)", fmt(g("range_deg"), 0), fmt(g("paper_range_deg"), 0)),
        ("... over a pressure span of (kPa)", fmt(g("range_kpa"), 0), fmt(g("paper_range_kpa"), 0)),
        ("Hysteresis width, max |ψ_up - ψ_down| (deg)",
         f"{fmt(g('hysteresis_width_deg'), 0)} at {fmt(g('hysteresis_width_at_kpa'), 0)} kPa", "n/a"),
        ("k_P fitted [95 % bootstrap CI]", k_ci, fmt(g("k_p_paper"), 1)),
    ]


def _table(ax: Axes, header: Sequence[str], rows: Sequence[Sequence[str]], col_widths: Sequence[float],
           fontsize: float = 8.0) -> None:
    ax.set_axis_off()
    table = ax.table(cellText=[list(r) for r in rows], colLabels=list(header), colWidths=list(col_widths),
                     loc="upper center", cellLoc="left", colLoc="left")
    table.auto_set_font_size(False)
    table.set_fontsize(fontsize)
    table.scale(1.0, 1.35)
    for (r, _c), cell in table.get_celld().items():
        cell.set_linewidth(0.4)
        if r == 0:
            cell.set_text_props(weight="bold")
            cell.set_facecolor("#eeeeee")


def plot_per_actuator(ax: Axes, data: ReportData, material: str, color: tuple[float, float, float]) -> None:
    """Mean psi of each actuator (over its trials): solid increasing, dashed decreasing pressure."""
    per = data.per_actuator[data.per_actuator["material"] == material]
    markers = "os^vD<>ph*"
    for i, (actuator, g) in enumerate(per.groupby("actuator", sort=True)):
        for direction, ls in (("up", "-"), ("down", "--")):
            b = g[g["direction"] == direction].sort_values("pressure_kpa")
            if b.empty:
                continue
            ax.plot(b["pressure_kpa"], b["psi_mean_deg"], linestyle=ls, marker=markers[i % len(markers)],
                    markersize=2.5, linewidth=0.9, color=color if direction == "up" else lighter(color, 0.4),
                    label=f"{actuator}" if direction == "up" else None)
    ax.axhline(0.0, color="0.5", linewidth=0.6, zorder=0)
    ax.set_xlim(left=0.0)
    ax.set_xlabel(P_LABEL)
    ax.set_ylabel(PSI_LABEL)
    ax.set_title("Per actuator (solid: increasing, dashed: decreasing P)", fontsize=8.5)
    if len(per):
        ax.legend(title="actuator", loc="best", frameon=False, fontsize=6.5, title_fontsize=7)


def draw_strip(fig_or_sub: Figure, strip: Strip | None) -> None:
    """Photos of one ramp in a row, captioned with pressure and measured psi."""
    if strip is None or not strip.photos:
        ax = fig_or_sub.subplots()
        ax.set_axis_off()
        ax.text(0.5, 0.5, "no photos for this material", ha="center", va="center")
        return
    axes = fig_or_sub.subplots(1, len(strip.photos), squeeze=False)[0]
    for ax, photo in zip(axes, strip.photos, strict=True):
        ax.set_axis_off()
        if photo.image is not None:
            ax.imshow(photo.image, interpolation="none")
        else:
            ax.text(0.5, 0.5, "photo\nnot found", ha="center", va="center", fontsize=7, transform=ax.transAxes)
        psi = "ψ: none" if not math.isfinite(photo.psi_deg) else f"ψ = {photo.psi_deg:.0f}°"
        flag = "" if photo.status == "ok" else f" ({photo.status})"
        ax.set_title(f"{photo.pressure_kpa:g} kPa\n{psi}{flag}", fontsize=7.5)
    direction = "increasing" if strip.direction == "up" else "decreasing"
    fig_or_sub.suptitle(
        f"Photos across the ramp (as Fig. 5): actuator {strip.actuator}, trial {strip.trial} ({strip.dataset}), "
        f"{direction} pressure\n{strip.note}",
        fontsize=8,
    )


def material_page(data: ReportData, material: str) -> Figure:
    """One material: Fig. 6 plot, per-actuator curves, metric table, Fig. 5-style photo strip."""
    color = material_colors(data.materials)[material]
    fig = page()
    fig.suptitle(f"{material}: bending angle versus pressure")
    top, middle, bottom = fig.subfigures(3, 1, height_ratios=[4.6, 3.6, 1.8])
    plot_hysteresis(top.subplots(), data, material, color,
                    title="Mean ± 1 sd over actuators and trials (as Fig. 6); dashed: model")
    left, right = middle.subfigures(1, 2, width_ratios=[1.0, 1.25])
    plot_per_actuator(left.subplots(), data, material, color)
    ax = right.subplots()
    _table(ax, ["", "this run", "paper"], _metric_rows(rms_row(data, material)), [0.56, 0.30, 0.14], fontsize=7)
    ax.set_title("Model comparison (rms.csv)", fontsize=8.5)
    draw_strip(bottom, build_strip(data, material))
    return fig


def comparison_page(data: ReportData) -> Figure:
    """Table of RMS, crossings and range per material beside the paper's values, and bar charts."""
    materials = data.materials
    fig = page(LANDSCAPE_SIZE_IN)
    fig.suptitle("Model versus measurements, beside the values reported in the paper (Section III.A)")
    upper, lower = fig.subfigures(2, 1, height_ratios=[0.8, 1.2])
    ax = upper.subplots()
    rows_by_m = {m: _metric_rows(rms_row(data, m)) for m in materials}
    labels = [r[0] for r in _metric_rows({})]
    body = []
    for i, label in enumerate(labels):
        cells = []
        for m in materials:
            ours, paper = rows_by_m[m][i][1], rows_by_m[m][i][2]
            cells.append(ours if paper == "n/a" else f"{ours}   (paper {paper})")
        body.append([label] + cells)
    n = max(len(materials), 1)
    _table(ax, ["this run (paper)"] + materials, body, [0.28] + [0.72 / n] * len(materials),
           fontsize=7.5 if n <= 2 else 7.0)
    axes = lower.subplots(1, 3)
    x = np.arange(len(materials))
    bars = (
        ("RMS model error, both directions", "RMS (deg)", "rms_deg", "paper_rms_deg"),
        ("Pressure at ψ = 0 (increasing P)", "P at ψ = 0 (kPa)", "p_zero_up_kpa", "paper_p_zero_kpa"),
        ("Total range of motion", "Range of motion (deg)", "range_deg", "paper_range_deg"),
    )
    for ax, (title, ylabel, ours_key, paper_key) in zip(axes, bars, strict=True):
        ours = [float(rms_row(data, m).get(ours_key, math.nan)) for m in materials]
        paper = [float(rms_row(data, m).get(paper_key, math.nan)) for m in materials]
        ax.bar(x - 0.2, np.nan_to_num(ours), width=0.4, color="#4c72b0", label="this run")
        ax.bar(x + 0.2, np.nan_to_num(paper), width=0.4, color="#bbbbbb", label="paper")
        ax.set_xticks(x, materials)
        ax.set_xlabel("Material")
        ax.set_ylabel(ylabel)
        ax.set_title(title, fontsize=9)
        ax.grid(axis="x", visible=False)
    axes[0].legend(frameon=False)
    lower.supxlabel("RMS: model (loading branch) at the measured pressure levels against the mean curve; "
                    "crossings interpolated linearly along each ramp; missing values drawn as 0 and shown n/a "
                    "in the table.", fontsize=7)
    return fig
